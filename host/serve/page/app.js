// The page of `pneumo serve` (host/serve/http_server.h lists the API). No framework: the server
// renders every image; this file sends the controls' values and shows what comes back.
"use strict";
const $ = (id) => document.getElementById(id);
// A port: its skin point on the CT as given, its target (an organ label, or a point from the scene)
// and its scope's optics; the controls show and change the selected one.
const state = { ports: [], selected: -1, yaw: 0, pitch: 0, shape: -1, viewBusy: false, viewAgain: false, solving: false };
// While the solver runs, the laparoscope's view comes at half size (a quarter of the pixels to cast)
// so the abdomen is seen moving sooner; the equilibrium's view comes at full size.
const VIEW = { w: 480, h: 360 }, MOVING_VIEW = { w: 240, h: 180 };
const OPTICS = { ins: "insertion_mm", fov: "fov_deg", oblique: "oblique_deg", roll: "roll_deg" };

function newPort(name, skin) {
  const p = { name, skin_point_mm: skin, target_label: +$("target").value || null };
  if (!p.target_label) {   // "the scene's point": the selected port's, else the first that has one
    const from = state.ports[state.selected] && state.ports[state.selected].target_mm ? state.ports[state.selected]
               : state.ports.find((q) => q.target_mm);
    if (from) p.target_mm = from.target_mm.slice();
  }
  for (const [id, key] of Object.entries(OPTICS)) p[key] = +$(id).value;
  return p;
}

function selectPort(k) {
  state.selected = k;
  const p = state.ports[k];
  state.yaw = p.yaw_deg || 0; state.pitch = p.pitch_deg || 0;   // each port keeps its dragged aim
  for (const [id, key] of Object.entries(OPTICS)) $(id).value = p[key];
  $("target").value = p.target_label !== null && p.target_label !== undefined ? p.target_label : "point";
  showOutputs(); showPorts(); refreshScope();
}

function fillTargets(labels, ports) {
  const t = $("target");
  for (const l of labels) {
    const o = document.createElement("option");
    o.value = l.id; o.textContent = l.id + (l.name ? " " + l.name : "");
    t.appendChild(o);
  }
  if (ports.some((p) => p.target_mm)) {
    const o = document.createElement("option");
    o.value = "point"; o.textContent = "the scene's point";
    t.appendChild(o);
  }
  const liver = labels.find((l) => l.id === 5);
  if (liver) t.value = 5;
}

async function post(path, body) {
  const r = await fetch(path, { method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body) });
  const j = await r.json();
  if (!r.ok) throw new Error(j.error || r.statusText);
  return j;
}

// The port as the scene writes it (its lens, up and near plane too), without the page's own keys.
function portJson(p) {
  const q = Object.assign({}, p);
  for (const k of ["name", "yaw_deg", "pitch_deg"]) delete q[k];
  if (q.target_label) delete q.target_mm; else delete q.target_label;
  return q;
}

function scopeUrl() {
  const p = state.ports[state.selected], size = state.solving ? MOVING_VIEW : VIEW;
  return "/api/scope.png?" + new URLSearchParams({ port: JSON.stringify(portJson(p)), yaw: state.yaw, pitch: state.pitch,
                                                   w: size.w, h: size.h, n: Date.now() });
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
  const ports = state.ports.map((p) => p.skin_point_mm.map((v) => v.toFixed(1)).join(",")).join(";");
  const q = { side: $("side").value, w: 480, h: 360, ports, n: Date.now() };
  if ($("heat").checked) q.heat = 1;
  $("exterior").src = "/api/exterior.png?" + new URLSearchParams(q);
}

function refreshSlices() { $("slices").src = "/api/slices.png?n=" + Date.now(); }

