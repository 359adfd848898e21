// xatlas (npm xatlasjs, the WebAssembly build behind xatlas-three) on a level's meshes, for the
// level unwrap benchmark (tools/bench_unwrap_levels.py). Prints one JSON line: charts, atlas
// size, coverage (texel centres inside a triangle over the atlas area, as `lmbake unwrap`
// counts them), charting and packing seconds (from xatlas's own progress callback).
//
// usage: node tools/xatlas_unwrap.mjs LEVEL.glb TEXELS_PER_UNIT PADDING
//
// The meshes of every node are put together in world space (translation, rotation, scale of
// the node and its parents). xatlasjs takes 16-bit indices, so vertices are welded by
// position first, as lmbake does; zero-area triangles are left out, as lmbake does.
import fs from "node:fs";
import path from "node:path";
import { createRequire } from "node:module";
import { fileURLToPath } from "node:url";

const here = path.dirname(fileURLToPath(import.meta.url));
const require = createRequire(path.join(here, "..", "package.json"));
const dist = path.dirname(require.resolve("xatlasjs/dist/node/api.mjs"));
const { Api } = await import(path.join(dist, "api.mjs"));
const createXAtlasModule = require(path.join(dist, "xatlas.js"));

function readGlb(file) {
  const b = fs.readFileSync(file);
  if (b.readUInt32LE(0) !== 0x46546c67) throw new Error(`${file}: not a binary glTF`);
  const jsonLen = b.readUInt32LE(12);
  const doc = JSON.parse(b.subarray(20, 20 + jsonLen).toString("utf8"));
  const binAt = 20 + jsonLen;
  const bin = b.subarray(binAt + 8, binAt + 8 + b.readUInt32LE(binAt));
  return { doc, bin };
}

function accessor(doc, bin, i) {
  const a = doc.accessors[i], v = doc.bufferViews[a.bufferView];
  const off = (v.byteOffset || 0) + (a.byteOffset || 0);
  const n = { SCALAR: 1, VEC2: 2, VEC3: 3 }[a.type] * a.count;
  const copy = Buffer.from(bin.subarray(off, off + n * (a.componentType === 5126 || a.componentType === 5125 ? 4 : 2)));
  if (v.byteStride && v.byteStride !== 12 && a.type === "VEC3") throw new Error("strided positions are not supported");
  if (a.componentType === 5126) return new Float32Array(copy.buffer, copy.byteOffset, n);
  if (a.componentType === 5125) return new Uint32Array(copy.buffer, copy.byteOffset, n);
  if (a.componentType === 5123) return new Uint16Array(copy.buffer, copy.byteOffset, n);
  throw new Error(`accessor ${i}: component type ${a.componentType} not supported`);
}

function nodeMatrix(n) {
  if (n.matrix) return n.matrix;
  const [x, y, z, w] = n.rotation || [0, 0, 0, 1], [sx, sy, sz] = n.scale || [1, 1, 1], t = n.translation || [0, 0, 0];
  return [
    (1 - 2 * (y * y + z * z)) * sx, 2 * (x * y + z * w) * sx, 2 * (x * z - y * w) * sx, 0,
    2 * (x * y - z * w) * sy, (1 - 2 * (x * x + z * z)) * sy, 2 * (y * z + x * w) * sy, 0,
    2 * (x * z + y * w) * sz, 2 * (y * z - x * w) * sz, (1 - 2 * (x * x + y * y)) * sz, 0,
    t[0], t[1], t[2], 1,
  ];
}

function mul(a, b) { // column-major 4x4
  const r = new Array(16).fill(0);
  for (let c = 0; c < 4; c++) for (let row = 0; row < 4; row++) for (let k = 0; k < 4; k++) r[4 * c + row] += a[4 * k + row] * b[4 * c + k];
  return r;
}

// World-space triangle soup of every node with a mesh (skipping EXT_mesh_gpu_instancing copies).
function levelTriangles(doc, bin) {
  const pos = [], idx = [];
  const visit = (ni, parent) => {
    const n = doc.nodes[ni], m = mul(parent, nodeMatrix(n));
    if (n.mesh !== undefined)
      for (const p of doc.meshes[n.mesh].primitives) {
        if ((p.mode ?? 4) !== 4) continue;
        const P = accessor(doc, bin, p.attributes.POSITION), base = pos.length / 3;
        for (let v = 0; v < P.length; v += 3)
          for (let r = 0; r < 3; r++) pos.push(m[r] * P[v] + m[4 + r] * P[v + 1] + m[8 + r] * P[v + 2] + m[12 + r]);
        const I = p.indices !== undefined ? accessor(doc, bin, p.indices) : [...Array(P.length / 3).keys()];
        for (const i of I) idx.push(base + i);
      }
    for (const c of n.children || []) visit(c, m);
  };
  for (const r of doc.scenes[doc.scene || 0].nodes) visit(r, [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);
  return { pos: Float32Array.from(pos), idx };
}

// Weld by exact position (float32), drop zero-area triangles.
function weld(pos, idx) {
  const map = new Map(), out = [], id = new Uint32Array(pos.length / 3);
  for (let v = 0; v < pos.length / 3; v++) {
    const key = `${pos[3 * v]},${pos[3 * v + 1]},${pos[3 * v + 2]}`;
    let w = map.get(key);
    if (w === undefined) { w = out.length / 3; map.set(key, w); out.push(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]); }
    id[v] = w;
  }
  const tris = [];
  for (let t = 0; t < idx.length; t += 3) {
    const a = id[idx[t]], b = id[idx[t + 1]], c = id[idx[t + 2]];
    const e1 = [0, 1, 2].map((k) => out[3 * b + k] - out[3 * a + k]), e2 = [0, 1, 2].map((k) => out[3 * c + k] - out[3 * a + k]);
    const cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2], cz = e1[0] * e2[1] - e1[1] * e2[0];
    if (cx * cx + cy * cy + cz * cz > 0) tris.push(a, b, c);
  }
  return { pos: Float32Array.from(out), idx: tris };
}

