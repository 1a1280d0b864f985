// pumpup explore: the page.  Every number drawn comes from the server (pumpup's own API), except the lit sphere,
// which WebGL 2 renders with the GLSL of pumpup.shader(spec, target="glsl-es") when the server sends it.
"use strict";

const BOOT = window.PUMPUP_BOOT || {initial: ["phong:n=20"]};
const COLOURS = ["#1f5fbf", "#d0552a", "#2a9d4b", "#9b3fb5"];
const OVERLAY_DASH = {pumped: "dash", kulla_conty: "dot", scaled: "dashdot"};
const OVERLAY_NAME = {pumped: "pumped", kulla_conty: "Kulla-Conty", scaled: "scaled 1/E"};
const BACKGROUND = [0.20, 0.24, 0.36];  // pumpup.render.BACKGROUND
const CLIP = [1, 0, 1];                   // pumpup.render.CLIP_COLOUR

// the page's data, for people and for the tests: explore.result is the last answer drawn
const explore = window.explore = {
  state: null, result: null, catalog: null, sent: 0, drawn: 0, drawnId: 0, errors: 0, ready: false,
  glErrors: [], sphereRadiance: null,
};

const $ = (id) => document.getElementById(id);

// ---------------------------------------------------------------------------------------------------------------
// State and URL
// ---------------------------------------------------------------------------------------------------------------

function shortSpec(spec) {
  if (typeof spec === "string") return spec;
  const keys = Object.keys(spec).filter((k) => k !== "type");
  if (keys.some((k) => typeof spec[k] === "object" && spec[k] !== null)) return JSON.stringify(spec);
  const items = keys.map((k) => `${k}=${typeof spec[k] === "string" ? spec[k] : JSON.stringify(spec[k])}`);
  return spec.type + (items.length ? ":" + items.join(",") : "");
}

function defaultState() {
  return {specs: BOOT.initial.slice(0, 4), active: 0, theta_i: 30, phi: 0, log: false,
          pump: {on: false, g: "g2", levels: 1}, kulla_conty: false, scaled: false,
          light: 30, light_azimuth: 0, exposure: -2, lobe3d: false};
}

function stateFromURL() {
  const st = defaultState();
  const q = new URLSearchParams(location.search);
  const specs = q.getAll("s");
  if (specs.length) st.specs = specs.slice(0, 4);
  const num = (k, d) => (q.has(k) && isFinite(parseFloat(q.get(k))) ? parseFloat(q.get(k)) : d);
  st.active = Math.min(Math.max(0, Math.round(num("active", 0))), st.specs.length - 1);
  st.theta_i = num("ti", st.theta_i); st.phi = num("phi", st.phi);
  st.log = q.get("log") === "1";
  if (q.has("pump")) {
    const [g, lv] = q.get("pump").split(":");
    st.pump = {on: true, g: g === "g1" ? "g1" : "g2", levels: Math.min(5, Math.max(1, parseInt(lv || "1", 10) || 1))};
  }
  st.kulla_conty = q.get("kc") === "1"; st.scaled = q.get("sc") === "1";
  st.light = num("light", st.light); st.light_azimuth = num("laz", st.light_azimuth);
  st.exposure = num("exp", st.exposure);
  st.lobe3d = q.get("3d") === "1";
  return st;
}

function writeURL() {
  const st = explore.state;
  if (!st) return;
  const q = new URLSearchParams();
  for (const s of st.specs) q.append("s", shortSpec(s));
  if (st.active) q.set("active", st.active);
  q.set("ti", st.theta_i); if (st.phi) q.set("phi", st.phi);
  if (st.log) q.set("log", "1");
  if (st.pump.on) q.set("pump", `${st.pump.g}:${st.pump.levels}`);
  if (st.kulla_conty) q.set("kc", "1");
  if (st.scaled) q.set("sc", "1");
  q.set("light", st.light); if (st.light_azimuth) q.set("laz", st.light_azimuth);
  if (st.exposure !== -2) q.set("exp", st.exposure);
  if (st.lobe3d) q.set("3d", "1");
  const search = "?" + q.toString();
  if (search !== location.search) history.replaceState(null, "", search);
}

// ---------------------------------------------------------------------------------------------------------------
// Messages
// ---------------------------------------------------------------------------------------------------------------

function showMessage(text) {
  const m = $("message");
  if (text) { m.textContent = text; m.hidden = false; } else { m.textContent = ""; m.hidden = true; }
}

function setStatus(text) { setIf($("status"), "textContent", text); }

// ---------------------------------------------------------------------------------------------------------------
// Connection: one WebSocket per tab; a newer request supersedes the one still running on the server
// ---------------------------------------------------------------------------------------------------------------

let socket = null;
let pending = null;  // a request waiting for the socket to open
const sentAt = {};

function connect() {
  const proto = location.protocol === "https:" ? "wss:" : "ws:";
  socket = new WebSocket(`${proto}//${location.host}/ws`);
  socket.onopen = () => { setStatus("connected"); if (pending) { socket.send(pending); pending = null; } };
  socket.onclose = () => { setStatus("disconnected: restart pumpup explore and reload"); };
  socket.onmessage = (ev) => { explore.receivedAt = performance.now(); onAnswer(JSON.parse(ev.data)); };
}

function request() {
  const st = explore.state;
  const id = ++explore.sent;
  sentAt[id] = performance.now();
  const msg = JSON.stringify({id, state: {
    specs: st.specs, theta_i: st.theta_i, phi: st.phi, pump: st.pump, kulla_conty: st.kulla_conty,
    scaled: st.scaled, light: st.light, light_azimuth: st.light_azimuth, lobe3d: st.lobe3d}});
  if (socket && socket.readyState === WebSocket.OPEN) socket.send(msg); else pending = msg;
  // the page's own bookkeeping runs while the server computes; the status says "computing" only when the answer
  // takes longer than a glance (a quick answer then changes the page once: one frame to draw, not two)
  writeURL();
  setTimeout(() => { if (explore.drawnId < id && explore.sent === id) setStatus("computing…"); }, 250);
  return id;
}

// plotly.js (4.8 MB, served by pumpup from the installed plotly package) draws the 3-D lobe only: it is loaded the
// first time that view is turned on
let plotlyLoading = null;

function loadPlotly() {
  if (!plotlyLoading) {
    plotlyLoading = new Promise((resolve, reject) => {
      const tag = document.createElement("script");
      tag.src = "/static/plotly.min.js";
      tag.onload = () => resolve();
      tag.onerror = () => { showMessage("plotly.js did not load from the server"); reject(new Error("plotly.js")); };
      document.head.appendChild(tag);
    });
  }
  return plotlyLoading;
}

