// The dashboard page of `piezoshift serve --http-port` (docs/dashboard.md): one EventSource on
// /api/stream feeds the scope and the status; every control is a list of GCS lines POSTed to
// /api/command, so the server applies the same limits and errors as to a GCS client.
import uPlot from "uplot";
import "uplot/dist/uPlot.min.css";

const $ = (id) => document.getElementById(id);
const token = new URLSearchParams(location.search).get("token");
const withToken = (url) => (token ? url + (url.includes("?") ? "&" : "?") + "token=" + encodeURIComponent(token) : url);

// Column store of everything received, trimmed to the longest window (60 s) plus slack.
const KEEP_S = 65;
const COLUMNS = [
  "t_s",
  "setpoint_z_um", "position_z_um", "interferometer_z_um", "true_z_um",
  "setpoint_u_urad", "position_u_urad", "interferometer_u_urad", "true_u_urad",
  "setpoint_v_urad", "position_v_urad", "interferometer_v_urad", "true_v_urad",
  "sgs1_V", "sgs2_V", "sgs3_V", "amp1_V", "amp2_V", "amp3_V",
];
const store = Object.fromEntries(COLUMNS.map((c) => [c, []]));

function append(samples) {
  if (!samples || !samples.t_s || samples.t_s.length === 0) return;
  // Only what is newer than the store: a stream event may repeat the end of the history.
  const t = store.t_s;
  const last = t.length ? t[t.length - 1] : -Infinity;
  let from = 0;
  while (from < samples.t_s.length && samples.t_s[from] <= last) from++;
  for (const c of COLUMNS) {
    const src = samples[c] || [];
    const dst = store[c];
    for (let i = from; i < samples.t_s.length; i++) dst.push(src[i] ?? null);
  }
  trim();
}

// The history (GET /api/history) goes before what the stream brought: only what is older.
function prepend(samples) {
  if (!samples || !samples.t_s || samples.t_s.length === 0) return;
  const first = store.t_s.length ? store.t_s[0] : Infinity;
  const n = lowerBound(samples.t_s, first);
  for (const c of COLUMNS) {
    const src = samples[c] || [];
    store[c] = Array.from({ length: n }, (_, i) => src[i] ?? null).concat(store[c]);
  }
}

function trim() {
  const t = store.t_s;
  const cut = lowerBound(t, t[t.length - 1] - KEEP_S);
  if (cut > 20000) for (const c of COLUMNS) store[c].splice(0, cut);
}

// ---- history: the last window on first load, so that the scope is full at once. The page
// draws nothing until it has arrived (or failed), so its first picture is the whole window.
let historyState = "pending"; // "pending", "loaded", "failed: why"
let historyFrom = Infinity; // the oldest loop time asked for so far
async function loadHistory(seconds) {
  const newest = store.t_s.length ? store.t_s[store.t_s.length - 1] : null;
  if (newest !== null && newest - seconds >= historyFrom) return; // already asked
  try {
    const res = await fetch(withToken(`/api/history?seconds=${Math.min(60, seconds)}`));
    if (!res.ok) throw new Error(`HTTP ${res.status}: ${(await res.text()).trim()}`);
    const body = await res.json();
    prepend(body.samples);
    if (store.t_s.length) historyFrom = Math.min(historyFrom, store.t_s[0]);
    historyState = "loaded";
  } catch (e) {
    if (historyState === "pending") historyState = `failed: ${e.message}`;
    log(`history: ${e.message}; the scope fills as data arrives`, false);
  }
}

function lowerBound(a, x) {
  let lo = 0, hi = a.length;
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if (a[mid] < x) lo = mid + 1; else hi = mid;
  }
  return lo;
}

// ---- charts
// The set-point is drawn last (on top), white and dashed, so that it stands out of the traces
// that sit within nanometres of it; the others keep the colours they had.
const palette = { sp: "#f0f6fc", pos: "#58a6ff", ifm: "#3fb950", tru: "#db61a2",
  c1: "#58a6ff", c2: "#e3b341", c3: "#3fb950" };
