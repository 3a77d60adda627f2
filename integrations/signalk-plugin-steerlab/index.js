/*
 * signalk-plugin-steerlab: steerlab's runtime autopilot as a Signal K autopilot provider.
 *
 * Registers one autopilot device (default id "steerlab") with the Signal K server's v2
 * Autopilot API (/signalk/v2/api/vessels/self/autopilots), so every Signal K app can engage,
 * disengage, set and adjust the target heading of `steerlab autopilot`.
 *
 * The link is steerlab's existing Signal K over UDP (no dependencies, Node's dgram only):
 *   - commands: delta messages to the autopilot's --signalk-listen port, paths
 *     steering.autopilot.target.headingTrue (rad) and steering.autopilot.state (auto|standby);
 *   - status: the autopilot's own deltas, sent each sample to --signalk-to (this plugin's
 *     statusPort): steering.autopilot.state and steering.autopilot.target.headingTrue.
 * Without a status datagram for `offlineTimeout` seconds the device is "off-line" and commands
 * are refused (503). While steerlab's status says it would not apply a target heading
 * (steering.autopilot.steerlab.targetRefused: it follows a route or a chart plotter's course),
 * setting or adjusting the target is refused (409) with steerlab's reason. Angles are radians, true heading, as everywhere in Signal K.
 * Signal K v1 PUTs on those two paths are handled too (registerPutHandler), with the same checks.
 */
'use strict'

const dgram = require('dgram')

const TWO_PI = 2 * Math.PI
const TARGET = 'steering.autopilot.target.headingTrue'
const STATE = 'steering.autopilot.state'
const REFUSED = 'steering.autopilot.steerlab.targetRefused' // steerlab's reason a target is not applied
const STATES = [
  { name: 'auto', engaged: true },
  { name: 'standby', engaged: false }
]
const MODES = ['compass'] // heading hold (true heading); steerlab's route/plotter modes are set at its CLI
const ACTIONS = [
  { id: 'dodge', name: 'Dodge', available: false },
  { id: 'tack', name: 'Tack', available: false },
  { id: 'gybe', name: 'Gybe', available: false },
  { id: 'courseCurrentPoint', name: 'Steer to current destination', available: false },
  { id: 'courseNextPoint', name: 'Steer to next point', available: false }
]

/** An error the server's Autopilot API turns into its JSON error response. */
function fail (statusCode, message) {
  const err = new Error(message)
  err.statusCode = statusCode
  err.state = 'FAILED'
  return err
}

/** An angle [rad] in [0, 2 pi) strictly. */
function wrap (a) {
  const w = ((a % TWO_PI) + TWO_PI) % TWO_PI
  return w >= TWO_PI ? 0 : w
}

/** {path: value} from a delta message (Buffer or string), or null. */
function parseDelta (data) {
  let msg
  try {
    msg = JSON.parse(data.toString('utf8'))
  } catch (e) {
    return null
  }
  if (!msg || !Array.isArray(msg.updates)) return null
  const out = {}
  for (const u of msg.updates) {
    if (!u || !Array.isArray(u.values)) return null
    for (const v of u.values) {
      if (v && typeof v.path === 'string') out[v.path] = v.value
    }
  }
  return out
}

function delta (values) {
  return JSON.stringify({
    context: 'vessels.self',
    updates: [{
      source: { label: 'signalk-plugin-steerlab', type: 'signalk' },
      timestamp: new Date().toISOString(),
      values: Object.entries(values).map(([path, value]) => ({ path, value }))
    }]
  })
}