function onAnswer(ans) {
  if (ans.cancelled) return;
  if (ans.id !== null && ans.id !== explore.sent) return;  // an older answer: a newer request is on its way
  if (!ans.ok) {
    explore.errors += 1;
    showMessage(ans.error);
    setStatus("error: the views show the last good state");
    // back to the last good models, so that the next slider move does not send the bad spec again (the spec box
    // keeps the text to correct)
    if (explore.result) {
      explore.state.specs = explore.result.models.map((m) => m.input);
      explore.state.active = Math.min(explore.state.active, explore.state.specs.length - 1);
      writeURL();
    }
    explore.drawnId = ans.id;
    explore.drawn += 1;
    document.body.dataset.drawn = String(explore.drawn);
    return;
  }
  showMessage("");
  const r = ans.result;
  // the server parsed every spec: keep the user's own parameters (the canonical spec also holds computed defaults)
  r.models.forEach((m, i) => { explore.state.specs[i] = m.input; });
  explore.result = r;
  try {
    draw(r);
  } catch (e) {
    showMessage("drawing failed: " + e);
    throw e;
  }
  const ms = performance.now() - sentAt[ans.id];
  const status = `${r.models.length} model${r.models.length > 1 ? "s" : ""}: server ${ans.ms.toFixed(0)} ms, ` +
                 `drawn ${ms.toFixed(0)} ms after the request`;
  explore.drawnId = ans.id;
  explore.drawn += 1;
  explore.lastMs = ms;
  // when the request left, its answer arrived and the views were drawn (performance.now(), for the benchmark)
  explore.timing = {sent: sentAt[ans.id], received: explore.receivedAt, drawn: performance.now()};
  explore.serverMs = ans.ms;
  document.body.dataset.drawn = String(explore.drawn);
  // the controls, links and URL in the same task as the views, so that one frame shows them all (only what
  // changed is touched)
  setStatus(status);
  writeURL();
  updateControls();
  explore.ready = explore.catalog !== null;  // the views drawn and the controls built
}

// ---------------------------------------------------------------------------------------------------------------
// Controls
// ---------------------------------------------------------------------------------------------------------------

function catalogEntry(type) { return (explore.catalog || []).find((m) => m.type === type); }

function activeSpec() {
  const s = explore.state.specs[explore.state.active];
  return typeof s === "string" ? null : s;
}

function activeCanonical() {
  const r = explore.result;
  return r && r.models[explore.state.active] ? r.models[explore.state.active].spec : null;
}

const LOG_STEPS = 1000;

function sliderToValue(slider, x) {
  const {lo, hi, log} = slider;
  const t = x / LOG_STEPS;
  return log ? Math.exp(Math.log(lo) + t * (Math.log(hi) - Math.log(lo))) : lo + t * (hi - lo);
}

function valueToSlider(slider, v) {
  const {lo, hi, log} = slider;
  let t = log ? (Math.log(Math.max(v, lo)) - Math.log(lo)) / (Math.log(hi) - Math.log(lo)) : (v - lo) / (hi - lo);
  t = Math.min(1, Math.max(0, isFinite(t) ? t : 0));
  return Math.round(t * LOG_STEPS);
}

function niceNumber(v, log) {
  if (!log) return parseFloat(v.toPrecision(4));
  return parseFloat(v.toPrecision(3));
}

function setParam(name, value) {
  const st = explore.state;
  const spec = Object.assign({}, activeSpec() || {type: activeCanonical().type});
  if (value === undefined) delete spec[name]; else spec[name] = value;
  st.specs[st.active] = spec;
  request();
}

function buildParams() {
  const box = $("params");
  box.innerHTML = "";
  const canon = activeCanonical();
  if (!canon) return;
  const entry = catalogEntry(canon.type);
  if (!entry) return;
  const user = activeSpec() || {};
  for (const p of entry.params) {
    const row = document.createElement("div");
    row.className = "param";
    row.dataset.param = p.name;
    const label = document.createElement("span");
    label.textContent = p.name;
    label.title = p.doc || "";
    row.appendChild(label);
    const current = canon[p.name];
    const given = Object.prototype.hasOwnProperty.call(user, p.name);
    if (p.slider) {
      const range = document.createElement("input");
      range.type = "range"; range.min = 0; range.max = LOG_STEPS; range.step = 1;
      range.id = `param-${p.name}`;
      if (typeof current === "number") range.value = valueToSlider(p.slider, current);
      range.addEventListener("input", () => {
        let v = niceNumber(sliderToValue(p.slider, +range.value), p.slider.log);
        if (p.kind === "int") v = Math.round(v);
        field.value = String(v); field.classList.remove("default");
        setParam(p.name, v);
      });
      row.appendChild(range);
      const field = document.createElement("input");
      field.type = "text"; field.id = `field-${p.name}`;
      field.value = current === undefined || current === null ? "" : String(current);
      if (!given) field.classList.add("default");
      field.title = given ? "" : "default (computed from the other parameters); type a value to set it";
      field.addEventListener("change", () => {
        const text = field.value.trim();
        if (text === "") { setParam(p.name, undefined); return; }
        const v = Number(text);
        if (!isFinite(v) || text === "") { showMessage(`${canon.type}: parameter '${p.name}' must be a number in ${p.range}, got '${text}'`); return; }
        setParam(p.name, v);
      });
      row.appendChild(field);
    } else if (p.choices && p.choices.length) {
      const sel = document.createElement("select");
      sel.id = `param-${p.name}`;
      for (const c of p.choices) { const o = document.createElement("option"); o.textContent = c; sel.appendChild(o); }
      if (current !== undefined) sel.value = current;
      sel.addEventListener("change", () => setParam(p.name, sel.value));
      row.appendChild(sel);
      row.appendChild(document.createElement("span"));
    } else if (p.kind === "bool") {
      const cb = document.createElement("input");
      cb.type = "checkbox"; cb.checked = !!current; cb.id = `param-${p.name}`;
      cb.addEventListener("change", () => setParam(p.name, cb.checked));
      row.appendChild(cb); row.appendChild(document.createElement("span"));
    } else {
      const span = document.createElement("code");
      span.textContent = current === undefined || current === null ? "—" : JSON.stringify(current);
      span.style.gridColumn = "2 / 4";
      span.title = "edit it in the spec box";
      row.appendChild(span);
    }
    const rg = document.createElement("div");
    rg.className = "range";
    rg.textContent = `${p.range}${p.slider && p.slider.log ? " (log slider)" : ""}${p.doc ? " · " + p.doc : ""}`;
    row.appendChild(rg);
    box.appendChild(row);
  }
}

// set an element's property only when its value changes (an unchanged page is not laid out or painted again)
function setIf(el, prop, value) { if (el[prop] !== value) el[prop] = value; }

function updateControls() {
  const st = explore.state;
  const tabs = $("model-tabs");
  const names = st.specs.map((s) => (typeof s === "string" ? s : s.type));
  const signature = JSON.stringify([names, st.active]);
  if (tabs.dataset.signature !== signature) buildTabs(tabs, names, signature);
  setIf($("add-model"), "disabled", st.specs.length >= 4);
  const canon = activeCanonical();
  if (canon) {
    setIf($("model-type"), "value", canon.type);
    if (document.activeElement !== $("spec-text")) setIf($("spec-text"), "value", shortSpec(activeSpec() || canon));
  }
  // rebuild the parameter rows unless the user is dragging one of them
  const focused = document.activeElement;
  if (!(focused && focused.closest && focused.closest("#params"))) buildParams();
  else if (canon) {
    for (const row of document.querySelectorAll("#params .param")) {
      const f = row.querySelector("input[type=text]");
      const v = canon[row.dataset.param];
      if (f && f !== focused && typeof v === "number") setIf(f, "value", String(v));
    }
  }
  // the downloads take the spec as the user gave it (the canonical one also names computed defaults)
  const spec = encodeURIComponent(JSON.stringify(activeSpec() || canon || {}));
  setIf($("dl-spec"), "href", new URL(`/download/spec.json?spec=${spec}`, location.href).href);
  setIf($("dl-nc"), "href", new URL(`/download/albedo.nc?spec=${spec}`, location.href).href);
  setIf($("dl-glsl"), "href", new URL(`/download/shader.glsl?spec=${spec}`, location.href).href);
  setIf($("dl-brdf"), "href", new URL(`/download/shader.brdf?spec=${spec}`, location.href).href);
  setIf($("dl-mitsuba"), "href", new URL(`/download/mitsuba.json?spec=${spec}`, location.href).href);
  setIf($("dl-lut-cycles"), "href", new URL(`/download/lut?preset=cycles&spec=${spec}`, location.href).href);
  setIf($("dl-lut-nc"), "href", new URL(`/download/lut?preset=netcdf&spec=${spec}`, location.href).href);
  setIf($("dl-lut-row"), "hidden",
        !(canon && ["ggx", "beckmann", "ward", "modified_ward", "cook_torrance"].includes(canon.type)));
  const r = explore.result;
  const m = r && r.models[st.active];
  const noShader = !(m && m.shader && m.shader.glsl);
  setIf($("dl-glsl"), "hidden", noShader);
  setIf($("dl-brdf"), "hidden", noShader);
  if (r) { setIf($("python"), "textContent", r.lines.python); setIf($("cli"), "textContent", r.lines.cli); }
}

