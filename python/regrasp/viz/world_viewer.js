"use strict";
// The regrasp world view: draws the data of viz/world_data.py on a 2-D canvas (painter's
// algorithm, flat shading) in the world frame: table, features, robot base, world axes, and for a
// world motion the gripper holding the object along the motion's times, its path by label, and
// the arm's bodies (their convex shapes) where the joint trajectory puts them.
const D = JSON.parse(document.getElementById("data").textContent);
const SELFTEST = typeof location !== "undefined" && location.hash === "#selftest";  // tests read the canvas back
const cv = document.getElementById("c"), ctx = cv.getContext("2d", { willReadFrequently: SELFTEST });
const slider = document.getElementById("t"), info = document.getElementById("info"), strip = document.getElementById("strip");
const speedBox = document.getElementById("speed"), playBtn = document.getElementById("play"), followBox = document.getElementById("follow");
const S = D.samples, N = S.times.length, T = S.times[N - 1];
let yaw = -0.9, pitch = 0.45, zoom = 1.0, playing = false, drawn = 0, W = cv.width, H = cv.height, lastFrame = null;
function lerpPose(a, b, u) {
  if (a === null || b === null) return a;
  return [0, 1, 2].map(i => a[i] + u*(b[i]-a[i])).concat(slerp(a.slice(3), b.slice(3), u));
}
function stateAt(t) {  // the motion at time t [s]: poses interpolated, the sample reached next (its label, push)
  t = Math.max(0, Math.min(T, t));
  let lo = 0, hi = N - 1;  // the first sample at or after t
  while (lo < hi) { const m = (lo + hi) >> 1; if (S.times[m] < t) lo = m + 1; else hi = m; }
  const k = lo, j = Math.max(0, k - 1), span = S.times[k] - S.times[j], u = span > 0 ? (t - S.times[j]) / span : 1;
  return { t, sample: k, index: span > 0 ? j + u : k, gripper: lerpPose(S.gripper[j], S.gripper[k], u),
           object: lerpPose(S.object[j], S.object[k], u), label: S.labels[k], push: S.push[k] };
}
const place = (q, pts) => { const r = q.slice(3), n = Math.hypot(...r), u = r.map(x => x / n);
  return pts.map(v => add(qrot(u, v), q)); };
let C = D.center, E = D.extent;
function view(v) {  // world -> camera (orbit about z), then perspective; CSS pixels and depth
  const cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
  const x = cy*(v[0]-C[0]) + sy*(v[1]-C[1]), y = -sy*(v[0]-C[0]) + cy*(v[1]-C[1]), z = v[2] - C[2];
  const y2 = cp*y - sp*z, z2 = sp*y + cp*z;
  const dist = 5 * E, s = 0.38 * Math.min(W, 1.2 * H) * zoom * dist / Math.max(dist + y2, 0.05 * dist) / E;
  return [W/2 + x*s, H/2 - z2*s, y2];
}
const towardsCamera = n => { const ny = -Math.sin(yaw)*n[0] + Math.cos(yaw)*n[1];
  return Math.cos(pitch)*ny - Math.sin(pitch)*n[2] < 0; };
const shadeOf = n => Math.max(0.15, dot(n, [0.3, -0.5, 0.8]) / (Math.hypot(...n) || 1));
const rgb = (c, sh, a) => `rgba(${c.map(x => Math.round(x * (0.45 + 0.55*sh))).join(",")},${a})`;
const COLOURS = { table: [200, 170, 130], feature: [160, 165, 180], active: [230, 40, 40], near: [240, 150, 60],
                  robot: [255, 180, 60], object: [150, 190, 240], painted: [250, 180, 70], jaw: [110, 110, 120],
                  arm: [95, 120, 165] };
