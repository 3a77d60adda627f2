// Unit tests of the plugin with a stand-in Signal K app and a stand-in steerlab on UDP (node --test).
'use strict'
const test = require('node:test')
const assert = require('node:assert')
const dgram = require('node:dgram')
const makePlugin = require('..')

function fakeApp () {
  return {
    updates: [],
    registered: null,
    autopilotUpdate (id, info) { this.updates.push([id, info]) },
    registerAutopilotProvider (provider, ids) { this.registered = [provider, ids] },
    setPluginStatus () {},
    setPluginError (msg) { this.error = msg }
  }
}

const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms))

async function udp () {
  const s = dgram.createSocket('udp4')
  await new Promise((resolve) => s.bind(0, '127.0.0.1', resolve))
  return s
}

test('wrap keeps headings in [0, 2 pi) strictly', () => {
  for (const a of [-1e-12, -1e-17, 2 * Math.PI, 2 * Math.PI - 1e-16, 7 * Math.PI, -3]) {
    const w = makePlugin.wrap(a)
    assert.ok(w >= 0 && w < 2 * Math.PI, `${a} -> ${w}`)
  }
  assert.strictEqual(makePlugin.wrap(2 * Math.PI), 0)
})

test('parseDelta takes deltas and refuses the rest', () => {
  assert.deepStrictEqual(makePlugin.parseDelta(Buffer.from(JSON.stringify(
    { updates: [{ values: [{ path: 'a.b', value: 1 }] }] }))), { 'a.b': 1 })
  for (const bad of ['', 'null', '[]', '{"updates": 3}', '{"updates": [{"values": 3}]}', '{']) {
    assert.strictEqual(makePlugin.parseDelta(Buffer.from(bad)), null, bad)
  }
})

test('off-line until steerlab speaks; then commands go out as deltas; bad values refused', async () => {
  const app = fakeApp()
  const steerlab = await udp() // stands in for `steerlab autopilot --signalk-listen`
  const statusPort = (await udp().then((s) => { const p = s.address().port; s.close(); return p }))
  const plugin = makePlugin(app)
  plugin.start({ commandPort: steerlab.address().port, statusPort, offlineTimeout: 1 })
  const [provider, ids] = app.registered
  assert.deepStrictEqual(ids, ['steerlab'])
  try {
    assert.strictEqual(await provider.getState('steerlab'), 'off-line')
    await assert.rejects(provider.engage('steerlab'), (e) => e.statusCode === 503)
    await assert.rejects(provider.getData('other'), (e) => e.statusCode === 404)

    const got = []
    steerlab.on('message', (m) => got.push(makePlugin.parseDelta(m)))
    const status = (values) => steerlab.send(JSON.stringify({
      context: 'vessels.self', updates: [{ values: Object.entries(values).map(([path, value]) => ({ path, value })) }]
    }), statusPort, '127.0.0.1')
    await sleep(50)
    status({ 'steering.autopilot.state': 'standby', 'steering.autopilot.target.headingTrue': -1e-9 })
    await sleep(100)
    assert.strictEqual(await provider.getState('steerlab'), 'standby')
    const t0 = await provider.getTarget('steerlab')
    assert.ok(t0 >= 0 && t0 < 2 * Math.PI)

    await provider.engage('steerlab')
    await provider.setTarget(Math.PI / 4, 'steerlab')
    await provider.adjustTarget(Math.PI / 18, 'steerlab')
    status({ 'steering.autopilot.target.headingTrue': Math.PI / 4 }) // stale: sent before the adjustment arrived
    await sleep(100)
    await provider.adjustTarget(-Math.PI / 180, 'steerlab') // adds to 55 deg, not to the stale 45
    await sleep(100)
    assert.deepStrictEqual(got.map((d) => Object.keys(d)[0]), [
      'steering.autopilot.state', 'steering.autopilot.target.headingTrue',
      'steering.autopilot.target.headingTrue', 'steering.autopilot.target.headingTrue'])
    assert.strictEqual(got[0]['steering.autopilot.state'], 'auto')
    assert.ok(Math.abs(got[3]['steering.autopilot.target.headingTrue'] - 54 * Math.PI / 180) < 1e-12)

    for (const v of [NaN, Infinity, 2 * Math.PI, -4, 'north']) {
      await assert.rejects(provider.setTarget(v, 'steerlab'), (e) => e.statusCode === 400, String(v))
    }
    await assert.rejects(provider.adjustTarget(4, 'steerlab'), (e) => e.statusCode === 400)
    await assert.rejects(provider.setMode('wind', 'steerlab'), (e) => e.statusCode === 400)
    await assert.rejects(provider.setState('dance', 'steerlab'), (e) => e.statusCode === 400)
    await assert.rejects(provider.tack('port', 'steerlab'), (e) => e.statusCode === 400)
    await provider.setMode('compass', 'steerlab')
    assert.strictEqual(got.length, 4) // nothing more was sent

    await sleep(2300) // no status for longer than offlineTimeout (+ one publish tick)
    assert.strictEqual(await provider.getState('steerlab'), 'off-line')
    assert.strictEqual((await provider.getData('_default')).engaged, false)
    assert.ok(app.updates.some(([, info]) => info.state === 'off-line'))
  } finally {
    plugin.stop()
    steerlab.close()
  }
})

