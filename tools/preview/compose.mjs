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
// better on one and worse on the other. The quick looks are read at each final texel through
// bake-map.mjs's map (the same point of the same triangle in both bakes).
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
// 2.88%; watch_compose's moved corner lamp 3.12 -> 2.78%, its corner lamp x 2 2.02 -> 1.99%. (rho
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
import fs from 'node:fs';
import path from 'node:path';
import { addQuick, applyPad, buildMap, layoutSignature, readAtlases, readBake, stamp, zeros } from './bake-map.mjs';
import { encodeHdr, readHdr } from './hdr.mjs';

const KEEP_TEXELS = 8e6; // the composer keeps the quick look before read through its map up to this many final texels
const RHO_MAX = 4; // the most the quick look's detail is scaled up where the light rose
const RHO_REACH = 3; // a rise this many texels from a fall (a 7 x 7 square) is a moved light: rho 1
const RHO_FLOOR = 0.01; // added to both quick looks' luminance in rho, x the final's mean: dark texels' noise does not make rho
const HDR_KEPT = 8; // decoded .hdr files a composer keeps (the final's, the quick looks', the four direct lights')

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

function linkOrCopy(from, to) {
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