const SETPOINT_DASH = [8, 5];
const axisStyle = { stroke: "#8a94a3", grid: { stroke: "#262c36", width: 1 },
  ticks: { stroke: "#2c323c", width: 1 } };

function chart(el, title, unit, series, height) {
  const width = () => Math.max(300, $(el).clientWidth - 4);
  const opts = {
    title, width: width(), height,
    legend: { live: true },
    cursor: { drag: { x: false, y: false } },
    scales: { x: { time: false } },
    axes: [
      { ...axisStyle, label: "t [s]", labelSize: 14, size: 36 },
      { ...axisStyle, label: unit, labelSize: 16, size: 60 },
    ],
    series: [{ label: "t [s]", value: (u, v) => (v == null ? "—" : v.toFixed(3)) },
      ...series.map(([label, stroke, dash, width]) => ({ label, stroke, width: width ?? 1.4, dash,
        spanGaps: false, show: traceShown(el, label),
        value: (u, v) => (v == null ? "—" : v.toFixed(4)) }))],
    hooks: { setSeries: [(u, i) => syncTraceBox(el, u, i)] },
  };
  const data = [[], ...series.map(() => [])];
  const u = new uPlot(opts, data, $(el));
  traceBoxes(el, u, series);
  window.addEventListener("resize", () => u.setSize({ width: width(), height }));
  return u;
}

// ---- which traces to show: a checkbox per trace above each chart, remembered by the browser
const SHOWN_KEY = "piezoshift.hiddenTraces";
const hidden = new Set(JSON.parse(localStorage.getItem(SHOWN_KEY) || "[]"));
const traceShown = (el, label) => !hidden.has(`${el}/${label}`);
function traceBoxes(el, u, series) {
  const bar = document.createElement("div");
  bar.className = "traces";
  bar.id = `${el}-traces`;
  series.forEach(([label, stroke, dash], k) => {
    const box = document.createElement("label");
    const input = document.createElement("input");
    input.type = "checkbox";
    input.checked = traceShown(el, label);
    input.dataset.series = String(k + 1);
    input.onchange = () => u.setSeries(k + 1, { show: input.checked });
    const swatch = document.createElement("span");
    swatch.className = "swatch";
    swatch.style.borderTop = `2px ${dash ? "dashed" : "solid"} ${stroke}`;
    box.append(input, swatch, label);
    bar.append(box);
  });
  $(el).prepend(bar);
}
function syncTraceBox(el, u, i) {
  if (i == null || i < 1) return;
  const label = u.series[i].label;
  const input = document.querySelector(`#${el}-traces input[data-series="${i}"]`);
  if (input) input.checked = u.series[i].show;
  if (u.series[i].show) hidden.delete(`${el}/${label}`);
  else hidden.add(`${el}/${label}`);
  localStorage.setItem(SHOWN_KEY, JSON.stringify([...hidden]));
}

const charts = {
  z: chart("chart-z", "Piston Z", "µm", [["position (SGS)", palette.pos],
    ["interferometer", palette.ifm], ["true plate", palette.tru, [2, 3]],
    ["set-point", palette.sp, SETPOINT_DASH, 2]], 250),
  uv: chart("chart-uv", "Tip U / tilt V", "µrad", [["U position", palette.pos],
    ["U interferometer", palette.ifm], ["U true", palette.tru, [2, 3]],
    ["V position", "#79c0ff"], ["V interferometer", "#7ee787"], ["V true", "#f2a7d0", [2, 3]],
    ["U set-point", palette.sp, SETPOINT_DASH, 2], ["V set-point", "#e3b341", SETPOINT_DASH, 2]], 190),
  sgs: chart("chart-sgs", "Strain gauges", "V", [["SGS 1", palette.c1], ["SGS 2", palette.c2],
    ["SGS 3", palette.c3]], 170),
  amp: chart("chart-amp", "Amplifier outputs", "V", [["ch 1", palette.c1], ["ch 2", palette.c2],
    ["ch 3", palette.c3]], 170),
};
const chartColumns = {
  z: ["position_z_um", "interferometer_z_um", "true_z_um", "setpoint_z_um"],
  uv: ["position_u_urad", "interferometer_u_urad", "true_u_urad",
    "position_v_urad", "interferometer_v_urad", "true_v_urad", "setpoint_u_urad", "setpoint_v_urad"],
  sgs: ["sgs1_V", "sgs2_V", "sgs3_V"],
  amp: ["amp1_V", "amp2_V", "amp3_V"],
};

