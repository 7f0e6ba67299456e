// The page of `pneumo serve` (host/serve/http_server.h lists the API). No framework: the server
// renders every image; this file sends the controls' values and shows what comes back.
"use strict";
const $ = (id) => document.getElementById(id);
const state = { ports: [], selected: -1, yaw: 0, pitch: 0, shape: -1, viewBusy: false, viewAgain: false };

async function post(path, body) {
  const r = await fetch(path, { method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body) });
  const j = await r.json();
  if (!r.ok) throw new Error(j.error || r.statusText);
  return j;
}

function scopeUrl() {
  const p = state.ports[state.selected];
  const q = new URLSearchParams({
    sx: p[0], sy: p[1], sz: p[2], label: $("target").value, ins: $("ins").value, fov: $("fov").value,
    obl: $("oblique").value, roll: $("roll").value, yaw: state.yaw, pitch: state.pitch, w: 480, h: 360,
    n: Date.now() });
  return "/api/scope.png?" + q;
}

// One view request at a time; a change meanwhile asks again once it is back (latest wins).
function refreshScope() {
  if (state.selected < 0) return;
  if (state.viewBusy) { state.viewAgain = true; return; }
  state.viewBusy = true;
  const img = $("scope");
  const done = () => { state.viewBusy = false; if (state.viewAgain) { state.viewAgain = false; refreshScope(); } };
  img.onload = done;
  img.onerror = done;
  img.src = scopeUrl();
}

function refreshExterior() {
  const ports = state.ports.map((p) => p.map((v) => v.toFixed(1)).join(",")).join(";");
  $("exterior").src = "/api/exterior.png?" + new URLSearchParams({ side: $("side").value, w: 480, h: 360, ports, n: Date.now() });
}

function refreshSlices() { $("slices").src = "/api/slices.png?n=" + Date.now(); }

function showPorts() {
  const list = $("port-list");
  list.textContent = "";
  state.ports.forEach((p, k) => {
    const b = document.createElement("button");
    b.textContent = "port " + (k + 1);
    b.className = k === state.selected ? "selected" : "";
    b.onclick = () => { state.selected = k; state.yaw = 0; state.pitch = 0; showPorts(); refreshScope(); };
    list.appendChild(b);
  });
}

// Only the control that changed is sent: the others stay as the server has them (a slider's step
// must not round the scene's own stiffness into another one).
async function inflate(change) {
  try { await post("/api/inflate", change); } catch (e) { setStatus(e.message, true); }
}

function setStatus(text, error) { $("status").textContent = text; $("status").className = error ? "error" : ""; }

async function poll() {
  try {
    const r = await fetch("/api/status");
    if (!r.ok) throw new Error(r.statusText);
    const s = await r.json();
    let text = s.solving ? `solving: step ${s.step}, ${(+s.pressure_mmhg).toFixed(1)} of ${s.target_pressure_mmhg} mmHg, ${(+s.seconds || 0).toFixed(1)} s`
                         : `${s.converged ? "converged" : "not converged"} at ${(+s.pressure_mmhg).toFixed(1)} mmHg`;
    if (!s.solving && s.anterior_rise_mm !== undefined)
      text += `: rise ${s.anterior_rise_mm.toFixed(1)} mm, cavity ${s.cavity_volume_ml.toFixed(0)} ml`;
    text += ` (${s.preset}, ${s.tetrahedra} tetrahedra)`;
    setStatus(s.error ? "error: " + s.error : text, !!s.error);
    if (s.shape !== state.shape) {   // a new shape: the views again
      state.shape = s.shape;
      refreshScope(); refreshExterior();
    }
    if (state.wasSolving !== false && !s.solving) refreshSlices();   // the slices once per equilibrium
    state.wasSolving = s.solving;
    $("plan-status").textContent = s.plan.state === "none" ? "" :
      s.plan.state === "done" ? "report ready" : "report: " + s.plan.state;
    if (s.plan.state === "done" && !$("plan-status").querySelector("a")) {
      const a = document.createElement("a");
      a.href = "/plan/report.html"; a.target = "_blank"; a.textContent = " open";
      $("plan-status").appendChild(a);
    }
    if (state.first === undefined) {
      state.first = true;
      $("pressure").value = s.target_pressure_mmhg; $("wall").value = s.wall_young_kpa;
      if (s.preset !== "none") $("preset").value = s.preset;
      showOutputs();
    }
  } catch (e) { setStatus("the server does not answer", true); }
  setTimeout(poll, 400);
}

function showOutputs() {
  $("pressure-out").textContent = $("pressure").value; $("wall-out").textContent = $("wall").value;
  $("roll-out").textContent = $("roll").value; $("fov-out").textContent = $("fov").value; $("ins-out").textContent = $("ins").value;
}

$("exterior").addEventListener("click", async (ev) => {
  const img = ev.target, r = img.getBoundingClientRect();
  const x = (ev.clientX - r.left) * img.naturalWidth / r.width, y = (ev.clientY - r.top) * img.naturalHeight / r.height;
  try {
    const j = await post("/api/pick", { x, y, side: $("side").value, w: img.naturalWidth, h: img.naturalHeight });
    if (!j.skin_point_mm) { setStatus("no skin under that point", true); return; }
    state.ports.push(j.skin_point_mm);
    state.selected = state.ports.length - 1; state.yaw = 0; state.pitch = 0;
    showPorts(); refreshScope(); refreshExterior();
  } catch (e) { setStatus(e.message, true); }
});

let drag = null;
$("scope").addEventListener("mousedown", (ev) => { drag = { x: ev.clientX, y: ev.clientY, yaw: state.yaw, pitch: state.pitch }; });
window.addEventListener("mouseup", () => { drag = null; });
window.addEventListener("mousemove", (ev) => {
  if (!drag) return;
  state.yaw = Math.max(-180, Math.min(180, drag.yaw - (ev.clientX - drag.x) * 0.3));
  state.pitch = Math.max(-89, Math.min(89, drag.pitch + (ev.clientY - drag.y) * 0.3));
  refreshScope();
});

for (const id of ["pressure", "wall"]) $(id).addEventListener("input", showOutputs);
$("pressure").addEventListener("change", () => inflate({ pressure_mmhg: +$("pressure").value }));
$("wall").addEventListener("change", () => inflate({ wall_young_kpa: +$("wall").value }));
$("preset").addEventListener("change", () => inflate({ preset: $("preset").value }));
$("refine").addEventListener("click", () => { $("preset").value = "balanced"; inflate({ preset: "balanced" }); });
for (const id of ["roll", "fov", "ins"]) $(id).addEventListener("input", () => { showOutputs(); refreshScope(); });
for (const id of ["oblique", "target"]) $(id).addEventListener("change", refreshScope);
$("side").addEventListener("change", refreshExterior);
$("plan").addEventListener("click", async () => {
  if (!state.ports.length) { setStatus("place a port on the skin first", true); return; }
  const ports = state.ports.map((p) => ({ skin_point_mm: p, target_label: +$("target").value, insertion_mm: +$("ins").value,
                                          fov_deg: +$("fov").value, oblique_deg: +$("oblique").value, roll_deg: +$("roll").value }));
  try { await post("/api/plan", { ports }); } catch (e) { setStatus(e.message, true); }
});
poll();
