"use strict";
// The regrasp browser view: draws the data of viz/view_data.py on a 2-D canvas (painter's
// algorithm, flat shading) in the gripper frame: ground, jaws, object, pushers, axes, gravity.
const D = JSON.parse(document.getElementById("data").textContent);
const SELFTEST = typeof location !== "undefined" && location.hash === "#selftest";  // tests read the canvas back
const cv = document.getElementById("c"), ctx = cv.getContext("2d", { willReadFrequently: SELFTEST });
const slider = document.getElementById("t"), info = document.getElementById("info");
const speedBox = document.getElementById("speed"), playBtn = document.getElementById("play");
let yaw = D.dimension === 2 ? 0.35 : 0.6, pitch = D.dimension === 2 ? 0.25 : 0.35, zoom = 1.0;
let playing = false, drawn = 0, drawnAll = 0, W = cv.width, H = cv.height, layer = "all", jawGap = null;
function poseAt(u) {  // u in [0, 1] along the plan: the pose and the step it is in
  const n = D.poses.length - 1; if (n <= 0) return [D.poses[0], 0];
  const f = Math.min(u * n, n - 1e-9), k = Math.floor(f), t = f - k, a = D.poses[k], b = D.poses[k+1];
  const p = [0,1,2].map(i => a[i] + t*(b[i]-a[i]));
  return [p.concat(slerp(a.slice(3), b.slice(3), t)), k + 1];
}
const place = (q, pts) => { const r = q.slice(3), n = Math.hypot(...r), u = r.map(x => x / n);
  return pts.map(v => add(qrot(u, v), q)); };
function view(v) {  // gripper frame -> camera (orbit about z), then perspective; CSS pixels and depth
  const cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
  const c = D.center, x = cy*(v[0]-c[0]) + sy*(v[1]-c[1]), y = -sy*(v[0]-c[0]) + cy*(v[1]-c[1]), z = v[2] - c[2];
  const y2 = cp*y - sp*z, z2 = sp*y + cp*z;
  const dist = 4 * D.extent + 3 * D.size, s = 0.3 * Math.min(W, 1.2 * H) * zoom * dist / Math.max(dist + y2, 0.05 * dist) / D.extent;
  return [W/2 + x*s, H/2 - z2*s, y2];
}
const towardsCamera = n => { const ny = -Math.sin(yaw)*n[0] + Math.cos(yaw)*n[1];
  return Math.cos(pitch)*ny - Math.sin(pitch)*n[2] < 0; };
const shadeOf = n => Math.max(0.15, dot(n, [0.3, -0.5, 0.8]) / (Math.hypot(...n) || 1));
const rgb = (c, sh, a) => `rgba(${c.map(x => Math.round(x * (0.45 + 0.55*sh))).join(",")},${a})`;
const COLOURS = { object: [150, 190, 240], painted: [250, 180, 70], jaw: [110, 110, 120], active: [230, 40, 40],
                  feature: [175, 150, 205] };
