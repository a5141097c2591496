// Runs the world view page's script in node with a minimal DOM and a recording canvas; for each
// time [s] given on the command line (argv[3], a JSON list) prints the state the page shows
// (gripper and object poses, label, push, highlighted feature, polygons drawn) and whether any
// drawn number was not finite, as JSON. The pytests that run it compare those with the motion.
const fs = require("fs");
const html = fs.readFileSync(process.argv[2], "utf8");
const data = html.match(/<script id="data" type="application\/json">([\s\S]*?)<\/script>/)[1];
const code = html.match(/<script>\n([\s\S]*?)<\/script>/)[1];
let finite = true;
const check = (...a) => { for (const x of a) if (typeof x === "number" && !Number.isFinite(x)) finite = false; };
const ctx = new Proxy({}, { get: (t, k) => (k in t ? t[k] : (...a) => { if (k === "moveTo" || k === "lineTo" || k === "arc") check(...a); }),
                            set: (t, k, v) => { t[k] = v; return true; } });
const stub = () => ({ value: "1", textContent: "", style: {}, checked: false, addEventListener: () => {} });
const elements = {
  data: { textContent: data },
  c: { width: 900, height: 620, getContext: () => ctx, addEventListener: () => {} },
  t: { value: "0", addEventListener: () => {} },
};
global.document = { getElementById: id => elements[id] || (elements[id] = stub()) };
global.window = { addEventListener: () => {} };
global.requestAnimationFrame = () => {};
new Function(code)();
const v = global.window.regraspWorld;
const out = { frames: [] };
for (const t of JSON.parse(process.argv[3] || "[0]")) {
  finite = true;
  v.setT(String(t));
  out.frames.push(Object.assign({ finite, info: elements.info.textContent }, v.frame()));
}
console.log(JSON.stringify(out));