let windowS = 2;
let paused = false;
let view = null; // what is on screen: {from, to} indices into store (frozen while paused)

let firstDrawn = null; // {t0, t1, window_s}: the first picture with data (for the browser test)
function render() {
  const t = store.t_s;
  if (t.length === 0 || historyState === "pending") return;
  if (!paused) {
    const to = t.length;
    const from = lowerBound(t, t[to - 1] - windowS);
    view = { from, to, t0: t[to - 1] - windowS, t1: t[to - 1] };
  } else if (view) {
    // Frozen in loop time: the indices move when older history arrives or the store is trimmed.
    view.from = lowerBound(t, view.t0);
    view.to = lowerBound(t, view.t1 + 1e-9);
  }
  if (!view) return;
  const x = t.slice(view.from, view.to);
  if (!firstDrawn && x.length) firstDrawn = { t0: x[0], t1: x[x.length - 1], window_s: windowS };
  for (const [name, u] of Object.entries(charts)) {
    const data = [x, ...chartColumns[name].map((c) => store[c].slice(view.from, view.to))];
    u.batch(() => {
      u.setData(data, false);
      u.setScale("x", { min: view.t0, max: view.t1 });
      // Legends show the newest values unless the cursor is over the chart.
      if (u.cursor.left == null || u.cursor.left < 0) u.setLegend({ idx: x.length - 1 });
    });
  }
}

// ---- status
const fmt = (v, d) => (v == null || !Number.isFinite(v) ? "—" : v.toFixed(d));
function pill(id, text, cls) {
  const el = $(id);
  el.textContent = text;
  el.className = "pill " + cls;
}

let lastStatus = null;
function showStatus(s) {
  lastStatus = s;
  $("t-s").textContent = fmt(s.t_s, 2);
  $("daq").textContent = s.daq;
  pill("pill-servo", s.servo_on ? "SERVO ON" : "SERVO OFF", s.servo_on ? "ok" : "off");
  const ont = s.on_target || {};
  const allOn = ont.z_um && ont.u_urad && ont.v_urad;
  pill("pill-ont", allOn ? "ON TARGET" : "NOT ON TARGET", allOn ? "ok" : s.servo_on ? "warn" : "off");
  const sup = (s.supervisor || "—").toUpperCase();
  pill("pill-sup", "SUPERVISOR " + sup, s.fault ? "bad" : sup === "RUNNING" ? "ok" : "warn");
  const rt = s.realtime;
  pill("pill-rt", rt ? (rt.sched_fifo ? "RT FIFO" : "RT NOT GRANTED") : "RT —",
    rt ? (rt.sched_fifo && rt.mlockall ? "ok" : "warn") : "off");
  for (const [k, a] of [["z", "z_um"], ["u", "u_urad"], ["v", "v_urad"]]) {
    $("tgt-" + k).textContent = fmt(s.target?.[a], k === "z" ? 4 : 2);
    $("pos-" + k).textContent = fmt(s.position?.[a], k === "z" ? 4 : 2);
  }
  const tm = s.timing || {};
  $("tm-rate").textContent = `${s.loop_rate_Hz} / ${s.stream_rate_Hz} Hz`;
  for (const [id, key] of [["per", "period_error"], ["lat", "wake_latency"]])
    for (const q of ["50", "99", "max"])
      $(`tm-${id}-${q}`).textContent = fmt(tm[`${key}_${q === "max" ? "max" : "p" + q}_us`], 1);
  $("tm-window").textContent = `${fmt(tm.window_s, 1)} s`;
  $("tm-overruns").textContent = tm.overruns ?? "—";
  $("tm-dropped").textContent = tm.samples_dropped ?? "—";
  $("tm-rt").textContent = rt
    ? `FIFO ${rt.sched_fifo ? "yes" : "no"} · mlockall ${rt.mlockall ? "yes" : "no"} · CPU ${rt.cpu >= 0 ? rt.cpu : "any"}`
    : "—";
  const lf = s.last_fault;
  $("tm-last-fault").textContent = lf ? `${lf.reason} at t = ${fmt(lf.t_s, 3)} s` : "none";
  const banner = $("fault-banner");
  if (s.fault) {
    banner.classList.remove("hidden");
    $("fault-reason").textContent = s.fault.reason + (s.fault.channel ? ` (channel ${s.fault.channel})` : "");
    $("fault-text").textContent = `— ${s.fault.text}; outputs ramped to 0 V at t = ${fmt(s.fault.t_s, 3)} s`;
  } else {
    banner.classList.add("hidden");
  }
}

