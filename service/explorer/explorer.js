// gearchaos design explorer: a form for a design, the verdict of one design, and the
// speed x torque envelope of the job queue. Plain JavaScript, no build step; the one library,
// plotly.js (the interactive map), is loaded from this server when the first map is drawn.
"use strict";

const $ = (id) => document.getElementById(id);
const KEY_STORE = "gearchaos.apiKey"; // sessionStorage: forgotten with the tab
const JOBS_STORE = "gearchaos.jobs"; // localStorage: recent envelopes of this browser
const CLASS_COLORS = {
  periodic: "#2b7bb9", quasi_periodic: "#e69f00", chaotic: "#d62728", diverged: "#555555",
};

// ---------------------------------------------------------------- the form, as data
// [path under design, label, kind, mode]; kind: unit (text with a unit), int, num, or a list of
// choices; mode: direct or geometry for fields of one form only.
const GEAR_FIELDS = [
  ["teeth", "teeth", "int"],
  ["base_radius", "base radius", "unit", "direct"],
  ["inertia", "inertia", "unit", "direct"],
  ["module", "module", "unit", "geometry"],
  ["face_width", "face width", "unit", "geometry"],
  ["pressure_angle", "pressure angle", "unit", "geometry"],
  ["profile_shift", "profile shift x", "num", "geometry"],
  ["bore", "bore diameter", "unit", "geometry"],
  ["material", "material", ["steel", "cast_iron", "bronze", "aluminium"], "geometry"],
];
const GROUPS = [
  ["driver", "Driver (gear a)", GEAR_FIELDS.map(([p, ...r]) => ["driver." + p, ...r])],
  ["driven", "Driven (gear b)", GEAR_FIELDS.map(([p, ...r]) => ["driven." + p, ...r])],
  ["", "Operating point", [
    ["speed", "driver speed", "unit"],
    ["torque", "driver torque", "unit"],
    ["braking_torque", "braking torque (optional)", "unit"],
  ]],
  ["mesh", "Mesh", [
    ["mesh.stiffness", "mean stiffness (or iso6336)", "unit"],
    ["mesh.stiffness_harmonics[0].amplitude", "stiffness variation", "unit"],
    ["mesh.damping_ratio", "damping ratio ζ", "num"],
    ["mesh.damping", "or damping c", "unit"],
    ["mesh.half_backlash", "half backlash", "unit"],
    ["backlash_law", "backlash law", ["piecewise", "cubic_fit"]],
  ]],
  ["transmission_error", "Transmission error", [
    ["transmission_error.harmonics[0].amplitude", "amplitude", "unit"],
    ["transmission_error.order", "order (default: teeth)", "num"],
  ]],
  ["torque_fluctuation", "Torque fluctuation", [
    ["torque_fluctuation.harmonics[0].amplitude", "amplitude", "unit"],
    ["torque_fluctuation.order", "order (× shaft speed)", "num"],
  ]],
  ["speed_range", "Melnikov speed scan (optional)", [
    ["speed_range[0]", "from", "unit"],
    ["speed_range[1]", "to", "unit"],
  ]],
];
const SETTINGS_FIELDS = [
  ["settings.transient_periods", "transient periods", "int", 500],
  ["settings.record_periods", "recorded periods", "int", 500],
  ["settings.steps_per_period", "steps per period", "int", 200],
  ["settings.basins.starts", "basin starts (optional: 16, 64, 256)", "int", ""],
];
const ENVELOPE_FIELDS = [
  ["axes[0].start", "speed from", "unit", "500 rpm"],
  ["axes[0].stop", "speed to", "unit", "6000 rpm"],
  ["axes[0].num", "speed points", "int", 21],
  ["axes[1].start", "torque from", "unit", "20 N*m"],
  ["axes[1].stop", "torque to", "unit", "200 N*m"],
  ["axes[1].num", "torque points", "int", 5],
  ["settings.transient_periods", "transient periods", "int", 100],
  ["settings.record_periods", "recorded periods", "int", 100],
];

let defaults = null; // {direct, geometry, params} from /explorer/defaults.json
let lastParams = null; // the dimensionless parameters of the last analysis

function el(tag, attrs = {}, ...children) {
  const node = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === "class") node.className = v;
    else if (k === "text") node.textContent = v;
    else node.setAttribute(k, v);
  }
  node.append(...children);
  return node;
}

function fieldInput(path, label, kind, mode) {
  const input = Array.isArray(kind)
    ? el("select", {}, ...kind.map((c) => el("option", { value: c, text: c })))
    : el("input", { type: "text", inputmode: kind === "unit" ? "text" : "decimal" });
  Object.assign(input.dataset, { path, kind: Array.isArray(kind) ? "choice" : kind });
  input.name = path;
  const wrap = el("label", { class: "field" }, el("span", { text: label }), input);
  if (mode) wrap.dataset.mode = mode;
  return wrap;
}

function buildForms() {
  const box = $("design-fields");
  for (const [group, title, fields] of GROUPS) {
    const set = el("fieldset", {}, el("legend", { text: title }));
    if (group) set.dataset.path = "design." + group;
    const grid = el("div", { class: "grid" });
    for (const [p, label, kind, mode] of fields) grid.append(fieldInput("design." + p, label, kind, mode));
    set.append(grid);
    box.append(set);
  }
  for (const [p, label, kind, value] of SETTINGS_FIELDS) {
    const f = fieldInput(p, label, kind);
    f.querySelector("input").value = value;
    $("settings-fields").append(f);
  }
  for (const [p, label, kind, value] of ENVELOPE_FIELDS) {
    const f = fieldInput("envelope." + p, label, kind);
    f.querySelector("input").value = value;
    $("envelope-fields").append(f);
  }
}

