// A bake's files (its glTF, buffers and lightmap atlases) and the map from each texel of a final
// bake's atlases to the same point of a quick bake's, through which the composer (compose.mjs)
// reads the quick looks.
//
// The map: each final texel reads a quick bake through the triangles both bakes share (the unwrap
// keeps the input's triangles in order): the texel centre's barycentric coordinates in its final
// TEXCOORD_1 triangle, the same point in the quick bake's triangle, read bilinearly
// (tools/bench_watch.py's mapping). Copies that share one TEXCOORD_1 in both bakes map rectangle
// to rectangle instead. Texels no triangle covers (the atlas's padding) take the difference of a
// covered neighbour (padPlan, applyPad).
import crypto from 'node:crypto';
import fs from 'node:fs';
import path from 'node:path';
import { readHdr } from './hdr.mjs';

const MAX_TRIANGLES = 5e6; // placed triangles mapped one by one at most (about 2 s here)
const PAD_PASSES = 8; // texels beyond the triangles filled from a neighbour, at most this far out

// A bake's folder: {dir, stem, doc (the glTF's JSON), buffer(i) (read once)}.
export function readBake(dir, stem) {
  const file = path.join(dir, `${stem}.gltf`);
  const doc = JSON.parse(fs.readFileSync(file, 'utf8'));
  const buffers = new Map();
  const buffer = (i) => {
    if (!buffers.has(i)) buffers.set(i, fs.readFileSync(path.join(dir, doc.buffers[i].uri)));
    return buffers.get(i);
  };
  return { dir, stem, doc, buffer };
}

const COMPONENTS = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 };
const TYPES = { 5126: Float32Array, 5125: Uint32Array, 5123: Uint16Array, 5121: Uint8Array };

// An accessor's values, flat (count x components), as numbers (no sparse, no normalisation).
function accessor(g, index) {
  const a = g.doc.accessors[index];
  const v = g.doc.bufferViews[a.bufferView];
  const Type = TYPES[a.componentType];
  if (!Type || a.sparse) throw new Error(`accessor ${index}: type ${a.componentType} not read here`);
  const n = COMPONENTS[a.type], size = Type.BYTES_PER_ELEMENT;
  const stride = v.byteStride || n * size;
  const data = g.buffer(v.buffer), start = data.byteOffset + (v.byteOffset || 0) + (a.byteOffset || 0);
  const view = new DataView(data.buffer);
  const get = { 5126: (o) => view.getFloat32(o, true), 5125: (o) => view.getUint32(o, true), 5123: (o) => view.getUint16(o, true), 5121: (o) => view.getUint8(o) }[a.componentType];
  const out = new Float64Array(a.count * n);
  for (let i = 0; i < a.count; i++) for (let c = 0; c < n; c++) out[i * n + c] = get(start + i * stride + c * size);
  return out;
}

// A file's identity for the composer's caches: path, inode, size and time.
export function stamp(file) {
  const st = fs.statSync(file);
  return `${path.resolve(file)}:${st.ino}:${st.size}:${st.mtimeMs}`;
}

// Atlas index -> {width, height, data (RGBA float32, row 0 on top), hdr (the file's name), texture};
// read: a file -> readHdr's answer (the composer's, which keeps the last few).
export function readAtlases(g, read = readHdr) {
  const atlases = new Map();
  (g.doc.textures || []).forEach((t, ti) => {
    const lm = t.extras && t.extras.lightmap;
    if (!lm || !lm.files || !lm.files.hdr) return;
    const img = read(path.join(g.dir, lm.files.hdr));
    atlases.set(lm.atlas, { width: img.width, height: img.height, data: img.data, hdr: lm.files.hdr, texture: ti });
  });
  return atlases;
}

// Every lightmapped node: {node, mesh, atlas, rects: [[sx, sy, ox, oy], ...] (one per copy)}.
function lightmappedNodes(g) {
  const out = [];
  (g.doc.nodes || []).forEach((n, i) => {
    const lm = n.extras && n.extras.lightmap;
    if (!lm || n.mesh === undefined) return;
    let rects;
    if (lm.scaleOffset) rects = [lm.scaleOffset];
    else {
      const inst = n.extensions && n.extensions.EXT_mesh_gpu_instancing;
      if (!inst || !inst.attributes._LIGHTMAP_SCALE) throw new Error(`node ${i}: no lightmap rectangle`);
      const s = accessor(g, inst.attributes._LIGHTMAP_SCALE), o = accessor(g, inst.attributes._LIGHTMAP_OFFSET);
      rects = [];
      for (let k = 0; k < s.length / 2; k++) rects.push([s[2 * k], s[2 * k + 1], o[2 * k], o[2 * k + 1]]);
    }
    out.push({ node: i, mesh: n.mesh, atlas: lm.atlas, rects });
  });
  return out;
}