function buildTabs(tabs, names, signature) {
  const st = explore.state;
  tabs.dataset.signature = signature;
  tabs.innerHTML = "";
  names.forEach((name, i) => {
    const b = document.createElement("button");
    b.type = "button";
    b.className = i === st.active ? "active" : "";
    b.style.color = COLOURS[i];
    b.textContent = `${i + 1}: ${name}`;
    b.addEventListener("click", () => { st.active = i; writeURL(); updateControls(); });
    tabs.appendChild(b);
    if (st.specs.length > 1) {
      const x = document.createElement("button");
      x.type = "button"; x.textContent = "×"; x.title = "remove from the comparison";
      x.addEventListener("click", () => {
        st.specs.splice(i, 1); st.active = Math.min(st.active, st.specs.length - 1); request();
      });
      tabs.appendChild(x);
    }
  });
}

function bindRange(id, apply, fmt) {
  const el = $(id), out = $(id + "-out");
  el.addEventListener("input", () => { if (out) out.textContent = fmt ? fmt(+el.value) : el.value; apply(+el.value); });
}

function initControls() {
  const st = explore.state;
  const sel = $("model-type");
  for (const m of explore.catalog) {
    const o = document.createElement("option"); o.value = m.type; o.textContent = m.type; o.title = m.doc; sel.appendChild(o);
  }
  sel.addEventListener("change", () => {
    const entry = catalogEntry(sel.value);
    st.specs[st.active] = Object.assign({}, entry.example);
    request();
  });
  const apply = () => {
    const text = $("spec-text").value.trim();
    st.specs[st.active] = text;  // the server parses and checks it; a bad one shows its message
    request();
  };
  $("spec-apply").addEventListener("click", apply);
  $("spec-text").addEventListener("keydown", (e) => { if (e.key === "Enter" && !e.shiftKey) { e.preventDefault(); apply(); } });
  $("add-model").addEventListener("click", () => {
    if (st.specs.length >= 4) return;
    st.specs.push(JSON.parse(JSON.stringify(st.specs[st.active])));
    st.active = st.specs.length - 1;
    request();
  });
  const setv = (id, v) => { $(id).value = v; const o = $(id + "-out"); if (o) o.textContent = v; };
  setv("theta-i", st.theta_i); setv("phi", st.phi); setv("pump-levels", st.pump.levels);
  setv("light", st.light); setv("light-az", st.light_azimuth); setv("exposure", st.exposure);
  $("log").checked = st.log; $("pump-on").checked = st.pump.on; $("pump-g").value = st.pump.g;
  $("kc").checked = st.kulla_conty; $("scaled").checked = st.scaled;
  bindRange("theta-i", (v) => { st.theta_i = v; request(); });
  bindRange("phi", (v) => { st.phi = v; request(); });
  bindRange("pump-levels", (v) => { st.pump.levels = v; if (st.pump.on) request(); else writeURL(); });
  bindRange("light", (v) => { st.light = v; lightMoved(); });
  bindRange("light-az", (v) => { st.light_azimuth = v; lightMoved(); });
  bindRange("exposure", (v) => { st.exposure = v; if (explore.result) drawSpheres(explore.result); writeURL(); });
  $("log").addEventListener("change", () => { st.log = $("log").checked; if (explore.result) draw(explore.result); writeURL(); });
  $("pump-on").addEventListener("change", () => { st.pump.on = $("pump-on").checked; request(); });
  $("pump-g").addEventListener("change", () => { st.pump.g = $("pump-g").value; if (st.pump.on) request(); else writeURL(); });
  $("kc").addEventListener("change", () => { st.kulla_conty = $("kc").checked; request(); });
  $("lobe3d-on").checked = st.lobe3d;
  $("lobe3d-on").addEventListener("change", () => { st.lobe3d = $("lobe3d-on").checked; request(); });
  $("scaled").addEventListener("change", () => { st.scaled = $("scaled").checked; request(); });
}

function lightMoved() {
  const r = explore.result;
  if (r && r.models.every((m) => m.shader && m.shader.glsl)) { drawSpheres(r); writeURL(); }
  else request();  // the server renders the sphere (no shader export)
}

// ---------------------------------------------------------------------------------------------------------------
// Plots: the lobe, the albedo and the image slice are drawn on the page's own canvases (a redraw is a few
// milliseconds of 2-D drawing, and no plotting library has to load before the page is ready); plotly.js is loaded
// only for the 3-D lobe
// ---------------------------------------------------------------------------------------------------------------

function label(m, i) {
  const text = m.short.length > 44 ? m.short.slice(0, 42) + "…" : m.short;
  return `${i + 1}: ${text}`;
}

const DASH = {solid: [], dash: [7, 4], dot: [2, 3], dashdot: [7, 3, 2, 3]};
const FONT = "11px system-ui, sans-serif";

// the CSS size of each plot box, kept by a ResizeObserver (a redraw does not read the layout)
const boxSize = {};
const resized = new ResizeObserver((entries) => {
  let changed = false;
  for (const e of entries) {
    const w = Math.round(e.contentRect.width), h = Math.round(e.contentRect.height);
    const old = boxSize[e.target.id];
    if (!old || old[0] !== w || old[1] !== h) { boxSize[e.target.id] = [w, h]; changed = true; }
  }
  if (changed) {
    const r = explore.result || {models: []};
    drawLobe(r); drawAlbedo(r, false);
  }
});

// the plot box's canvas, sized to the box (device pixels), cleared, with a context in CSS pixels
function plotCanvas(id) {
  const box = $(id);
  let c = box.firstElementChild;
  if (!c) {
    c = document.createElement("canvas");
    box.appendChild(c);
    resized.observe(box);
    hover(box, c);
  }
  if (!boxSize[id]) boxSize[id] = [box.clientWidth, box.clientHeight];
  const [w, h] = boxSize[id];
  const dpr = window.devicePixelRatio || 1;
  const W = Math.max(1, Math.round(w * dpr)), H = Math.max(1, Math.round(h * dpr));
  if (c.width !== W || c.height !== H) { c.width = W; c.height = H; c.style.width = `${w}px`; c.style.height = `${h}px`; }
  const ctx = c.getContext("2d");
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, w, h);
  ctx.font = FONT;
  return {ctx, w, h, canvas: c};
}

