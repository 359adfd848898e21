// The watch's composed quick picture (docs/watch.md#the-composed-quick-picture): after a change
// that keeps the layout, the quick look is shown as
//
//     rho final(before) + quick(after) - rho quick(before)
//
// in the final bake's atlas. final(before) - quick(before) is the detail the quick look misses
// (its resolution and noise); rho (detailScale) says how much of it the picture after keeps:
//   - where the change does not reach, rho = 1: the picture is the last final bake plus the
//     difference of the two quick looks (same layout, same seed: close to zero), at the final's
//     resolution and noise;
//   - where the light fell, rho = quick(after) / quick(before) (luminance): a lamp's old hot spot
//     leaves with its lamp instead of staying behind as a ghost (final(before)'s sharp spot minus
//     the quick look's blurred one), and a dimmed lamp's spot dims with its detail;
//   - where it rose, that ratio (at most RHO_MAX): a brighter lamp's spot keeps its shape at the
//     final's resolution; but 1 when a light moved (the caller says so: `moved`, the watch's
//     /status placesKept false): the detail there belongs to the light before; and 1 where the
//     light fell within RHO_REACH texels even when no light is said to have moved.
// On level-single-10 (Lamp 1 x 2, x 4, / 2, / 4, moved 2 m, and moved back) rho with the
// RHO_REACH rule alone took the 9 x 9-averaged error against the final from 7.3, 21.2, 7.7, 24.5,
// 12.3, 12.3% (rho = 1: the plain difference) to 2.0, 5.8, 1.3, 2.5, 10.1, 13.7%; rho 1 wherever
// a moved light's light rose: Lamp 1 moved from where it was 5.39 -> 5.20%, watch_compose's moved
// corner lamp 3.72 -> 3.51% (4.51% plain), while for a brighter lamp it would lose (2.40 -> 2.89%).
// Taking rho's least over the square where the light fell, or scaling up beside a fall, did
// better on one and worse on the other. The quick looks are read at each final texel through the
// triangles both bakes share (the unwrap keeps the input's triangles in order): the texel
// centre's barycentric coordinates in its final TEXCOORD_1 triangle, the same point in the
// quick bake's triangle, read bilinearly (tools/bench_watch.py's mapping). Copies that share one
// TEXCOORD_1 in both bakes map rectangle to rectangle instead. Texels no triangle covers (the
// atlas's padding) take the difference of a covered neighbour.
//
// Once the final bake of the change has its direct light (each bake of the watch writes the light
// of its stages as it goes, `lmbake bake --stages-out`), the picture is refined:
//
//     direct(after) + rho [final(before) - direct(before)]
//                   + [quick(after) - qdirect(after)] - rho [quick(before) - qdirect(before)]
//
// with qdirect the quick looks' direct light and direct the two final bakes': the direct light
// (lights, sky, emissive surfaces) is then taken at the final's resolution (texel for texel: the
// same layout), and only the rest, its bounced light, is composed as above, with rho from the
// quick looks' light less their direct light (the part it scales). A moved lamp's hot spot, a few
// texels wide, is what the quick look's resolution blurs. On level-single-10 against rho = 1
// (the refinement until then): Lamp 1 x 2 1.73 -> 0.85%, / 2 0.90 -> 0.47% (rho = 1 had left the
// refinement further from the final than the first picture, 1.60 and 0.79%), moved 3.29 ->
// 2.88%; watch_compose's moved corner lamp 3.12 -> 2.78%, its corner lamp x 2 2.03 -> 1.99%. (rho
// from the quick looks' whole light: 0.78, 0.47%, but 2.32% on the brighter corner lamp; rho
// that scales up a moved light's rises too: the moved lamp 3.90%.)
//
// Once the final bake has run its bounce passes, the picture is refined again to
//
//     final(before) + [bounces(after) - bounces(before)]
//
// with bounces the light the two final bakes' bounce passes reached (the direct light, its
// bounces and their extrapolated tail, before the final gather): texel for texel, no quick look.
// (rho = 1 here, whether or not a light moved: rho from the two bakes' bounced light took
// level-single-10's lamp x 2 from 0.58 to 0.53% and / 2 from 0.47 to 0.37%, the moved lamp 1.00%
// either way, but watch_compose's moved corner lamp from 0.76 to 2.20%; for a change that moves
// no light, bevy's Cornell box's emissive ceiling x 2 0.84 -> 0.40%, level-single-10's Lamp 1 x 2
// and / 2 unchanged (0.40, 0.34%), but watch_compose's corner lamp x 2 0.54 -> 0.80%.)
//
// compose(...) writes OUT: the final's glTF with its lightmap textures naming only the composed
// .hdr (no KTX2 or EXR: those are the old final's), the final's other files hard-linked (or
// copied), and the composed .hdr. It returns {ok: true, ms} or {ok: false, why} (then the quick
// look is shown as baked).
import crypto from 'node:crypto';
import fs from 'node:fs';
import path from 'node:path';
import { HDRLoader } from 'three/examples/jsm/loaders/HDRLoader.js';