// ---- stream
let events = 0;
const arrivals = []; // performance.now() of the updates of the last 2 s
function showRate() {
  const now = performance.now();
  while (arrivals.length && arrivals[0] < now - 2000) arrivals.shift();
  const rate = lastStatus?.stream_rate_Hz;
  $("rate").textContent = events === 0 ? "waiting for the stream"
    : `${(arrivals.length / 2).toFixed(0)} updates/s` + (rate ? `, ${rate} samples/s` : "");
}
function connect() {
  const es = new EventSource("/api/stream" + (token ? "?token=" + encodeURIComponent(token) : ""));
  es.onopen = () => pill("pill-link", "STREAM LIVE", "ok");
  es.onerror = () => pill("pill-link", "STREAM LOST", "bad");
  es.addEventListener("update", (e) => {
    const msg = JSON.parse(e.data);
    append(msg.samples);
    if (msg.status) showStatus(msg.status);
    events++;
    arrivals.push(performance.now());
    // The history once the stream runs, so that nothing falls between the two.
    if (events === 1) loadHistory(windowS);
  });
}
setInterval(showRate, 500);
let lastFrame = 0;
function frame(now) {
  if (now - lastFrame >= 40) { // 25 frames/s at most: the stream's own rate
    lastFrame = now;
    render();
  }
  requestAnimationFrame(frame);
}

// ---- controls
function log(text, ok) {
  const li = document.createElement("li");
  li.className = ok ? "ok" : "err";
  li.textContent = `${new Date().toLocaleTimeString()}  ${text}`;
  const list = $("log");
  list.prepend(li);
  while (list.children.length > 50) list.lastChild.remove();
}

async function gcs(commands, quiet) {
  const headers = { "Content-Type": "application/json" };
  if (token) headers.Authorization = "Bearer " + token;
  let res;
  try {
    res = await fetch("/api/command", { method: "POST", headers, body: JSON.stringify({ commands }) });
  } catch (e) {
    log(`${commands.join("; ")}: server unreachable (${e.message})`, false);
    return false;
  }
  const type = res.headers.get("Content-Type") || "";
  const body = type.startsWith("application/json") ? await res.json() : { error: { text: await res.text() } };
  if (res.ok && body.ok) {
    if (!quiet) log(commands.join("; "), true);
    return true;
  }
  const e = body.error || {};
  log(`${e.command || commands.join("; ")}: ${e.code !== undefined ? "GCS error " + e.code + ", " : "HTTP " + res.status + ", "}${(e.text || "").trim()}`, false);
  return false;
}

const num = (id) => Number($(id).value);
$("btn-servo-on").onclick = () => gcs(["SVO Z 1 U 1 V 1"]);
$("btn-servo-off").onclick = () => gcs(["SVO Z 0 U 0 V 0"]);
$("btn-clear").onclick = $("btn-clear-banner").onclick = () =>
  gcs([lastStatus && lastStatus.servo_on ? "SVO Z 1 U 1 V 1" : "SVO Z 0 U 0 V 0"]);