test('a target steerlab would not apply (route, chart plotter) is refused 409 with its reason', async () => {
  const app = fakeApp()
  const steerlab = await udp()
  const statusPort = (await udp().then((s) => { const p = s.address().port; s.close(); return p }))
  const plugin = makePlugin(app)
  plugin.start({ commandPort: steerlab.address().port, statusPort, offlineTimeout: 5 })
  const [provider] = app.registered
  const got = []
  steerlab.on('message', (m) => got.push(makePlugin.parseDelta(m)))
  const status = (values) => steerlab.send(JSON.stringify({
    context: 'vessels.self', updates: [{ values: Object.entries(values).map(([path, value]) => ({ path, value })) }]
  }), statusPort, '127.0.0.1')
  const reason = 'following a route (--route): the route is the only course source; target not applied'
  try {
    await sleep(50)
    status({ 'steering.autopilot.state': 'auto', 'steering.autopilot.target.headingTrue': 1, 'steering.autopilot.steerlab.targetRefused': reason })
    await sleep(100)
    await assert.rejects(provider.setTarget(0.5, 'steerlab'), (e) => e.statusCode === 409 && e.message === reason)
    await assert.rejects(provider.adjustTarget(0.1, 'steerlab'), (e) => e.statusCode === 409 && e.message === reason)
    await provider.disengage('steerlab') // the state is still steerlab's to take
    await sleep(100)
    assert.deepStrictEqual(got.map((d) => Object.keys(d)), [['steering.autopilot.state']])
    status({ 'steering.autopilot.state': 'standby', 'steering.autopilot.target.headingTrue': 1 }) // the route ended
    await sleep(100)
    await provider.setTarget(0.5, 'steerlab')
    await sleep(100)
    assert.strictEqual(got.length, 2)
    assert.strictEqual(got[1]['steering.autopilot.target.headingTrue'], 0.5)
  } finally {
    plugin.stop()
    steerlab.close()
  }
})

test('signed link: unsigned and forged statuses are ignored and counted; alarms become notifications', async () => {
  const fs = require('node:fs')
  const os = require('node:os')
  const path = require('node:path')
  const app = fakeApp()
  app.messages = []
  app.handleMessage = (id, d) => { for (const u of d.updates) for (const v of u.values) app.messages.push([v.path, v.value]) }
  const key = Buffer.from('a key of at least sixteen bytes')
  const keyFile = path.join(fs.mkdtempSync(path.join(os.tmpdir(), 'sl-')), 'key')
  fs.writeFileSync(keyFile, Buffer.concat([key, Buffer.from('\n')]))
  const steerlab = await udp()
  const statusPort = (await udp().then((s) => { const p = s.address().port; s.close(); return p }))
  const plugin = makePlugin(app)
  plugin.start({ commandPort: steerlab.address().port, statusPort, offlineTimeout: 1, keyFile })
  const [provider] = app.registered
  const signer = { session: 1, seq: 0 }
  const text = (values) => JSON.stringify({ updates: [{ values: Object.entries(values).map(([p, value]) => ({ path: p, value })) }] })
  const signed = (values) => steerlab.send(makePlugin.signDatagram(key, signer, text(values)), statusPort, '127.0.0.1')
  const got = []
  steerlab.on('message', (m) => got.push(m))
  try {
    await sleep(50)
    steerlab.send(text({ 'steering.autopilot.state': 'auto' }), statusPort, '127.0.0.1') // unsigned
    steerlab.send(makePlugin.signDatagram(Buffer.from('another key, sixteen+ bytes'), { session: 2, seq: 0 },
      text({ 'steering.autopilot.state': 'auto' })), statusPort, '127.0.0.1') // wrong key
    await sleep(100)
    assert.strictEqual(await provider.getState('steerlab'), 'off-line')
    signed({
      'steering.autopilot.state': 'standby',
      'steering.autopilot.target.headingTrue': 1,
      'steering.autopilot.steerlab.mode': 'compass',
      'steering.autopilot.steerlab.alarms': [{ name: 'off_course', message: 'off by 12 deg', state: 'alarm' },
        { name: 'sensor_fault', message: 'compass stale', state: 'alarm' }]
    })
    await sleep(100)
    assert.strictEqual(await provider.getState('steerlab'), 'standby')
    const alarm = app.updates.find(([, info]) => info.alarm)
    assert.strictEqual(alarm[1].alarm.path, 'heading')
    assert.strictEqual(alarm[1].alarm.value.state, 'alarm')
    const raised = app.messages.find(([p]) => p === 'notifications.steering.autopilot.sensorFault')
    assert.strictEqual(raised[1].state, 'alarm')
    assert.deepStrictEqual(app.messages.find(([p]) => p === 'steering.autopilot.steerlab.linkRejected'),
      ['steering.autopilot.steerlab.linkRejected', 2])
    signed({ 'steering.autopilot.state': 'standby', 'steering.autopilot.steerlab.alarms': [] }) // both ended
    await sleep(100)
    assert.strictEqual(app.messages.filter(([p]) => p === 'notifications.steering.autopilot.sensorFault').pop()[1].state, 'normal')
    assert.strictEqual(app.updates.filter(([, info]) => info.alarm).pop()[1].alarm.value.state, 'normal')
    await provider.engage('steerlab') // commands are signed
    await sleep(100)
    assert.ok(makePlugin.verifyDatagram(key, got[0], new Map(), 3000, Date.now()).text.includes('"auto"'))
    await sleep(2300) // silent: the autopilot-gone notification
    assert.strictEqual(app.messages.filter(([p]) => p === 'notifications.steering.autopilot.offline').pop()[1].state, 'emergency')
  } finally {
    plugin.stop()
    steerlab.close()
  }
})