const FLOAT_TYPE = 1015; // three's FloatType: HDRLoader decodes to float32 RGBA
const MAX_TRIANGLES = 5e6; // placed triangles mapped one by one at most (about 2 s here)
const PAD_PASSES = 8; // texels beyond the triangles filled from a neighbour, at most this far out
const KEEP_TEXELS = 8e6; // the composer keeps the quick look before read through its map up to this many final texels
const RHO_MAX = 4; // the most the quick look's detail is scaled up where the light rose
const RHO_REACH = 3; // a rise this many texels from a fall (a 7 x 7 square) is a moved light: rho 1
const RHO_FLOOR = 0.01; // added to both quick looks' luminance in rho, x the final's mean: dark texels' noise does not make rho
const HDR_KEPT = 8; // decoded .hdr files a composer keeps (the final's, the quick looks', the four direct lights')

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

// A Radiance .hdr as three's HDRLoader reads it for the page: {width, height, data (RGBA float32)}.
export function readHdr(file) {
  const bytes = fs.readFileSync(file);
  const loader = new HDRLoader();
  loader.setDataType(FLOAT_TYPE);
  return loader.parse(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.length));
}

// A file's identity for the composer's caches: path, inode, size and time.
function stamp(file) {
  const st = fs.statSync(file);
  return `${path.resolve(file)}:${st.ino}:${st.size}:${st.mtimeMs}`;
}