// about n round numbers from lo to hi (steps of 1, 2 or 5 times a power of ten)
function niceTicks(lo, hi, n) {
  const span = hi - lo;
  if (!(span > 0) || !isFinite(span)) return [lo];
  const raw = span / n, mag = Math.pow(10, Math.floor(Math.log10(raw))), f = raw / mag;
  const step = (f < 1.5 ? 1 : f < 3 ? 2 : f < 7 ? 5 : 10) * mag;
  const out = [];
  for (let k = Math.ceil(lo / step - 1e-9); k * step <= hi + 1e-9 * step; k++) out.push(k * step);
  return out;
}

function tickText(v) {
  if (v === 0) return "0";
  const a = Math.abs(v);
  return a >= 1e4 || a < 1e-3 ? v.toExponential(0).replace("e+", "e") : String(parseFloat(v.toPrecision(6)));
}

function strokePath(ctx, pts, colour, width, dash) {
  ctx.strokeStyle = colour; ctx.lineWidth = width; ctx.setLineDash(DASH[dash || "solid"]);
  ctx.beginPath();
  let pen = false;
  for (const p of pts) {
    if (p === null) { pen = false; continue; }
    if (pen) ctx.lineTo(p[0], p[1]); else { ctx.moveTo(p[0], p[1]); pen = true; }
  }
  ctx.stroke();
  ctx.setLineDash([]);
}

// a legend in rows across the top of a plot: [name, colour, width, dash]
function drawLegend(ctx, entries, x0, y0, w) {
  let x = x0, y = y0;
  ctx.textAlign = "left"; ctx.textBaseline = "middle";
  for (const [name, colour, width, dash] of entries) {
    const tw = 26 + ctx.measureText(name).width + 14;
    if (x + tw > x0 + w && x > x0) { x = x0; y += 15; }
    strokePath(ctx, [[x, y], [x + 20, y]], colour, width, dash);
    ctx.fillStyle = "#333"; ctx.fillText(name, x + 25, y);
    x += tw;
  }
  return y + 10;
}

// what the page shows under the pointer: each plot sets plotHover[id] = (x, y) -> text or null
const plotHover = {};

function hover(box, canvas) {
  const tip = document.createElement("div");
  tip.className = "tip"; tip.hidden = true;
  box.appendChild(tip);
  canvas.addEventListener("mousemove", (ev) => {
    const f = plotHover[box.id];
    const rect = canvas.getBoundingClientRect();
    const x = ev.clientX - rect.left, y = ev.clientY - rect.top;
    const text = f ? f(x, y) : null;
    if (!text) { tip.hidden = true; return; }
    tip.textContent = text; tip.hidden = false;
    tip.style.left = `${Math.min(x + 12, rect.width - 200)}px`; tip.style.top = `${y + 12}px`;
  });
  canvas.addEventListener("mouseleave", () => { tip.hidden = true; });
}

// the lobe in the plane of incidence, f_r cos(theta_o): a half disc, theta_o = 0 (the normal) up, the mirror side
// (theta_o > 0) right, the light (-theta_i) a grey dotted spoke
function drawLobe(r) {
  const st = explore.state;
  const {ctx, w, h} = plotCanvas("lobe");
  const curves = [];
  r.models.forEach((m, i) => {
    if (m.lobe && !m.lobe.error) curves.push([label(m, i), m.lobe, COLOURS[i], 2, "solid"]);
    for (const [k, o] of Object.entries(m.overlays || {})) {
      if (o.lobe && !o.lobe.error) curves.push([`${i + 1}: ${OVERLAY_NAME[k]}`, o.lobe, COLOURS[i], 1.5, OVERLAY_DASH[k]]);
    }
  });
  let rmax = 0;
  for (const c of curves) for (const v of c[1].value) if (v > rmax) rmax = v;
  const legend = curves.map(([name, , colour, width, dash]) => [name, colour, width, dash]);
  const top = drawLegend(ctx, legend.concat([["light", "#888", 1, "dot"]]), 10, 10, w - 20);
  const cx = w / 2, cy = h - 22;
  const R = Math.max(10, Math.min(w / 2 - 34, cy - top - 14));
  // the radial scale: linear from 0 to a round number >= the largest value, or four decades below it (log)
  let toR, ticks, lo = 0, hi = 1;
  if (st.log) {
    hi = rmax > 0 ? Math.log10(rmax) + 0.05 : 0; lo = hi - 4.05;
    toR = (v) => (v > 0 ? R * Math.max(0, (Math.log10(v) - lo) / (hi - lo)) : null);
    ticks = [];
    for (let k = Math.ceil(lo); k <= hi; k++) ticks.push(Math.pow(10, k));
  } else {
    const t = niceTicks(0, rmax > 0 ? rmax : 1, 4);
    hi = t[t.length - 1] < rmax ? t[t.length - 1] + (t[1] - t[0]) : t[t.length - 1];
    if (hi < rmax || !(hi > 0)) hi = rmax > 0 ? rmax : 1;
    toR = (v) => R * Math.max(0, v) / hi;
    ticks = niceTicks(0, hi, 4).filter((v) => v > 0);
  }
  const at = (deg, rad) => [cx + rad * Math.sin(deg * Math.PI / 180), cy - rad * Math.cos(deg * Math.PI / 180)];
  // grid: half circles at the radial ticks, spokes every 15 degrees
  ctx.strokeStyle = "#e2e4ea"; ctx.lineWidth = 1;
  for (const v of ticks) { const rr = toR(v); ctx.beginPath(); ctx.arc(cx, cy, rr, Math.PI, 2 * Math.PI); ctx.stroke(); }
  ctx.fillStyle = "#555"; ctx.textAlign = "center"; ctx.textBaseline = "middle";
  for (let d = -90; d <= 90; d += 15) {
    const [x, y] = at(d, R);
    ctx.strokeStyle = d === 0 ? "#c8ccd6" : "#e2e4ea";
    ctx.beginPath(); ctx.moveTo(cx, cy); ctx.lineTo(x, y); ctx.stroke();
    const [lx, ly] = at(d, R + 14);
    ctx.fillText(`${d}°`, lx, ly);
  }
  ctx.strokeStyle = "#9aa0ad"; ctx.beginPath(); ctx.arc(cx, cy, R, Math.PI, 2 * Math.PI); ctx.stroke();
  ctx.textBaseline = "top";
  for (const v of ticks) ctx.fillText(tickText(v), cx + toR(v), cy + 4);
  // the light, then the curves
  strokePath(ctx, [at(-st.theta_i, 0), at(-st.theta_i, R)], "#888", 1, "dot");
  ctx.save();
  ctx.beginPath(); ctx.rect(0, 0, w, cy + 1); ctx.clip();
  for (const [, lobe, colour, width, dash] of curves) {
    const pts = lobe.theta_o.map((t, k) => { const rr = toR(lobe.value[k]); return rr === null ? null : at(t, rr); });
    strokePath(ctx, pts, colour, width, dash);
  }
  ctx.restore();
  plotHover.lobe = (x, y) => {
    if (!curves.length) return null;
    const t = Math.atan2(x - cx, cy - y) * 180 / Math.PI;
    if (!(Math.abs(t) < 90) || Math.hypot(x - cx, y - cy) > R + 8) return null;
    return `θo ${t.toFixed(1)}°: ` + curves.map(([name, lobe]) => {
      let best = 0;
      for (let k = 1; k < lobe.theta_o.length; k++) if (Math.abs(lobe.theta_o[k] - t) < Math.abs(lobe.theta_o[best] - t)) best = k;
      return `${name} ${lobe.value[best].toPrecision(4)}`;
    }).join(" · ");
  };
}

