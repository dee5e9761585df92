// gearchaos design explorer: a measured signal (a rig's transmission error, an accelerometer)
// read as periodic, quasi-periodic, chaotic or noise. The samples are pasted, or a CSV or
// single-column text file is loaded into the same box; the text goes to the server as it is
// (POST /v1/signals/upload, whose parser reads one value a line or columns, a first column of
// times setting the rate), and its figure from POST /v1/signals/upload/plot (the server
// answers it from the reading it has just cached). Loaded after explorer.js, whose helpers
// ($, el, problemOf, showProblem, clearErrors, fieldInput, readGroup, fmt) it uses, and which
// makes every figure's image (this one's too) open at full size on a click.
"use strict";

const SIGNAL_FIELDS = [
  ["signal.sample_rate", "sample rate (else the time column)", "unit", "20 kHz"],
  ["speed", "shaft speed (optional)", "unit", ""],
  ["teeth", "teeth on that shaft (optional)", "int", ""],
  ["signal.unit", "unit of the values", "unit", "um"],
];
const QUANTITIES = ["transmission_error", "acceleration", "displacement", "velocity", "other"];
const VERDICT_COLORS = {
  periodic: "#2e7d32", quasi_periodic: "#1565c0", chaotic: "#c62828",
  stochastic: "#6d4c41", undetermined: "#555",
};

function buildSignalForm() {
  for (const [path, label, kind, value] of SIGNAL_FIELDS) {
    const f = fieldInput(path, label, kind);
    f.querySelector("input").value = value;
    $("signal-fields").append(f);
  }
  $("signal-fields").append(fieldInput("signal.quantity", "what was measured", QUANTITIES));
  $("signal-file").addEventListener("change", loadSignalFile);
  $("signal-form").addEventListener("submit", (ev) => { ev.preventDefault(); readSignal(); });
}

async function loadSignalFile() {
  const file = $("signal-file").files[0];
  if (!file) return;
  $("signal-values").value = await file.text();
  const lines = $("signal-values").value.split(/\r?\n/).filter((l) => l.trim()).length;
  $("signal-file-note").textContent = `${file.name}: ${lines.toLocaleString("en-US")} lines`;
}

// the query of the upload routes: the fields the text does not carry
function signalQuery() {
  const f = readGroup($("signal-fields"), "");
  const query = new URLSearchParams();
  if (f.signal.sample_rate !== undefined) query.set("rate", f.signal.sample_rate);
  if (f.speed !== undefined) query.set("speed", f.speed);
  if (f.teeth !== undefined) query.set("teeth", f.teeth);
  query.set("quantity", f.signal.quantity);
  if (f.signal.unit !== undefined) query.set("unit", f.signal.unit);
  return query.toString();
}

function upload(path, text, accept) {
  const headers = { Accept: accept, "Content-Type": "text/csv" };
  const key = sessionStorage.getItem(KEY_STORE);
  if (key) headers.Authorization = "Bearer " + key;
  return fetch(path, { method: "POST", headers, body: text });
}

async function readSignal() {
  const form = $("signal-form");
  clearErrors(form);
  const text = $("signal-values").value;
  const query = signalQuery();
  $("read-signal").disabled = true;
  $("signal-status").textContent = "reading…";
  let res;
  try {
    res = await upload("/v1/signals/upload?" + query, text, "application/json, application/problem+json");
  } catch (err) {
    return showProblem(form, { detail: "the server did not answer: " + err.message });
  } finally {
    $("read-signal").disabled = false;
    $("signal-status").textContent = "";
  }
  if (!res.ok) {
    // the upload names the query's fields by the request's paths (signal.sample_rate, speed)
    return showProblem(form, await problemOf(res));
  }
  showReading(await res.json());
  loadSignalFigure(text, query);
}

