// Runs the viewer page's script in node with a minimal DOM and a recording canvas, sets its
// slider to five times along the plan and prints, for each, what it drew (faces and pads filled,
// pusher contact dots), the pose it shows and its info line, as JSON. The pytest that runs it
// checks those (front faces drawn, pusher contacts shown, the last pose is the plan's).
const fs = require("fs");
const html = fs.readFileSync(process.argv[2], "utf8");
const data = html.match(/<script id="data" type="application\/json">([\s\S]*?)<\/script>/)[1];
const code = html.match(/<script>\n([\s\S]*?)<\/script>/)[1];
const calls = { fill: 0, arc: 0, errors: 0 };
const ctx = new Proxy({}, { get: (t, k) => (k in t ? t[k] : (...a) => { if (k === "fill") calls.fill++; if (k === "arc") calls.arc++; }),
                            set: (t, k, v) => { t[k] = v; return true; } });
const elements = {
  data: { textContent: data },
  c: { width: 900, height: 620, getContext: () => ctx, addEventListener: () => {} },
  t: { value: "0", addEventListener: () => {} },
  info: { textContent: "" },
  play: { addEventListener: () => {} },
};
global.document = { getElementById: id => elements[id] };
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
  out.frames.push({ t, drawn: v.drawn(), fills: calls.fill, pusher_dots: calls.arc, pose: q, info: elements.info.textContent,
                    finite: q.every(Number.isFinite) });
}
console.log(JSON.stringify(out));