module.exports = function (app) {
  const plugin = {
    id: 'signalk-plugin-steerlab',
    name: 'steerlab autopilot',
    description: 'steerlab runtime autopilot as a Signal K autopilot provider (v2 Autopilot API)'
  }

  plugin.schema = {
    type: 'object',
    properties: {
      deviceId: { type: 'string', title: 'Autopilot id', default: 'steerlab' },
      host: { type: 'string', title: 'steerlab autopilot host (its --signalk-listen)', default: '127.0.0.1' },
      commandPort: { type: 'number', title: 'steerlab --signalk-listen UDP port', default: 10111 },
      statusHost: { type: 'string', title: 'bind address for the status deltas', default: '127.0.0.1' },
      statusPort: { type: 'number', title: 'UDP port steerlab --signalk-to sends to', default: 10112 },
      offlineTimeout: { type: 'number', title: 'off-line after no status for [s]', default: 3 }
    }
  }

  let sock = null
  let timer = null
  let opts = {}
  let last = { state: null, target: null, seen: 0, refused: null }
  let published = {}
  // a command's value wins over status deltas that were already on their way (for SETTLE_MS,
  // or until steerlab reports it), so two quick adjustments add up instead of using a stale base
  const SETTLE_MS = 1500
  let pending = {}
  const expect = (key, value) => { pending[key] = { value, until: Date.now() + SETTLE_MS } }
  const accept = (key, value, same) => {
    const p = pending[key]
    if (p && Date.now() < p.until && !same(p.value, value)) return false
    delete pending[key]
    return true
  }

  const online = () => last.seen > 0 && (Date.now() - last.seen) / 1000 <= opts.offlineTimeout
  const state = () => (online() ? last.state : 'off-line')
  const engaged = () => state() === 'auto'

  function publish () {
    const info = { state: state(), mode: 'compass', target: last.target, engaged: engaged() }
    const changed = {}
    for (const [k, v] of Object.entries(info)) {
      if (published[k] !== v) changed[k] = v
    }
    if (Object.keys(changed).length) {
      published = { ...published, ...changed }
      app.autopilotUpdate(opts.deviceId, changed)
    }
  }

  function send (values) {
    return new Promise((resolve, reject) => {
      if (!sock) return reject(fail(503, 'steerlab plugin is not running'))
      if (!online()) return reject(fail(503, `steerlab autopilot is off-line (no status on UDP ${opts.statusPort})`))
      sock.send(delta(values), opts.commandPort, opts.host, (err) =>
        err ? reject(fail(502, `cannot reach steerlab: ${err.message}`)) : resolve())
    })
  }

  /** Refuse a target heading steerlab would not apply (409, its reason). */
  function checkTargetApplies () {
    if (online() && last.refused) throw fail(409, last.refused)
  }

  function checkDevice (deviceId) {
    if (deviceId !== opts.deviceId && deviceId !== '_default') {
      throw fail(404, `unknown autopilot ${deviceId}`)
    }
  }

  const provider = {
    async getData (deviceId) {
      checkDevice(deviceId)
      return {
        options: { states: STATES, modes: MODES, actions: ACTIONS },
        state: state(),
        mode: 'compass',
        target: last.target,
        engaged: engaged()
      }
    },
    async getState (deviceId) {
      checkDevice(deviceId)
      return state()
    },
    async setState (value, deviceId) {
      checkDevice(deviceId)
      if (!STATES.some((s) => s.name === value)) {
        throw fail(400, `state must be one of ${STATES.map((s) => s.name).join(', ')}`)
      }
      await send({ [STATE]: value })
      last.state = value
      expect('state', value)
      publish()
    },
    async getMode (deviceId) {
      checkDevice(deviceId)
      return 'compass'
    },
    async setMode (value, deviceId) {
      checkDevice(deviceId)
      if (!MODES.includes(value)) throw fail(400, `mode must be one of ${MODES.join(', ')}`)
    },
    async getTarget (deviceId) {
      checkDevice(deviceId)
      return last.target
    },
    async setTarget (value, deviceId) {
      checkDevice(deviceId)
      // the server clamps the request to [-pi, 2 pi]: 2 pi itself stands for anything above it
      if (typeof value !== 'number' || !Number.isFinite(value) || value < -Math.PI || value >= TWO_PI) {
        throw fail(400, 'target must be a heading in radians, -pi <= value < 2 pi')
      }
      checkTargetApplies()
      const t = wrap(value)
      await send({ [TARGET]: t })
      last.target = t
      expect('target', t)
      publish()
    },
    async adjustTarget (value, deviceId) {
      checkDevice(deviceId)
      if (typeof value !== 'number' || !Number.isFinite(value) || Math.abs(value) > Math.PI) {
        throw fail(400, 'adjustment must be in radians, |value| <= pi')
      }
      if (last.target === null) throw fail(409, 'no target heading yet to adjust')
      checkTargetApplies()
      const t = wrap(last.target + value)
      await send({ [TARGET]: t })
      last.target = t
      expect('target', t)
      publish()
    },
    async engage (deviceId) {
      checkDevice(deviceId)
      await send({ [STATE]: 'auto' })
      last.state = 'auto'
      expect('state', 'auto')
      publish()
    },
    async disengage (deviceId) {
      checkDevice(deviceId)
      await send({ [STATE]: 'standby' })
      last.state = 'standby'
      expect('state', 'standby')
      publish()
    },
    async tack (direction, deviceId) {
      checkDevice(deviceId)
      throw fail(400, 'tack is not supported by steerlab (a powered-ship autopilot)')
    },
    async gybe (direction, deviceId) {
      checkDevice(deviceId)
      throw fail(400, 'gybe is not supported by steerlab (a powered-ship autopilot)')
    },
    async dodge (value, deviceId) {
      checkDevice(deviceId)
      throw fail(400, 'dodge is not supported by steerlab; adjust the target instead')
    }
  }

  plugin.start = function (options) {
    opts = { ...{ deviceId: 'steerlab', host: '127.0.0.1', commandPort: 10111, statusHost: '127.0.0.1', statusPort: 10112, offlineTimeout: 3 }, ...(options || {}) }
    last = { state: null, target: null, seen: 0, refused: null }
    published = {}
    pending = {}
    sock = dgram.createSocket('udp4')
    sock.on('message', (data) => {
      const values = parseDelta(data)
      if (!values) return
      const s = values[STATE]
      const t = values[TARGET]
      if (s === undefined && t === undefined) return
      last.seen = Date.now()
      last.refused = typeof values[REFUSED] === 'string' ? values[REFUSED] : null // absent: applied
      if ((s === 'auto' || s === 'standby' || s === 'alarm') && accept('state', s, (a, b) => a === b)) {
        last.state = s
      }
      if (typeof t === 'number' && Number.isFinite(t) &&
          accept('target', wrap(t), (a, b) => Math.abs(Math.sin((a - b) / 2)) < 1e-9)) {
        last.target = wrap(t)
      }
      publish()
    })
    sock.on('error', (err) => app.setPluginError(`UDP ${opts.statusHost}:${opts.statusPort}: ${err.message}`))
    sock.bind(opts.statusPort, opts.statusHost, () => {
      app.setPluginStatus(`listening for steerlab on UDP ${opts.statusHost}:${opts.statusPort}, ` +
                          `commands to ${opts.host}:${opts.commandPort}`)
    })
    timer = setInterval(publish, 1000) // notices off-line
    app.registerAutopilotProvider(provider, [opts.deviceId])
    // Signal K v1 PUT (REST .../vessels/self/steering/autopilot/... or a stream PUT) on the two
    // paths steerlab takes: the same checks and link as the v2 API
    const v1 = (fn) => (context, path, value) => fn(value).then(
      () => ({ state: 'COMPLETED', statusCode: 200 }),
      (e) => ({ state: 'COMPLETED', statusCode: e.statusCode || 500, message: e.message }))
    if (typeof app.registerPutHandler === 'function') {
      app.registerPutHandler('vessels.self', STATE, v1((v) => provider.setState(v, opts.deviceId)), plugin.id)
      app.registerPutHandler('vessels.self', TARGET, v1((v) => provider.setTarget(v, opts.deviceId)), plugin.id)
    }
  }

  plugin.stop = function () {
    if (timer) clearInterval(timer)
    timer = null
    if (sock) sock.close()
    sock = null
  }

  plugin.provider = provider // for tests
  return plugin
}

module.exports.wrap = wrap
module.exports.parseDelta = parseDelta
