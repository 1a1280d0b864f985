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
  socket.onmessage = (ev) => onAnswer(JSON.parse(ev.data));
}

function request() {
  const st = explore.state;
  const id = ++explore.sent;
  sentAt[id] = performance.now();
  const msg = JSON.stringify({id, state: {
    specs: st.specs, theta_i: st.theta_i, phi: st.phi, pump: st.pump, kulla_conty: st.kulla_conty,
    scaled: st.scaled, light: st.light, light_azimuth: st.light_azimuth, lobe3d: st.lobe3d}});
  if (socket && socket.readyState === WebSocket.OPEN) socket.send(msg); else pending = msg;
  // the page's own bookkeeping runs while the server computes
  writeURL();
  setStatus("computing…");
  return id;
}

// plotly.js (4.6 MB) loads while the first views are computed; drawing waits for it
const plotlyReady = new Promise((resolve) => {
  if (window.Plotly) { resolve(); return; }
  const tag = document.getElementById("plotly-js");
  tag.addEventListener("load", () => resolve());
  tag.addEventListener("error", () => showMessage("plotly.js did not load from the server"));
});

function onAnswer(ans) {
  if (!window.Plotly) { plotlyReady.then(() => onAnswer(ans)); return; }
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
// Plots
// ---------------------------------------------------------------------------------------------------------------

const PLOT_CONFIG = {displaylogo: false, responsive: true};

function label(m, i) {
  const text = m.short.length > 44 ? m.short.slice(0, 42) + "…" : m.short;
  return `${i + 1}: ${text}`;
}

function drawLobe(r) {
  const st = explore.state;
  const traces = [];
  let rmax = 0;
  const clean = (v) => (st.log ? v.map((x) => (x > 0 ? x : null)) : v);
  r.models.forEach((m, i) => {
    if (m.lobe.error) return;
    rmax = Math.max(rmax, ...m.lobe.value);
    traces.push({type: "scatterpolar", mode: "lines", theta: m.lobe.theta_o, r: clean(m.lobe.value),
                 name: label(m, i), line: {color: COLOURS[i], width: 2}});
    for (const [k, o] of Object.entries(m.overlays || {})) {
      if (!o.lobe || o.lobe.error) continue;
      rmax = Math.max(rmax, ...o.lobe.value);
      traces.push({type: "scatterpolar", mode: "lines", theta: o.lobe.theta_o, r: clean(o.lobe.value),
                   name: `${i + 1}: ${OVERLAY_NAME[k]}`, line: {color: COLOURS[i], width: 1.5, dash: OVERLAY_DASH[k]}});
    }
  });
  traces.push({type: "scatterpolar", mode: "lines", theta: [-st.theta_i, -st.theta_i], r: [st.log ? rmax * 1e-6 : 0, rmax || 1],
               name: "light", line: {color: "#888", dash: "dot"}, hoverinfo: "skip"});
  const layout = {margin: {l: 30, r: 30, t: 20, b: 20}, showlegend: true, legend: {orientation: "h"},
                  polar: {sector: [0, 180], angularaxis: {rotation: 90, direction: "clockwise", dtick: 15},
                          radialaxis: {type: st.log ? "log" : "linear", exponentformat: "power",
                                       // log: four decades below the largest value
                                       range: st.log && rmax > 0 ? [Math.log10(rmax) - 4, Math.log10(rmax) + 0.05] : undefined}}};
  Plotly.react("lobe", traces, layout, PLOT_CONFIG);
}

function drawAlbedo(r) {
  const st = explore.state;
  const traces = [], shapes = [];
  r.models.forEach((m, i) => {
    const a = m.albedo;
    if (!a || a.error) return;
    const up = a.a.map((v, k) => v + a.err[k]), lo = a.a.map((v, k) => v - a.err[k]);
    traces.push({x: a.theta, y: up, mode: "lines", line: {width: 0}, showlegend: false, hoverinfo: "skip"});
    traces.push({x: a.theta, y: lo, mode: "lines", line: {width: 0}, fill: "tonexty",
                 fillcolor: COLOURS[i] + "55", name: `${i + 1}: error band`, showlegend: false, hoverinfo: "skip"});
    traces.push({x: a.theta, y: a.a, mode: "lines", name: label(m, i), line: {color: COLOURS[i], width: 2},
                 customdata: a.err, hovertemplate: "θi %{x:.2f}°: a = %{y:.10g} ± %{customdata:.2g}<extra></extra>"});
    for (const [k, o] of Object.entries(m.overlays || {})) {
      if (!o.albedo || o.albedo.error) continue;
      traces.push({x: o.albedo.theta, y: o.albedo.a, mode: "lines", name: `${i + 1}: ${OVERLAY_NAME[k]}`,
                   line: {color: COLOURS[i], width: 1.5, dash: OVERLAY_DASH[k]}});
    }
    for (const [t0, t1] of a.above_one) {
      shapes.push({type: "rect", xref: "x", yref: "paper", x0: t0 - 0.5, x1: t1 + 0.5, y0: 0, y1: 1,
                   fillcolor: "#ff000022", line: {width: 0}});
    }
  });
  shapes.push({type: "line", xref: "paper", x0: 0, x1: 1, y0: 1, y1: 1, line: {color: "#a00", dash: "dot", width: 1}});
  shapes.push({type: "line", xref: "x", yref: "paper", x0: st.theta_i, x1: st.theta_i, y0: 0, y1: 1,
               line: {color: "#888", dash: "dot", width: 1}});
  Plotly.react("albedo", traces, {margin: {l: 50, r: 10, t: 10, b: 40}, shapes, legend: {orientation: "h"},
    xaxis: {title: {text: "θi (degrees)"}, range: [0, 90]}, yaxis: {title: {text: "a(θi)"}}}, PLOT_CONFIG);
  const body = $("numbers").querySelector("tbody");
  body.innerHTML = "";
  const rows = [];
  r.models.forEach((m, i) => {
    rows.push([label(m, i), m, COLOURS[i]]);
    for (const [k, o] of Object.entries(m.overlays || {})) rows.push([`${i + 1}: ${OVERLAY_NAME[k]}`, o, COLOURS[i]]);
  });
  rows.forEach(([name, m], k) => {
    const tr = document.createElement("tr");
    tr.dataset.row = k;
    const cell = (cls, text, value) => {
      const td = document.createElement("td"); td.className = cls; td.textContent = text;
      if (value !== undefined) td.dataset.value = String(value);
      tr.appendChild(td);
    };
    cell("name", name);
    if (m.error) { cell("error", m.error); body.appendChild(tr); return; }
    cell("mean-albedo", m.mean_albedo !== undefined ? m.mean_albedo.toPrecision(10) : "—", m.mean_albedo);
    const mc = m.max_constant;
    cell("max-constant", mc ? `${mc.name} ≤ ${mc.value.toPrecision(8)} (max a at ${mc.theta.toFixed(2)}°)` : "—",
         mc ? mc.value : undefined);
    cell("max-albedo", m.albedo && !m.albedo.error ? m.albedo.max.toPrecision(10) : "—", m.albedo ? m.albedo.max : undefined);
    const spans = m.albedo && m.albedo.above_one ? m.albedo.above_one : [];
    cell("above-one", spans.length ? spans.map(([a, b]) => `${a.toFixed(1)}–${b.toFixed(1)}°`).join(", ") : "nowhere");
    body.appendChild(tr);
    for (const note of m.notes || []) {
      const nr = document.createElement("tr");
      nr.className = "note";
      const td = document.createElement("td");
      td.colSpan = 5; td.textContent = "note: " + note;
      nr.appendChild(td); body.appendChild(nr);
    }
  });
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

function drawSlice(r) {
  const st = explore.state;
  if (sameInputs("slice", [st.log, ...r.models.map((m) => (m.slice ? m.slice.data || m.slice.error : null))])) return;
  const traces = [];
  const n = r.models.length;
  let zmax = 0;
  const images = r.models.map((m) => (m.slice && !m.slice.error ? decode64(m.slice.data) : null));
  images.forEach((im) => { if (im) for (const v of im) if (v > zmax) zmax = v; });
  r.models.forEach((m, i) => {
    const im = images[i];
    if (!im) return;
    const k = m.slice.n, z = [];
    for (let row = 0; row < k; row++) {
      const line = im.subarray(row * k, row * k + k);
      z.push(st.log ? Array.from(line, (v) => (v > 0 ? Math.log10(v) : null)) : line);
    }
    const ax = i === 0 ? "" : String(i + 1);
    // pixel centres on a uniform grid (x0, dx): plotly draws one image of n x n pixels, scaled without smoothing
    const a = m.slice.axis, d = a.length > 1 ? a[1] - a[0] : 90;
    traces.push({type: "heatmap", x0: a[0], dx: d, y0: a[0], dy: d, z, zsmooth: "fast", coloraxis: "coloraxis",
                 xaxis: "x" + ax, yaxis: "y" + ax, name: label(m, i),
                 hovertemplate: "θh %{x:.1f}°, θd %{y:.1f}°: %{z:.4g}<extra>" + label(m, i) + "</extra>"});
  });
  const cmin = st.log ? Math.log10(Math.max(zmax, 1e-30)) - 4 : 0;
  const cmax = st.log ? Math.log10(Math.max(zmax, 1e-30)) : zmax;
  // the colour bar is drawn beside the plot (drawColourBar): plotly's own redraws its ticks and margins at every
  // move, which costs more than the image
  const layout = {margin: {l: 45, r: 10, t: 25, b: 40}, grid: {rows: 1, columns: n, pattern: "independent"},
    coloraxis: {colorscale: VIRIDIS, cmin, cmax, showscale: false},
    annotations: r.models.map((m, i) => ({text: n > 1 ? String(i + 1) : label(m, i), showarrow: false, xref: `x${i ? i + 1 : ""} domain`,
                                         yref: `y${i ? i + 1 : ""} domain`, x: 0.5, y: 1.08, font: {color: COLOURS[i]}}))};
  for (let i = 0; i < n; i++) {
    const ax = i === 0 ? "" : String(i + 1);
    layout["xaxis" + ax] = {title: {text: "θh (°)"}, range: [0, 90]};
    layout["yaxis" + ax] = {title: {text: i === 0 ? "θd (°)" : ""}, range: [0, 90], matches: i ? "y" : undefined};
  }
  Plotly.react("slice", traces, layout, PLOT_CONFIG);
  drawColourBar($("slice-scale"), cmin, cmax, st.log ? "log10 fr" : "fr");
}

// plotly's Viridis
const VIRIDIS = [[0, "#440154"], [0.06274509803921569, "#48186a"], [0.12549019607843137, "#472d7b"],
  [0.18823529411764706, "#424086"], [0.25098039215686274, "#3b528b"], [0.3137254901960784, "#33638d"],
  [0.3764705882352941, "#2c728e"], [0.4392156862745098, "#26828e"], [0.5019607843137255, "#21918c"],
  [0.5647058823529412, "#1fa088"], [0.6274509803921569, "#28ae80"], [0.6901960784313725, "#3fbc73"],
  [0.7529411764705882, "#5ec962"], [0.8156862745098039, "#84d44b"], [0.8784313725490196, "#addc30"],
  [0.9411764705882353, "#d8e219"], [1, "#fde725"]];

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
  box.querySelector(".cb-title").textContent = title;
  box.dataset.cmin = String(cmin);
  box.dataset.cmax = String(cmax);
  box.querySelectorAll(".cb-ticks span").forEach((t, k) => {
    const v = cmin + (k / 4) * (cmax - cmin);
    t.textContent = Math.abs(v) >= 1e4 || (v !== 0 && Math.abs(v) < 1e-2) ? v.toExponential(1) : String(parseFloat(v.toPrecision(3)));
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
  view.hidden = !on;
  if (!on) { if ($("lobe3d").data) Plotly.purge("lobe3d"); return; }
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
    PLOT_CONFIG);
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
  // while the server computes the first answer, plotly draws the empty lobe and albedo axes (its first drawing of
  // each kind of plot is the slow one)
  plotlyReady.then(() => { if (!explore.result) { drawLobe({models: []}); drawAlbedo({models: []}); } });
  connect();
  request();  // the views are computed while the model list loads
  const res = await fetch("/api/models");
  explore.catalog = await res.json();
  initControls();
  if (explore.result) { updateControls(); explore.ready = true; }
}

start().catch((e) => showMessage("the page could not start: " + e));