// Atlas index -> {width, height, data (RGBA float32, row 0 on top), hdr (the file's name), texture};
// read: a file -> readHdr's answer (the composer's, which keeps the last few).
function readAtlases(g, read = readHdr) {
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
function layoutSignature(g) {
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

function applyPad(pad, delta) {
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
function buildMap(f, q, read) {
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
function addQuick(map, g, weight, values, read) {
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

// The composed atlas as an .hdr: final + delta (padded beyond the triangles, plus the exact part
// when given), at least 0.
function composedHdr(img, pad, delta, exact) {
  applyPad(pad, delta);
  if (exact) for (let i = 0; i < delta.length; i++) delta[i] += exact[i];
  const rgba = new Float32Array(img.data.length), data = img.data;
  for (let i = 0, n = img.width * img.height; i < n; i++) {
    const o = 4 * i, t = 3 * i;
    rgba[o] = Math.max(data[o] + delta[t], 0);
    rgba[o + 1] = Math.max(data[o + 1] + delta[t + 1], 0);
    rgba[o + 2] = Math.max(data[o + 2] + delta[t + 2], 0);
    rgba[o + 3] = 1;
  }
  return encodeHdr(img.width, img.height, rgba);
}

// rho per final texel (the header above) from the two quick looks through the map (qa: the one
// after, qbNeg: minus the one before; 3 numbers a final texel): the ratio r of their luminance
// (each plus RHO_FLOOR x the final's mean, so that dark texels' noise does not make it; the mean
// kept in the map); where the light fell (r < 1) rho = r; where it rose, rho = min(r, RHO_MAX),
// or 1 when it fell at a texel within RHO_REACH (the light moved), or 1 wherever it rose when the
// caller knows a light moved (moved); 1 on uncovered texels. Returns atlas -> Float32Array.
const lum = (r, g, b) => 0.2126 * r + 0.7152 * g + 0.0722 * b;
function detailScale(map, qa, qbNeg, moved) {
  if (map.meanLum === undefined) {
    let sum = 0, n = 0;
    for (const [a, m] of map.byAtlas) {
      const d = map.atlases.get(a).data;
      for (let t = 0; t < m.covered.length; t++) if (m.covered[t]) { sum += lum(d[4 * t], d[4 * t + 1], d[4 * t + 2]); n++; }
    }
    map.meanLum = n ? sum / n : 0;
  }
  const floor = RHO_FLOOR * map.meanLum + 1e-30, scale = new Map();
  for (const [a, { width: W, height: H, covered }] of map.byAtlas) {
    const A = qa.get(a), B = qbNeg.get(a), N = W * H, rho = new Float32Array(N).fill(1), fell = new Uint8Array(N);
    for (let t = 0; t < N; t++) {
      if (!covered[t]) continue;
      const after = Math.max(lum(A[3 * t], A[3 * t + 1], A[3 * t + 2]), 0), before = Math.max(-lum(B[3 * t], B[3 * t + 1], B[3 * t + 2]), 0);
      rho[t] = (after + floor) / (before + floor);
      fell[t] = rho[t] < 1 ? 1 : 0;
      if (moved && rho[t] > 1) rho[t] = 1;
    }
    // texels with a fall within RHO_REACH (a (2 RHO_REACH + 1)^2 square): rows, then columns
    const rows = new Uint8Array(N);
    for (let y = 0; y < H; y++) for (let x = 0; x < W; x++) {
      let v = 0;
      for (let u = Math.max(0, x - RHO_REACH), e = Math.min(W - 1, x + RHO_REACH); u <= e && !v; u++) v = fell[y * W + u];
      rows[y * W + x] = v;
    }
    for (let y = 0; y < H; y++) for (let x = 0; x < W; x++) {
      const t = y * W + x;
      if (!covered[t] || rho[t] <= 1) continue;
      let v = 0;
      for (let u = Math.max(0, y - RHO_REACH), e = Math.min(H - 1, y + RHO_REACH); u <= e && !v; u++) v = rows[u * W + x];
      rho[t] = v ? 1 : Math.min(rho[t], RHO_MAX);
    }
    scale.set(a, rho);
  }
  return scale;
}

// The composed picture's change on the covered texels of the final's atlases (padded later, in
// composedHdr): (rho - 1) final + quick(after) - rho quick(before); refined with the direct light
// (q.qda, q.qdb and directBefore, the final's direct light before (readAtlases), given), with rho
// of quick - qdirect: (rho - 1) (final - direct(before)) + quick(after) - qdirect(after) - rho
// (quick(before) - qdirect(before)); the direct light's change, direct(after) - direct(before), is
// added after padding (directChange). q: {qa, qda, qdb} through the map (3 numbers a texel; q.qa
// becomes the change, in place); qbNeg: minus the quick look before through the map; moved: a
// light moved (detailScale).
function composedDelta(map, q, qbNeg, directBefore, moved) {
  const refined = !!q.qda, values = new Map();
  let rho;
  if (!refined) rho = detailScale(map, q.qa, qbNeg, moved);
  else { // rho of the quick looks' light less their direct light: the part it scales
    const rest = new Map(), restBeforeNeg = new Map();
    for (const [a] of map.byAtlas) {
      const A = q.qa.get(a), Bneg = qbNeg.get(a), QDA = q.qda.get(a), QDB = q.qdb.get(a);
      rest.set(a, A.map((v, i) => v - QDA[i]));
      restBeforeNeg.set(a, Bneg.map((v, i) => v + QDB[i]));
    }
    rho = detailScale(map, rest, restBeforeNeg, moved);
  }
  for (const [a, m] of map.byAtlas) {
    const A = q.qa.get(a), F = map.atlases.get(a).data, Bneg = qbNeg.get(a);
    if (refined) {
      const QDA = q.qda.get(a), QDB = q.qdb.get(a), DB = directBefore.get(a).data, p = rho.get(a);
      for (let t = 0; t < m.covered.length; t++) {
        if (!m.covered[t]) continue;
        for (let ch = 0, i = 3 * t; ch < 3; ch++, i++) A[i] = (p[t] - 1) * (F[4 * t + ch] - DB[4 * t + ch]) + A[i] - QDA[i] + p[t] * (Bneg[i] + QDB[i]);
      }
    } else {
      const p = rho.get(a);
      for (let t = 0; t < m.covered.length; t++) {
        if (!m.covered[t]) continue;
        for (let ch = 0; ch < 3; ch++) A[3 * t + ch] = (p[t] - 1) * F[4 * t + ch] + A[3 * t + ch] + p[t] * Bneg[3 * t + ch];
      }
    }
    values.set(a, A);
  }
  return values;
}

const zeros = (map) => new Map([...map.byAtlas].map(([a, m]) => [a, new Float64Array(3 * m.width * m.height)]));

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

// The direct light's change at the final's resolution: {change: direct(after) - direct(before), per
// final atlas (3 floats a texel), before: direct(before)'s atlases}, or {why} when their atlases
// are not the final's (da, db: the final's glTF with the direct-light folders' .hdr files).
function directChange(atlases, da, db, read) {
  const change = new Map();
  const [ia, ib] = [readAtlases(da, read), readAtlases(db, read)];
  for (const [a, img] of atlases) {
    const A = ia.get(a), B = ib.get(a);
    if (!A || !B || A.width !== img.width || A.height !== img.height || B.width !== img.width || B.height !== img.height) return { why: 'the direct light has other atlases' };
    const d = new Float32Array(3 * img.width * img.height);
    for (let i = 0, n = img.width * img.height; i < n; i++) for (let c = 0; c < 3; c++) d[3 * i + c] = A.data[4 * i + c] - B.data[4 * i + c];
    change.set(a, d);
  }
  return { change, before: ib };
}

// A Radiance .hdr (RGBE, each scanline run-length framed with literal runs only: what three's
// HDRLoader and OIIO read). Mantissas are rounded for three's decoding, byte x 2^(e-128) / 255
// (the page's reader), so an .hdr read by HDRLoader and written again keeps its bytes.
const POW2 = Float64Array.from({ length: 256 }, (_, k) => 2 ** (k - 128)); // 2^e at e + 128
const f64 = new Float64Array(1), u32 = new Uint32Array(f64.buffer); // a double's bits (little-endian)
export function encodeHdr(width, height, rgba) {
  const head = Buffer.from(`#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y ${height} +X ${width}\n`, 'ascii');
  const rle = width >= 8 && width < 32768;
  const perLine = rle ? 4 + 4 * (width + Math.ceil(width / 128)) : 4 * width;
  const out = Buffer.alloc(head.length + height * perLine);
  head.copy(out);
  let o = head.length;
  const line = new Uint8Array(4 * width);
  for (let y = 0; y < height; y++) {
    for (let x = 0; x < width; x++) {
      const i = (y * width + x) * 4;
      const r = Math.max(rgba[i], 0), g = Math.max(rgba[i + 1], 0), b = Math.max(rgba[i + 2], 0);
      const m = Math.max(r, g, b);
      if (!(m > 1e-32) || !Number.isFinite(m)) { line.fill(0, 4 * x, 4 * x + 4); continue; }
      // the smallest e with m <= 2^e, from the double's exponent: m = f 2^x, f in [0.5, 1)
      f64[0] = m;
      const hi = u32[1];
      let e = ((hi >>> 20) & 0x7ff) - 1022;
      if ((hi & 0xfffff) === 0 && u32[0] === 0) e--; // m is 2^(x - 1) exactly
      if (e > 127) e = 127;
      if (e < -127) e = -127;
      const scale = 255 / POW2[e + 128];
      line[4 * x] = Math.min(Math.round(r * scale), 255);
      line[4 * x + 1] = Math.min(Math.round(g * scale), 255);
      line[4 * x + 2] = Math.min(Math.round(b * scale), 255);
      line[4 * x + 3] = e + 128;
    }
    if (!rle) { out.set(line, o); o += 4 * width; continue; }
    out[o++] = 2; out[o++] = 2; out[o++] = width >> 8; out[o++] = width & 255;
    for (let c = 0; c < 4; c++) {
      for (let x = 0; x < width; x += 128) {
        const n = Math.min(128, width - x);
        out[o++] = n;
        for (let k = 0; k < n; k++) out[o++] = line[4 * (x + k) + c];
      }
    }
  }
  return out.subarray(0, o);
}

export function linkOrCopy(from, to) {
  try { fs.linkSync(from, to); } catch { fs.copyFileSync(from, to); }
}

// OUT (emptied) := the final bake f (read from folder final) with each atlas's .hdr given by
// hdrOf(atlas, img) (the bytes): its glTF naming only the .hdr and the PNG beside it (its KTX2
// and EXR are the old light), its other files linked (or copied).
function writeComposed(f, final, out, stem, atlases, hdrOf) {
  fs.rmSync(out, { recursive: true, force: true });
  fs.mkdirSync(out, { recursive: true });
  const hdrs = new Set([...atlases.values()].map((a) => a.hdr));
  for (const [a, img] of atlases) fs.writeFileSync(path.join(out, img.hdr), hdrOf(a, img));
  const doc = f.doc;
  const keep = (files) => Object.fromEntries(Object.entries(files).filter(([key]) => key === 'hdr' || key === 'png'));
  for (const t of doc.textures || []) if (t.extras && t.extras.lightmap && t.extras.lightmap.files) t.extras.lightmap.files = keep(t.extras.lightmap.files);
  for (const n of doc.nodes || []) if (n.extras && n.extras.lightmap && n.extras.lightmap.files) n.extras.lightmap.files = keep(n.extras.lightmap.files);
  fs.writeFileSync(path.join(out, `${stem}.gltf`), JSON.stringify(doc));
  for (const name of fs.readdirSync(final)) {
    if (name === `${stem}.gltf` || hdrs.has(name) || /\.(ktx2|exr)$/i.test(name)) continue;
    if (fs.statSync(path.join(final, name)).isFile()) linkOrCopy(path.join(final, name), path.join(out, name));
  }
}

// The watch's composer: compose() as below, keeping what the next composition on the same final
// bake reads again (the last few decoded .hdr files, the map to the quick layout and the quick
// look before the change read through it). prepare() builds those ahead, while the watch is idle
// after a final bake, so that the picture after the next change waits only for its own quick look.
export function createComposer() {
  const hdrKept = new Map();
  const read = (file) => {
    const key = stamp(file);
    if (hdrKept.has(key)) return hdrKept.get(key);
    const img = readHdr(file);
    hdrKept.set(key, img);
    if (hdrKept.size > HDR_KEPT) hdrKept.delete(hdrKept.keys().next().value);
    return img;
  };
  // layoutSignature by the bake's glTF stamp: the quick look before and the correction states are
  // the same files from one change to the next
  const sigKept = new Map();
  const signature = (g) => {
    const key = stamp(path.join(g.dir, `${g.stem}.gltf`));
    if (!sigKept.has(key)) {
      sigKept.set(key, layoutSignature(g));
      if (sigKept.size > 2 * HDR_KEPT) sigKept.delete(sigKept.keys().next().value);
    }
    return sigKept.get(key);
  };
  let kept = null; // {key, sig, map, before: {key, values}}: the last final and quick layout's map
  const mapFor = (f, q) => {
    const sig = signature(q), key = `${stamp(path.join(f.dir, `${f.stem}.gltf`))}|${sig}`;
    if (kept && kept.key === key) return kept;
    const map = buildMap(f, q, read);
    if (map.why) return map;
    kept = { key, sig, map, before: null };
    return kept;
  };
  // -(quick look before) through the map, kept by its files' stamps (up to KEEP_TEXELS final
  // texels: 24 bytes each)
  const before = (k, qb) => {
    const key = [...readAtlases(qb, () => ({}))].map(([, x]) => stamp(path.join(qb.dir, x.hdr))).join('|');
    if (!k.before || k.before.key !== key) {
      const values = zeros(k.map);
      const r = addQuick(k.map, qb, -1, values, read);
      if (r.why) return r;
      const texels = [...k.map.byAtlas.values()].reduce((n, m) => n + m.width * m.height, 0);
      if (texels > KEEP_TEXELS) return { values };
      k.before = { key, values };
    }
    return { values: k.before.values };
  };

  // final: the last final bake's folder; quickBefore: its quick look's; quickAfter: the new quick
  // look's; out: the folder to write (made here). stem: the level's file name without extension.
  // direct (optional): {before, after, quickBefore, quickAfter}, the folders of the direct light
  // (`lmbake bake --stages-out`'s direct stage) of the last final bake, of this change's final bake and of the
  // two quick looks: each the .hdr files of its bake's atlases, read with that bake's glTF. moved:
  // the change moved a light, or the caller cannot tell that it did not (rho is then 1 wherever
  // the light rose: detailScale).
  function compose({ final, quickBefore, quickAfter, out, stem, direct = null, moved = true }) {
    const t0 = Date.now();
    let f, qb, qa, c = null, k, base;
    try {
      [f, qb, qa] = [final, quickBefore, quickAfter].map((d) => readBake(d, stem));
      // a direct-light folder is its bake's atlases: the bake's glTF, the folder's .hdr files
      if (direct) c = { quickDirectAfter: { ...qa, dir: direct.quickAfter }, quickDirectBefore: { ...qb, dir: direct.quickBefore }, directAfter: { ...f, dir: direct.after }, directBefore: { ...f, dir: direct.before } };
      k = mapFor(f, qb);
      if (k.why) return { ok: false, why: k.why };
      if (signature(qa) !== k.sig) return { ok: false, why: 'the quick looks have different layouts' };
      base = before(k, qb);
    } catch (e) {
      return { ok: false, why: `cannot read a bake (${e.message})` };
    }
    if (base.why) return { ok: false, why: base.why };
    // the quick looks (and their direct light) through the map: minus the one before (kept), the others as read
    const mapped = { qa: zeros(k.map), qda: c && zeros(k.map), qdb: c && zeros(k.map) };
    for (const [g, into] of [[qa, mapped.qa], ...(c ? [[c.quickDirectAfter, mapped.qda], [c.quickDirectBefore, mapped.qdb]] : [])]) {
      let r;
      try { r = addQuick(k.map, g, 1, into, read); } catch (e) { r = { why: `cannot read a quick look's light (${e.message})` }; }
      if (r.why) return { ok: false, why: r.why };
    }
    let exactPart = { change: null, before: null };
    try {
      if (c) exactPart = directChange(k.map.atlases, c.directAfter, c.directBefore, read);
    } catch (e) {
      return { ok: false, why: `cannot read the direct light (${e.message})` };
    }
    if (exactPart.why) return { ok: false, why: exactPart.why };
    const values = composedDelta(k.map, mapped, base.values, exactPart.before, moved);
    writeComposed(f, final, out, stem, k.map.atlases, (a, img) => composedHdr(img, k.map.byAtlas.get(a).pad, values.get(a), exactPart.change && exactPart.change.get(a)));
    return { ok: true, ms: Date.now() - t0 };
  }

  // The picture once the final bake of the change has run its bounce passes: final(before) +
  // [bounces(after) - bounces(before)], texel for texel in the final's layout (bounces: the
  // light the bounce passes reached, `lmbake bake --stages-out`, of the last final bake and of the
  // running one: no quick look). final, out, stem as for compose(); before, after: the two
  // bounces folders. {ok, ms} or {ok: false, why}.
  function composeBounces({ final, out, stem, before, after }) {
    const t0 = Date.now();
    let f, atlases, A, B;
    try {
      f = readBake(final, stem);
      atlases = readAtlases(f, read);
      [A, B] = [after, before].map((dir) => readAtlases({ ...f, dir }, read));
    } catch (e) {
      return { ok: false, why: `cannot read the bounced light (${e.message})` };
    }
    for (const [a, img] of atlases) {
      const x = A.get(a), y = B.get(a);
      if (!x || !y || x.width !== img.width || x.height !== img.height || y.width !== img.width || y.height !== img.height) return { ok: false, why: 'the bounced light has other atlases' };
    }
    writeComposed(f, final, out, stem, atlases, (a, img) => {
      const x = A.get(a).data, y = B.get(a).data, rgba = new Float32Array(img.data.length);
      for (let i = 0; i < rgba.length; i += 4) {
        for (let c = 0; c < 3; c++) rgba[i + c] = Math.max(img.data[i + c] + x[i + c] - y[i + c], 0);
        rgba[i + 3] = 1;
      }
      return encodeHdr(img.width, img.height, rgba);
    });
    return { ok: true, ms: Date.now() - t0 };
  }

  // What the next compose() on this final and quick look reads again, built now: {ok, ms} or
  // {ok: false, why}.
  function prepare({ final, quickBefore, stem }) {
    const t0 = Date.now();
    try {
      const [f, qb] = [final, quickBefore].map((d) => readBake(d, stem));
      const k = mapFor(f, qb);
      const r = k.why ? k : before(k, qb);
      if (r.why) return { ok: false, why: r.why };
      // the final as composed on a change of nothing, thrown away: node compiles the loops the
      // picture after the next change runs (0.3 -> 0.2 s on level-single-10)
      const values = composedDelta(k.map, { qa: zeros(k.map) }, r.values, null, false);
      for (const [a, img] of k.map.atlases) composedHdr(img, k.map.byAtlas.get(a).pad, values.get(a), null);
      return { ok: true, ms: Date.now() - t0 };
    } catch (e) {
      return { ok: false, why: `cannot read a bake (${e.message})` };
    }
  }
  return { compose, composeBounces, prepare };
}

// One composition with nothing kept (createComposer's compose).
export function compose(args) {
  return createComposer().compose(args);
}

// One bounced-light composition with nothing kept (createComposer's composeBounces).
export function composeBounces(args) {
  return createComposer().composeBounces(args);
}