$("btn-stop").onclick = async () => {
  sequenceAbort = true;
  // STP answers error 10 by design (PI controllers do); the page says it plainly.
  const headers = { "Content-Type": "application/json" };
  if (token) headers.Authorization = "Bearer " + token;
  const res = await fetch("/api/command", { method: "POST", headers, body: JSON.stringify({ commands: ["STP"] }) });
  const body = await res.json().catch(() => ({}));
  log(body.error && body.error.code === 10 ? "STP: stopped, holding position" : "STP failed", body.error?.code === 10);
};
$("btn-move").onclick = () => gcs([`MOV Z ${num("move-z")} U ${num("move-u")} V ${num("move-v")}`]);
$("btn-move-rel").onclick = () => gcs([`MVR Z ${num("move-z")} U ${num("move-u")} V ${num("move-v")}`]);
$("btn-lambda8").onclick = () => { $("seq-step").value = (632.8 / 8).toFixed(1); };

let sequenceAbort = false;
let sequenceRunning = false;
$("btn-seq-stop").onclick = () => { sequenceAbort = true; };
$("btn-seq").onclick = async () => {
  if (sequenceRunning) return;
  const stepUm = num("seq-step") / 1000;
  const count = Math.max(1, Math.min(1000, Math.round(num("seq-count"))));
  const dwell = Math.max(10, num("seq-dwell"));
  sequenceRunning = true;
  sequenceAbort = false;
  log(`sequence: ${count} steps of ${(stepUm * 1000).toFixed(1)} nm, ${dwell} ms dwell`, true);
  for (let i = 0; i < count && !sequenceAbort; i++) {
    $("seq-state").textContent = `step ${i + 1} / ${count}`;
    if (!(await gcs([`MVR Z ${stepUm}`], true))) break;
    await new Promise((r) => setTimeout(r, dwell));
  }
  $("seq-state").textContent = sequenceAbort ? "aborted" : "idle";
  sequenceRunning = false;
};

$("window").onchange = async (e) => {
  windowS = Number(e.target.value);
  if (paused) paused = false;
  await loadHistory(windowS);
  render();
};
$("btn-pause").onclick = (e) => {
  paused = !paused;
  e.target.textContent = paused ? "Resume" : "Pause";
  e.target.classList.toggle("active", paused);
};
$("btn-csv").onclick = () => {
  if (!view) return;
  const rows = [COLUMNS.join(",")];
  for (let i = view.from; i < view.to; i++)
    rows.push(COLUMNS.map((c) => (store[c][i] == null ? "" : store[c][i])).join(","));
  const blob = new Blob([rows.join("\n") + "\n"], { type: "text/csv" });
  const a = document.createElement("a");
  a.href = URL.createObjectURL(blob);
  a.download = `piezoshift-${view.t0.toFixed(3)}s-${windowS}s.csv`;
  a.click();
  URL.revokeObjectURL(a.href);
};