// A mesh's lightmapped primitives: [{uv (TEXCOORD_1, flat), index (flat)}].
function meshUv1(g, mesh, cache) {
  if (!cache.has(mesh)) {
    cache.set(mesh, g.doc.meshes[mesh].primitives.filter((p) => p.attributes.TEXCOORD_1 !== undefined).map((p) => {
      const uv = accessor(g, p.attributes.TEXCOORD_1);
      const index = p.indices !== undefined ? accessor(g, p.indices) : Float64Array.from({ length: uv.length / 2 }, (_, k) => k);
      return { uv, index };
    }));
  }
  return cache.get(mesh);
}

const sameArray = (a, b) => a.length === b.length && a.every((x, i) => x === b[i]);

// A bake's layout as the map reads it (its lightmapped nodes, their rectangles and atlases, every
// TEXCOORD_1 and index), hashed: two quick looks with the same signature share one map.
export function layoutSignature(g) {
  const h = crypto.createHash('sha1'), nodes = lightmappedNodes(g), meshes = new Map();
  h.update(JSON.stringify(nodes));
  for (const n of nodes) {
    if (meshes.has(n.mesh)) continue;
    for (const p of meshUv1(g, n.mesh, meshes)) h.update(new Uint8Array(p.uv.buffer)).update(new Uint8Array(p.index.buffer));
  }
  return h.digest('hex');
}

// The map's recorder for one final atlas (dst) read from quick atlas qa: put(t, u, v) says
// final texel t reads the quick atlas at (u, v); a texel put again (two triangles' edges) keeps
// the last.
function recorder(dst, qa) {
  return (t, u, v) => {
    dst.u[t] = u;
    dst.v[t] = v;
    dst.qatlas[t] = qa;
    dst.covered[t] = 1;
  };
}

// Rasterises final triangle f (atlas uv, 6 numbers) into the final atlas: each covered texel
// centre reads the same barycentric point of quick triangle q.
function mapTriangle(f, q, dst, put) {
  const W = dst.width, H = dst.height;
  const ax = f[0] * W, ay = f[1] * H, bx = f[2] * W, by = f[3] * H, cx = f[4] * W, cy = f[5] * H;
  const det = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay);
  if (Math.abs(det) < 1e-12) return;
  const x0 = Math.max(Math.floor(Math.min(ax, bx, cx) - 0.5), 0), x1 = Math.min(Math.ceil(Math.max(ax, bx, cx) - 0.5), W - 1);
  const y0 = Math.max(Math.floor(Math.min(ay, by, cy) - 0.5), 0), y1 = Math.min(Math.ceil(Math.max(ay, by, cy) - 0.5), H - 1);
  const eps = 1e-9;
  for (let y = y0; y <= y1; y++) {
    for (let x = x0; x <= x1; x++) {
      const px = x + 0.5 - ax, py = y + 0.5 - ay;
      const l1 = (px * (cy - ay) - (cx - ax) * py) / det, l2 = ((bx - ax) * py - px * (by - ay)) / det;
      if (l1 < -eps || l2 < -eps || l1 + l2 > 1 + eps) continue;
      put(y * W + x, q[0] + l1 * (q[2] - q[0]) + l2 * (q[4] - q[0]), q[1] + l1 * (q[3] - q[1]) + l2 * (q[5] - q[1]));
    }
  }
}

// Every texel of a copy's final rectangle reads the same point of its quick rectangle (both bakes
// share the copy's TEXCOORD_1, so the map is the rectangles' affine map).
function mapRect(rf, rq, dst, put) {
  const W = dst.width, H = dst.height;
  const x0 = Math.max(Math.floor(rf[2] * W), 0), x1 = Math.min(Math.ceil((rf[2] + rf[0]) * W) - 1, W - 1);
  const y0 = Math.max(Math.floor(rf[3] * H), 0), y1 = Math.min(Math.ceil((rf[3] + rf[1]) * H) - 1, H - 1);
  for (let y = y0; y <= y1; y++) {
    for (let x = x0; x <= x1; x++) {
      const s = ((x + 0.5) / W - rf[2]) / rf[0], t = ((y + 0.5) / H - rf[3]) / rf[1];
      put(y * W + x, s * rq[0] + rq[2], t * rq[1] + rq[3]);
    }
  }
}