// the directional albedo a(theta_i) with its error band, the overlays, where a > 1 (red) and the line a = 1;
// then the table of numbers (only when ``table``)
function drawAlbedo(r, table = true) {
  const st = explore.state;
  const {ctx, w, h} = plotCanvas("albedo");
  const entries = [], curves = [];
  let ylo = Infinity, yhi = -Infinity;
  r.models.forEach((m, i) => {
    const a = m.albedo;
    if (!a || a.error) return;
    a.a.forEach((v, k) => { ylo = Math.min(ylo, v - a.err[k]); yhi = Math.max(yhi, v + a.err[k]); });
    entries.push([label(m, i), COLOURS[i], 2, "solid"]);
    curves.push([a, COLOURS[i], 2, "solid", true]);
    for (const [k, o] of Object.entries(m.overlays || {})) {
      if (!o.albedo || o.albedo.error) continue;
      o.albedo.a.forEach((v) => { ylo = Math.min(ylo, v); yhi = Math.max(yhi, v); });
      entries.push([`${i + 1}: ${OVERLAY_NAME[k]}`, COLOURS[i], 1.5, OVERLAY_DASH[k]]);
      curves.push([o.albedo, COLOURS[i], 1.5, OVERLAY_DASH[k], false]);
    }
  });
  ylo = Math.min(ylo, 1); yhi = Math.max(yhi, 1);  // the line a = 1 is always in view
  if (!isFinite(ylo)) { ylo = 0; yhi = 1; }
  const pad = 0.05 * (yhi - ylo || 1);
  ylo -= pad; yhi += pad;
  const top = entries.length ? drawLegend(ctx, entries, 55, 10, w - 65) : 10;
  const L = 55, Rr = w - 10, T = top + 4, B = h - 38;
  const X = (t) => L + (Rr - L) * t / 90, Y = (v) => B - (B - T) * (v - ylo) / (yhi - ylo);
  ctx.fillStyle = "#ff000022";
  for (const m of r.models) {
    if (!m.albedo || m.albedo.error) continue;
    for (const [t0, t1] of m.albedo.above_one) ctx.fillRect(X(t0 - 0.5), T, X(t1 + 0.5) - X(t0 - 0.5), B - T);
  }
  // axes and grid
  ctx.strokeStyle = "#e2e4ea"; ctx.lineWidth = 1; ctx.fillStyle = "#555";
  ctx.textAlign = "center"; ctx.textBaseline = "top";
  for (let t = 0; t <= 90; t += 15) {
    ctx.beginPath(); ctx.moveTo(X(t), T); ctx.lineTo(X(t), B); ctx.stroke();
    ctx.fillText(String(t), X(t), B + 4);
  }
  ctx.textAlign = "right"; ctx.textBaseline = "middle";
  for (const v of niceTicks(ylo, yhi, 5)) {
    ctx.beginPath(); ctx.moveTo(L, Y(v)); ctx.lineTo(Rr, Y(v)); ctx.stroke();
    ctx.fillText(tickText(v), L - 5, Y(v));
  }
  ctx.strokeStyle = "#9aa0ad"; ctx.strokeRect(L, T, Rr - L, B - T);
  ctx.textAlign = "center"; ctx.textBaseline = "bottom";
  ctx.fillText("θi (degrees)", (L + Rr) / 2, h - 2);
  ctx.save(); ctx.translate(12, (T + B) / 2); ctx.rotate(-Math.PI / 2); ctx.textBaseline = "middle";
  ctx.fillText("a(θi)", 0, 0); ctx.restore();
  strokePath(ctx, [[L, Y(1)], [Rr, Y(1)]], "#a00", 1, "dot");
  strokePath(ctx, [[X(st.theta_i), T], [X(st.theta_i), B]], "#888", 1, "dot");
  ctx.save();
  ctx.beginPath(); ctx.rect(L, T, Rr - L, B - T); ctx.clip();
  for (const [a, colour, width, dash, band] of curves) {
    if (band) {  // the error band: a +- err
      ctx.fillStyle = colour + "55";
      ctx.beginPath();
      a.theta.forEach((t, k) => ctx.lineTo(X(t), Y(a.a[k] + a.err[k])));
      for (let k = a.theta.length - 1; k >= 0; k--) ctx.lineTo(X(a.theta[k]), Y(a.a[k] - a.err[k]));
      ctx.closePath(); ctx.fill();
    }
    strokePath(ctx, a.theta.map((t, k) => [X(t), Y(a.a[k])]), colour, width, dash);
  }
  ctx.restore();
  plotHover.albedo = (x, y) => {
    if (!curves.length || x < L || x > Rr || y < T || y > B) return null;
    const t = 90 * (x - L) / (Rr - L);
    const a0 = curves[0][0];
    let best = 0;
    for (let k = 1; k < a0.theta.length; k++) if (Math.abs(a0.theta[k] - t) < Math.abs(a0.theta[best] - t)) best = k;
    return `θi ${a0.theta[best].toFixed(2)}°: ` + curves.map(([a], c) =>
      `${entries[c][0]}: a = ${a.a[best].toPrecision(10)}` + (a.err ? ` ± ${a.err[best].toPrecision(2)}` : "")).join(" · ");
  };
  if (table) drawNumbers(r);
}

function drawNumbers(r) {
  const body = $("numbers").querySelector("tbody");
  const old = body.children;
  let at = 0;  // rows are rewritten in place (only the text that changed), so the table is laid out only as needed
  const row = (cls) => {
    let tr = old[at];
    if (!tr || tr.className !== cls) {
      const fresh = document.createElement("tr");
      fresh.className = cls;
      if (tr) body.replaceChild(fresh, tr); else body.appendChild(fresh);
      tr = fresh;
    }
    at += 1;
    return tr;
  };
  const rows = [];
  r.models.forEach((m, i) => {
    rows.push([label(m, i), m, COLOURS[i]]);
    for (const [k, o] of Object.entries(m.overlays || {})) rows.push([`${i + 1}: ${OVERLAY_NAME[k]}`, o, COLOURS[i]]);
  });
  rows.forEach(([name, m], k) => {
    const tr = row(m.error ? "model error" : "model");
    if (tr.dataset.row !== String(k)) tr.dataset.row = k;
    let c = 0;
    const cell = (cls, text, value) => {
      let td = tr.children[c++];
      if (!td) { td = document.createElement("td"); tr.appendChild(td); }
      setIf(td, "className", cls); setIf(td, "textContent", text);
      if (value !== undefined) { if (td.dataset.value !== String(value)) td.dataset.value = String(value); }
      else delete td.dataset.value;
    };
    cell("name", name);
    if (m.error) { cell("error", m.error); while (tr.children.length > c) tr.removeChild(tr.lastChild); return; }
    cell("mean-albedo", m.mean_albedo !== undefined ? m.mean_albedo.toPrecision(10) : "—", m.mean_albedo);
    const mc = m.max_constant;
    cell("max-constant", mc ? `${mc.name} ≤ ${mc.value.toPrecision(8)} (max a at ${mc.theta.toFixed(2)}°)` : "—",
         mc ? mc.value : undefined);
    cell("max-albedo", m.albedo && !m.albedo.error ? m.albedo.max.toPrecision(10) : "—", m.albedo ? m.albedo.max : undefined);
    const spans = m.albedo && m.albedo.above_one ? m.albedo.above_one : [];
    cell("above-one", spans.length ? spans.map(([a, b]) => `${a.toFixed(1)}–${b.toFixed(1)}°`).join(", ") : "nowhere");
    while (tr.children.length > c) tr.removeChild(tr.lastChild);
    for (const note of m.notes || []) {
      const nr = row("note");
      if (!nr.firstChild) { const td = document.createElement("td"); td.colSpan = 5; nr.appendChild(td); }
      setIf(nr.firstChild, "textContent", "note: " + note);
    }
  });
  while (body.children.length > at) body.removeChild(body.lastChild);
}

