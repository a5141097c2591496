// Runs the viewer page's script in node with a minimal DOM and a recording canvas, sets its
// slider to five times along the plan and prints, for each, what it drew (object faces and pads
// filled, every polygon, pusher contact dots), the pose it shows, its info line and the jaws'
// gap, as JSON; then where the ground and the jaws are drawn at the start (CSS pixels in a canvas
// of argv[3] x argv[4], default 900 x 620). The pytests that run it check those (front faces drawn, pusher contacts shown,
// the last pose is the plan's, the jaws at the grasp's width).
const fs = require("fs");
const html = fs.readFileSync(process.argv[2], "utf8");
const data = html.match(/<script id="data" type="application\/json">([\s\S]*?)<\/script>/)[1];
const code = html.match(/<script>\n([\s\S]*?)<\/script>/)[1];
const calls = { fill: 0, arc: 0, errors: 0 };
const ctx = new Proxy({}, { get: (t, k) => (k in t ? t[k] : (...a) => { if (k === "fill") calls.fill++; if (k === "arc") calls.arc++; }),
                            set: (t, k, v) => { t[k] = v; return true; } });
const stub = () => ({ value: "1", textContent: "", style: {}, addEventListener: () => {} });
const elements = {
  data: { textContent: data },
  c: { width: Number(process.argv[3] || 900), height: Number(process.argv[4] || 620), getContext: () => ctx, addEventListener: () => {} },
  t: { value: "0", addEventListener: () => {} },
  info: { textContent: "" },
  play: { addEventListener: () => {} },
};
global.document = { getElementById: id => elements[id] || (elements[id] = stub()) };
global.window = { addEventListener: () => {} };
global.requestAnimationFrame = () => {};
new Function(code)();
const v = global.window.regraspViewer;
const D = JSON.parse(data);
const out = { triangles: D.triangles.length, frames: [] };
for (const t of [0, 250, 500, 750, 1000]) {
  calls.fill = 0; calls.arc = 0;
  v.setT(String(t));
  const [q] = v.poseAt(t / 1000);
  out.frames.push({ t, drawn: v.drawn(), drawn_all: v.drawnAll(), fills: calls.fill, pusher_dots: calls.arc, pose: q,
                    info: elements.info.textContent, finite: q.every(Number.isFinite), jaw_gap: v.jawGap() });
}
v.setT("0");
out.probes = v.probes();
console.log(JSON.stringify(out));