function showPorts() {
  const list = $("port-list");
  list.textContent = "";
  state.ports.forEach((p, k) => {
    const b = document.createElement("button");
    b.textContent = p.name;
    b.className = k === state.selected ? "selected" : "";
    b.onclick = () => selectPort(k);
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
    state.solving = s.solving;
    if (s.shape !== state.shape) {   // a new shape: the views again
      state.shape = s.shape;
      refreshScope(); refreshExterior();
    } else if (state.wasSolving && !s.solving) refreshScope();   // the equilibrium's view at full size
    if (state.wasSolving !== false && !s.solving) refreshSlices();   // the slices once per equilibrium
    state.wasSolving = s.solving;
    $("plan-status").textContent = s.plan.state === "none" ? "" :
      s.plan.state === "done" ? "report ready" : "report: " + s.plan.state;
    if (s.plan.state === "done" && !$("plan-status").querySelector("a")) {
      const a = document.createElement("a");
      a.href = "/plan/report.html"; a.target = "_blank"; a.textContent = " open";
      $("plan-status").appendChild(a);
    }
    if (state.first === undefined) {   // the scene's settings, labels and ports to start from
      const r = await fetch("/api/case");
      if (!r.ok) throw new Error(r.statusText);
      const c = await r.json();
      state.first = true;
      $("pressure").value = s.target_pressure_mmhg; $("wall").value = s.wall_young_kpa;
      if (s.preset !== "none") $("preset").value = s.preset;
      fillTargets(c.labels, c.ports);
      state.ports = c.ports.map((p) => Object.assign({ target_label: null }, p));
      showOutputs(); showPorts();
      if (state.ports.length) selectPort(0);
    }
  } catch (e) { setStatus("the server does not answer", true); }
  setTimeout(poll, state.solving ? 100 : 400);   // closely while the shape moves
}

function showOutputs() {
  $("pressure-out").textContent = $("pressure").value; $("wall-out").textContent = $("wall").value;
  $("roll-out").textContent = $("roll").value; $("fov-out").textContent = $("fov").value; $("ins-out").textContent = $("ins").value;
}

// Natural-pixel coordinates of a mouse event on the body's view.
function onImage(ev) {
  const img = $("exterior"), r = img.getBoundingClientRect();
  return { x: (ev.clientX - r.left) * img.naturalWidth / r.width, y: (ev.clientY - r.top) * img.naturalHeight / r.height,
           r, img };
}

// Dragging on the body paints a rectangle to rank the ports within; a click without a drag places
// a port.
let paint = null;
$("exterior").addEventListener("mousedown", (ev) => { paint = { start: onImage(ev), moved: false }; ev.preventDefault(); });
window.addEventListener("mousemove", (ev) => {
  if (!paint) return;
  const p = onImage(ev), a = paint.start;
  if (Math.hypot(p.x - a.x, p.y - a.y) < 6 && !paint.moved) return;
  paint.moved = true;
  const box = $("region"), k = p.r.width / p.img.naturalWidth;
  Object.assign(box.style, { left: Math.min(a.x, p.x) * k + "px", top: Math.min(a.y, p.y) * k + "px",
                             width: Math.abs(p.x - a.x) * k + "px", height: Math.abs(p.y - a.y) * k + "px" });
  box.hidden = false;
  state.region = { side: $("side").value, w: p.img.naturalWidth, h: p.img.naturalHeight, x0: a.x, y0: a.y, x1: p.x, y1: p.y };
});
window.addEventListener("mouseup", (ev) => {
  if (paint && paint.moved) {
    $("clear-region").hidden = false;
    if (ev.target === $("exterior")) state.justPainted = true;   // the click that follows ends the drag
  }
  paint = null;
});
function clearRegion() { state.region = null; $("region").hidden = true; $("clear-region").hidden = true; }
$("clear-region").addEventListener("click", clearRegion);

$("exterior").addEventListener("click", async (ev) => {
  if (state.justPainted) { state.justPainted = false; return; }   // the end of a drag, not a click
  const { x, y, img } = onImage(ev);
  try {
    const j = await post("/api/pick", { x, y, side: $("side").value, w: img.naturalWidth, h: img.naturalHeight });
    if (!j.skin_point_mm) { setStatus("no skin under that point", true); return; }
    state.ports.push(newPort("port " + (state.ports.length + 1), j.skin_point_mm));
    selectPort(state.ports.length - 1);
    refreshExterior();
  } catch (e) { setStatus(e.message, true); }
});

let drag = null;
$("scope").addEventListener("mousedown", (ev) => { drag = { x: ev.clientX, y: ev.clientY, yaw: state.yaw, pitch: state.pitch }; });
window.addEventListener("mouseup", () => { drag = null; });
window.addEventListener("mousemove", (ev) => {
  if (!drag) return;
  state.yaw = Math.max(-180, Math.min(180, drag.yaw - (ev.clientX - drag.x) * 0.3));
  state.pitch = Math.max(-89, Math.min(89, drag.pitch + (ev.clientY - drag.y) * 0.3));
  if (state.selected >= 0) Object.assign(state.ports[state.selected], { yaw_deg: state.yaw, pitch_deg: state.pitch });
  refreshScope();
});

for (const id of ["pressure", "wall"]) $(id).addEventListener("input", showOutputs);
$("pressure").addEventListener("change", () => inflate({ pressure_mmhg: +$("pressure").value }));
$("wall").addEventListener("change", () => inflate({ wall_young_kpa: +$("wall").value }));
$("preset").addEventListener("change", () => inflate({ preset: $("preset").value }));
$("refine").addEventListener("click", () => { $("preset").value = "balanced"; inflate({ preset: "balanced" }); });
// The optics and the target belong to the selected port.
for (const [id, key] of Object.entries(OPTICS))
  $(id).addEventListener("input", () => {
    if (state.selected >= 0) state.ports[state.selected][key] = +$(id).value;
    showOutputs(); refreshScope();
  });
$("target").addEventListener("change", () => {
  if (state.selected < 0 || $("target").value === "point") return;
  state.ports[state.selected].target_label = +$("target").value;
  refreshScope();
});
$("side").addEventListener("change", () => { clearRegion(); refreshExterior(); });
$("heat").addEventListener("change", refreshExterior);
// Port ranking (docs/ports.md): the target's candidates on the skin, scored; the best listed, each
// placed as a port by a click.
$("rank").addEventListener("click", async () => {
  const target = +$("target").value;
  if (!target) { setStatus("choose an organ as the target first", true); return; }
  $("rank").disabled = true;
  try {
    const t = await post("/api/ports", { target_label: target, ports: state.ports.map((p) => p.skin_point_mm), top: 5,
                                         region: state.region || null });
    const list = $("ranked");
    list.textContent = "";
    for (const c of t.candidates.filter((c) => c.feasible && c.skin_point_mm)) {
      const li = document.createElement("li");
      li.textContent = `score ${c.score.toFixed(2)}: sees ${(100 * c.visible_fraction).toFixed(0)} %, ` +
                       `${c.skin_to_target_mm.toFixed(0)} mm to the target`;
      li.onclick = () => {
        const p = newPort("port " + (state.ports.length + 1), c.skin_point_mm);
        // The ranked path: to the organ's centroid, or to the exposed point it was re-aimed at.
        if (c.reaimed && c.aim_mm) { p.target_label = null; p.target_mm = c.aim_mm; }
        else { p.target_label = target; delete p.target_mm; }
        state.ports.push(p);
        selectPort(state.ports.length - 1);
        refreshExterior();
      };
      list.appendChild(li);
    }
    if (!list.children.length)
      setStatus(`no port ${state.region ? "in the region " : ""}reaches ${t.target.name}: every path meets an organ or no gas`, true);
    $("heat").disabled = false;
    $("heat").checked = true;
    refreshExterior();
  } catch (e) { setStatus(e.message, true); }
  $("rank").disabled = false;
});
$("plan").addEventListener("click", async () => {
  if (!state.ports.length) { setStatus("place a port on the skin first", true); return; }
  // Each port as the scene writes it (from /api/case, or placed here), its dragged aim beside it:
  // the server reads it as a scene's port and turns the aim into a target point.
  const ports = state.ports.map((p) => Object.assign(portJson(p), { yaw_deg: p.yaw_deg || 0, pitch_deg: p.pitch_deg || 0 }));
  try { await post("/api/plan", { ports }); } catch (e) { setStatus(e.message, true); }
});
poll();