// ---------------------------------------------------------------- paths <-> documents
const inputs = (box) => box.querySelectorAll("input[data-path], select[data-path], textarea[data-path]");
const splitPath = (path) => path.replace(/\[(\d+)\]/g, ".$1").split(".");

function getAt(doc, path) {
  return splitPath(path).reduce((node, k) => (node == null ? undefined : node[k]), doc);
}

function setAt(doc, path, value) {
  const keys = splitPath(path);
  let node = doc;
  keys.slice(0, -1).forEach((k, i) => {
    if (node[k] == null) node[k] = /^\d+$/.test(keys[i + 1]) ? [] : {};
    node = node[k];
  });
  node[keys[keys.length - 1]] = value;
}

function inputValue(input) {
  const text = input.value.trim();
  if (text === "") return undefined;
  if (input.dataset.kind === "int" || input.dataset.kind === "num") {
    const n = Number(text);
    return Number.isFinite(n) ? n : text; // not a number: the server names the field
  }
  return text;
}

const mode = () => document.querySelector("input[name=form-mode]:checked").value;
const visible = (input) => !input.closest("[data-mode]") || input.closest("[data-mode]").dataset.mode === mode();

function readDesign() {
  const doc = {};
  for (const input of inputs($("design-fields"))) {
    const v = inputValue(input);
    if (v !== undefined && visible(input)) setAt(doc, input.dataset.path, v);
  }
  const design = doc.design || {};
  for (const exc of ["transmission_error", "torque_fluctuation"]) {
    if (design[exc] && !design[exc].harmonics) delete design[exc]; // no amplitude: no excitation
  }
  const train = $("train").value.trim();
  if (train) {
    try {
      design.train = JSON.parse(train);
    } catch (err) {
      throw { errors: [{ path: "design.train", message: "not valid JSON: " + err.message }] };
    }
  }
  return design;
}

function fillDesign(design) {
  for (const input of inputs($("design-fields"))) {
    const v = getAt({ design }, input.dataset.path);
    input.value = v === undefined || v === null ? (input.tagName === "SELECT" ? input.options[0].value : "") : String(v);
  }
}

function readGroup(container, prefix) {
  const doc = {};
  for (const input of inputs(container)) {
    const v = inputValue(input);
    if (v !== undefined) setAt(doc, input.dataset.path.slice(prefix.length), v);
  }
  return doc;
}

function designOrParams() {
  if (!$("advanced").checked) return { design: readDesign() };
  try {
    return { params: JSON.parse($("params").value) };
  } catch (err) {
    throw { errors: [{ path: "params", message: "not valid JSON: " + err.message }] };
  }
}

// ---------------------------------------------------------------- the API
function api(method, path, body) {
  const headers = { Accept: "application/json, application/problem+json, image/png" };
  const key = sessionStorage.getItem(KEY_STORE);
  if (key) headers.Authorization = "Bearer " + key;
  if (body !== undefined) headers["Content-Type"] = "application/json";
  return fetch(path, { method, headers, body: body === undefined ? undefined : JSON.stringify(body) });
}

async function problemOf(res) {
  let doc = {};
  try {
    doc = await res.json();
  } catch (_) { /* not JSON */ }
  if (res.status === 401) doc.detail = (doc.detail || "unauthorized") + ": enter the API key at the top of the page";
  return { detail: doc.detail || `${res.status} ${res.statusText}`, errors: doc.errors || [] };
}

// ---------------------------------------------------------------- field errors
function clearErrors(form) {
  form.querySelectorAll(".field-error").forEach((n) => n.remove());
  form.querySelectorAll(".invalid").forEach((n) => n.classList.remove("invalid"));
  form.querySelector(".problem").hidden = true;
}