function readingFacts(r) {
  const rows = [];
  const rec = r.record;
  rows.push(["Record", `${rec.samples.toLocaleString("en-US")} samples at ${rec.sample_rate_hz.toLocaleString("en-US")} Hz, ${fmt(rec.duration_s)} s; rms ${fmt(rec.rms)} ${rec.unit}, peak to peak ${fmt(rec.peak_to_peak)} ${rec.unit}`]);
  const ref = r.reference;
  if (ref.shaft_rpm) {
    rows.push(["Shaft", `${fmt(ref.shaft_rpm)} rpm (${ref.source})` + (ref.mesh_hz ? `, mesh ${fmt(ref.mesh_hz)} Hz (${ref.teeth} teeth)` : "")]);
  }
  if (ref.cycle) rows.push(["Strobed", `once per ${ref.cycle.replaceAll("_", " ")}: ${fmt(ref.cycles)} cycles of ${ref.samples_per_cycle} samples`]);
  const lines = r.spectrum.lines.slice(0, 3).map((l) => `${l.label} ${fmt(l.amplitude, 3)} ${rec.unit}`);
  if (lines.length) rows.push(["Strongest lines", lines.join("; ")]);
  if (r.periodicity && r.periodicity.cycles) rows.push(["Period", `${r.periodicity.cycles} cycle(s), ${fmt(r.periodicity.seconds)} s`]);
  if (r.zero_one) rows.push(["0-1 test K", `${fmt(r.zero_one.k, 3)} (quartiles ${r.zero_one.k_quartiles.map((k) => fmt(k, 3)).join("–")}; ~0 regular, ~1 chaotic)`]);
  const ly = r.lyapunov;
  if (ly && ly.per_second !== null) {
    rows.push(["Largest Lyapunov exponent", `${fmt(ly.per_second, 3)} per s` + (ly.per_revolution !== null ? `, ${fmt(ly.per_revolution, 3)} per revolution` : "") + ` (Rosenstein, embedding dimension ${ly.dimension}, delay ${fmt(ly.delay_s, 3)} s)`]);
  }
  if (r.correlation_dimension !== null) rows.push(["Correlation dimension", fmt(r.correlation_dimension, 3)]);
  const s = r.surrogates;
  if (s) rows.push(["Surrogate test", `p = ${fmt(s.p_value, 3)} over ${s.surrogates} ${s.method} surrogates: ${s.rejected ? "more deterministic than linear noise" : "not distinguished from linear noise"}`]);
  if (r.model) rows.push(["Model at this speed", r.model.summary]);
  return rows;
}

function showReading(r) {
  $("welcome").hidden = true;
  $("refused").hidden = true;
  $("reading").hidden = false;
  $("reading-verdict").textContent = r.verdict.replaceAll("_", "-");
  $("reading-verdict").style.background = VERDICT_COLORS[r.verdict] || "#555";
  $("reading-summary").textContent = r.summary;
  $("reading-evidence").replaceChildren(...r.evidence.map((text) => el("li", { text })));
  $("reading-facts").replaceChildren(...readingFacts(r).flatMap(([k, v]) => [el("dt", { text: k }), el("dd", { text: v })]));
  $("reading-notes").replaceChildren(...r.notes.map((text) => el("li", { text })));
  $("reading").scrollIntoView({ block: "start" });
}

async function loadSignalFigure(text, query) {
  const img = $("signal-figure");
  img.dataset.state = "loading";
  $("signal-figure-note").textContent = "";
  const res = await upload("/v1/signals/upload/plot?format=png&" + query, text, "image/png, application/problem+json");
  if (img.src.startsWith("blob:")) URL.revokeObjectURL(img.src);
  if (!res.ok) {
    img.removeAttribute("src");
    img.dataset.state = "failed";
    $("signal-figure-note").textContent = "(not available: " + (await problemOf(res)).detail + ")";
    return;
  }
  img.onload = () => { img.dataset.state = "shown"; };
  img.src = URL.createObjectURL(await res.blob());
}

document.addEventListener("DOMContentLoaded", buildSignalForm);