// The padding's plan: the uncovered texels next to covered ones take their covered neighbours'
// mean, ring by ring (PAD_PASSES rings); each ring reads only the texels covered before it, so the
// plan (texel k: pad.texel[k] is the mean of pad.from[pad.start[k] .. pad.start[k + 1]]) is
// applied in order, in place.
function padPlan(W, H, coveredIn) {
  const covered = Uint8Array.from(coveredIn), queued = new Uint8Array(W * H);
  const texel = [], start = [0], from = [];
  const around = (i, each) => {
    const x = i % W, y = (i - x) / W;
    for (let dy = -1; dy <= 1; dy++) {
      for (let dx = -1; dx <= 1; dx++) {
        const xx = x + dx, yy = y + dy;
        if (xx >= 0 && yy >= 0 && xx < W && yy < H) each(yy * W + xx);
      }
    }
  };
  let ring = [];
  for (let i = 0; i < W * H; i++) {
    if (covered[i]) continue;
    let next = false;
    around(i, (j) => { next = next || covered[j] === 1; });
    if (next) { ring.push(i); queued[i] = 1; }
  }
  for (let pass = 0; pass < PAD_PASSES && ring.length; pass++) {
    for (const i of ring) {
      around(i, (j) => { if (covered[j]) from.push(j); });
      texel.push(i);
      start.push(from.length);
    }
    for (const i of ring) covered[i] = 1;
    const next = [];
    for (const i of ring) around(i, (j) => { if (!covered[j] && !queued[j]) { queued[j] = 1; next.push(j); } });
    ring = next;
  }
  return { texel: Int32Array.from(texel), start: Int32Array.from(start), from: Int32Array.from(from) };
}

export function applyPad(pad, delta) {
  const { texel, start, from } = pad;
  for (let k = 0; k < texel.length; k++) {
    let r = 0, g = 0, b = 0;
    const s = start[k], e = start[k + 1];
    for (let m = s; m < e; m++) { const j = 3 * from[m]; r += delta[j]; g += delta[j + 1]; b += delta[j + 2]; }
    const n = e - s, t = 3 * texel[k];
    delta[t] = r / n; delta[t + 1] = g / n; delta[t + 2] = b / n;
  }
}

// The map from the final bake f's atlases to quick bake q's layout (layoutSignature): {atlases
// (the final's, readAtlases), byAtlas: final atlas -> {width, height, covered (1: a triangle's or
// copy's texel), u, v, qatlas (per texel: where in which quick atlas it reads, bilinearly; float32:
// 11 bytes a texel in all), pad (padPlan)}, quickSize: quick atlas -> [width, height]} or {why}
// when the bakes do not correspond.
export function buildMap(f, q, read) {
  const nf = lightmappedNodes(f), nq = lightmappedNodes(q);
  if (!(nf.length === nq.length && nf.every((x, i) => x.node === nq[i].node && x.mesh === nq[i].mesh && x.rects.length === nq[i].rects.length))) return { why: 'the bakes light different nodes' };
  const atlases = readAtlases(f, read), qAtlases = readAtlases(q, read);
  const build = new Map();
  for (const [a, img] of atlases) {
    const n = img.width * img.height;
    build.set(a, { width: img.width, height: img.height, covered: new Uint8Array(n), u: new Float32Array(n), v: new Float32Array(n), qatlas: new Uint16Array(n) });
  }
  const fMeshes = new Map(), qMeshes = new Map(), meshChecked = new Map();
  let triangles = 0;
  for (let k = 0; k < nf.length; k++) {
    const fn = nf[k], qn = nq[k];
    const dst = build.get(fn.atlas), qimg = qAtlases.get(qn.atlas);
    if (!dst || !qimg) return { why: `node ${fn.node}: an atlas has no .hdr` };
    const put = recorder(dst, qn.atlas);
    const fp = meshUv1(f, fn.mesh, fMeshes), qp = meshUv1(q, qn.mesh, qMeshes);
    if (!meshChecked.has(fn.mesh)) { // once per mesh: the nodes that share it share its answers
      if (fp.length !== qp.length) return { why: `mesh ${fn.mesh}: the bakes' primitives differ` };
      meshChecked.set(fn.mesh, fp.every((p, i) => sameArray(p.uv, qp[i].uv) && sameArray(p.index, qp[i].index)));
    }
    const shared = meshChecked.get(fn.mesh); // the same TEXCOORD_1 in the final and quick bakes
    const identity = fn.rects.length === 1 && sameArray(fn.rects[0], [1, 1, 0, 0]) && sameArray(qn.rects[0], [1, 1, 0, 0]);
    if (shared && !identity) {
      fn.rects.forEach((r, c) => mapRect(r, qn.rects[c], dst, put));
      continue;
    }
    for (let p = 0; p < fp.length; p++) {
      const { uv: fu, index: fi } = fp[p], { uv: qu, index: qi } = qp[p];
      if (fi.length !== qi.length) return { why: `mesh ${fn.mesh}: the bakes' triangles differ` };
      triangles += (fi.length / 3) * fn.rects.length;
      if (triangles > MAX_TRIANGLES) return { why: `more than ${MAX_TRIANGLES} placed triangles to map` };
      const tf = new Float64Array(6), tq = new Float64Array(6);
      for (let c = 0; c < fn.rects.length; c++) {
        const rf = fn.rects[c], rq = qn.rects[c];
        for (let t = 0; t < fi.length; t += 3) {
          for (let v = 0; v < 3; v++) {
            tf[2 * v] = fu[2 * fi[t + v]] * rf[0] + rf[2]; tf[2 * v + 1] = fu[2 * fi[t + v] + 1] * rf[1] + rf[3];
            tq[2 * v] = qu[2 * qi[t + v]] * rq[0] + rq[2]; tq[2 * v + 1] = qu[2 * qi[t + v] + 1] * rq[1] + rq[3];
          }
          mapTriangle(tf, tq, dst, put);
        }
      }
    }
  }
  const byAtlas = new Map();
  for (const [a, b] of build) {
    byAtlas.set(a, { ...b, pad: padPlan(b.width, b.height, b.covered) });
  }
  const quickSize = new Map([...qAtlases].map(([a, img]) => [a, [img.width, img.height]]));
  return { atlases, byAtlas, quickSize };
}