function decode64(text) {
  const bin = atob(text);
  const bytes = new Uint8Array(bin.length);
  for (let k = 0; k < bin.length; k++) bytes[k] = bin.charCodeAt(k);
  return new Float64Array(bytes.buffer);
}

// what a view drew last: a view whose inputs did not change is not drawn again (the slice and the furnace do not
// depend on the incidence angle)
const lastDrawn = {};

function sameInputs(view, key) {
  const old = lastDrawn[view];
  lastDrawn[view] = key;
  return old !== undefined && old.length === key.length && old.every((v, k) => v === key[k]);
}

// plotly's Viridis
const VIRIDIS = [[0, "#440154"], [0.06274509803921569, "#48186a"], [0.12549019607843137, "#472d7b"],
  [0.18823529411764706, "#424086"], [0.25098039215686274, "#3b528b"], [0.3137254901960784, "#33638d"],
  [0.3764705882352941, "#2c728e"], [0.4392156862745098, "#26828e"], [0.5019607843137255, "#21918c"],
  [0.5647058823529412, "#1fa088"], [0.6274509803921569, "#28ae80"], [0.6901960784313725, "#3fbc73"],
  [0.7529411764705882, "#5ec962"], [0.8156862745098039, "#84d44b"], [0.8784313725490196, "#addc30"],
  [0.9411764705882353, "#d8e219"], [1, "#fde725"]];

// Viridis in 256 steps: entry k is the colour of t = k / 255, interpolated linearly in RGB between the stops
const VIRIDIS_LUT = (() => {
  const rgb = VIRIDIS.map(([t, c]) => [t, [1, 3, 5].map((o) => parseInt(c.slice(o, o + 2), 16))]);
  const out = [];
  for (let k = 0; k < 256; k++) {
    const t = k / 255;
    let j = 0;
    while (j < rgb.length - 2 && rgb[j + 1][0] < t) j++;
    const [t0, c0] = rgb[j], [t1, c1] = rgb[j + 1];
    const u = Math.min(1, Math.max(0, (t - t0) / (t1 - t0)));
    out.push(c0.map((v, q) => Math.round(v + u * (c1[q] - v))));
  }
  return out;
})();

// the colour of z on the scale [cmin, cmax] (null: no value, drawn transparent)
function viridis(z, cmin, cmax) {
  if (z === null || !isFinite(z)) return null;
  const t = cmax > cmin ? (z - cmin) / (cmax - cmin) : 0;
  return VIRIDIS_LUT[Math.round(255 * Math.min(1, Math.max(0, t)))];
}
explore.viridis = viridis;

// the colour bar spans the height of the first panel's image
const sliceResized = new ResizeObserver((entries) => {
  for (const e of entries) setIf($("slice-scale").style, "height", `${Math.round(e.contentRect.height) + 60}px`);
});

// the image slice f_r(theta_h, theta_d): one panel per model, every panel on one colour scale (the bar beside
// them); a panel is an n x n canvas, one pixel per value (theta_d up, theta_h right), scaled without smoothing
function drawSlice(r) {
  const st = explore.state;
  if (sameInputs("slice", [st.log, ...r.models.map((m) => (m.slice ? m.slice.data || m.slice.error : null))])) return;
  const box = $("slice");
  const n = r.models.length;
  while (box.children.length > n) box.removeChild(box.lastChild);
  let zmax = 0;
  const images = r.models.map((m) => (m.slice && !m.slice.error ? decode64(m.slice.data) : null));
  images.forEach((im) => { if (im) for (const v of im) if (v > zmax) zmax = v; });
  const cmin = st.log ? Math.log10(Math.max(zmax, 1e-30)) - 4 : 0;
  const cmax = st.log ? Math.log10(Math.max(zmax, 1e-30)) : zmax;
  r.models.forEach((m, i) => {
    let panel = box.children[i];
    if (!panel) {
      panel = document.createElement("div");
      panel.className = "slice-panel";
      const ticks = (cls) => `<div class="${cls}">` + [0, 30, 60, 90].map((t) => `<span style="--at:${t / 90}">${t}</span>`).join("") + "</div>";
      panel.innerHTML = `<div class="slice-title"></div><div class="slice-y">θd (°)</div>${ticks("slice-yticks")}` +
        `<canvas class="slice-img" id="slice-${i}"></canvas>${ticks("slice-xticks")}<div class="slice-x">θh (°)</div>` +
        `<div class="slice-err"></div>`;
      box.appendChild(panel);
      const canvas = panel.querySelector("canvas");
      if (i === 0) sliceResized.observe(canvas);
      canvas.addEventListener("mousemove", (ev) => {
        const im = canvas._values, k = canvas.width;
        if (!im) return;
        const rect = canvas.getBoundingClientRect();
        const col = Math.min(k - 1, Math.floor(k * (ev.clientX - rect.left) / rect.width));
        const row = Math.min(k - 1, Math.floor(k * (rect.bottom - ev.clientY) / rect.height));
        const a = canvas._axis;
        canvas.title = `θh ${a[col].toFixed(1)}°, θd ${a[row].toFixed(1)}°: ${im[row * k + col].toPrecision(4)}`;
      });
    }
    const title = panel.querySelector(".slice-title");
    setIf(title, "textContent", n > 1 ? String(i + 1) : label(m, i));
    title.style.color = COLOURS[i];
    const canvas = panel.querySelector("canvas"), im = images[i];
    setIf(panel.querySelector(".slice-err"), "textContent", m.slice && m.slice.error ? "slice: " + m.slice.error : "");
    canvas.hidden = !im;
    if (!im) { canvas._values = null; return; }
    const k = m.slice.n;
    if (canvas.width !== k) { canvas.width = k; canvas.height = k; }
    const ctx = canvas.getContext("2d");
    const data = ctx.createImageData(k, k);
    for (let row = 0; row < k; row++) {
      for (let col = 0; col < k; col++) {
        const v = im[row * k + col];
        const c = viridis(st.log ? (v > 0 ? Math.log10(v) : null) : v, cmin, cmax);
        const o = ((k - 1 - row) * k + col) * 4;  // canvas rows from the top: theta_d grows upwards
        if (c) { data.data[o] = c[0]; data.data[o + 1] = c[1]; data.data[o + 2] = c[2]; data.data[o + 3] = 255; }
      }
    }
    ctx.putImageData(data, 0, 0);
    canvas._values = im; canvas._axis = m.slice.axis;
    canvas.dataset.cmin = String(cmin); canvas.dataset.cmax = String(cmax);
  });
  drawColourBar($("slice-scale"), cmin, cmax, st.log ? "log10 fr" : "fr");
}

