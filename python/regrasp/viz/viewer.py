"""An interactive 3-D view of a 3-D plan in the browser: one self-contained HTML page (no
network, no libraries) with the object, the finger pads and the active pusher's contacts, drawn
on a canvas with flat shading; drag to orbit, wheel to zoom, a slider and a play button to move
along the plan (poses interpolated by slerp between knots)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..files import write_text
from ..planning.plan import as_plan

PAGE = r"""<!doctype html>
<html><head><meta charset="utf-8"><title>regrasp: __TITLE__</title>
<style>
body{font-family:system-ui,sans-serif;margin:0;background:#f4f4f4}
#bar{padding:8px;display:flex;gap:10px;align-items:center}
canvas{background:#fff;display:block;margin:0 8px;border:1px solid #ccc}
#info{font-size:13px;color:#333}
</style></head><body>
<div id="bar"><button id="play">play</button><input id="t" type="range" min="0" max="1000" value="0" style="width:50%">
<span id="info"></span></div>
<canvas id="c" width="900" height="620"></canvas>
<script id="data" type="application/json">__DATA__</script>
<script>
"use strict";
const D = JSON.parse(document.getElementById("data").textContent);
const cv = document.getElementById("c"), ctx = cv.getContext("2d");
const slider = document.getElementById("t"), info = document.getElementById("info");
let yaw = 0.6, pitch = 0.35, zoom = 1.0, playing = false, drawn = 0;
function qmul(a, b) { return [a[0]*b[0]-a[1]*b[1]-a[2]*b[2]-a[3]*b[3], a[0]*b[1]+a[1]*b[0]+a[2]*b[3]-a[3]*b[2],
  a[0]*b[2]-a[1]*b[3]+a[2]*b[0]+a[3]*b[1], a[0]*b[3]+a[1]*b[2]-a[2]*b[1]+a[3]*b[0]]; }
function qrot(q, v) { const p = qmul(qmul(q, [0, v[0], v[1], v[2]]), [q[0], -q[1], -q[2], -q[3]]); return [p[1], p[2], p[3]]; }
function slerp(a, b, t) {
  let d = a[0]*b[0]+a[1]*b[1]+a[2]*b[2]+a[3]*b[3]; if (d < 0) { b = b.map(x => -x); d = -d; }
  if (d > 0.9995) { const r = a.map((x, i) => x + t*(b[i]-x)); const n = Math.hypot(...r); return r.map(x => x/n); }
  const th = Math.acos(d), s = Math.sin(th);
  return a.map((x, i) => (Math.sin((1-t)*th)*x + Math.sin(t*th)*b[i]) / s);
}
function poseAt(u) {  // u in [0, 1] along the plan
  const n = D.poses.length - 1; if (n <= 0) return [D.poses[0], 0];
  const f = Math.min(u * n, n - 1e-9), k = Math.floor(f), t = f - k, a = D.poses[k], b = D.poses[k+1];
  const p = [0,1,2].map(i => a[i] + t*(b[i]-a[i]));
  return [p.concat(slerp(a.slice(3), b.slice(3), t)), k + 1];
}
function view(v) {  // gripper frame -> camera (orbit), then perspective
  const cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
  let x = cy*v[0] + sy*v[1], y = -sy*v[0] + cy*v[1], z = v[2];
  const y2 = cp*y - sp*z, z2 = sp*y + cp*z;
  const dist = 4 * D.size, s = 0.3 * cv.height * zoom * dist / (dist + y2) / D.size;
  return [cv.width/2 + x*s, cv.height/2 - z2*s, y2];
}
function draw() {
  const u = slider.value / 1000, [q, step] = poseAt(u);
  const pos = q.slice(0, 3), rot = q.slice(3);
  const world = D.vertices.map(v => { const r = qrot(rot, v); return [r[0]+pos[0], r[1]+pos[1], r[2]+pos[2]]; });
  const tris = [];
  const light = [0.3, -0.5, 0.8];
  for (const [i, t] of D.triangles.entries()) {
    const a = world[t[0]], b = world[t[1]], c = world[t[2]];
    const e1 = [b[0]-a[0], b[1]-a[1], b[2]-a[2]], e2 = [c[0]-a[0], c[1]-a[1], c[2]-a[2]];
    const n = [e1[1]*e2[2]-e1[2]*e2[1], e1[2]*e2[0]-e1[0]*e2[2], e1[0]*e2[1]-e1[1]*e2[0]];
    const nn = Math.hypot(...n) || 1, sh = Math.max(0.15, (n[0]*light[0]+n[1]*light[1]+n[2]*light[2]) / nn);
    // a convex object: only the faces turned towards the camera (depth axis y2, camera at -y2)
    const cy = Math.cos(yaw), sy = Math.sin(yaw), ny = -sy*n[0] + cy*n[1];
    if (Math.cos(pitch)*ny - Math.sin(pitch)*n[2] > 0) continue;
    const P = [a, b, c].map(view);
    const col = D.marks[i] ? `rgb(${Math.round(140+110*sh)},${Math.round(90+90*sh)},${Math.round(30+40*sh)})`
                           : `rgb(${Math.round(90+120*sh)},${Math.round(110+110*sh)},${Math.round(140+100*sh)})`;
    tris.push([P, (P[0][2]+P[1][2]+P[2][2]) / 3, col]);
  }
  // the pads: discs at the gripper's +-Y extremes of the object
  const pads = [];
  for (const sgn of [1, -1]) {
    let top = -1e9; for (const w of world) top = Math.max(top, sgn*w[1]);
    const ring = []; for (let k = 0; k < 24; k++) { const a = 2*Math.PI*k/24; ring.push(view([D.pad*Math.cos(a), sgn*top, D.pad*Math.sin(a)])); }
    // a pad on the object's near side is drawn over it, one on the far side is hidden by it
    const facing = Math.cos(pitch)*(Math.cos(yaw)*sgn) < 0;
    pads.push([ring, facing]);
  }
  tris.sort((x, y) => y[1] - x[1]);
  ctx.clearRect(0, 0, cv.width, cv.height);
  drawn = 0;
  const poly = (pts, fill, stroke) => {
    ctx.beginPath(); ctx.moveTo(pts[0][0], pts[0][1]); for (const p of pts.slice(1)) ctx.lineTo(p[0], p[1]);
    ctx.closePath(); ctx.fillStyle = fill; ctx.fill(); ctx.strokeStyle = stroke; ctx.stroke(); drawn++;
  };
  for (const [ring, facing] of pads) if (!facing) poly(ring, "rgba(60,60,60,0.55)", "rgba(0,0,0,0.3)");
  for (const t of tris) poly(t[0], t[2], t[2]);
  for (const [ring, facing] of pads) if (facing) poly(ring, "rgba(60,60,60,0.55)", "rgba(0,0,0,0.3)");
  // the pusher of the current step: its contact points, moving with the object
  const name = D.pushers_of_steps[Math.min(step, D.pushers_of_steps.length - 1)];
  // (a plane touches the object where it is lowest along its normal, given in the gripper frame)
  let contacts = [];
  if (name && D.planes[name]) {
    const n = D.planes[name], dot = p => p[0]*n[0] + p[1]*n[1] + p[2]*n[2];
    if (D.sphere) contacts = [[pos[0] - D.sphere*n[0], pos[1] - D.sphere*n[1], pos[2] - D.sphere*n[2]]];
    else { const lo = Math.min(...world.map(dot)); contacts = world.filter(p => dot(p) < lo + 1e-6*D.size); }
    // the plane itself: a square around the contact
    const c = contacts[0], a = Math.abs(n[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0];
    let t1 = [n[1]*a[2]-n[2]*a[1], n[2]*a[0]-n[0]*a[2], n[0]*a[1]-n[1]*a[0]];
    const l = Math.hypot(...t1); t1 = t1.map(x => x / l);
    const t2 = [n[1]*t1[2]-n[2]*t1[1], n[2]*t1[0]-n[0]*t1[2], n[0]*t1[1]-n[1]*t1[0]], h = 1.3 * D.size;
    const sq = [[1, 1], [-1, 1], [-1, -1], [1, -1]].map(([i, j]) => view([0, 1, 2].map(k => c[k] + h*(i*t1[k] + j*t2[k]))));
    poly(sq, "rgba(214,39,40,0.12)", "rgba(214,39,40,0.5)");
  } else if (name && D.pusher_points[name]) {
    contacts = D.pusher_points[name].map(pnt => { const r = qrot(rot, pnt); return [r[0]+pos[0], r[1]+pos[1], r[2]+pos[2]]; });
  }
  ctx.fillStyle = "#d62728";
  for (const pnt of contacts) {
    const P = view(pnt);
    ctx.beginPath(); ctx.arc(P[0], P[1], 5, 0, 2*Math.PI); ctx.fill();
  }
  info.textContent = `${D.name}: step ${step} of ${D.poses.length - 1}` + (name ? `, pusher ${name}` : "") +
    ` — position [${pos.map(x => (1000*x).toFixed(1)).join(", ")}] mm`;
}
let drag = null;
cv.addEventListener("mousedown", e => { drag = [e.clientX, e.clientY]; });
window.addEventListener("mouseup", () => { drag = null; });
window.addEventListener("mousemove", e => { if (!drag) return; yaw += (e.clientX - drag[0]) * 0.01;
  pitch = Math.max(-1.5, Math.min(1.5, pitch + (e.clientY - drag[1]) * 0.01)); drag = [e.clientX, e.clientY]; draw(); });
cv.addEventListener("wheel", e => { e.preventDefault(); zoom *= e.deltaY < 0 ? 1.1 : 1/1.1; draw(); });
slider.addEventListener("input", draw);
document.getElementById("play").addEventListener("click", () => { playing = !playing; if (playing) tick(); });
function tick() { if (!playing) return; slider.value = (Number(slider.value) + 5) % 1001; draw(); requestAnimationFrame(tick); }
draw();
window.regraspViewer = { draw, poseAt, drawn: () => drawn, setT: v => { slider.value = v; draw(); } };
if (typeof location !== "undefined" && location.hash === "#selftest") {  // for tests in a headless browser: walk the plan, report
  const frames = [];
  for (const t of [0, 250, 500, 750, 1000]) {
    slider.value = t; draw();
    const [q] = poseAt(t / 1000);
    const px = ctx.getImageData(0, 0, cv.width, cv.height).data;
    let ink = 0; for (let i = 3; i < px.length; i += 4) if (px[i] > 0) ink++;
    frames.push({ t, drawn, ink, pose: q, info: info.textContent });
  }
  yaw += 1.0; draw(); yaw -= 1.0;
  const out = document.createElement("pre"); out.id = "selftest";
  out.textContent = JSON.stringify({ triangles: D.triangles.length, frames });
  document.body.appendChild(out);
  slider.value = 500; draw();
}
</script></body></html>
"""


def marks(scene) -> np.ndarray:
    """Which of the object's triangles are painted (1) — a sphere's alternate octants, so its
    turning shows (the thesis' paint marks on the ball, Fig 4-8); none for other objects."""
    v, t = scene.mesh()
    if not scene._core.sphere:
        return np.zeros(len(t), int)
    c = np.asarray(v, float)[np.asarray(t, int)].mean(axis=1)
    return (np.prod(np.sign(c + 1e-12), axis=1) > 0).astype(int)


def page(scene, plan) -> str:
    """The HTML page of ``plan`` (a 3-D :class:`~regrasp.Plan` or plan dict) for ``scene`` (a Scene3D)."""
    plan = as_plan(plan, scene)
    v, t = scene.mesh()
    v = np.asarray(v, float)
    size = float(np.linalg.norm(v, axis=1).max())
    data = {
        "name": scene.name,
        "vertices": v.tolist(),
        "triangles": np.asarray(t, int).tolist(),
        "poses": plan.poses.tolist(),
        "pushers_of_steps": plan.pushers,
        "pusher_points": {n: np.asarray(scene._core.pusher_points(n), float).tolist() for n in scene.pusher_names},
        # plane pushers: their normals (gripper frame); the page finds where they touch
        "planes": {n: np.asarray(scene._core.pusher_normal(n), float).tolist() for n in scene.pusher_names
                   if scene._core.is_plane(n)},
        "sphere": scene._core.sphere,
        "marks": marks(scene).tolist(),
        "pad": float(scene._core.pad_radius),
        "size": size,
    }
    text = json.dumps(data).replace("</", "<\\/")
    import html

    return PAGE.replace("__TITLE__", html.escape(scene.name)).replace("__DATA__", text)


def write_html(scene, plan, path) -> Path:
    """Writes the view of ``plan`` in ``scene`` as one self-contained HTML page at ``path``
    (atomically); returns the path."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    return write_text(p, page(scene, plan))
