// gearchaos design explorer: the probability map of a robustness study (POST /v1/robustness)
// over the envelope form's speed x torque grid, with progress and cancel. Loaded after
// explorer.js, whose helpers ($, el, api, readDesign, readGroup, showProblem, problemOf,
// clearErrors, fieldInput, loadPlotly) it uses; it adds the "Manufacturing tolerances" form.
"use strict";

const ROBUSTNESS_FIELDS = [
  ["class", "ISO 1328 class (1-11)", "int", "7"],
  ["backlash_min", "backlash band from", "unit", "80 um"],
  ["backlash_max", "backlash band to", "unit", "120 um"],
  ["samples", "samples (power of 2)", "int", "32"],
];
const PROBABILITIES = [
  ["chaotic", "P(chaotic)"], ["separation", "P(tooth separation)"], ["back_flank", "P(back-flank impacts)"],
];
const studyJob = new JobWatcher({
  route: "robustness", prefix: "robustness", cancel: "cancel-study", unit: "runs (samples × points)",
  onResult: (id, result) => drawProbabilities(result),
});

function buildRobustnessForm() {
  for (const [p, label, kind, value] of ROBUSTNESS_FIELDS) {
    const f = fieldInput("robustness." + p, label, kind);
    f.querySelector("input").value = value;
    $("robustness-fields").append(f);
  }
  for (const [name, label] of PROBABILITIES) $("robustness-output").append(el("option", { value: name, text: label }));
  $("robustness-form").addEventListener("submit", (ev) => { ev.preventDefault(); studyRange(); });
  $("cancel-study").addEventListener("click", () => studyJob.stop());
  $("robustness-output").addEventListener("change", () => studyJob.job && studyJob.job.result && drawProbabilities(studyJob.job.result));
}

function studyBody() {
  const r = readGroup($("robustness-fields"), "robustness.");
  const env = readGroup($("envelope-fields"), "envelope.");
  const tolerances = {};
  if (r.class !== undefined) tolerances.accuracy = { standard: "ISO 1328-1:2013", class: r.class };
  if (r.backlash_min !== undefined || r.backlash_max !== undefined) {
    tolerances.backlash = { min: r.backlash_min, max: r.backlash_max };
  }
  const axes = [{ parameter: "speed", ...env.axes[0] }, { parameter: "torque", ...env.axes[1] }];
  return { design: { ...readDesign(), tolerances }, axes, settings: env.settings, samples: r.samples };
}

async function studyRange() {
  // the tolerances' errors (by path, or a design-level check naming them) are this form's;
  // the rest belong to the design form
  const mine = (e) => e.path.startsWith("design.tolerances") || e.message.includes("tolerances.")
    || !e.path.startsWith("design");
  const job = await postJob($("robustness-form"), "study-range", "/v1/robustness", studyBody(), mine);
  if (!job) return;
  $("welcome").hidden = true;
  $("robustness").hidden = false;
  $("robustness-progress-row").hidden = false;
  $("robustness-map").replaceChildren();
  $("robustness").scrollIntoView({ block: "start" });
  studyJob.start(job.id);
}

async function drawProbabilities(result) {
  const Plotly = await loadPlotly();
  $("robustness-progress-row").hidden = true;
  const name = $("robustness-output").value;
  const xs = [...new Set(result.points.map((p) => p.shown.speed))].sort((a, b) => a - b);
  const ys = [...new Set(result.points.map((p) => p.shown.torque))].sort((a, b) => a - b);
  const at = (x, y) => result.points.find((p) => p.shown.speed === x && p.shown.torque === y);
  const prob = (x, y) => at(x, y).probabilities[name];
  const trace = {
    type: "heatmap", x: xs, y: ys, zmin: 0, zmax: 1,
    colorscale: [[0, "#ffffcc"], [0.5, "#fd8d3c"], [1, "#800026"]], // 0: pale, 1: dark red
    z: ys.map((y) => xs.map((x) => prob(x, y).value)),
    customdata: ys.map((y) => xs.map((x) => {
      const p = prob(x, y);
      return [p.interval[0].toFixed(3), p.interval[1].toFixed(3), p.count, p.samples];
    })),
    hovertemplate: "speed %{x:,.0f} rpm<br>torque %{y:,.1f} N·m<br>probability %{z:.3f}"
      + "<br>95 % interval [%{customdata[0]}, %{customdata[1]}]<br>%{customdata[2]} of %{customdata[3]} samples<extra></extra>",
    colorbar: { title: { text: "probability" } },
  };
  const layout = {
    margin: { l: 60, r: 10, t: 10, b: 50 }, height: 420,
    xaxis: { title: { text: "driver speed [rpm]" } }, yaxis: { title: { text: "driver torque [N·m]" } },
  };
  await Plotly.newPlot($("robustness-map"), [trace], layout, { displaylogo: false, responsive: true });
}

document.addEventListener("DOMContentLoaded", buildRobustnessForm);