// value (3 numbers a final texel) += weight x quick bake g read through the map; {why} when g's
// atlases are not the map's sizes.
export function addQuick(map, g, weight, values, read) {
  const imgs = [];
  for (const [a, img] of readAtlases(g, read)) {
    const size = map.quickSize.get(a);
    if (!size || size[0] !== img.width || size[1] !== img.height) return { why: 'the quick looks have different atlases' };
    imgs[a] = img.data;
  }
  const qwOf = [], qhOf = [];
  for (const [qa, [w, h]] of map.quickSize) { qwOf[qa] = w; qhOf[qa] = h; }
  for (const [a, m] of map.byAtlas) {
    const { covered, u, v, qatlas } = m, out = values.get(a);
    for (let t = 0; t < covered.length; t++) {
      if (!covered[t]) continue;
      const qa = qatlas[t], d = imgs[qa];
      if (!d) return { why: 'the quick looks have different atlases' };
      const qw = qwOf[qa], qh = qhOf[qa];
      const x = Math.min(Math.max(u[t] * qw - 0.5, 0), qw - 1), y = Math.min(Math.max(v[t] * qh - 0.5, 0), qh - 1);
      const x0 = Math.floor(x), y0 = Math.floor(y), x1 = Math.min(x0 + 1, qw - 1), y1 = Math.min(y0 + 1, qh - 1);
      const fx = x - x0, fy = y - y0;
      const i0 = 4 * (y0 * qw + x0), i1 = 4 * (y0 * qw + x1), i2 = 4 * (y1 * qw + x0), i3 = 4 * (y1 * qw + x1);
      const w0 = (1 - fx) * (1 - fy), w1 = fx * (1 - fy), w2 = (1 - fx) * fy, w3 = fx * fy;
      for (let c = 0; c < 3; c++) out[3 * t + c] += weight * (w0 * d[i0 + c] + w1 * d[i1 + c] + w2 * d[i2 + c] + w3 * d[i3 + c]);
    }
  }
  return {};
}

export const zeros = (map) => new Map([...map.byAtlas].map(([a, m]) => [a, new Float64Array(3 * m.width * m.height)]));

// The weighted sum of quick bakes read at each texel of the final bake's atlases. f: the final
// (readBake); quicks: [{g (readBake), weight}] sharing one layout. Returns {atlases (the
// final's, readAtlases), mapped: atlas -> {value (3 numbers a texel), covered (1: a triangle's or
// copy's texel)}} or {why} when the bakes do not correspond.
export function mapQuicks(f, quicks) {
  const map = buildMap(f, quicks[0].g, readHdr);
  if (map.why) return map;
  const sig = layoutSignature(quicks[0].g);
  if (!quicks.slice(1).every((q) => layoutSignature(q.g) === sig)) return { why: 'the quick looks have different layouts' };
  const values = zeros(map);
  for (const q of quicks) {
    const r = addQuick(map, q.g, q.weight, values, readHdr);
    if (r.why) return r;
  }
  return { atlases: map.atlases, mapped: new Map([...map.byAtlas].map(([a, m]) => [a, { value: values.get(a), covered: m.covered }])) };
}