// ---- camera (serve --camera): the live frame, its fringe visibility, measurements
function ticks(id, lo, hi, digits) {
  // Five labels from hi (top) to lo (bottom): the PNGs' scale bar has its ticks at each quarter.
  const el = $(id);
  el.replaceChildren(...[1, 0.75, 0.5, 0.25, 0].map((q) => {
    const d = document.createElement("div");
    d.textContent = fmt(lo + q * (hi - lo), digits);
    return d;
  }));
}
async function getJson(url) {
  const res = await fetch(withToken(url));
  return res.ok ? res.json() : null;
}
let cameraOn = false;
let shownFrame = -1;
let shownMeasurement = -1;
let measurement = null;
async function pollCamera() {
  if (!lastStatus || !lastStatus.camera) return;
  if (!cameraOn) {
    cameraOn = true;
    $("camera-panel").classList.remove("hidden");
    ticks("vis-ticks", 0, 1, 2);
  }
  const cam = await getJson("/api/camera").catch(() => null);
  if (cam) {
    $("cam-name").textContent = cam.camera;
    $("cam-msg").textContent = cam.message || "";
    const f = cam.frame;
    if (f && f.id !== shownFrame) {
      shownFrame = f.id;
      $("cam-frame").src = withToken(`/api/camera/frame.png?n=${f.id}`);
      $("cam-vis-map").src = withToken(`/api/camera/visibility.png?n=${f.id}`);
      ticks("cam-ticks", 0, f.full_scale_counts, 0);
      $("cam-id").textContent = `${f.id}, ${f.width_px} × ${f.height_px} px, ${f.bits} bit, t = ${fmt(f.trigger_time_s, 3)} s`;
      $("cam-max").textContent = `${fmt(f.max_counts, 0)} / ${fmt(f.mean_counts, 0)} of ${fmt(f.full_scale_counts, 0)}`;
      $("cam-sat").textContent = `${f.saturated_pixels} px (${fmt(100 * f.saturated_fraction, 2)} %)`;
      $("cam-sat").className = f.saturated_pixels > 0 ? "bad" : "";
      $("cam-vis").textContent = `${fmt(f.visibility.p90, 2)} / ${fmt(f.visibility.median, 2)}`;
    }
  }
  measurement = await getJson("/api/measure").catch(() => null);
  if (measurement) showMeasurement(measurement);
}
function showMeasurement(m) {
  const l = m.last;
  $("btn-measure").disabled = m.running;
  if (m.running) $("meas-state").textContent = `measurement ${m.id} running: ${m.progress.frames} of ${m.progress.of || "…"} frames`;
  if (!l || l.id === shownMeasurement || m.running) return;
  shownMeasurement = l.id;
  $("meas-state").textContent = l.valid
    ? `measurement ${l.id}: valid (${l.algorithm}, ${l.frames} frames × ${l.averages})`
    : `measurement ${l.id} FAILED: ${l.reason}`;
  $("meas-state").className = l.valid ? "muted" : "bad";
  const s = l.valid ? l.surface : null;
  $("meas-fig").textContent = s ? `${fmt(s.pv_nm, 2)} / ${fmt(s.pvr_nm, 2)} / ${fmt(s.rms_nm, 3)} nm` : "—";
  $("meas-err").textContent = s && l.error_rms_nm != null ? `${fmt(l.error_rms_nm, 3)} nm` : "—";
  $("meas-steps").textContent = l.steps ? l.steps.worst_error : "—";
  $("meas-rec").textContent = l.steps && l.steps.recovered_rad.length
    ? l.steps.recovered_rad[0].map((v) => v.toFixed(3)).join(", ") : "—";
  $("meas-time").textContent = `${fmt(l.wall_time_s, 3)} / ${fmt(l.floor_s, 3)} s`;
  // A failed measurement shows its reason, never a surface.
  if (s) {
    $("meas-surface").src = withToken(`/api/measure/surface.png?n=${l.id}`);
    ticks("surf-ticks", s.lo_nm, s.hi_nm, 1);
  } else {
    $("meas-surface").removeAttribute("src");
    $("surf-ticks").replaceChildren();
  }
  if (l.modulation) {
    $("meas-mod").src = withToken(`/api/measure/modulation.png?n=${l.id}`);
    ticks("mod-ticks", l.modulation.lo, l.modulation.hi, 0);
  } else {
    $("meas-mod").removeAttribute("src");
    $("mod-ticks").replaceChildren();
  }
}
$("btn-measure").onclick = async () => {
  const headers = { "Content-Type": "application/json" };
  if (token) headers.Authorization = "Bearer " + token;
  const body = { algorithm: $("meas-alg").value, averages: Math.round(num("meas-avg")) };
  const res = await fetch("/api/measure", { method: "POST", headers, body: JSON.stringify(body) });
  const text = await res.text();
  log(res.ok ? `measure: ${body.algorithm} × ${body.averages} started` : `measure: HTTP ${res.status}, ${text.trim()}`, res.ok);
};
setInterval(pollCamera, 500);

// For tests and the console: the charts and the last status.
window.piezoshift = { charts, store, status: () => lastStatus, events: () => events,
  history: () => historyState, firstDrawn: () => firstDrawn, windowS: () => windowS,
  measurement: () => measurement, frameShown: () => shownFrame };
connect();
requestAnimationFrame(frame);