const LABEL_COLOURS = { start: "#888888", transfer: "#888888", approach: "#1f77b4", push: "#d62728", retreat: "#2ca02c" };
function mesh(out, world, tris, colour, alpha, kind) {  // front faces of a closed mesh, for depth sorting
  for (const [i, t] of tris.entries()) {
    const a = world[t[0]], b = world[t[1]], c = world[t[2]], n = cross(sub(b, a), sub(c, a));
    if (!towardsCamera(n)) continue;
    const P = [a, b, c].map(view), col = typeof colour === "function" ? colour(i) : colour;
    out.push({ P, depth: (P[0][2]+P[1][2]+P[2][2]) / 3, fill: rgb(col, shadeOf(n), alpha), kind });
  }
}
const BOX = [[0,2,1],[0,3,2],[4,5,6],[4,6,7],[0,1,5],[0,5,4],[2,3,7],[2,7,6],[1,2,6],[1,6,5],[0,4,7],[0,7,3]];
function box(lo, hi) { const v = []; for (const z of [lo[2], hi[2]])
  for (const [x, y] of [[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]]) v.push([x, y, z]); return v; }
function jawParts() {  // the jaws in the gripper frame: two fingers at the object's extremes along y, the palm
  const J = D.gripper, th = J.thickness, b = J.breadth;
  return [box([-b, J.top, -b], [b, J.top + th, J.palm_z]), box([-b, J.bot - th, -b], [b, J.bot, J.palm_z]),
          box([-b, J.bot - th, J.palm_z], [b, J.top + th, J.palm_z + th])];
}
function poly(pts, fill, stroke) {
  ctx.beginPath(); ctx.moveTo(pts[0][0], pts[0][1]); for (const p of pts.slice(1)) ctx.lineTo(p[0], p[1]);
  ctx.closePath(); ctx.fillStyle = fill; ctx.fill(); if (stroke) { ctx.strokeStyle = stroke; ctx.stroke(); }
  drawn++;
}
function line(a, b, colour, width) {
  const A = view(a), B = view(b);
  ctx.beginPath(); ctx.moveTo(A[0], A[1]); ctx.lineTo(B[0], B[1]);
  ctx.strokeStyle = colour; ctx.lineWidth = width || 1; ctx.stroke(); ctx.lineWidth = 1;
  return B;
}
function label(p, text, colour) { const P = view(p); ctx.fillStyle = colour; ctx.font = "bold 13px sans-serif"; ctx.fillText(text, P[0] + 4, P[1] - 4); }
function frameAxis(f, i) { return qrot(f.slice(3), [0, 1, 2].map(j => (j === i ? 1 : 0))); }
function drawContact(p) {  // where the push's feature touches (its contact frame in the world), red
  const o = p.frame.slice(0, 3), x = frameAxis(p.frame, 0), y = frameAxis(p.frame, 1);
  if (p.kind === "edge") line(add(o, mul(x, -p.length/2)), add(o, mul(x, p.length/2)), "#e62828", 4);
  else if (p.kind === "face") {
    const [a, b] = p.extent;
    poly([[1, 1], [-1, 1], [-1, -1], [1, -1]].map(([i, j]) => view(add(o, add(mul(x, i*a), mul(y, j*b))))), "rgba(230,40,40,0.35)", "#e62828");
  } else { const P = view(o); ctx.fillStyle = "#e62828"; ctx.beginPath(); ctx.arc(P[0], P[1], 5, 0, 2*Math.PI); ctx.fill(); }
}
function armPoses(index) {  // the arm's body poses at a fractional sample index: between the kept frames
  const A = D.arm, idx = A.samples, F = idx.length;
  let lo = 0, hi = F - 1; while (lo < hi) { const m = (lo + hi) >> 1; if (idx[m] < index) lo = m + 1; else hi = m; }
  const b = lo, a = Math.max(0, b - 1), span = idx[b] - idx[a], u = span > 0 ? (index - idx[a]) / span : 1;
  return A.poses[a].map((p, i) => lerpPose(p, A.poses[b][i], Math.max(0, Math.min(1, u))));
}
let PATH = null;  // the gripper's path: its origin at every sample
function draw() {
  const st = stateAt(Number(slider.value)), active = st.push >= 0 ? D.pushes.find(p => p.index === st.push) : null;
  if (followBox && followBox.checked && st.gripper) { C = st.gripper.slice(0, 3); E = Math.max(3 * (D.object ? D.object.size : 0), 0.05); }
  else { C = D.center; E = D.extent; }
  ctx.clearRect(0, 0, W, H); drawn = 0;
  const back = [], items = [];
  for (const p of D.table.parts) mesh(back, p.vertices, p.triangles, COLOURS.table, 1, "table");
  back.sort((x, y) => y.depth - x.depth);
  for (const it of back) poly(it.P, it.fill, it.fill);  // the table first: everything stands on it
  const pushing = active && st.label === "push";
  for (const f of D.features) {
    const on = active && active.body === f.name;
    mesh(items, f.vertices, f.triangles, on ? (pushing ? COLOURS.active : COLOURS.near) : COLOURS.feature, on ? 0.9 : 0.75, "feature");
  }
  mesh(items, D.robot.vertices, D.robot.triangles, COLOURS.robot, 0.9, "robot");
  const arm = D.arm ? armPoses(st.index) : null;
  if (arm) D.arm.bodies.forEach((b, i) => mesh(items, place(arm[i], b.vertices), b.triangles, COLOURS.arm, 1, "arm"));
  if (D.object && st.object) mesh(items, place(st.object, D.object.vertices), D.object.triangles,
    i => D.object.marks[i] ? COLOURS.painted : COLOURS.object, 1, "object");
  if (D.gripper && st.gripper) for (const v of jawParts()) mesh(items, place(st.gripper, v), BOX, COLOURS.jaw, 0.6, "jaw");
  const triad = !D.gripper && st.gripper;  // without the scene's jaws: the gripper frame's axes
  items.sort((x, y) => y.depth - x.depth);
  const boxes = {};  // the screen box [x0, y0, x1, y1] (CSS pixels) of each kind drawn
  for (const it of items) {
    poly(it.P, it.fill, it.kind === "object" || it.kind === "arm" ? it.fill : null);
    const b = boxes[it.kind] || (boxes[it.kind] = [Infinity, Infinity, -Infinity, -Infinity]);
    for (const p of it.P) { b[0] = Math.min(b[0], p[0]); b[1] = Math.min(b[1], p[1]); b[2] = Math.max(b[2], p[0]); b[3] = Math.max(b[3], p[1]); }
  }
  if (active && pushing) drawContact(active);
  if (PATH) for (let i = 1; i < N; i++) line(PATH[i-1], PATH[i], LABEL_COLOURS[S.labels[i]] || "#888", S.labels[i] === "push" ? 3 : 1.5);
  if (triad) for (const [i, c] of [[0, "#d62728"], [1, "#2ca02c"], [2, "#1f5fd6"]])
    line(st.gripper.slice(0, 3), add(st.gripper.slice(0, 3), mul(frameAxis(st.gripper, i), 0.25 * D.axes.length)), c, 3);
  const o = D.axes.origin, L = D.axes.length;
  for (const [i, c, t] of [[0, "#d62728", "x"], [1, "#2ca02c", "y"], [2, "#1f5fd6", "z"]]) {
    const e = o.slice(); e[i] += L; line(o, e, c, 2.5); label(e, t, c);
  }
  label(add(D.robot.base.slice(0, 3), [0, 0, D.robot.height]), D.arm && D.arm.robot ? D.arm.robot : D.robot.name, "#a06000");
  for (const f of D.features) label(f.pose.slice(0, 3), f.name, "rgba(60,60,80,0.8)");
  info.textContent = (N > 1 ? `${D.scene}: t = ${st.t.toFixed(2)} s of ${T.toFixed(2)} s, ${st.label}` : `workcell ${D.name}`) +
    (active ? `, push ${active.index} (pusher ${active.pusher}) at ${active.feature}` : "");
  lastFrame = { t: st.t, label: st.label, push: st.push, gripper: st.gripper, object: st.object,
                highlighted: active ? active.body : null, pushing: !!pushing, drawn, boxes, arm };
}
if (N > 1 && S.gripper[0]) PATH = S.gripper.map(g => g.slice(0, 3));
function fit() {  // the canvas fills its box, at the screen's pixel density
  const r = (typeof window.devicePixelRatio === "number" && window.devicePixelRatio) || 1;
  if (cv.clientWidth) { W = cv.clientWidth; H = cv.clientHeight; cv.width = Math.round(W * r); cv.height = Math.round(H * r); }
  if (ctx.setTransform) ctx.setTransform(r, 0, 0, r, 0, 0);
  draw();
}
if (strip && strip.style && N > 1) {  // the labels along the time slider
  const stops = []; for (let i = 1; i < N; i++) { const c = LABEL_COLOURS[S.labels[i]] || "#888";
    stops.push(`${c} ${(100*S.times[i-1]/T).toFixed(3)}%`, `${c} ${(100*S.times[i]/T).toFixed(3)}%`); }
  strip.style.background = `linear-gradient(to right, ${stops.join(", ")})`;
}
let drag = null;
cv.addEventListener("mousedown", e => { drag = [e.clientX, e.clientY]; });
window.addEventListener("mouseup", () => { drag = null; });
window.addEventListener("mousemove", e => { if (!drag) return; yaw += (e.clientX - drag[0]) * 0.01;
  pitch = Math.max(0.02, Math.min(1.5, pitch + (e.clientY - drag[1]) * 0.01)); drag = [e.clientX, e.clientY]; draw(); });
