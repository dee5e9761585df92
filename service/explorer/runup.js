// gearchaos design explorer: a run-up (POST /v1/runups) of the design through a speed ramp,
// with progress and cancel: the server's run-up figure (GET /v1/runups/{id}/plot) and, per
// direction, where the response is chaotic, where the teeth separate and where it jumps.
// Loaded after explorer.js, whose helpers ($, el, api, readDesign, readGroup, showProblem,
// problemOf, clearErrors, fieldInput, enlarge) it uses; it adds the "Run-up" form.
"use strict";

const RUNUP_FIELDS = [
  ["from_speed", "from speed", "unit", "1000 rpm"],
  ["to_speed", "to speed", "unit", "6000 rpm"],
  ["rate", "ramp rate", "unit", "2000 rpm/s"],
  ["direction", "direction", ["up", "down", "up_down"], "up"],
  ["bin_rpm", "bin width [rpm]", "num", "100"],
];
const runupJob = new JobWatcher({
  route: "runups", prefix: "runup", cancel: "cancel-runup", unit: "ramp segments",
  onResult: (id, result) => showRunup(id, result),
});

function buildRunupForm() {
  for (const [p, label, kind, value] of RUNUP_FIELDS) {
    const f = fieldInput("runup." + p, label, kind);
    f.querySelector("input, select").value = value;
    $("runup-fields").append(f);
  }
  $("runup-form").addEventListener("submit", (ev) => { ev.preventDefault(); runUp(); });
  $("cancel-runup").addEventListener("click", () => runupJob.stop());
  $("runup-figure").addEventListener("click", () => enlarge($("runup-figure")));
}

function runupBody() {
  return { design: readDesign(), ...readGroup($("runup-fields"), "runup.") };
}

async function runUp() {
  const job = await postJob($("runup-form"), "start-runup", "/v1/runups", runupBody());
  if (!job) return;
  $("welcome").hidden = true;
  $("runup").hidden = false;
  $("runup-progress-row").hidden = false;
  $("runup-figure").removeAttribute("src");
  $("runup-figure").dataset.state = "waiting";
  $("runup-summary").replaceChildren();
  $("runup").scrollIntoView({ block: "start" });
  runupJob.start(job.id);
}

// runs of neighbouring bins where pick(bin) holds, as "1,200-1,800 rpm"
function spans(bins, pick) {
  const out = [];
  for (const b of bins) {
    const [lo, hi] = b.speed_rpm;
    const last = out[out.length - 1];
    if (!pick(b)) continue;
    if (last && Math.abs(last[1] - lo) < 1e-6 * hi) last[1] = hi;
    else if (last && Math.abs(last[0] - hi) < 1e-6 * hi) last[0] = lo; // a down branch
    else out.push([lo, hi]);
  }
  const rpm = (v) => v.toLocaleString("en-US", { maximumFractionDigits: 0 });
  return out.map(([a, b]) => `${rpm(Math.min(a, b))}-${rpm(Math.max(a, b))} rpm`).join(", ");
}

function branchLines(name, branch) {
  const bins = branch.bins;
  const chaotic = spans(bins, (b) => b.chaotic === true);
  const apart = spans(bins, (b) => b.contact === "separation" || b.contact === "both_flanks");
  const jumps = branch.jumps.map((j) => `${Math.round(j.speed_rpm).toLocaleString("en-US")} rpm `
    + `(${j.from_um.toFixed(1)} → ${j.to_um.toFixed(1)} µm)`).join(", ");
  const words = [chaotic ? `chaotic at ${chaotic}` : "never chaotic",
    apart ? `teeth separate at ${apart}` : "teeth always in contact",
    jumps ? `jumps at ${jumps}` : "no jumps"];
  return el("li", {}, el("strong", { text: `${name}: ` }),
    el("span", { text: `${words.join("; ")} (${bins.length} bins of ${branch.bins[0] ? Math.abs(bins[0].speed_rpm[1] - bins[0].speed_rpm[0]) : 0} rpm)` }));
}

async function showRunup(id, result) {
  $("runup-progress-row").hidden = true;
  const list = el("ul");
  if (result.up) list.append(branchLines("run-up", result.up));
  if (result.down) list.append(branchLines("run-down", result.down));
  const windows = result.melnikov_windows_rpm.map(([a, b]) => `${Math.round(a)}-${Math.round(b)} rpm`);
  list.append(el("li", { text: `Melnikov windows: ${windows.join(", ") || "none"}; `
    + `${result.duration_s.toFixed(2)} s of ramp` }));
  $("runup-summary").replaceChildren(list, ...result.notes.map((n) => el("p", { class: "hint", text: n })));
  const img = $("runup-figure");
  img.dataset.state = "loading";
  const res = await api("GET", `/v1/runups/${id}/plot?format=png`);
  if (!res.ok) {
    img.dataset.state = "failed";
    $("runup-summary").append(el("p", { class: "hint", text: "(figure not available: " + (await problemOf(res)).detail + ")" }));
    return;
  }
  if (img.src.startsWith("blob:")) URL.revokeObjectURL(img.src);
  img.onload = () => { img.dataset.state = "shown"; };
  img.src = URL.createObjectURL(await res.blob());
}

document.addEventListener("DOMContentLoaded", buildRunupForm);
