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
 *
 * Modes: steerlab reports its steering mode (compass, route, plotter) and the modes it has the
 * source for (steering.autopilot.steerlab.mode / .modes); PUT mode switches it, a mode it lacks
 * the source for is refused (409, why). Profiles and gains (steering.autopilot.steerlab.profile /
 * .gains) are v1 PUT paths. steerlab answers every command in its next status
 * (steering.autopilot.steerlab.reply: [{id, code, message}], its last 8); the request gets that answer, so a
 * command steerlab refused is never answered 200.
 *
 * Alarms: steerlab's active alarms (steering.autopilot.steerlab.alarms) become Signal K
 * notifications, raised when they start and set back to state "normal" when they end: off course
 * as notifications.steering.autopilot.heading and arrival as ...waypointArrival (through the
 * Autopilot API's alarm update), every other alarm as notifications.steering.autopilot.<name>.
 * A steerlab that falls silent raises notifications.steering.autopilot.offline (emergency if it
 * was engaged).
 *
 * With a key (keyFile: the file steerlab reads with --key-file) the link is signed both ways
 * (steerlab.runtime.signalk_link: HMAC-SHA256 over the datagram's body, session, sequence and
 * stamp): an unsigned, forged, stale or replayed status is ignored and counted (rejected, by
 * reason; steering.autopilot.steerlab.linkRejected on the server), and commands are signed.
 */
'use strict'

const crypto = require('crypto')
const dgram = require('dgram')
const fs = require('fs')

const TWO_PI = 2 * Math.PI
const TARGET = 'steering.autopilot.target.headingTrue'
const STATE = 'steering.autopilot.state'
const REFUSED = 'steering.autopilot.steerlab.targetRefused' // steerlab's reason a target is not applied
const SL = 'steering.autopilot.steerlab.'
const MODE = SL + 'mode'
const MODES_AVAILABLE = SL + 'modes'
const PROFILE = SL + 'profile'
const PROFILES = SL + 'profiles'
const GAINS = SL + 'gains'
const ALARMS = SL + 'alarms'
const REPLY = SL + 'reply'
const COMMAND_ID = SL + 'commandId'
const LINK_REJECTED = SL + 'linkRejected'
const ALL_MODES = ['compass', 'route', 'plotter']
const API_ALARMS = { off_course: 'heading', arrival: 'waypointArrival' } // the Autopilot API's own names
const REPLY_TIMEOUT_MS = 2000
const TAG_HEX = 64
const MAX_SESSIONS = 16
const STATES = [
  { name: 'auto', engaged: true },
  { name: 'standby', engaged: false }
]
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

/** Key bytes of a key file, surrounding ASCII whitespace stripped (as steerlab's load_key). */
function readKey (path) {
  const b = fs.readFileSync(path)
  let i = 0
  let j = b.length
  const ws = (c) => c === 0x20 || (c >= 0x09 && c <= 0x0d)
  while (i < j && ws(b[i])) i++
  while (j > i && ws(b[j - 1])) j--
  const key = b.subarray(i, j)
  if (key.length < 16) throw new Error(`key in ${path} has ${key.length} bytes; at least 16 needed`)
  return key
}

/** A signed datagram: hex HMAC-SHA256(key, body), newline, body (steerlab.runtime.signalk_link). */
function signDatagram (key, signer, text) {
  signer.seq += 1
  const body = Buffer.from(JSON.stringify({ session: signer.session, seq: signer.seq, stamp_ms: Date.now(), delta: text }), 'utf8')
  const tag = crypto.createHmac('sha256', key).update(body).digest('hex')
  return Buffer.concat([Buffer.from(tag + '\n', 'ascii'), body])
}

/**
 * The delta text of a signed datagram, or {reason}: unauthenticated, bad_mac, malformed, stale,
 * replayed. `sessions` (Map session -> last seq) is updated for an accepted one.
 */
function verifyDatagram (key, data, sessions, maxAgeMs, now) {
  if (data.length < TAG_HEX + 2 || data[TAG_HEX] !== 0x0a) return { reason: 'unauthenticated' }
  const tag = data.subarray(0, TAG_HEX).toString('latin1').toLowerCase()
  const body = data.subarray(TAG_HEX + 1)
  const want = crypto.createHmac('sha256', key).update(body).digest('hex')
  if (!/^[0-9a-f]{64}$/.test(tag) || !crypto.timingSafeEqual(Buffer.from(want), Buffer.from(tag))) return { reason: 'bad_mac' }
  let m
  try {
    m = JSON.parse(body.toString('utf8'))
  } catch (e) {
    return { reason: 'malformed' }
  }
  if (!m || !Number.isSafeInteger(m.session) || !Number.isSafeInteger(m.seq) || !Number.isSafeInteger(m.stamp_ms) ||
      typeof m.delta !== 'string') return { reason: 'malformed' }
  if (Math.abs(now - m.stamp_ms) > maxAgeMs) return { reason: 'stale' }
  const last = sessions.get(m.session)
  if (last !== undefined && m.seq <= last) return { reason: 'replayed' }
  sessions.delete(m.session)
  sessions.set(m.session, m.seq)
  while (sessions.size > MAX_SESSIONS) sessions.delete(sessions.keys().next().value)
  return { text: m.delta }
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
      offlineTimeout: { type: 'number', title: 'off-line after no status for [s]', default: 3 },
      keyFile: { type: 'string', title: 'HMAC key file (steerlab --key-file): sign the link both ways', default: '' }
    }
  }

  let sock = null
  let timer = null
  let opts = {}
  let last = { state: null, target: null, seen: 0, refused: null, mode: null, modes: null, profiles: null, replies: false }
  let published = {}
  let key = null
  let signer = null
  let sessions = new Map()
  let counts = { accepted: 0 }
  let reportedRejected = 0
  let raised = new Map() // notification path -> true while raised by this plugin
  let wasOnline = false
  let commandSeq = 0
  const waiting = new Map() // command id -> {resolve, reject, timer}
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

  const mode = () => last.mode || 'compass'
  const modes = () => last.modes || ['compass']

  function notify (name, value) {
    const path = `notifications.steering.autopilot.${name}`
    if (typeof app.handleMessage === 'function') {
      app.handleMessage(plugin.id, {
        context: 'vessels.self',
        updates: [{ values: [{ path, value }] }]
      })
    }
  }

  /** Raise or clear one notification (an Autopilot API alarm name through autopilotUpdate). */
  function setNotification (name, on, state, message) {
    const value = on
      ? { state, method: ['visual', 'sound'], message }
      : { state: 'normal', method: [], message: `${message || name} (cleared)` }
    if (Object.values(API_ALARMS).includes(name)) {
      app.autopilotUpdate(opts.deviceId, { alarm: { path: name, value } })
    } else {
      notify(name, value)
    }
    if (on) raised.set(name, true)
    else raised.delete(name)
  }

  /** steerlab's active alarms -> notifications: new ones raised, ended ones cleared. */
  function syncAlarms (list) {
    const now = new Map()
    for (const a of list) {
      if (!a || typeof a.name !== 'string' || !/^[A-Za-z0-9_]{1,40}$/.test(a.name)) continue
      const name = API_ALARMS[a.name] || a.name.replace(/_([a-z])/g, (_, c) => c.toUpperCase())
      const state = ['alert', 'warn', 'alarm', 'emergency'].includes(a.state) ? a.state : 'alarm'
      now.set(name, { state, message: `steerlab: ${typeof a.message === 'string' ? a.message.slice(0, 200) : a.name}` })
    }
    for (const [name, a] of now) {
      if (!raised.has(name)) setNotification(name, true, a.state, a.message)
    }
    for (const name of [...raised.keys()]) {
      if (name !== 'offline' && !now.has(name)) setNotification(name, false, 'normal', `steerlab: ${name}`)
    }
  }

  function reportRejected () {
    const n = Object.entries(counts).reduce((s, [k, v]) => (k === 'accepted' ? s : s + v), 0)
    if (n !== reportedRejected && typeof app.handleMessage === 'function') {
      reportedRejected = n
      app.handleMessage(plugin.id, { context: 'vessels.self', updates: [{ values: [{ path: LINK_REJECTED, value: n }] }] })
    }
  }

  function publish () {
    const on = online()
    if (wasOnline && !on) {
      setNotification('offline', true, last.state === 'auto' ? 'emergency' : 'alarm',
        `steerlab autopilot silent for more than ${opts.offlineTimeout} s` +
        (last.state === 'auto' ? ' while engaged: steer by hand' : ''))
    } else if (!wasOnline && on && raised.has('offline')) {
      setNotification('offline', false, 'normal', 'steerlab autopilot on-line again')
    }
    wasOnline = on
    reportRejected()
    const info = { state: state(), mode: mode(), target: last.target, engaged: engaged() }
    const changed = {}
    for (const [k, v] of Object.entries(info)) {
      if (published[k] !== v) changed[k] = v
    }
    if (Object.keys(changed).length) {
      published = { ...published, ...changed }
      app.autopilotUpdate(opts.deviceId, changed)
    }
  }

  /**
   * Send a command; resolves once steerlab applied it (its reply in the next status, when
   * steerlab sends replies), rejects with steerlab's code and reason when it refused it.
   */
  function send (values) {
    return new Promise((resolve, reject) => {
      if (!sock) return reject(fail(503, 'steerlab plugin is not running'))
      if (!online()) return reject(fail(503, `steerlab autopilot is off-line (no status on UDP ${opts.statusPort})`))
      const id = ++commandSeq
      const text = delta(last.replies ? { ...values, [COMMAND_ID]: id } : values)
      const data = key ? signDatagram(key, signer, text) : text
      sock.send(data, opts.commandPort, opts.host, (err) => {
        if (err) return reject(fail(502, `cannot reach steerlab: ${err.message}`))
        if (!last.replies) return resolve()
        const timer = setTimeout(() => {
          waiting.delete(id)
          reject(fail(504, `steerlab did not confirm the command within ${REPLY_TIMEOUT_MS / 1000} s`))
        }, REPLY_TIMEOUT_MS)
        waiting.set(id, { resolve, reject, timer })
      })
    })
  }

  function onReply (r) {
    if (!r || !Number.isSafeInteger(r.id)) return
    const w = waiting.get(r.id)
    if (!w) return
    waiting.delete(r.id)
    clearTimeout(w.timer)
    if (r.code === 200) w.resolve()
    else w.reject(fail(Number.isInteger(r.code) && r.code >= 400 && r.code < 600 ? r.code : 409,
      typeof r.message === 'string' ? r.message : 'refused by steerlab'))
  }

  async function switchMode (value) {
    if (!ALL_MODES.includes(value)) throw fail(400, `mode must be one of ${ALL_MODES.join(', ')}; got ${String(value).slice(0, 40)}`)
    if (value === mode() && online()) return
    if (!modes().includes(value)) {
      throw fail(409, `mode ${value} is not available: steerlab has ${modes().join(', ')} ` +
        '(route needs steerlab autopilot --route, plotter --nmea-listen)')
    }
    await send({ [MODE]: value })
    last.mode = value
    expect('mode', value)
    publish()
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
        options: { states: STATES, modes: modes(), actions: actions() },
        state: state(),
        mode: mode(),
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
      return mode()
    },
    async setMode (value, deviceId) {
      checkDevice(deviceId)
      await switchMode(value)
    },
    async getTarget (deviceId) {
      checkDevice(deviceId)
      return last.target
    },
    async setTarget (value, deviceId) {
      checkDevice(deviceId)
      // the server clamps the request onto [-pi, 2 pi] before it reaches here: -pi and 2 pi
      // stand for anything beyond them (-1e308 arrives as -pi), so both are refused, never
      // taken as a course (180 deg is pi)
      if (typeof value !== 'number' || !Number.isFinite(value) || value <= -Math.PI || value >= TWO_PI) {
        throw fail(400, 'target must be a heading in radians, -pi < value < 2 pi ' +
          '(the server clamps values outside onto -pi and 2 pi, so those are refused; 180 deg is pi)')
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
    },
    async courseCurrentPoint (deviceId) {
      checkDevice(deviceId)
      // the current destination comes to steerlab from a chart plotter's APB/RMB (for example
      // the server's own course API sent as NMEA 0183) or from its own route
      const m = modes().includes('plotter') ? 'plotter' : modes().includes('route') ? 'route' : null
      if (m === null) {
        throw fail(409, 'steerlab has no destination source: start steerlab autopilot with --nmea-listen ' +
          '(a chart plotter\'s APB/RMB) or --route')
      }
      await switchMode(m)
    },
    async courseNextPoint (deviceId) {
      checkDevice(deviceId)
      throw fail(409, 'steerlab does not advance waypoints itself: the chart plotter advances its route ' +
        '(APB/RMB), and steerlab\'s own route advances at its acceptance radius')
    }
  }

  function actions () {
    const dest = modes().includes('plotter') || modes().includes('route')
    return ACTIONS.map((a) => (a.id === 'courseCurrentPoint' ? { ...a, available: dest } : a))
  }

  plugin.start = function (options) {
    opts = { ...{ deviceId: 'steerlab', host: '127.0.0.1', commandPort: 10111, statusHost: '127.0.0.1', statusPort: 10112, offlineTimeout: 3, keyFile: '' }, ...(options || {}) }
    last = { state: null, target: null, seen: 0, refused: null, mode: null, modes: null, profiles: null, replies: false }
    published = {}
    pending = {}
    sessions = new Map()
    counts = { accepted: 0 }
    reportedRejected = 0
    raised = new Map()
    wasOnline = false
    key = null
    if (opts.keyFile) {
      try {
        key = readKey(opts.keyFile)
      } catch (e) {
        app.setPluginError(`keyFile: ${e.message}`)
        return
      }
      signer = { session: crypto.randomInt(0, 2 ** 32), seq: 0 }
    }
    sock = dgram.createSocket('udp4')
    sock.on('message', (data) => {
      let payload = data
      if (key) {
        const v = verifyDatagram(key, data, sessions, Math.max(1000, opts.offlineTimeout * 1000), Date.now())
        if (v.reason) {
          counts[v.reason] = (counts[v.reason] || 0) + 1
          return
        }
        payload = v.text
      }
      const values = parseDelta(payload)
      if (!values) {
        counts.malformed = (counts.malformed || 0) + 1
        return
      }
      const s = values[STATE]
      const t = values[TARGET]
      if (s === undefined && t === undefined) return
      counts.accepted += 1
      last.seen = Date.now()
      last.refused = typeof values[REFUSED] === 'string' ? values[REFUSED] : null // absent: applied
      if (Array.isArray(values[MODES_AVAILABLE])) last.modes = values[MODES_AVAILABLE].filter((m) => ALL_MODES.includes(m))
      if (ALL_MODES.includes(values[MODE]) && accept('mode', values[MODE], (a, b) => a === b)) last.mode = values[MODE]
      if (Array.isArray(values[PROFILES])) last.profiles = values[PROFILES].filter((p) => typeof p === 'string')
      if (Array.isArray(values[REPLY])) { // steerlab's answers to the last commands
        last.replies = true
        for (const r of values[REPLY]) onReply(r)
      }
      if (Array.isArray(values[ALARMS])) syncAlarms(values[ALARMS])
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
      app.registerPutHandler('vessels.self', MODE, v1((v) => provider.setMode(v, opts.deviceId)), plugin.id)
      app.registerPutHandler('vessels.self', PROFILE, v1(async (v) => {
        if (typeof v !== 'string' || (last.profiles && !last.profiles.includes(v))) {
          throw fail(400, `profile must be one of ${(last.profiles || []).join(', ')}; got ${String(v).slice(0, 40)}`)
        }
        await send({ [PROFILE]: v })
      }), plugin.id)
      app.registerPutHandler('vessels.self', GAINS, v1(async (v) => {
        if (!v || typeof v !== 'object' || Array.isArray(v)) throw fail(400, 'gains must be an object, e.g. {"Kp": 2.0}')
        await send({ [GAINS]: v })
      }), plugin.id)
    }
  }

  plugin.stop = function () {
    for (const w of waiting.values()) {
      clearTimeout(w.timer)
      w.reject(fail(503, 'steerlab plugin stopped'))
    }
    waiting.clear()
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
module.exports.signDatagram = signDatagram
module.exports.verifyDatagram = verifyDatagram