// a vertical colour bar: the colour scale from cmin (bottom) to cmax (top), five labelled ticks and a title
function drawColourBar(box, cmin, cmax, title) {
  if (!box.firstChild) {
    box.innerHTML = '<div class="cb-title"></div><div class="cb-body"><div class="cb-ramp"></div><div class="cb-ticks"></div></div>';
    box.querySelector(".cb-ramp").style.background =
      `linear-gradient(to top, ${VIRIDIS.map(([t, c]) => `${c} ${(100 * t).toFixed(2)}%`).join(", ")})`;
    const ticks = box.querySelector(".cb-ticks");
    for (let k = 0; k < 5; k++) {
      const t = document.createElement("span");
      t.style.bottom = `${25 * k}%`;
      ticks.appendChild(t);
    }
  }
  setIf(box.querySelector(".cb-title"), "textContent", title);
  box.dataset.cmin = String(cmin);
  box.dataset.cmax = String(cmax);
  box.querySelectorAll(".cb-ticks span").forEach((t, k) => {
    const v = cmin + (k / 4) * (cmax - cmin);
    setIf(t, "textContent", Math.abs(v) >= 1e4 || (v !== 0 && Math.abs(v) < 1e-2) ? v.toExponential(1) : String(parseFloat(v.toPrecision(3))));
  });
}

// ---------------------------------------------------------------------------------------------------------------
// Spheres: WebGL 2 with pumpup's GLSL (lit), and pumpup's exact furnace image
// ---------------------------------------------------------------------------------------------------------------

const VERTEX = `#version 300 es
in vec2 p_pos;
void main() { gl_Position = vec4(p_pos, 0.0, 1.0); }
`;

// the geometry of pumpup.render (orthographic unit sphere, local frame T, B, N per pixel): L_r = f_r(L, V) (N.L)+
const MAIN = `
uniform float p_size;
uniform vec3 p_light;
uniform float p_exposure;
uniform int p_raw;
out vec4 p_colour;
vec3 p_srgb(vec3 v) {
  v = clamp(v, 0.0, 1.0);
  return mix(12.92 * v, 1.055 * pow(v, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), v));
}
void main() {
  float x = -1.0 + 2.0 * gl_FragCoord.x / p_size;
  float y = -1.0 + 2.0 * gl_FragCoord.y / p_size;
  float r2 = x * x + y * y;
  if (r2 >= 1.0) {
    p_colour = p_raw == 1 ? vec4(0.0, 0.0, 0.0, 0.0) : vec4(${BACKGROUND.join(", ")}, 1.0);
    return;
  }
  vec3 n = vec3(x, y, sqrt(1.0 - r2));
  float h = sqrt(n.x * n.x + n.z * n.z);
  vec3 t = vec3(n.z / h, 0.0, -n.x / h);
  vec3 b = cross(n, t);
  vec3 wi = vec3(dot(p_light, t), dot(p_light, b), dot(p_light, n));
  vec3 wo = vec3(t.z, b.z, n.z);
  float rad = pumpup_brdf(wi, wo) * max(wi.z, 0.0);
  if (p_raw == 1) { p_colour = vec4(rad, 0.0, 0.0, 1.0); return; }
  float v = rad * exp2(p_exposure);
  p_colour = v > 1.0 + 1e-9 ? vec4(${CLIP.join(".0, ")}.0, 1.0) : vec4(p_srgb(vec3(v)), 1.0);
}
`;

const glCache = new Map();  // canvas -> {gl, source, program}

function lightVector() {
  const st = explore.state;
  const p = st.light * Math.PI / 180, a = st.light_azimuth * Math.PI / 180;
  return [Math.sin(p) * Math.cos(a), Math.sin(p) * Math.sin(a), Math.cos(p)];  // pumpup.render.light_direction
}

function compile(gl, type, src) {
  const s = gl.createShader(type);
  gl.shaderSource(s, src);
  gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error("GLSL: " + gl.getShaderInfoLog(s));
  return s;
}

function glProgram(canvas, glsl) {
  let c = glCache.get(canvas);
  if (!c) {
    const gl = canvas.getContext("webgl2", {preserveDrawingBuffer: true, antialias: false});
    if (!gl) throw new Error("this browser has no WebGL 2");
    c = {gl, source: null, program: null};
    glCache.set(canvas, c);
  }
  // the header comment names the parameter values: only the code decides whether to compile again (a parameter
  // that is a uniform changes no code)
  const code = glsl.split("\n").filter((line) => !line.startsWith("//")).join("\n");
  if (c.source !== code) {
    const gl = c.gl;
    // what the shader contract says the explorer prepends, and nothing else
    const src = "#version 300 es\nprecision highp float;\n" + code + "\n" + MAIN;
    const prog = gl.createProgram();
    gl.attachShader(prog, compile(gl, gl.VERTEX_SHADER, VERTEX));
    gl.attachShader(prog, compile(gl, gl.FRAGMENT_SHADER, src));
    gl.linkProgram(prog);
    if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error("GLSL link: " + gl.getProgramInfoLog(prog));
    const buf = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, buf);
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array([-1, -1, 3, -1, -1, 3]), gl.STATIC_DRAW);
    const loc = gl.getAttribLocation(prog, "p_pos");
    gl.enableVertexAttribArray(loc);
    gl.vertexAttribPointer(loc, 2, gl.FLOAT, false, 0, 0);
    if (c.program) gl.deleteProgram(c.program);
    c.program = prog; c.source = code;
  }
  return c;
}

function glDraw(c, m, size, raw) {
  const gl = c.gl;
  gl.useProgram(c.program);
  for (const [name, value] of Object.entries(m.shader.uniforms || {})) {
    const loc = gl.getUniformLocation(c.program, name);
    if (loc !== null) gl.uniform1f(loc, value);
  }
  gl.uniform1f(gl.getUniformLocation(c.program, "p_size"), size);
  gl.uniform3fv(gl.getUniformLocation(c.program, "p_light"), lightVector());
  gl.uniform1f(gl.getUniformLocation(c.program, "p_exposure"), explore.state.exposure);
  gl.uniform1i(gl.getUniformLocation(c.program, "p_raw"), raw ? 1 : 0);
  gl.viewport(0, 0, size, size);
  gl.drawArrays(gl.TRIANGLES, 0, 3);
}

// the lit sphere's linear radiance as WebGL computes it (float32 render target), rows from the top as
// pumpup.render.sphere orders them; for the tests and for people who want the numbers
explore.sphereRadiance = function (index, size) {
  const canvas = document.querySelector(`#lit-${index}`);
  const m = explore.result.models[index];
  const c = glProgram(canvas, m.shader.glsl);
  const gl = c.gl;
  if (!gl.getExtension("EXT_color_buffer_float")) throw new Error("no EXT_color_buffer_float");
  const tex = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_2D, tex);
  gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, size, size, 0, gl.RGBA, gl.FLOAT, null);
  const fb = gl.createFramebuffer();
  gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
  gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0);
  glDraw(c, m, size, true);
  const px = new Float32Array(size * size * 4);
  gl.readPixels(0, 0, size, size, gl.RGBA, gl.FLOAT, px);
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  gl.deleteFramebuffer(fb); gl.deleteTexture(tex);
  const out = [];
  for (let row = 0; row < size; row++) {  // GL row 0 is the bottom
    const src = size - 1 - row;
    for (let col = 0; col < size; col++) out.push(px[(src * size + col) * 4]);
  }
  drawSpheres(explore.result);  // the display canvas again
  return out;
};

function srgb(v) { v = Math.min(1, Math.max(0, v)); return v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055; }