function mesh(out, world, tris, colour, alpha, kind) {  // front faces of a closed mesh, for depth sorting
  for (const [i, t] of tris.entries()) {
    const a = world[t[0]], b = world[t[1]], c = world[t[2]], n = cross(sub(b, a), sub(c, a));
    if (!towardsCamera(n)) continue;
    const P = [a, b, c].map(view);
    const col = typeof colour === "function" ? colour(i) : colour;
    out.push({ P, depth: (P[0][2]+P[1][2]+P[2][2]) / 3, fill: rgb(col, shadeOf(n), alpha), kind });
  }
}
const BOX = [[0,2,1],[0,3,2],[4,5,6],[4,6,7],[0,1,5],[0,5,4],[2,3,7],[2,7,6],[1,2,6],[1,6,5],[0,4,7],[0,7,3]];
function box(lo, hi) {  // an axis-aligned box: vertices, outward triangles
  const v = []; for (const z of [lo[2], hi[2]]) for (const [x, y] of [[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]]) v.push([x, y, z]);
  return v;
}
function gripper(world) {  // the jaws at the object's extremes along y: fingers, palm, pads
  const J = D.jaws, th = J.thickness, b = J.breadth;
  let top = -1e9, bot = 1e9; for (const w of world) { top = Math.max(top, w[1]); bot = Math.min(bot, w[1]); }
  jawGap = top - bot;
  const parts = [box([-b, top, -b], [b, top + th, J.palm_z]), box([-b, bot - th, -b], [b, bot, J.palm_z]),
                 box([-b, bot - th, J.palm_z], [b, top + th, J.palm_z + th])];
  const pads = [[top, 1], [bot, -1]].map(([y, sgn]) => {
    const R = D.pad_rect, ring = R ? [[1, 1], [-1, 1], [-1, -1], [1, -1]].map(([i, j]) => view([i*R[0], y, j*R[1]])) : [];
    if (!R) for (let k = 0; k < 24; k++) { const a = 2*Math.PI*k/24; ring.push(view([J.pad*Math.cos(a), y, J.pad*Math.sin(a)])); }
    return [ring, towardsCamera([0, -sgn, 0])];  // the pad's face looks at the object (-sgn y)
  });
  return { parts, pads, top, bot };
}
function poly(pts, fill, stroke, counted) {
  ctx.beginPath(); ctx.moveTo(pts[0][0], pts[0][1]); for (const p of pts.slice(1)) ctx.lineTo(p[0], p[1]);
  ctx.closePath(); ctx.fillStyle = fill; ctx.fill(); if (stroke) { ctx.strokeStyle = stroke; ctx.stroke(); }
  drawnAll++; if (counted) drawn++;
}
function line(a, b, colour, width, dash) {
  const A = view(a), B = view(b);
  ctx.beginPath(); ctx.setLineDash && ctx.setLineDash(dash || []); ctx.moveTo(A[0], A[1]); ctx.lineTo(B[0], B[1]);
  ctx.strokeStyle = colour; ctx.lineWidth = width || 1; ctx.stroke(); ctx.setLineDash && ctx.setLineDash([]); ctx.lineWidth = 1;
  return B;
}
function label(p, text, colour) { const P = view(p); ctx.fillStyle = colour; ctx.font = "bold 14px sans-serif"; ctx.fillText(text, P[0] + 4, P[1] - 4); }
function drawGround() {
  const G = D.ground, h = G.half, corner = (i, j) => add(G.point, add(mul(G.t1, i*h), mul(G.t2, j*h)));
  poly([corner(1, 1), corner(-1, 1), corner(-1, -1), corner(1, -1)].map(view), "rgba(205,185,150,0.45)", "rgba(140,115,80,0.8)", false);
  for (let k = -3; k <= 3; k++) {
    line(corner(k/4, -1), corner(k/4, 1), "rgba(140,115,80,0.35)"); line(corner(-1, k/4), corner(1, k/4), "rgba(140,115,80,0.35)");
  }
}
function drawOverlays(pos, rot, world, name) {
  const o = D.axes.origin, L = D.axes.length;  // axes of the gripper frame, labelled
  for (const [i, c, t] of [[0, "#d62728", "x"], [1, "#2ca02c", "y"], [2, "#1f5fd6", "z"]]) {
    const e = o.slice(); e[i] += L; line(o, e, c, 2.5); label(e, t, c);
  }
  const g = D.gravity.direction, a = add(D.center, add([1.5 * D.size, 0, 0], mul(g, -0.4 * D.size))), tip = add(a, mul(g, 0.8 * D.size));
  const T = line(a, tip, "#7b2fbf", 3), S = view(add(a, mul(g, 0.68 * D.size)));
  const dx = T[0] - S[0], dy = T[1] - S[1];  // the arrow head
  poly([[T[0], T[1]], [S[0] - dy*0.4, S[1] + dx*0.4], [S[0] + dy*0.4, S[1] - dx*0.4]], "#7b2fbf", null, false);
  label(tip, D.gravity.in_plane ? "g (in plane)" : "g", "#7b2fbf");
  if (D.goal) {  // the goal pose: the object's edges dashed over a faint fill
    const gw = place(D.goal, D.vertices), ghost = [];
    mesh(ghost, gw, D.triangles, [60, 200, 110], 0.08, "goal");
    for (const it of ghost) poly(it.P, it.fill, null, false);
    for (const [i, j] of D.edges) line(gw[i], gw[j], "rgba(20,140,60,0.7)", 1.2, [5, 3]);
  }
  // the pusher of the current step: where it touches, moving with the object
  let contacts = [];
  if (name && D.planes[name]) {  // a plane touches the object where it is lowest along its normal
    const n = D.planes[name];
    if (D.sphere) contacts = [sub(pos, mul(n, D.sphere))];
    else { const lo = Math.min(...world.map(p => dot(p, n))); contacts = world.filter(p => dot(p, n) < lo + 1e-6*D.size); }
    const c = contacts[0], ax = Math.abs(n[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0], t1 = cross(n, ax), l = Math.hypot(...t1);
    const u = mul(t1, 1 / l), v = cross(n, u), h = 1.3 * D.size;
    const sq = [[1, 1], [-1, 1], [-1, -1], [1, -1]].map(([i, j]) => view(add(c, add(mul(u, i*h), mul(v, j*h)))));
    poly(sq, "rgba(214,39,40,0.12)", "rgba(214,39,40,0.5)", false);
  } else if (name && D.pusher_points[name]) {
    contacts = place(pos.concat(rot), D.pusher_points[name]);
  }
  ctx.fillStyle = "#d62728";
  for (const pnt of contacts) { const P = view(pnt); ctx.beginPath(); ctx.arc(P[0], P[1], 5, 0, 2*Math.PI); ctx.fill(); }
}
function draw() {
  const n = D.poses.length - 1, [q, step] = poseAt(slider.value / 1000);
  const pos = q.slice(0, 3), rot = q.slice(3), world = place(q, D.vertices);
  const name = D.pushers_of_steps[Math.min(step, D.pushers_of_steps.length - 1)];
  ctx.clearRect(0, 0, W, H);
  drawn = 0; drawnAll = 0;
  const items = [];
  mesh(items, world, D.triangles, i => D.marks[i] ? COLOURS.painted : COLOURS.object, 1, "object");
  const grip = D.jaws ? gripper(world) : null;
  if (layer === "all") {
    drawGround();
    if (grip) for (const v of grip.parts) mesh(items, v, BOX, COLOURS.jaw, 0.55, "jaw");
    for (const f of D.features) {
      const on = f.name === name;
      mesh(items, place(q, f.vertices), f.triangles, on ? COLOURS.active : COLOURS.feature, on ? 0.9 : 0.4, "feature");
    }
  }
  items.sort((x, y) => y.depth - x.depth);
  const pad = "rgba(50,50,50,0.7)";
  if (grip) for (const [ring, facing] of grip.pads) if (!facing) poly(ring, pad, "rgba(0,0,0,0.3)", true);
  for (const it of items) poly(it.P, it.fill, it.kind === "object" ? it.fill : null, it.kind === "object");
  if (grip) for (const [ring, facing] of grip.pads) if (facing) poly(ring, pad, "rgba(0,0,0,0.3)", true);
  if (layer === "all") drawOverlays(pos, rot, world, name);
  info.textContent = (n > 0 ? `${D.name}: step ${step} of ${n}` : `${D.name}: the start` + (D.goal ? " (the goal dashed)" : "")) +
    (name ? `, pusher ${name}` : "") + ` — position [${pos.map(x => (1000*x).toFixed(1)).join(", ")}] mm`;
}
function probes() {  // where the ground and the jaws are drawn (CSS pixels in the canvas), for tests
  const G = D.ground, out = { ground: [0.5, -0.5].map(i => view(add(G.point, add(mul(G.t1, i*G.half), mul(G.t2, 0.6*G.half))))) };
  if (D.jaws) {
    const J = D.jaws, world = place(poseAt(slider.value / 1000)[0], D.vertices), g = gripper(world), z = J.palm_z - 0.5*J.thickness;
    out.jaws = [view([0, 0, J.palm_z + 0.5*J.thickness]), view([0, g.top + 0.5*J.thickness, z]), view([0, g.bot - 0.5*J.thickness, z])];
  }
  return out;
}
function fit() {  // the canvas fills its box, at the screen's pixel density
  const r = (typeof window.devicePixelRatio === "number" && window.devicePixelRatio) || 1;
  if (cv.clientWidth) { W = cv.clientWidth; H = cv.clientHeight; cv.width = Math.round(W * r); cv.height = Math.round(H * r); }
  if (ctx.setTransform) ctx.setTransform(r, 0, 0, r, 0, 0);
  draw();
}
let drag = null;
cv.addEventListener("mousedown", e => { drag = [e.clientX, e.clientY]; });
window.addEventListener("mouseup", () => { drag = null; });
window.addEventListener("mousemove", e => { if (!drag) return; yaw += (e.clientX - drag[0]) * 0.01;
  pitch = Math.max(-1.5, Math.min(1.5, pitch + (e.clientY - drag[1]) * 0.01)); drag = [e.clientX, e.clientY]; draw(); });
cv.addEventListener("wheel", e => { e.preventDefault(); zoom *= e.deltaY < 0 ? 1.1 : 1/1.1; draw(); });
slider.addEventListener("input", draw);
window.addEventListener("resize", fit);
if (typeof ResizeObserver !== "undefined") new ResizeObserver(fit).observe(cv);
if (D.poses.length < 2) { slider.disabled = true; playBtn.disabled = true; }
playBtn.addEventListener("click", () => { playing = !playing; playBtn.textContent = playing ? "pause" : "play"; if (playing) tick(); });
function tick() {  // about 0.7 s a step at speed 1
  if (!playing) return;
  const per = 1000 / (40 * Math.max(1, D.poses.length - 1)) * Number(speedBox.value || 1);
  slider.value = (Number(slider.value) + per) % 1001; draw(); requestAnimationFrame(tick);
}
if (!D.jaws) for (const el of document.querySelectorAll ? document.querySelectorAll(".jaws") : []) el.style.display = "none";
// a link to a point along the plan, as in the world view: #t=0.5 (half-way), #t=50% (the same)
const at = typeof location !== "undefined" && /^#t=([0-9.]+)(%)?$/.exec(location.hash);
if (at) slider.value = Math.min(1000, at[2] === "%" ? 10 * Number(at[1]) : 1000 * Number(at[1]));
fit();
window.regraspViewer = { draw, poseAt, probes, drawn: () => drawn, drawnAll: () => drawnAll, jawGap: () => jawGap,
                         setT: v => { slider.value = v; draw(); } };
if (SELFTEST) {  // for tests in a headless browser: walk the plan, report
  const inkOf = () => { const px = ctx.getImageData(0, 0, cv.width, cv.height).data;
    let ink = 0; for (let i = 3; i < px.length; i += 4) if (px[i] > 0) ink++; return ink; };
  fit();  // the layout as it is now (the window may have changed since the script started)
  const frames = [];
  for (const t of [0, 250, 500, 750, 1000]) {
    slider.value = t; layer = "object"; draw(); const ink = inkOf();  // the object (and pads) alone
    layer = "all"; draw();
    const [q] = poseAt(t / 1000);
    frames.push({ t, drawn, drawn_all: drawnAll, ink, ink_all: inkOf(), pose: q, info: info.textContent, jaw_gap: jawGap });
  }
  yaw += 1.0; draw(); yaw -= 1.0;
  slider.value = 0; draw();
  const r = window.devicePixelRatio || 1, P = probes(), rect = cv.getBoundingClientRect();
  const pixel = p => Array.from(ctx.getImageData(Math.round(p[0]*r), Math.round(p[1]*r), 1, 1).data);
  const out = document.createElement("pre"); out.id = "selftest";
  out.textContent = JSON.stringify({ triangles: D.triangles.length, frames, css: [W, H], pixels: [cv.width, cv.height],
    offset: [rect.left, rect.top], viewport: [window.innerWidth, window.innerHeight], dpr: r, probes: P,
    probe_pixels: Object.fromEntries(Object.entries(P).map(([k, v]) => [k, v.map(pixel)])) });
  document.body.appendChild(out);
}