// The element a server path such as design.mesh.half_backlash (or design.axes[0].start,
// prefixed by the caller) belongs to: the field itself, else its nearest fieldset.
function target(form, path) {
  for (let p = path; p; p = p.replace(/(\.[^.]*|\[\d+\])$/, "")) {
    const hit = [...form.querySelectorAll("[data-path]")].find((n) => n.dataset.path === p && !n.closest("[hidden]"));
    if (hit) return hit;
    if (!/[.[]/.test(p)) break;
  }
  return null;
}

function showProblem(form, problem, prefix = "") {
  clearErrors(form);
  const loose = [];
  for (const e of problem.errors || []) {
    const message = e.message.replace(/^Value error, /, "");
    const node = target(form, prefix + e.path);
    if (!node) { loose.push(`${e.path}: ${message}`); continue; }
    node.classList.add("invalid");
    const whole = node.tagName === "FIELDSET" || node.tagName === "TEXTAREA"; // name the field
    const note = el("span", { class: "field-error", role: "alert", text: whole ? `${e.path}: ${message}` : message });
    if (node.tagName === "FIELDSET") node.append(note);
    else node.closest("label").append(note);
  }
  const box = form.querySelector(".problem");
  if (loose.length || !(problem.errors || []).length) {
    box.textContent = loose.length ? loose.join("\n") : problem.detail;
    box.hidden = false;
  }
  const first = form.querySelector(".invalid");
  if (first) first.scrollIntoView({ block: "center" });
}

// ---------------------------------------------------------------- one design
// a number to `digits` significant digits, trailing zeros dropped, exponent when tiny or huge
function fmt(x, digits = 4) {
  if (x === null || x === undefined) return "—";
  const a = Math.abs(x);
  const text = a && (a < 1e-3 || a >= 1e6) ? Number(x).toExponential(digits - 1) : Number(x).toPrecision(digits);
  return text.replace(/(\.\d*?)0+(e|$)/, "$1$2").replace(/\.(e|$)/, "$1").replace("e+", "e");
}
const rpm = (x) => Math.round(x).toLocaleString("en-US");
const CONTACT = {
  no_impact: "teeth always in contact",
  single_sided: "tooth separation: the teeth apart at some time",
  double_sided: "back-flank impacts: the separation reaches the back flank",
};

// the LLE in the page's units: per s with a design (as its figure), per unit τ otherwise
function lleText(n, eng) {
  if (n.lle === null || n.lle === undefined) return "—";
  const tau = `${fmt(n.lle)} ± ${fmt(n.lle_stderr, 2)} per unit τ`;
  if (!eng) return tau;
  const s = eng.time_scale_s;
  return `${fmt(n.lle / s)} ± ${fmt(n.lle_stderr / s, 2)} per s (${tau})`;
}

function facts(result) {
  const n = result.numerics;
  const eng = result.engineering;
  const resp = eng && eng.response;
  const rows = [["Numerical class", n.classification.replace("_", "-")],
    ["Period", n.period ? `${n.period}T` + (resp && resp.period_ms ? ` (${fmt(resp.period_ms, 3)} ms)` : "") : "none found"],
    ["Largest Lyapunov exponent", lleText(n, eng)],
    ["Stability margin", n.floquet && n.floquet.stability_margin !== null && n.floquet.stability_margin !== undefined
      ? n.floquet.stability_margin.toFixed(3)
        + (n.floquet.nearest_bifurcation ? ` (nearest: ${n.floquet.nearest_bifurcation.replace("_", "-")})` : "")
      : "—" + (n.floquet_note ? ` (${n.floquet_note})` : "")],
    ["Melnikov", result.melnikov.chaos_possible === null ? "not applicable at this load (no saddle)"
      : result.melnikov.chaos_possible ? "chaos possible" : "chaos ruled out"]];
  if (eng) {
    const w = eng.speed_windows_rpm || [];
    const scan = eng.speed_range_rpm ? ` (scanned ${rpm(eng.speed_range_rpm[0])}–${rpm(eng.speed_range_rpm[1])} rpm)` : "";
    rows.push(["Melnikov speed windows", (w.length ? w.map(([a, b]) => `${rpm(a)}–${rpm(b)} rpm`).join(", ") : "none")
      + (eng.speed_windows_note ? ` (${eng.speed_windows_note})` : scan)]);
    if (eng.critical_torque_nm !== null && eng.critical_torque_nm !== undefined) {
      rows.push(["Critical torque", `${fmt(eng.critical_torque_nm, 3)} N·m (the Melnikov criterion applies below it)`]);
    }
  }
  // with basins the DTE and the dynamic factor are the largest over the attractors, named
  const worst = eng && eng.most_adverse;
  const largest = (key, unit) => `${fmt(worst[key].value, 3)}${unit} (the largest over the attractors: `
    + `${worst[key].label}, ${fmt(100 * worst[key].fraction, 2)} % of starts)`;
  if (resp) {
    rows.push(["Dynamic transmission error", worst && worst.dte ? largest("dte", " µm peak to peak")
      : `${fmt(resp.dte_peak_to_peak_um, 3)} µm peak to peak`],
      ["Dynamic factor", worst && worst.dynamic_factor ? largest("dynamic_factor", "")
        : fmt(resp.dynamic_factor, 3)],
      ["Contact", (CONTACT[resp.contact.regime] || resp.contact.regime)
        + (resp.contact.separation_fraction
          ? `, separated ${fmt(100 * resp.contact.separation_fraction, 2)} % of the time` : "")]);
  }
  rows.push(["Agreement", result.verdict.agreement.replaceAll("_", " ")]);
  return rows;
}

// Beside the form, in the results' place: what the server refused, field by field.
function showRefusal(problem) {
  const n = problem.errors.length;
  $("welcome").hidden = true;
  $("verdict").hidden = true;
  const title = n ? `The server refused ${n === 1 ? "a field" : n + " fields"} (marked in red)` : "The server refused the request";
  const lines = n ? problem.errors.map((e) => `${e.path}: ${e.message.replace(/^Value error, /, "")}`) : [problem.detail];
  $("refused").replaceChildren(el("h2", { text: title }), ...lines.map((text) => el("p", { text })));
  $("refused").hidden = false;
}

function showVerdict(result) {
  $("welcome").hidden = true;
  $("verdict").hidden = false;
  const cls = result.numerics.classification;
  $("verdict-class").textContent = cls.replace("_", "-");
  $("verdict-class").style.background = CLASS_COLORS[cls] || "#555";
  $("verdict-summary").textContent = result.engineering ? result.engineering.summary : result.verdict.summary;
  $("verdict-facts").replaceChildren(...facts(result).flatMap(([k, v]) => [el("dt", { text: k }), el("dd", { text: v })]));
}

// With settings.basins: one row per attractor and the basin picture.
// a gear train's modes (engineering.modes) and its Campbell diagram; hidden for a pair
function showModes(result, subject) {
  const found = result.engineering && result.engineering.modes;
  $("modes").hidden = !found;
  if (!found) return;
  const head = el("tr", {}, ...["mode", "frequency Hz", "damping ratio", "mesh energy"]
    .map((t) => el("th", { text: t })));
  const rows = found.modes.map((m, k) => el("tr", k === found.mesh_mode ? { class: "mesh-mode" } : {},
    ...[k === found.mesh_mode ? `${k + 1} (mesh mode)` : String(k + 1), fmt(m.frequency_hz, 5),
      fmt(m.damping_ratio, 3), `${(100 * m.mesh_energy_share).toFixed(1)} %`]
      .map((t) => el("td", { text: t }))));
  $("modes-table").replaceChildren(head, ...rows);
  $("modes-note").textContent = `(linearised in contact; stiff limit ${fmt(found.stiff_limit_hz, 4)} Hz)`;
  loadFigure($("campbell-figure"), "/v1/analyses/campbell/plot", { design: subject.design }, $("campbell-note"));
}

function showAttractors(result, body) {
  const found = result.numerics.attractors;
  $("basins").hidden = !found;
  if (!found) return;
  const b = result.numerics.basins;
  const pct = (x) => `${(100 * x).toFixed(0)} %`;
  const head = el("tr", {}, ...["attractor", "basin", "95 % interval", "starts", "LLE", "DTE µm"]
    .map((t) => el("th", { text: t })));
  const rows = found.map((a) => el("tr", {}, ...[a.label, pct(a.fraction),
    `${pct(a.interval[0])} – ${pct(a.interval[1])}`, String(a.count), fmt(a.lle),
    a.dte_um === null || a.dte_um === undefined ? "—" : fmt(a.dte_um, 3)].map((t) => el("td", { text: t }))));
  $("attractors-table").replaceChildren(head, ...rows);
  $("basins-count").textContent = `(${b.starts} starts, ${b.diverged} diverged, ${b.unsettled} unsettled)`;
  loadFigure($("basins-figure"), "/v1/analyses/basins/plot", body);
}

// A figure fetched with the key (an <img src> could not send it); data-state tells tests
// and styles whether it is loading, shown or failed.
async function loadFigure(img, path, body, note) {
  if (note) note.textContent = "";
  img.dataset.state = "loading";
  const res = await api("POST", path, body);
  if (img.src.startsWith("blob:")) URL.revokeObjectURL(img.src);
  if (!res.ok) {
    img.removeAttribute("src");
    img.dataset.state = "failed";
    if (note) note.textContent = "(not available: " + (await problemOf(res)).detail + ")";
    return;
  }
  img.onload = () => { img.dataset.state = "shown"; };
  img.src = URL.createObjectURL(await res.blob());
}

let thresholdSubject = null;
function loadThresholds() {
  if (!thresholdSubject) return;
  loadFigure($("threshold-figure"), "/v1/thresholds/plot",
    { ...thresholdSubject, parameter: $("threshold-parameter").value }, $("threshold-note"));
}

async function analyse() {
  const form = $("design-form");
  let subject;
  try {
    subject = designOrParams();
  } catch (problem) {
    return showProblem(form, problem);
  }
  const body = { ...subject, settings: readGroup($("settings-fields"), "settings.") };
  clearErrors(form);
  $("analyse").disabled = true;
  $("analyse-status").textContent = "Analysing…";
  try {
    const res = await api("POST", "/v1/analyses", body);
    if (!res.ok) {
      const problem = await problemOf(res);
      showProblem(form, problem);
      showRefusal(problem);
      $("analyse-status").textContent = "";
      return;
    }
    $("refused").hidden = true;
    const result = await res.json();
    lastParams = result.params || subject.params || null;
    showVerdict(result);
    $("analyse-status").textContent = "Done.";
    $("verdict").scrollIntoView({ block: "start" });
    loadFigure($("analysis-figure"), "/v1/analyses/plot", body);
    showAttractors(result, body);
    showModes(result, subject);
    const train = result.engineering && result.engineering.modes;
    thresholdSubject = result.melnikov.applicable && !train ? subject : null;
    if (train) {  // the threshold curves are the pair's (Eq. 9): not drawn for a train
      $("threshold-figure").removeAttribute("src");
      $("threshold-figure").dataset.state = "failed";
      $("threshold-note").textContent = "(a gear train: " + (result.melnikov.notes[0] || "") + ")";
    } else if (thresholdSubject) {
      loadThresholds();
    } else {  // above the critical torque: no saddle, so no threshold curves to draw
      const img = $("threshold-figure");
      img.removeAttribute("src");
      img.dataset.state = "failed";
      const t = result.engineering && result.engineering.critical_torque_nm;
      $("threshold-note").textContent = "(the Melnikov criterion does not apply at this load"
        + (t ? ` — above the critical torque ${fmt(t, 3)} N·m` : "") + ": no threshold curves)";
    }
  } catch (err) {
    showProblem(form, { detail: "the server did not answer: " + err.message });
    $("analyse-status").textContent = "";
  } finally {
    $("analyse").disabled = false;
  }
}

// ---------------------------------------------------------------- the envelope
const recentJobs = () => JSON.parse(localStorage.getItem(JOBS_STORE) || "[]");
function rememberJob(job) {
  const jobs = [job, ...recentJobs().filter((j) => j.id !== job.id)].slice(0, 10);
  localStorage.setItem(JOBS_STORE, JSON.stringify(jobs));
  listJobs();
}
function updateJob(id, changes) {
  localStorage.setItem(JOBS_STORE, JSON.stringify(recentJobs().map((j) => (j.id === id ? { ...j, ...changes } : j))));
  listJobs();
}

function listJobs() {
  const items = recentJobs().map((j) => {
    const open = el("button", { type: "button", class: "link", text: j.label });
    open.addEventListener("click", () => watchJob(j.id));
    return el("li", {}, open, el("small", { text: ` ${j.status || ""} · ${new Date(j.created).toLocaleString()}` }));
  });
  $("recent-jobs").replaceChildren(...(items.length ? items : [el("li", { class: "hint", text: "none yet" })]));
}

async function mapRange() {
  const form = $("envelope-form");
  clearErrors(form);
  if ($("advanced").checked) {
    const detail = "the envelope sweeps speed and torque of a design in physical units: switch off the advanced mode";
    return showProblem(form, { detail });
  }
  const env = readGroup($("envelope-fields"), "envelope.");
  const design = readDesign();
  const axes = [{ parameter: "speed", ...env.axes[0] }, { parameter: "torque", ...env.axes[1] }];
  const label = `${axes[0].start}–${axes[0].stop} × ${axes[1].start}–${axes[1].stop}`;
  const body = { design, axes, settings: env.settings, label };
  let res;
  $("map-range").disabled = true;
  try {
    res = await api("POST", "/v1/sweeps", body);
  } catch (err) {
    return showProblem(form, { detail: "the server did not answer: " + err.message });
  } finally {
    $("map-range").disabled = false;
  }
  if (!res.ok) {
    // errors name design.* (the design form) or axes.* and settings.* (this form)
    const problem = await problemOf(res);
    const own = problem.errors.filter((e) => !e.path.startsWith("design"));
    const theirs = problem.errors.filter((e) => e.path.startsWith("design"));
    if (theirs.length) showProblem($("design-form"), { ...problem, errors: theirs });
    if (own.length || !theirs.length) showProblem(form, { ...problem, errors: own }, "envelope.");
    return;
  }
  const job = await res.json();
  rememberJob({ id: job.id, label, design, settings: env.settings, axes, created: Date.now(), status: job.status });
  watchJob(job.id);
}

function watchJob(id) {
  $("welcome").hidden = true;
  $("envelope").hidden = false;
  $("envelope-progress-row").hidden = false;
  $("envelope-hint").hidden = true;
  $("envelope-map").replaceChildren();
  $("windows").replaceChildren();
  $("envelope").scrollIntoView({ block: "start" });
  envelopeJob.start(id);
}

// One durable job watched in its panel (the envelope, a robustness study, a run-up): its status
// and progress in <prefix>-status, <prefix>-progress and <prefix>-progress-text, polled every
// second (every 3 s while the server does not answer: the job is durable, keep asking), the
// cancel button shown while it is queued or running, and its result handed to onResult.
class JobWatcher {
  constructor({ route, prefix, cancel, unit, onResult, onStatus = () => {} }) {
    Object.assign(this, { route, prefix, cancel, unit, onResult, onStatus });
    this.job = null; // {id, timer, result}
  }

  start(id) {
    if (this.job) clearTimeout(this.job.timer);
    this.job = { id, timer: null };
    this.poll(id);
  }

  text(t) { $(`${this.prefix}-progress-text`).textContent = t; }

  async poll(id) {
    if (!this.job || this.job.id !== id) return;
    let res;
    try {
      res = await api("GET", `/v1/${this.route}/${id}`);
    } catch (err) {
      this.text("server not answering, retrying…");
      this.job.timer = setTimeout(() => this.poll(id), 3000);
      return;
    }
    if (!res.ok) {
      $(`${this.prefix}-status`).textContent = "unavailable";
      this.text((await problemOf(res)).detail);
      this.onStatus(id, res.status === 404 ? "gone" : "unavailable");
      return;
    }
    const job = await res.json();
    const { done, total } = job.progress;
    $(`${this.prefix}-status`).textContent = job.status;
    $(`${this.prefix}-progress`).max = total || 1;
    $(`${this.prefix}-progress`).value = done;
    this.text(`${done} / ${total} ${this.unit}`);
    $(this.cancel).hidden = !["queued", "running"].includes(job.status);
    this.onStatus(id, job.status);
    if (job.status === "queued" || job.status === "running") {
      this.job.timer = setTimeout(() => this.poll(id), 1000);
    } else if (job.status === "succeeded") {
      const result = await api("GET", `/v1/${this.route}/${id}/result`);
      if (result.ok) {
        this.job.result = await result.json();
        this.onResult(id, this.job.result);
      }
    } else {
      this.text(`${done} / ${total} ${this.unit}` + (job.error ? ` · ${job.error}` : ""));
    }
  }

  async stop() {
    if (!this.job) return;
    await api("DELETE", `/v1/${this.route}/${this.job.id}`);
    this.poll(this.job.id);
  }
}

// POST a job from its form (its button disabled meanwhile): the accepted job's document, or
// null with the refusal shown, errors mine(e) in this form as "path: message" lines and the
// design's in the design form.
async function postJob(form, button, path, body, mine = (e) => !e.path.startsWith("design")) {
  clearErrors(form);
  let res;
  $(button).disabled = true;
  try {
    res = await api("POST", path, body);
  } catch (err) {
    showProblem(form, { detail: "the server did not answer: " + err.message });
    return null;
  } finally {
    $(button).disabled = false;
  }
  if (res.ok) return res.json();
  const problem = await problemOf(res);
  const own = problem.errors.filter(mine);
  const theirs = problem.errors.filter((e) => !own.includes(e));
  if (theirs.length) showProblem($("design-form"), { ...problem, errors: theirs });
  if (own.length || !theirs.length) {
    showProblem(form, { detail: own.map((e) => `${e.path}: ${e.message}`).join("\n") || problem.detail });
  }
  return null;
}

const envelopeJob = new JobWatcher({
  route: "sweeps", prefix: "envelope", cancel: "cancel-sweep", unit: "points",
  onResult: (id, result) => drawEnvelope(id, result),
  onStatus: (id, status) => updateJob(id, { status }),
});

let plotlyLoading = null;
function loadPlotly() {
  plotlyLoading = plotlyLoading || new Promise((resolve, reject) => {
    const s = el("script", { src: "/static/plotly.min.js" });
    s.onload = () => resolve(window.Plotly);
    s.onerror = () => reject(new Error("could not load /static/plotly.min.js"));
    document.head.append(s);
  });
  return plotlyLoading;
}

// speed in rpm and torque in N m of a point (the `physical` block, else SI values)
const pointSpeed = (p) => (p.physical && p.physical.speed ? p.physical.speed.value : p.values.speed * 30 / Math.PI);
const pointTorque = (p) => (p.physical && p.physical.torque ? p.physical.torque.value : p.values.torque);

// the map's marker of a point: its shape says how the teeth meet, its size the dynamic factor
const IMPACT_SYMBOLS = { no_impact: "square", single_sided: "triangle-up", double_sided: "x" };
const physicalText = (p, key, digits, unit) => (p.physical && p.physical[key] ? fmt(p.physical[key].value, digits) + unit : "—");
function factorSize(p) {
  const f = p.physical && p.physical.dynamic_factor ? p.physical.dynamic_factor.value : 1;
  return Math.max(7, Math.min(20, 7 + 13 * (f - 1))); // 1 → 7 px, 2 and over → 20 px
}
// legend entries of the shapes (markers drawn nowhere)
const shapeLegend = () => Object.entries(IMPACT_SYMBOLS).map(([regime, symbol]) => ({
  type: "scatter", mode: "markers", x: [null], y: [null], name: CONTACT[regime], hoverinfo: "skip",
  marker: { symbol, color: "#777", size: 10 },
}));

async function drawEnvelope(id, result) {
  $("envelope-progress-row").hidden = true;
  $("envelope-hint").hidden = false;
  const map = $("envelope-map");
  await drawMap(map, result, 420);
  map.on("plotly_click", (ev) => {
    const hit = ev.points.find((p) => p.data.type === "scatter");
    if (hit) openPoint(id, hit.x, hit.y);
  });
  showWindows(result.windows);
  offerFix(id, result);
}

// With basins a point's DTE and dynamic factor are the largest over its attractors above the
// threshold (``magnitudes_from``): the attractor they come from, with its fraction.
function magnitudesFrom(p) {
  const a = p.magnitudes_from && p.magnitudes_from.dte;
  return a ? `<br>(largest over the attractors: ${a.label}, ${fmt(100 * a.fraction, 2)} % of starts)` : "";
}

// A speed x torque map of a sweep result into ``map``: one marker per point by class, the
// Melnikov region shaded.
async function drawMap(map, result, height) {
  const Plotly = await loadPlotly();
  const pts = result.points.map((p) => ({ ...p, rpm: pointSpeed(p), nm: pointTorque(p) }));
  const traces = Object.keys(CLASS_COLORS).map((cls) => {
    const sel = pts.filter((p) => p.classification === cls);
    return {
      type: "scatter", mode: "markers", name: cls.replace("_", "-"),
      x: sel.map((p) => p.rpm), y: sel.map((p) => p.nm),
      customdata: sel.map((p) => [
        p.classification.replace("_", "-"), p.period ? p.period + "T" : "none", fmt(p.lle), fmt(p.lle_stderr, 2),
        CONTACT[p.impact_regime] || "no verdict on contact",
        p.melnikov_chaos_possible === null ? "not applicable (above T_crit)"
          : p.melnikov_chaos_possible ? "chaos possible" : "chaos ruled out",
        physicalText(p, "dynamic_factor", 3, ""), physicalText(p, "dte", 3, " µm"),
        // with basins the verdict is the worst attractor's: name it and its fraction
        p.decided_by ? `<br>decided by ${p.decided_by}` : "",
        magnitudesFrom(p),
      ]),
      hovertemplate: "speed %{x:,.0f} rpm<br>torque %{y:,.1f} N·m"
        + "<br>class %{customdata[0]}, period %{customdata[1]}<br>LLE %{customdata[2]} ± %{customdata[3]} per unit τ"
        + "<br>%{customdata[4]}<br>dynamic factor %{customdata[6]}, DTE %{customdata[7]}%{customdata[9]}"
        + "<br>Melnikov: %{customdata[5]}%{customdata[8]}<extra></extra>",
      marker: {
        color: CLASS_COLORS[cls], symbol: sel.map((p) => IMPACT_SYMBOLS[p.impact_regime] || "square"),
        size: sel.map((p) => factorSize(p)), line: { color: "white", width: 1 },
      },
    };
  }).filter((t) => t.x.length).concat(shapeLegend());
  const xs = [...new Set(pts.map((p) => p.rpm))].sort((a, b) => a - b);
  const ys = [...new Set(pts.map((p) => p.nm))].sort((a, b) => a - b);
  if (xs.length > 1 && ys.length > 1) {
    const z = ys.map((y) => xs.map((x) => {
      const p = pts.find((q) => q.rpm === x && q.nm === y);
      return p && p.melnikov_chaos_possible ? 1 : 0;
    }));
    traces.unshift({
      type: "contour", x: xs, y: ys, z, name: "Melnikov: chaos possible", showlegend: true,
      showscale: false, hoverinfo: "skip", autocontour: false,
      contours: { start: 0.5, end: 0.5, size: 1, coloring: "fill" },
      colorscale: [[0, "rgba(255,255,255,0)"], [1, "rgba(214,39,40,0.13)"]],
      line: { color: "#d62728", dash: "dash", width: 2 },
    });
  }
  const layout = {
    margin: { l: 60, r: 10, t: 10, b: 50 }, height,
    xaxis: { title: { text: "driver speed [rpm]" }, zeroline: false },
    yaxis: { title: { text: "driver torque [N·m]" }, zeroline: false },
    legend: { orientation: "h", y: -0.18 }, hovermode: "closest",
  };
  await Plotly.newPlot(map, traces, layout, { displaylogo: false, responsive: true });
}

// ---------------------------------------------------------------- remedies
let fixing = null; // the failing envelope "How do I fix it?" searches: {design, settings, axes}

function offerFix(id, result) {
  const job = recentJobs().find((j) => j.id === id);
  const failing = result.points.some((p) => ["chaotic", "diverged"].includes(p.classification));
  const axes = job && (job.axes || result.axes);
  fixing = failing && axes && axes.length === 2 ? { design: job.design, settings: job.settings, axes } : null;
  $("fix").hidden = !fixing;
  $("fix-status").textContent = "";
  $("fix-answer").textContent = "";
  $("fix-maps").replaceChildren();
}

// POST /v1/remedies under the gate's default rule (--fail-on chaotic), then the ranked answer
// and the map at each remedy (the envelope report's sweep).
async function fixIt() {
  const [s, t] = fixing.axes;
  const envelope = { speed: `${s.start}:${s.stop}`, speed_points: s.num, torque: `${t.start}:${t.stop}`, torque_points: t.num };
  // the starts of the map shown (its basins, else its one start), not the CI gate's default
  const starts = (fixing.settings && fixing.settings.basins && fixing.settings.basins.starts) || 1;
  const body = { design: fixing.design, settings: fixing.settings, envelope, starts, fail_on: ["chaotic"] };
  $("fix-it").disabled = true;
  let res;
  try {
    res = await api("POST", "/v1/remedies", body);
  } catch (err) {
    res = null;
    $("fix-answer").textContent = "the server did not answer: " + err.message;
  }
  if (res && !res.ok) $("fix-answer").textContent = (await problemOf(res)).detail;
  if (!res || !res.ok) { $("fix-it").disabled = false; return; }
  pollFix((await res.json()).id);
}

async function pollFix(id) {
  const res = await api("GET", `/v1/remedies/${id}`);
  const job = res.ok ? await res.json() : { status: "unavailable", progress: { done: 0, total: 0 } };
  $("fix-status").textContent = `${job.status} · ${job.progress.done} / ${job.progress.total} searches`;
  if (job.status === "queued" || job.status === "running") {
    setTimeout(() => pollFix(id), 1000);
    return;
  }
  $("fix-it").disabled = false;
  if (job.status !== "succeeded") return;
  const result = await (await api("GET", `/v1/remedies/${id}/result`)).json();
  $("fix-answer").textContent = result.answer.charAt(0).toUpperCase() + result.answer.slice(1) + ".";
  for (const r of result.remedies) {
    const map = el("div", { class: "fix-map", "aria-label": `map at ${r.lever} = ${r.to} ${r.unit}` });
    const verdict = r.check.passed ? "the envelope passes" : `${r.check.failing_points} points still fail`;
    const caption = `${r.bound}: ${r.lever} ${r.from} → ${fmt(r.to)} ${r.unit === "1" ? "" : r.unit} (${verdict})`;
    $("fix-maps").append(el("figure", {}, el("figcaption", { text: caption }), map));
    await drawMap(map, r.check.sweep, 300);
  }
}

// The windows table: per torque level, the speed intervals [rpm] of each response, of tooth
// contact (separation, back-flank) and of Melnikov chaos (the result's `windows`).
const span = ([a, b]) => (a === b ? `${rpm(a)}` : `${rpm(a)}–${rpm(b)}`) + " rpm";
const runs = (byName) => Object.entries(byName)
  .map(([name, list]) => `${name.replaceAll("_", "-")}: ${list.map(span).join(", ")}`);

function showWindows(windows) {
  const box = $("windows");
  if (!windows || !windows.length) return box.replaceChildren();
  const row = (w) => {
    const level = Object.entries(w.level)
      .map(([k, v]) => `${k} ${fmt(v.value)} ${v.unit.replace("*", "·")}`).join(", ") || "all";
    const cells = [[level], runs(w.response), runs(w.contact).concat(w.contact && Object.keys(w.contact).length ? [] : ["always in contact"]),
      (w.melnikov.length ? w.melnikov.map(span) : ["none"])
        .concat((w.melnikov_not_applicable || []).map((s) => `not applicable: ${span(s)}`))];
    return el("tr", {}, ...cells.map((lines) => el("td", {}, ...lines.flatMap((t, i) => (i ? [el("br"), t] : [t])))));
  };
  box.replaceChildren(el("h3", { text: "Speed windows" }), el("table", {},
    el("thead", {}, el("tr", {}, ...["level", "response", "tooth contact", "Melnikov: chaos possible"]
      .map((c) => el("th", { text: c })))),
    el("tbody", {}, ...windows.map(row))));
}

// A point of the map: its design (the job's, at that speed and torque) analysed with the
// sweep's settings, so the verdict is the one the map shows.
function openPoint(id, speedRpm, torqueNm) {
  const job = recentJobs().find((j) => j.id === id);
  $("advanced").checked = false;
  toggleAdvanced();
  const design = {
    ...(job ? job.design : readDesign()),
    speed: `${+speedRpm.toPrecision(10)} rpm`,
    torque: `${+torqueNm.toPrecision(10)} N*m`,
  };
  if (job && job.design.driver && job.design.driver.module) setMode("geometry");
  else if (job) setMode("direct");
  fillDesign(design);
  if (job && job.settings) {
    for (const [k, v] of Object.entries(job.settings)) {
      const input = $("settings-fields").querySelector(`[data-path="settings.${k}"]`);
      if (input) input.value = v;
    }
  }
  analyse();
}

// a figure at full size in a dialog (click or Escape closes it)
function enlarge(img) {
  if (!img.src) return;
  $("enlarged-img").src = img.src;
  $("enlarged-img").alt = img.alt;
  $("enlarged").showModal();
}

// ---------------------------------------------------------------- modes and start-up
function setMode(m) {
  document.querySelector(`input[name=form-mode][value=${m}]`).checked = true;
  document.querySelectorAll("#design-fields [data-mode]").forEach((n) => { n.hidden = n.dataset.mode !== m; });
}

function switchMode(m) {
  const design = readDesign();
  clearErrors($("design-form")); // a refusal of the other form's fields no longer applies
  $("refused").hidden = true;
  const other = defaults[m === "direct" ? "geometry" : "direct"];
  setMode(m);
  // keep what the user typed; fields of the new form come from its example, and the mesh
  // stiffness follows the form while it still holds the other form's example value
  const example = defaults[m];
  const merged = { ...example, ...design,
    driver: { ...example.driver, teeth: design.driver?.teeth },
    driven: { ...example.driven, teeth: design.driven?.teeth } };
  if (design.mesh && design.mesh.stiffness === other.mesh.stiffness) {
    merged.mesh = { ...design.mesh, stiffness: example.mesh.stiffness, stiffness_harmonics: example.mesh.stiffness_harmonics };
  }
  fillDesign(merged);
}

function toggleAdvanced() {
  const on = $("advanced").checked;
  $("design-fields").hidden = on;
  $("train-box").hidden = on;
  $("params-box").hidden = !on;
  document.querySelectorAll("input[name=form-mode]").forEach((r) => { r.disabled = on; });
  if (on && !$("params").value) $("params").value = JSON.stringify(lastParams || defaults.params, null, 2);
}

async function start() {
  buildForms();
  $("api-key").value = sessionStorage.getItem(KEY_STORE) || "";
  $("api-key").addEventListener("input", (e) => sessionStorage.setItem(KEY_STORE, e.target.value.trim()));
  defaults = await (await fetch("/explorer/defaults.json")).json();
  setMode("direct");
  fillDesign(defaults.direct);
  document.querySelectorAll("input[name=form-mode]").forEach((r) => r.addEventListener("change", () => switchMode(r.value)));
  $("advanced").addEventListener("change", toggleAdvanced);
  $("train-example").addEventListener("click", () => { $("train").value = JSON.stringify(defaults.train, null, 1); });
  $("design-form").addEventListener("submit", (e) => { e.preventDefault(); analyse(); });
  $("envelope-form").addEventListener("submit", (e) => { e.preventDefault(); mapRange(); });
  $("cancel-sweep").addEventListener("click", () => envelopeJob.stop());
  $("fix-it").addEventListener("click", fixIt);
  $("threshold-parameter").addEventListener("change", loadThresholds);
  document.querySelectorAll("figure img, #campbell-figure").forEach((img) => img.addEventListener("click", () => enlarge(img)));
  $("enlarged").addEventListener("click", () => $("enlarged").close());
  listJobs();
  document.body.dataset.ready = "true"; // for tests: the form is built and prefilled
}

document.addEventListener("DOMContentLoaded", start);
