// The cellrt live page: one more viewer of the cell's live view (Foxglove WebSocket protocol,
// subprotocol foxglove.sdk.v1), in plain script. It subscribes to every advertised channel and
// decodes the protobuf messages with the schema the server advertises (a FileDescriptorSet),
// so field names and enum names come from the cell, not from this file.
"use strict";

(() => {
  const LIVE_PORT = document.querySelector('meta[name="cellrt-live-port"]').content;
  const SUBPROTOCOLS = ["foxglove.sdk.v1", "foxglove.websocket.v1"];
  const MESSAGE_DATA = 0x01; // binary opcode of a message on a subscription
  const PLOT_SAMPLES = 4000; // per axis: the scrolling plot's window (4 s at 1 kHz)
  const EVENTS_SHOWN = 200;
  const LATENCY_BINS_US = 2000; // 1 µs bins, and one bin above
  const CYCLE_TOPIC = "/cell/cycle";
  const EVENTS_TOPIC = "/cell/events";
  const AXIS_PREFIX = "/axis/";

  // ---- protobuf wire format -------------------------------------------------------------

  /** Calls `visit(number, wireType, value, bytes)` for each field of `bytes`; `value` is the
   *  varint, the offset of a fixed-size value, or the bytes of a length-delimited one. */
  function eachField(bytes, visit) {
    let p = 0;
    const varint = () => {
      let x = 0, scale = 1, b;
      do {
        if (p >= bytes.length) throw new Error("truncated varint");
        b = bytes[p++];
        x += (b & 0x7f) * scale;
        scale *= 128;
      } while (b & 0x80);
      return x;
    };
    while (p < bytes.length) {
      const key = varint();
      const number = Math.floor(key / 8), wire = key % 8;
      if (wire === 0) {
        visit(number, wire, varint(), bytes);
      } else if (wire === 1) {
        visit(number, wire, p, bytes);
        p += 8;
      } else if (wire === 2) {
        const n = varint();
        if (p + n > bytes.length) throw new Error("truncated field");
        visit(number, wire, bytes.subarray(p, p + n), bytes);
        p += n;
      } else if (wire === 5) {
        visit(number, wire, p, bytes);
        p += 4;
      } else {
        throw new Error("unsupported wire type " + wire);
      }
    }
  }

  const text = new TextDecoder();

  /** Messages (full name → fields) and enums (full name → number → name) of a
   *  FileDescriptorSet. */
  function parseDescriptorSet(bytes) {
    const messages = new Map(), enums = new Map();
    const parseEnum = (b, scope) => {
      let name = "";
      const values = new Map();
      eachField(b, (no, _w, v) => {
        if (no === 1) name = text.decode(v);
        if (no === 2) {
          let vn = "", vv = 0;
          eachField(v, (n2, _w2, x) => {
            if (n2 === 1) vn = text.decode(x);
            if (n2 === 2) vv = x;
          });
          values.set(vv, vn);
        }
      });
      enums.set(scope + "." + name, values);
    };
    const parseMessage = (b, scope) => {
      let name = "";
      const fields = [], nested = [], nestedEnums = [];
      eachField(b, (no, _w, v) => {
        if (no === 1) name = text.decode(v);
        if (no === 2) {
          const f = { name: "", number: 0, type: 0, typeName: "" };
          eachField(v, (n2, _w2, x) => {
            if (n2 === 1) f.name = text.decode(x);
            if (n2 === 3) f.number = x;
            if (n2 === 5) f.type = x;
            if (n2 === 6) f.typeName = text.decode(x);
          });
          fields.push(f);
        }
        if (no === 3) nested.push(v);
        if (no === 4) nestedEnums.push(v);
      });
      const full = scope + "." + name;
      messages.set(full, fields);
      nested.forEach((n) => parseMessage(n, full));
      nestedEnums.forEach((e) => parseEnum(e, full));
    };
    eachField(bytes, (no, _w, file) => {
      if (no !== 1) return;
      let pkg = "";
      const msgs = [], ens = [];
      eachField(file, (n2, _w2, v) => {
        if (n2 === 2) pkg = text.decode(v);
        if (n2 === 4) msgs.push(v);
        if (n2 === 5) ens.push(v);
      });
      const scope = pkg ? "." + pkg : "";
      msgs.forEach((m) => parseMessage(m, scope));
      ens.forEach((e) => parseEnum(e, scope));
    });
    return { messages, enums };
  }

  const zigzag = (x) => (x % 2 === 1 ? -(x + 1) / 2 : x / 2);

  /** A function that decodes message `name` of `set` into a plain object: one pass over the
   *  bytes without a call per field (the page decodes some 17 000 messages a second). */
  function makeDecoder(set, name) {
    const fields = set.messages.get("." + name);
    if (!fields) throw new Error("schema has no message " + name);
    const byNumber = [];
    const defaults = {};
    for (const f of fields) {
      const enumValues = f.type === 14 ? set.enums.get(f.typeName) || new Map() : null;
      byNumber[f.number] = { name: f.name, type: f.type, enumValues };
      defaults[f.name] = f.type === 9 ? "" : f.type === 8 ? false : enumValues ? enumValues.get(0) : 0;
    }
    const varintValue = (f, v) => {
      switch (f.type) {
        case 17: case 18: return zigzag(v); // sint32, sint64
        case 5: case 3: return v >= 2 ** 63 ? v - 2 ** 64 : v; // int32, int64
        case 8: return v !== 0; // bool
        case 14: return f.enumValues.get(v) ?? v; // enum
        default: return v; // uint32, uint64
      }
    };
    return (bytes) => {
      const out = { ...defaults };
      const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
      const n = bytes.length;
      let p = 0;
      while (p < n) {
        let key = 0, scale = 1, b;
        do { b = bytes[p++]; key += (b & 0x7f) * scale; scale *= 128; } while (b & 0x80 && p < n);
        const f = byNumber[Math.floor(key / 8)], wire = key % 8;
        if (wire === 0) {
          let v = 0;
          scale = 1;
          do { b = bytes[p++]; v += (b & 0x7f) * scale; scale *= 128; } while (b & 0x80 && p < n);
          if (f) out[f.name] = varintValue(f, v);
        } else if (wire === 1) {
          if (p + 8 > n) throw new Error("truncated field");
          if (f) {
            out[f.name] = f.type === 1 ? view.getFloat64(p, true)
              : f.type === 16 ? Number(view.getBigInt64(p, true)) : Number(view.getBigUint64(p, true));
          }
          p += 8;
        } else if (wire === 2) {
          let len = 0;
          scale = 1;
          do { b = bytes[p++]; len += (b & 0x7f) * scale; scale *= 128; } while (b & 0x80 && p < n);
          if (p + len > n) throw new Error("truncated field");
          if (f) out[f.name] = f.type === 9 ? text.decode(bytes.subarray(p, p + len)) : bytes.subarray(p, p + len);
          p += len;
        } else if (wire === 5) {
          if (p + 4 > n) throw new Error("truncated field");
          if (f) {
            out[f.name] = f.type === 2 ? view.getFloat32(p, true)
              : f.type === 15 ? view.getInt32(p, true) : view.getUint32(p, true);
          }
          p += 4;
        } else {
          throw new Error("unsupported wire type " + wire);
        }
      }
      return out;
    };
  }

  // ---- what the page shows ---------------------------------------------------------------

  const $ = (id) => document.getElementById(id);
  const pretty = (name) =>
    typeof name === "string" ? name.charAt(0) + name.slice(1).toLowerCase().replaceAll("_", " ") : String(name);
  const hex4 = (n) => n.toString(16).toUpperCase().padStart(4, "0") + "h";

  let state;
  function reset() {
    state = {
      subscriptions: new Map(), // subscription id → { topic, decode, kind, axis }
      axes: new Map(),
      cell: null,
      received: 0,
      missed: 0,
      latency: new Uint32Array(LATENCY_BINS_US + 1),
      latencyCount: 0,
      latencyMax: 0,
      newEvents: [],
      lastCycle: null,
    };
    $("axes").replaceChildren();
    $("events").replaceChildren();
  }

  /** Each axis' unit and counts per unit, as the cell's configuration gives them. */
  const AXIS_SCALES = (() => {
    try {
      const meta = document.querySelector('meta[name="cellrt-axes"]');
      return new Map(JSON.parse(meta ? meta.content : "[]").map((a) => [a.name, a]));
    } catch (e) {
      return new Map();
    }
  })();

  /** The smallest span of the following-error scale, counts (as `cellrt report`'s). */
  const MIN_ERROR_SPAN_COUNTS = 40;

  function axisCard(name) {
    const scale = AXIS_SCALES.get(name) || { unit: "", counts_per_unit: 1 };
    const unit = scale.unit ? " [" + scale.unit + "]" : "";
    const card = document.createElement("article");
    card.className = "axis";
    card.dataset.axis = name;
    card.innerHTML =
      '<h3><span class="name"></span><span class="fsa">–</span></h3>' +
      '<dl class="values">' +
      '<div><dt>position<span class="unit"></span></dt><dd class="actual">–</dd></div>' +
      '<div><dt>setpoint<span class="unit"></span></dt><dd class="setpoint">–</dd></div>' +
      '<div><dt>following error<span class="unit"></span></dt><dd class="fe">–</dd></div>' +
      '<div><dt>alarm (603Fh)</dt><dd class="alarm">–</dd></div>' +
      '<div><dt>mode</dt><dd class="mode">–</dd></div>' +
      '<div><dt>cycle</dt><dd class="cycle">–</dd></div>' +
      "</dl>" +
      '<canvas width="800" height="300"></canvas>' +
      '<div class="legend"><span class="actual">━ position</span> <span class="setpoint">╍ setpoint</span> ' +
      '<span class="fe">━ following error</span> (last <span class="window">–</span>)</div>';
    card.querySelector(".name").textContent = name;
    for (const u of card.querySelectorAll(".unit")) u.textContent = unit;
    $("axes").append(card);
    const canvas = card.querySelector("canvas");
    canvas.dataset.axis = name;
    canvas.dataset.samples = "0";
    return {
      card,
      canvas,
      cycle: new Float64Array(PLOT_SAMPLES),
      setpoint: new Float64Array(PLOT_SAMPLES),
      actual: new Float64Array(PLOT_SAMPLES),
      fe: new Float64Array(PLOT_SAMPLES),
      unit,
      minErrorSpan: MIN_ERROR_SPAN_COUNTS / (scale.counts_per_unit > 0 ? scale.counts_per_unit : 1),
      count: 0,
      last: null,
      lastCycle: null,
      dirty: false,
    };
  }

  function onAxis(axis, m) {
    const i = axis.count % PLOT_SAMPLES;
    axis.cycle[i] = m.cycle;
    axis.setpoint[i] = m.setpoint_position;
    axis.actual[i] = m.actual_position;
    axis.fe[i] = m.following_error;
    axis.count++;
    axis.last = m;
    axis.dirty = true;
  }

  function onCycle(m) {
    state.cell = m;
    const us = Math.min(Math.round(m.wakeup_latency_ns / 1000), LATENCY_BINS_US);
    state.latency[us]++;
    state.latencyCount++;
    state.latencyMax = Math.max(state.latencyMax, m.wakeup_latency_ns / 1000);
  }

  /** Counts the cycle messages the server dropped for this page: the cycle number's jump
   *  beyond one, less the deadlines the RT thread skipped in between (its overrun count). */
  function countMissed(m) {
    const last = state.cell;
    if (last) state.missed += Math.max(0, m.cycle - last.cycle - 1 - (m.overruns - last.overruns));
  }

  function onMessage(buffer) {
    const bytes = new Uint8Array(buffer);
    if (bytes[0] !== MESSAGE_DATA || bytes.length < 13) return;
    const view = new DataView(buffer);
    const sub = state.subscriptions.get(view.getUint32(1, true));
    if (!sub) return;
    const m = sub.decode(bytes.subarray(13));
    state.received++;
    if (sub.kind === "cycle") {
      countMissed(m);
      onCycle(m);
    } else if (sub.kind === "axis") {
      onAxis(sub.axis, m);
    } else {
      state.newEvents.push(m);
    }
  }

  function subscribe(ws, channels) {
    const subs = [];
    // The server numbers the channels in the cell's order: the axes appear as configured.
    for (const ch of [...channels].sort((a, b) => a.id - b.id)) {
      if (ch.encoding !== "protobuf" || [...state.subscriptions.values()].some((s) => s.channelId === ch.id)) continue;
      let decode;
      try {
        const raw = Uint8Array.from(atob(ch.schema), (c) => c.charCodeAt(0));
        decode = makeDecoder(parseDescriptorSet(raw), ch.schemaName);
      } catch (e) {
        console.warn("cannot decode " + ch.topic + ": " + e);
        continue;
      }
      const id = state.subscriptions.size + 1;
      const sub = { topic: ch.topic, channelId: ch.id, decode };
      if (ch.topic === CYCLE_TOPIC) sub.kind = "cycle";
      else if (ch.topic === EVENTS_TOPIC) sub.kind = "events";
      else if (ch.topic.startsWith(AXIS_PREFIX)) {
        const name = ch.topic.slice(AXIS_PREFIX.length);
        sub.kind = "axis";
        sub.axis = axisCard(name);
        state.axes.set(name, sub.axis);
      } else continue;
      state.subscriptions.set(id, sub);
      subs.push({ id, channelId: ch.id });
    }
    if (subs.length) ws.send(JSON.stringify({ op: "subscribe", subscriptions: subs }));
  }

  // ---- drawing ---------------------------------------------------------------------------

  /** The samples of `axis` in the plot's window, oldest first, as indexes into its rings. */
  function windowIndexes(axis) {
    const n = Math.min(axis.count, PLOT_SAMPLES);
    const start = axis.count - n;
    return { n, at: (k) => (start + k) % PLOT_SAMPLES };
  }

  /** The scale of `series` in the window: 8 % headroom, spanning at least `minSpan`. */
  function range(series, w, minSpan = 2e-3) {
    let lo = Infinity, hi = -Infinity;
    for (const s of series) for (let k = 0; k < w.n; k++) { const v = s[w.at(k)]; if (v < lo) lo = v; if (v > hi) hi = v; }
    if (!isFinite(lo)) return [-1, 1];
    const pad = (hi - lo) * 0.08;
    lo -= pad; hi += pad;
    if (hi - lo < minSpan) { const mid = (lo + hi) / 2; return [mid - minSpan / 2, mid + minSpan / 2]; }
    return [lo, hi];
  }

  /** Draws `series` (per pixel column its min and max) into the band top..top+height. */
  function trace(g, series, w, x0, width, top, height, [lo, hi], colour, dash = []) {
    const y = (v) => top + height - ((v - lo) / (hi - lo)) * height;
    g.strokeStyle = colour;
    g.lineWidth = dash.length ? 2 : 3;
    g.setLineDash(dash);
    g.beginPath();
    let column = -1, min = 0, max = 0, started = false;
    const flush = () => {
      if (column < 0) return;
      const x = x0 + column;
      if (!started) { g.moveTo(x, y(min)); started = true; } else g.lineTo(x, y(min));
      g.lineTo(x, y(max));
    };
    for (let k = 0; k < w.n; k++) {
      const c = Math.floor(((PLOT_SAMPLES - w.n + k) / PLOT_SAMPLES) * width);
      const v = series[w.at(k)];
      if (c !== column) { flush(); column = c; min = max = v; } else { if (v < min) min = v; if (v > max) max = v; }
    }
    flush();
    g.stroke();
    g.setLineDash([]);
  }

  function band(g, label, [lo, hi], x0, width, top, height) {
    g.strokeStyle = "#e4e7ec";
    g.strokeRect(x0, top, width, height);
    g.fillStyle = "#667085";
    g.font = "20px system-ui, sans-serif";
    g.fillText(hi.toPrecision(4), 4, top + 18);
    g.fillText(lo.toPrecision(4), 4, top + height - 4);
    g.fillText(label, x0 + 8, top + 20);
    if (lo < 0 && hi > 0) {
      const y0 = top + height - (-lo / (hi - lo)) * height;
      g.beginPath(); g.moveTo(x0, y0); g.lineTo(x0 + width, y0); g.stroke();
    }
  }

  function drawAxis(axis) {
    const c = axis.canvas, g = c.getContext("2d");
    const css = getComputedStyle(document.documentElement);
    g.clearRect(0, 0, c.width, c.height);
    const w = windowIndexes(axis);
    const x0 = 90, width = c.width - x0 - 4, split = Math.round(c.height * 0.6);
    const pos = range([axis.actual, axis.setpoint], w);
    const fe = range([axis.fe], w, axis.minErrorSpan);
    band(g, "position / setpoint" + axis.unit, pos, x0, width, 2, split - 6);
    band(g, "following error" + axis.unit, fe, x0, width, split + 2, c.height - split - 4);
    trace(g, axis.actual, w, x0, width, 2, split - 6, pos, css.getPropertyValue("--actual"));
    trace(g, axis.setpoint, w, x0, width, 2, split - 6, pos, css.getPropertyValue("--setpoint"), [10, 8]);
    trace(g, axis.fe, w, x0, width, split + 2, c.height - split - 4, fe, css.getPropertyValue("--fe"));
    c.dataset.samples = String(axis.count);
    c.dataset.lastCycle = String(axis.last ? axis.last.cycle : "");
  }

  function drawAxisValues(axis, period) {
    const m = axis.last, q = (cls) => axis.card.querySelector("." + cls);
    if (!m) return;
    q("actual").textContent = m.actual_position.toFixed(3);
    q("setpoint").textContent = m.setpoint_position.toFixed(3);
    q("fe").textContent = m.following_error.toFixed(4);
    const fsa = q("fsa");
    fsa.textContent = pretty(m.fsa_state);
    fsa.className = "fsa" + (m.fsa_state === "OPERATION_ENABLED" ? " enabled" : /FAULT/.test(String(m.fsa_state)) ? " fault" : "");
    const alarm = q("alarm");
    alarm.textContent = m.error_code ? hex4(m.error_code) : "none";
    alarm.className = "alarm" + (m.error_code ? " active" : "");
    q("mode").textContent = { 8: "csp", 9: "csv", 10: "cst" }[m.mode_display] || String(m.mode_display);
    q("cycle").textContent = String(m.cycle);
    if (period) q("window").textContent = ((PLOT_SAMPLES * period) / 1e9).toFixed(1) + " s";
  }

  function latencyPercentile(p) {
    const want = p * state.latencyCount;
    let seen = 0;
    for (let us = 0; us <= LATENCY_BINS_US; us++) {
      seen += state.latency[us];
      if (seen >= want) return us;
    }
    return LATENCY_BINS_US;
  }

  /** Bars of 1-2-5 µs bins on a logarithmic count scale. */
  function drawLatency() {
    const c = $("latency"), g = c.getContext("2d");
    const edges = [0, 1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, Infinity];
    const counts = edges.slice(0, -1).map((lo, i) => {
      let n = 0;
      for (let us = lo; us < Math.min(edges[i + 1], LATENCY_BINS_US + 1); us++) n += state.latency[us];
      return n;
    });
    g.clearRect(0, 0, c.width, c.height);
    const top = Math.log10(Math.max(...counts, 1) + 1), bw = c.width / counts.length, h = c.height - 22;
    g.font = "11px system-ui, sans-serif";
    counts.forEach((n, i) => {
      const bh = (Math.log10(n + 1) / top) * (h - 12);
      g.fillStyle = "#1f6feb";
      g.fillRect(i * bw + 2, h - bh, bw - 4, bh);
      g.fillStyle = "#667085";
      const k = (us) => (us >= 1000 ? us / 1000 + "k" : String(us));
      g.fillText(edges[i + 1] === Infinity ? ">" + k(edges[i]) : "<" + k(edges[i + 1]), i * bw + 4, c.height - 6);
      if (n) g.fillText(String(n), i * bw + 3, h - bh - 2);
    });
    if (state.latencyCount) {
      $("latency-stats").textContent =
        `${state.latencyCount} cycles: p50 ${latencyPercentile(0.5)} µs, p99 ${latencyPercentile(0.99)} µs, ` +
        `max ${state.latencyMax.toFixed(1)} µs (bins in µs)`;
    }
  }

  function drawEvents() {
    const list = $("events");
    for (const e of state.newEvents.splice(0)) {
      const li = document.createElement("li");
      li.dataset.kind = e.kind;
      li.textContent = `cycle ${e.cycle}: ${e.kind}${e.axis ? " [" + e.axis + "]" : ""}${e.detail ? ": " + e.detail : ""}`;
      list.prepend(li);
    }
    while (list.children.length > EVENTS_SHOWN) list.lastChild.remove();
  }

  let period = null;
  function draw() {
    const m = state.cell;
    if (m) {
      $("cell-state").textContent = pretty(m.cell_state);
      $("cycle").textContent = String(m.cycle);
      $("overruns").textContent = String(m.overruns);
      $("dropped").textContent = String(m.dropped_records);
      if (state.lastCycle && m.cycle > state.lastCycle.cycle) {
        period = (m.deadline_ns - state.lastCycle.deadline_ns) / (m.cycle - state.lastCycle.cycle);
      }
      state.lastCycle = m;
    }
    $("received").textContent = String(state.received);
    $("missed").textContent = String(state.missed);
    for (const axis of state.axes.values()) {
      if (!axis.dirty) continue;
      axis.dirty = false;
      drawAxisValues(axis, period);
      drawAxis(axis);
    }
    drawEvents();
    drawLatency();
  }

  // ---- the connection --------------------------------------------------------------------

  function connect() {
    reset();
    const link = $("link");
    const ws = new WebSocket(`ws://${location.hostname}:${LIVE_PORT}`, SUBPROTOCOLS);
    ws.binaryType = "arraybuffer";
    ws.onopen = () => { link.textContent = "connected"; link.className = "up"; };
    ws.onmessage = (ev) => {
      if (typeof ev.data !== "string") return onMessage(ev.data);
      const doc = JSON.parse(ev.data);
      if (doc.op === "advertise") subscribe(ws, doc.channels);
    };
    ws.onclose = () => {
      link.textContent = "disconnected (retrying)";
      link.className = "down";
      setTimeout(connect, 1000);
    };
  }

  connect();
  setInterval(draw, 200);
})();