// pumpup.render.tone_map of an image sent by the server
function paintImage(canvas, img, error, exposure) {
  const size = img.size;
  canvas.width = size; canvas.height = size;
  const ctx = canvas.getContext("2d");
  const data = ctx.createImageData(size, size);
  const rad = decode64(img.data);
  const k = Math.pow(2, exposure);
  for (let i = 0; i < size; i++) {
    for (let j = 0; j < size; j++) {
      const x = -1 + (2 * j + 1) / size, y = 1 - (2 * i + 1) / size;
      const o = (i * size + j) * 4;
      let c;
      if (x * x + y * y >= 1) c = BACKGROUND;
      else {
        const v = rad[i * size + j] * k;
        c = v > 1 + 1e-9 + (error || 0) * k ? CLIP : [srgb(v), srgb(v), srgb(v)];
      }
      data.data[o] = Math.round(c[0] * 255); data.data[o + 1] = Math.round(c[1] * 255);
      data.data[o + 2] = Math.round(c[2] * 255); data.data[o + 3] = 255;
    }
  }
  ctx.putImageData(data, 0, 0);
}

function dragLight(canvas) {
  const move = (ev) => {
    if (!(ev.buttons & 1)) return;
    const rect = canvas.getBoundingClientRect();
    const x = 2 * (ev.clientX - rect.left) / rect.width - 1, y = 1 - 2 * (ev.clientY - rect.top) / rect.height;
    const rr = Math.min(1, Math.hypot(x, y));
    const st = explore.state;
    st.light = Math.round(Math.asin(rr) * 180 / Math.PI * (rr >= 1 ? 1.9 : 1));
    st.light = Math.min(179, st.light);
    st.light_azimuth = Math.round(Math.atan2(y, x) * 180 / Math.PI);
    $("light").value = st.light; $("light-out").textContent = st.light;
    $("light-az").value = st.light_azimuth; $("light-az-out").textContent = st.light_azimuth;
    lightMoved();
  };
  canvas.addEventListener("pointerdown", move);
  canvas.addEventListener("pointermove", move);
}

function drawSpheres(r) {
  const box = $("spheres");
  const size = 128;
  while (box.children.length > r.models.length) box.removeChild(box.lastChild);
  let usesGL = false, usesServer = false;
  r.models.forEach((m, i) => {
    let pair = box.children[i];
    if (!pair) {
      pair = document.createElement("div");
      pair.className = "sphere-pair";
      pair.innerHTML = `<canvas id="lit-${i}" width="${size}" height="${size}"></canvas>` +
                       `<canvas id="lit2d-${i}" width="${size}" height="${size}" hidden></canvas>` +
                       `<canvas id="furnace-${i}" width="64" height="64"></canvas><div class="cap"></div><div class="err"></div>`;
      box.appendChild(pair);
      dragLight(pair.querySelector(`#lit-${i}`));
      dragLight(pair.querySelector(`#lit2d-${i}`));
      lastDrawn[`furnace-${i}`] = undefined;  // a new, blank canvas
    }
    const lit = pair.querySelector(`#lit-${i}`), lit2d = pair.querySelector(`#lit2d-${i}`);
    const errs = [];
    if (m.shader && m.shader.glsl) {
      lit.hidden = false; lit2d.hidden = true; usesGL = true;
      try { glDraw(glProgram(lit, m.shader.glsl), m, size, false); }
      catch (e) { errs.push(String(e.message || e)); explore.glErrors.push(String(e.message || e)); }
    } else {
      lit.hidden = true; lit2d.hidden = false; usesServer = true;
      if (m.sphere && !m.sphere.error) paintImage(lit2d, m.sphere, 0, explore.state.exposure);
      else if (m.sphere) errs.push("sphere: " + m.sphere.error);
      if (m.shader && m.shader.error) errs.push("shader: " + m.shader.error);
    }
    const fc = pair.querySelector(`#furnace-${i}`);
    // the furnace at exposure 0: magenta where a(mu_V) > 1 beyond the table's bound (more light out than in)
    if (m.furnace && !m.furnace.error) {
      if (!sameInputs(`furnace-${i}`, [m.furnace.data, m.furnace.bound])) paintImage(fc, m.furnace, m.furnace.bound, 0);
    } else {
      lastDrawn[`furnace-${i}`] = undefined;
      if (m.furnace) errs.push("furnace: " + m.furnace.error);
    }
    pair.querySelector(".cap").textContent = `${label(m, i)}: lit | furnace`;
    pair.querySelector(".cap").style.color = COLOURS[i];
    pair.querySelector(".err").textContent = errs.join("; ");
  });
  $("sphere-source").textContent = usesGL && !usesServer ? "(WebGL 2, pumpup.shader GLSL)" :
    usesServer && !usesGL ? "(rendered by pumpup.render.sphere)" : "(WebGL 2 where a shader exists, else pumpup.render.sphere)";
}

function drawLobe3d(r) {
  const view = $("lobe3d-view");
  const on = r.models.some((m) => m.lobe3d && !m.lobe3d.error);
  setIf(view, "hidden", !on);
  if (!on) { if (window.Plotly && $("lobe3d").data) Plotly.purge("lobe3d"); return; }
  if (!window.Plotly) {  // drawn once plotly.js has loaded, if this answer is still the newest
    loadPlotly().then(() => { if (explore.result === r) drawLobe3d(r); }).catch(() => {});
    return;
  }
  const traces = [];
  r.models.forEach((m, i) => {
    if (!m.lobe3d || m.lobe3d.error) return;
    const v = decode64(m.lobe3d.data), th = m.lobe3d.theta, ph = m.lobe3d.phi;
    const x = [], y = [], z = [];
    th.forEach((t, a) => {
      const xr = [], yr = [], zr = [];
      ph.forEach((p, b) => {
        const rr = v[a * ph.length + b], tr = t * Math.PI / 180, pr = p * Math.PI / 180;
        xr.push(rr * Math.sin(tr) * Math.cos(pr)); yr.push(rr * Math.sin(tr) * Math.sin(pr)); zr.push(rr * Math.cos(tr));
      });
      x.push(xr); y.push(yr); z.push(zr);
    });
    traces.push({type: "surface", x, y, z, name: label(m, i), showscale: false, opacity: 0.85,
                 colorscale: [[0, COLOURS[i]], [1, COLOURS[i]]], surfacecolor: z.map((row) => row.map(() => 0)),
                 cmin: 0, cmax: 1, hoverinfo: "name"});
  });
  Plotly.react("lobe3d", traces, {margin: {l: 0, r: 0, t: 0, b: 0},
    scene: {aspectmode: "data", xaxis: {title: {text: "x"}}, yaxis: {title: {text: "y"}}, zaxis: {title: {text: "N"}}}},
    {displaylogo: false, responsive: true});
}

function draw(r) {
  const t = [performance.now()];
  for (const f of [drawLobe, drawAlbedo, drawSpheres, drawSlice, drawLobe3d]) { f(r); t.push(performance.now()); }
  explore.drawMs = {lobe: t[1] - t[0], albedo: t[2] - t[1], spheres: t[3] - t[2], slice: t[4] - t[3],
                    lobe3d: t[5] - t[4]};
}

// ---------------------------------------------------------------------------------------------------------------
// Start
// ---------------------------------------------------------------------------------------------------------------

async function start() {
  explore.state = stateFromURL();
  connect();
  request();  // the views are computed while the model list loads
  // empty axes while the server computes the first answer
  if (!explore.result) { drawLobe({models: []}); drawAlbedo({models: []}, false); }
  const res = await fetch("/api/models");
  explore.catalog = await res.json();
  initControls();
  if (explore.result) { updateControls(); explore.ready = true; }
}

start().catch((e) => showMessage("the page could not start: " + e));
