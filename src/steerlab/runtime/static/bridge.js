// steerlab bridge page: WebSocket status in, actions out. SI from the server; degrees here.
"use strict";
(function () {
  const DEG = 180 / Math.PI;
  const $ = (id) => document.getElementById(id);
  const fmt = (x, unit, nd = 1) => (x === null || x === undefined) ? "-" : (x.toFixed(nd) + unit);
  // a direction in [0, 360): wrap, round, wrap the rounded text again (359.99 -> "0.0", never "360.0")
  const fmtDeg = (rad, nd = 1) => {
    if (rad === null || rad === undefined) return "-";
    let t = (((rad * DEG) % 360 + 360) % 360).toFixed(nd);
    if (parseFloat(t) >= 360) t = (0).toFixed(nd);
    return t + "\u00b0";
  };
  let ws = null;
  let track = [];
  let lastT = null;

  // compass ticks every 10 degrees, labels every 30
  const ticks = $("ticks");
  const NS = "http://www.w3.org/2000/svg";
  for (let d = 0; d < 360; d += 10) {
    const a = d / DEG, long = d % 30 === 0;
    const l = document.createElementNS(NS, "line");
    l.setAttribute("x1", Math.sin(a) * 100); l.setAttribute("y1", -Math.cos(a) * 100);
    l.setAttribute("x2", Math.sin(a) * (long ? 88 : 94)); l.setAttribute("y2", -Math.cos(a) * (long ? 88 : 94));
    l.setAttribute("stroke", "#9ab"); ticks.appendChild(l);
    if (long) {
      const t = document.createElementNS(NS, "text");
      t.setAttribute("x", Math.sin(a) * 74); t.setAttribute("y", -Math.cos(a) * 74 + 4);
      t.setAttribute("fill", "#9ab"); t.setAttribute("font-size", "10"); t.setAttribute("text-anchor", "middle");
      t.textContent = d === 0 ? "N" : d === 90 ? "E" : d === 180 ? "S" : d === 270 ? "W" : String(d);
      ticks.appendChild(t);
    }
  }

  function rotate(id, rad) {
    if (rad === null || rad === undefined) return;
    $(id).setAttribute("transform", "rotate(" + (rad * DEG) + ")");
  }

  // a scale bar of a round length (1, 2 or 5 x 10^k m) about a quarter of the plot wide
  function drawScale(span) {
    const target = span / 4;
    const p = Math.pow(10, Math.floor(Math.log10(target)));
    const nice = [5, 2, 1].map((k) => k * p).find((v) => v <= target) || p;
    const px = nice / span * 300;
    $("scale-bar").setAttribute("x2", (10 + px).toFixed(1));
    $("scale-text").textContent = nice >= 1000 ? (nice / 1000) + " km" : nice + " m";
  }

  function drawTrack(s) {
    if (Array.isArray(s.track)) {        // the autopilot's own history: the whole track, whenever the page opened
      track = s.track.slice();
    } else if (s.position) {
      if (lastT !== null && s.t < lastT) track = [];
      lastT = s.t;
      const p = s.position;
      const q = track[track.length - 1];
      if (!q || Math.hypot(q[0] - p[0], q[1] - p[1]) > 1) track.push(p);
      if (track.length > 3000) track.shift();
    }
    const pts = track.concat(s.route || []);
    if (!pts.length) return;
    let xmin = Infinity, xmax = -Infinity, ymin = Infinity, ymax = -Infinity;
    for (const [x, y] of pts) { xmin = Math.min(xmin, x); xmax = Math.max(xmax, x); ymin = Math.min(ymin, y); ymax = Math.max(ymax, y); }
    const span = Math.max(xmax - xmin, ymax - ymin, 200) * 1.1;
    drawScale(span);
    const cx = (xmin + xmax) / 2, cy = (ymin + ymax) / 2;
    const toSvg = ([x, y]) => [150 + (y - cy) / span * 300, 150 - (x - cx) / span * 300];  // east right, north up
    const poly = (arr) => arr.map(toSvg).map(([a, b]) => a.toFixed(1) + "," + b.toFixed(1)).join(" ");
    $("track-line").setAttribute("points", poly(track));
    $("route-line").setAttribute("points", poly(s.route || []));
    if (track.length) {
      const [a, b] = toSvg(track[track.length - 1]);
      $("ship-dot").setAttribute("cx", a); $("ship-dot").setAttribute("cy", b);
    }
  }

  function show(s) {
    $("mode").textContent = s.mode;
    $("mode").className = "badge " + s.mode;
    $("link").textContent = s.link_ok ? "link OK" : "link LOST";
    $("link").className = "badge " + (s.link_ok ? "ok" : "bad");
    $("controller").textContent = "controller: " + s.controller + "   t = " + fmt(s.t, " s", 1);
    // the heading the autopilot steers by (NMEA HDT/THS or the ship state) and where it came from
    const steered = (s.steered_heading === null || s.steered_heading === undefined) ? s.heading : s.steered_heading;
    $("heading").textContent = fmtDeg(steered);
    $("heading-source").textContent = s.heading_source ? "(" + s.heading_source + ")" : "";
    $("state-heading").textContent = fmtDeg(s.heading);
    $("set-course").textContent = fmtDeg(s.set_course);
    $("course-source").textContent = s.course_source ? "(" + s.course_source + ")" : "";
    $("reference").textContent = fmtDeg(s.reference);
    $("yaw-rate").textContent = s.yaw_rate === null ? "-" : fmt(s.yaw_rate * DEG * 60, " \u00b0/min", 1);
    $("speed").textContent = s.speed === null ? "-" : fmt(s.speed / 0.514444, " kn", 1);
    $("rudder-angle").textContent = s.rudder === null ? "-" : fmt(s.rudder * DEG, "\u00b0", 1);
    $("rudder-order").textContent = s.rudder_cmd === null ? "-" : fmt(s.rudder_cmd * DEG, "\u00b0", 1);
    rotate("ship-needle", steered);
    rotate("set-marker", s.set_course);
    rotate("ref-marker", s.reference);
    const r = s.rudder === null ? 0 : Math.max(-35, Math.min(35, s.rudder * DEG)) / 35 * 100;
    $("rudder-bar").setAttribute("x", Math.min(0, r)); $("rudder-bar").setAttribute("width", Math.abs(r));
    const c = s.rudder_cmd === null ? 0 : Math.max(-35, Math.min(35, s.rudder_cmd * DEG)) / 35 * 100;
    $("rudder-cmd").setAttribute("x1", c); $("rudder-cmd").setAttribute("x2", c);
    const ul = $("alarms");
    ul.textContent = "";
    if (!s.alarms.length) { const li = document.createElement("li"); li.className = "muted"; li.textContent = "none"; ul.appendChild(li); }
    for (const a of s.alarms) {
      const li = document.createElement("li");
      li.className = (a.active ? "active" : "") + (a.acknowledged ? "" : " unack");
      li.textContent = a.name + ": " + a.message + (a.active ? "" : " (cleared)") + (a.acknowledged ? " - acknowledged" : "");
      li.dataset.alarm = a.name;
      ul.appendChild(li);
    }
    $("steering-mode").textContent = s.steering_mode || "-";
    for (const b of modeButtons()) {
      b.className = b.dataset.mode === s.steering_mode ? "on" : "";
      b.disabled = !(s.modes || []).includes(b.dataset.mode);
    }
    fillSelect($("profile"), s.profiles || [], s.profile);
    const names = Object.keys(s.settings || {}).filter((n) => n !== "type" && n !== "sample_time" &&
      (typeof s.settings[n] === "number" || s.settings[n] === null));
    fillSelect($("gain-name"), names, null);
    $("settings").textContent = Object.entries(s.settings || {}).filter(([n]) => names.includes(n))
      .map(([n, v]) => n + " = " + (v === null ? "-" : v)).join(", ");
    const k = s.link || {};
    $("counts").textContent = "states accepted " + (k.accepted || 0) + ", rejected " +
      Object.entries(k).filter(([n]) => n !== "accepted").reduce((acc, [, v]) => acc + v, 0);
    drawTrack(s);
  }

  const modeButtons = () => Array.from(document.querySelectorAll("[data-mode]")).filter((b) => b.dataset.mode);

  // options of a select, rebuilt only when they change (a select the user has open keeps its state)
  function fillSelect(sel, values, chosen) {
    const have = Array.from(sel.options || []).map((o) => o.value);
    if (have.join("\n") !== values.join("\n")) {
      sel.textContent = "";
      for (const v of values) { const o = document.createElement("option"); o.value = v; o.textContent = v; sel.appendChild(o); }
    }
    if (chosen !== null && document.activeElement !== sel) sel.value = chosen;
  }

  function send(obj) { if (ws && ws.readyState === 1) ws.send(JSON.stringify(obj)); }

  function connect() {
    // the operator's token, from the address's fragment (#op=...): a reserved slot (issue 35)
    const op = new URLSearchParams((location.hash || "").slice(1)).get("op");
    ws = new WebSocket((location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws"
                       + (op ? "?op=" + encodeURIComponent(op) : ""));
    ws.onmessage = (ev) => {
      const m = JSON.parse(ev.data);
      if (m.type === "status") show(m);
      else if (m.type === "reply") $("reply").textContent = m.ok ? ("ok: " + m.action) : ("refused: " + m.error);
    };
    ws.onclose = () => { $("link").textContent = "page disconnected"; $("link").className = "badge bad"; setTimeout(connect, 1000); };
  }

  $("engage").onclick = () => send({ action: "engage" });
  $("standby").onclick = () => send({ action: "standby" });
  $("ack").onclick = () => send({ action: "ack" });
  for (const b of document.querySelectorAll("[data-adjust]")) b.onclick = () => send({ action: "adjust", deg: Number(b.dataset.adjust) });
  for (const b of modeButtons()) b.onclick = () => send({ action: "mode", mode: b.dataset.mode });
  $("profile").onchange = () => send({ action: "profile", profile: $("profile").value });
  $("gain-set").onclick = () => {
    const v = Number($("gain-value").value);
    if ($("gain-value").value === "" || !Number.isFinite(v)) { $("reply").textContent = "refused: enter a number"; return; }
    send({ action: "gains", gains: { [$("gain-name").value]: v } });
  };
  connect();
})();