cv.addEventListener("wheel", e => { e.preventDefault(); zoom *= e.deltaY < 0 ? 1.1 : 1/1.1; draw(); });
slider.addEventListener("input", draw);
if (followBox) followBox.addEventListener("change", draw);
window.addEventListener("resize", fit);
if (typeof ResizeObserver !== "undefined") new ResizeObserver(fit).observe(cv);
if (N < 2) { slider.disabled = true; playBtn.disabled = true; }
if (document.querySelectorAll) {
  if (!D.object) for (const el of document.querySelectorAll(".held")) el.style.display = "none";
  if (!D.arm) for (const el of document.querySelectorAll(".arm")) el.style.display = "none";
  if (N < 2) for (const el of document.querySelectorAll(".moving")) el.style.display = "none";
}
let wall = null;
playBtn.addEventListener("click", () => { playing = !playing; playBtn.textContent = playing ? "pause" : "play"; wall = null; if (playing) tick(); });
function tick(now) {  // the motion's own time, times the speed
  if (!playing) return;
  if (typeof now === "number") { if (wall !== null) {
    let t = Number(slider.value) + (now - wall) / 1000 * Number(speedBox.value || 1); if (t > T) t = 0; slider.value = t; draw(); }
    wall = now; }
  requestAnimationFrame(tick);
}
// a link to a moment, as in the plan view: #t=0.5 (half-way), #t=50% (the same), #t=12.5s (seconds)
const at = typeof location !== "undefined" && /^#t=([0-9.]+)(s|%)?$/.exec(location.hash);
if (at) slider.value = Math.min(T, at[2] === "s" ? Number(at[1]) : at[2] === "%" ? T * Number(at[1]) / 100 : T * Math.min(1, Number(at[1])));
fit();
window.regraspWorld = { draw, stateAt, frame: () => lastFrame, drawn: () => drawn, setT: v => { slider.value = v; draw(); } };
if (SELFTEST) {  // for tests in a headless browser: walk the motion, report
  const inkOf = () => { const px = ctx.getImageData(0, 0, cv.width, cv.height).data;
    let ink = 0; for (let i = 3; i < px.length; i += 4) if (px[i] > 0) ink++; return ink; };
  fit();
  const frames = [];
  for (const f of [0, 0.25, 0.5, 0.75, 1]) { slider.value = f * T; draw(); frames.push(Object.assign({ ink: inkOf() }, lastFrame)); }
  if (followBox) { followBox.checked = true; draw(); frames.push(Object.assign({ ink: inkOf(), follow: true }, lastFrame)); followBox.checked = false; }
  slider.value = 0; draw();
  const out = document.createElement("pre"); out.id = "selftest";
  out.textContent = JSON.stringify({ frames, css: [W, H], pixels: [cv.width, cv.height], info: info.textContent });
  document.body.appendChild(out);
}