// Texel centres inside a triangle (the rule lmbake's report uses: a centre on a shared edge
// counts once), and charts as groups of triangles joined by xatlas's output vertices.
function measure(uv, index, width, height) {
  let covered = 0;
  const seen = new Uint8Array(width * height);
  for (let t = 0; t < index.length; t += 3) {
    const p = [0, 1, 2].map((k) => [uv[2 * index[t + k]], uv[2 * index[t + k] + 1]]);
    const area = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
    if (area === 0) continue;
    const x0 = Math.max(0, Math.floor(Math.min(p[0][0], p[1][0], p[2][0]) - 0.5)), x1 = Math.min(width - 1, Math.ceil(Math.max(p[0][0], p[1][0], p[2][0])));
    const y0 = Math.max(0, Math.floor(Math.min(p[0][1], p[1][1], p[2][1]) - 0.5)), y1 = Math.min(height - 1, Math.ceil(Math.max(p[0][1], p[1][1], p[2][1])));
    for (let y = y0; y <= y1; y++)
      for (let x = x0; x <= x1; x++) {
        const cx = x + 0.5, cy = y + 0.5;
        let inside = true;
        for (let k = 0; k < 3 && inside; k++) {
          const a = p[k], b = p[(k + 1) % 3];
          const e = ((b[0] - a[0]) * (cy - a[1]) - (b[1] - a[1]) * (cx - a[0])) * Math.sign(area);
          inside = e >= 0;
        }
        if (inside && !seen[y * width + x]) { seen[y * width + x] = 1; covered++; }
      }
  }
  const parent = new Uint32Array(index.length / 3).map((_, i) => i), owner = new Map();
  const find = (a) => { while (parent[a] !== a) a = parent[a] = parent[parent[a]]; return a; };
  for (let t = 0; t < index.length; t++) {
    const f = Math.floor(t / 3), o = owner.get(index[t]);
    if (o === undefined) owner.set(index[t], f);
    else { const a = find(o), b = find(f); if (a !== b) parent[Math.max(a, b)] = Math.min(a, b); }
  }
  let charts = 0;
  for (let f = 0; f < parent.length; f++) charts += find(f) === f;
  return { covered, charts };
}

const [file, tpu, padding] = process.argv.slice(2);
if (!file || !tpu) {
  console.error("usage: node tools/xatlas_unwrap.mjs LEVEL.glb TEXELS_PER_UNIT [PADDING]");
  process.exit(2);
}
const { doc, bin } = readGlb(file);
const soup = levelTriangles(doc, bin), welded = weld(soup.pos, soup.idx);
if (welded.pos.length / 3 > 65535) {
  console.error(`${file}: ${welded.pos.length / 3} distinct vertex positions; xatlasjs takes at most 65535`);
  process.exit(1);
}
const marks = {};
const XAtlas = Api(createXAtlasModule);
const api = await new Promise((resolve) => {
  const a = new XAtlas(() => resolve(a), null, (mode, counter) => { if (!(mode in marks)) marks[mode] = performance.now(); });
});
api.createAtlas();
api.addMesh(Uint16Array.from(welded.idx), welded.pos);
const t0 = performance.now();
api.generateAtlas({}, { padding: Number(padding ?? 2), texelsPerUnit: Number(tpu), resolution: 0 }, false);
const t1 = performance.now();
const X = api.xatlas, atlas = X.getAtlas(), data = X.getMeshData(api.meshes[0].meshId);
const index = Uint32Array.from(X.HEAPU32.subarray(data.indexOffset / 4, data.indexOffset / 4 + data.newIndexCount));
let uv = Float32Array.from(X.HEAPF32.subarray(data.uvOffset / 4, data.uvOffset / 4 + 2 * data.newVertexCount));
if (Math.max(...uv.subarray(0, Math.min(uv.length, 4096))) <= 1.0001) // normalised: to texels
  uv = uv.map((v, i) => v * (i % 2 ? atlas.height : atlas.width));
const m = measure(uv, index, atlas.width, atlas.height);
// ProgressCategory: 0 AddMesh, 1 ComputeCharts, 2 PackCharts, 3 BuildOutputMeshes
const at = (k, fallback) => (k in marks ? marks[k] : fallback);
const charting = (at(2, t1) - at(1, t0)) / 1000, packing = (at(3, t1) - at(2, t1)) / 1000;
console.log(JSON.stringify({ tool: "xatlas", texels_per_unit: Number(tpu), triangles: welded.idx.length / 3,
  charts: m.charts, width: atlas.width, height: atlas.height, atlases: atlas.atlasCount,
  coverage: m.covered / (atlas.width * atlas.height), charting_s: charting, packing_s: packing, total_s: (t1 - t0) / 1000 }));
