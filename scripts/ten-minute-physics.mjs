// Times Ten Minute Physics' own soft-body solver (10-softBodies.html, Matthias Müller, MIT) in
// Node on a TetGen mesh: its vector functions and its SoftBody class are read out of the page
// the user downloaded (none of its code is in this repository), three.js is replaced by an
// object that does nothing, and the page's substep loop (preSolve, solve, postSolve for each of
// numSubsteps) is run for FRAMES frames after WARMUP. Prints one JSON line: ms_per_frame, the
// tets, the edges and the projections per frame.
//
// Usage: node scripts/ten-minute-physics.mjs PAGE.html MESH(.node/.ele, without extension) FRAMES [WARMUP]
import { readFileSync } from "node:fs";

const [page, mesh, framesText, warmupText = "20"] = process.argv.slice(2);
if (!page || !mesh || !framesText) {
  console.error("usage: node scripts/ten-minute-physics.mjs PAGE.html MESH FRAMES [WARMUP]");
  process.exit(2);
}
const frames = Number(framesText);
const warmup = Number(warmupText);
const html = readFileSync(page, "utf8");

function between(start, end) {
  const a = html.indexOf(start);
  const b = html.indexOf(end, a);
  if (a < 0 || b < 0) {
    console.error(`${page}: no "${start}" ... "${end}": not Ten Minute Physics' 10-softBodies.html?`);
    process.exit(2);
  }
  return html.slice(a, b);
}

// The class, from "class SoftBody" to its matching brace.
function classText(name) {
  const a = html.indexOf(`class ${name}`);
  if (a < 0) {
    console.error(`${page}: no class ${name}: not Ten Minute Physics' 10-softBodies.html?`);
    process.exit(2);
  }
  let depth = 0;
  for (let i = html.indexOf("{", a); i < html.length; i++) {
    if (html[i] === "{") depth++;
    if (html[i] === "}" && --depth === 0) return html.slice(a, i + 1);
  }
  console.error(`${page}: class ${name} never ends`);
  process.exit(2);
}

// What three.js would be: every property, call and construction gives the same do-nothing object.
const nothing = new Proxy(function () {}, {
  get: () => nothing,
  set: () => true,
  apply: () => nothing,
  construct: () => nothing,
});

const vectorMath = between("function vecSetZero", "var gThreeScene");
const SoftBody = new Function("THREE", `${vectorMath}\n${classText("SoftBody")}\nreturn SoftBody;`)(nothing);

// The mesh as the page's tetMesh: vertices, tets, and each tet's six edges once.
function numbers(path) {
  return readFileSync(path, "utf8")
    .split("\n")
    .filter((line) => line.trim() && !line.trim().startsWith("#"))
    .map((line) => line.trim().split(/\s+/).map(Number));
}
const [nodeHeader, ...nodeRows] = numbers(`${mesh}.node`);
const [eleHeader, ...eleRows] = numbers(`${mesh}.ele`);
const verts = nodeRows.slice(0, nodeHeader[0]).flatMap((row) => row.slice(1, 4));
const tetIds = eleRows.slice(0, eleHeader[0]).flatMap((row) => row.slice(1, 5));
const seen = new Set();
const tetEdgeIds = [];
for (let t = 0; t < tetIds.length; t += 4) {
  for (const [a, b] of [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]]) {
    const [i, j] = [tetIds[t + a], tetIds[t + b]].sort((x, y) => x - y);
    if (!seen.has(i * 1e6 + j)) {
      seen.add(i * 1e6 + j);
      tetEdgeIds.push(i, j);
    }
  }
}

const scene = { gravity: [0.0, -10.0, 0.0], dt: 1.0 / 60.0, numSubsteps: 10 };
const body = new SoftBody({ verts, tetIds, tetEdgeIds, tetSurfaceTriIds: [] }, nothing);
function frame() {
  const sdt = scene.dt / scene.numSubsteps;
  for (let step = 0; step < scene.numSubsteps; step++) {
    body.preSolve(sdt, scene.gravity);
    body.solve(sdt);
    body.postSolve(sdt);
  }
}
for (let f = 0; f < warmup; f++) frame();
const start = process.hrtime.bigint();
for (let f = 0; f < frames; f++) frame();
const ms = Number(process.hrtime.bigint() - start) / 1e6;
for (const x of body.pos) {
  if (!Number.isFinite(x)) {
    console.error("the solver produced a non-finite position");
    process.exit(1);
  }
}
const tets = tetIds.length / 4;
const edges = tetEdgeIds.length / 2;
console.log(
  JSON.stringify({
    ms_per_frame: ms / frames,
    tets,
    edges,
    projections_per_frame: (tets + edges) * scene.numSubsteps,
    substeps: scene.numSubsteps,
    frames,
  }),
);
