#!/usr/bin/env node
// End-to-end test of the browser preview on a bake: starts tools/preview's server, opens the
// page in headless Chromium for each view mode, saves the screenshots and checks facts about
// their pixels against the bake's files (the .gltf's TEXCOORD_1 triangles, the .hdr/.exr).
//   usage: node tests/preview/preview_e2e.mjs BAKE_OUT_GLTF EXR_OR_HDR SHOTS_DIR
// (an .exr: the .hdr beside it, which the page shows, is checked against it first)
// Exit 0: every check passed; 1: a check failed (or the page did not load).
import fs from 'node:fs';
import path from 'node:path';
import { startServer } from '../../tools/preview/server.mjs';
import { launchBrowser, openPreview, showPreview, VIEWPORT } from '../../tools/preview/browser.mjs';
import { decodePng, readImage, lightmapTriangles, srgb, luma } from './lib.mjs';

const [gltfPath, imgPath, shotsDir] = process.argv.slice(2);
if (!shotsDir) { console.error('usage: node tests/preview/preview_e2e.mjs BAKE_OUT_GLTF EXR_OR_HDR SHOTS_DIR'); process.exit(1); }
const EV = -3, GAIN = 2 ** EV / Math.PI;           // lightmap-only: colour = E/pi x 2^EV, tonemap none
const BG = [20, 20, 40], BORDER = [255, 89, 0], MAGENTA = [255, 0, 255]; // page constants, sRGB 8-bit
// 8-bit output rounds to +-0.5 level; the GPU holds the .hdr as half floats (rel. 2^-11,
// < 0.13 level at 255) and bilinear weights at finite precision: 2 levels covers both with margin.
const TOL = 2;
const results = [];
const check = (name, ok, detail) => { results.push(ok); console.log(`${ok ? 'PASS' : 'FAIL'} ${name}: ${detail}`); };
const t0 = Date.now();

// The page draws the .hdr (MOZ_texture_rgbe): pixels are checked against it. Given the .exr
// (the accurate output), the .hdr beside it is checked against it too.
const hdrPath = imgPath.replace(/\.exr$/i, '.hdr'), hdrName = path.basename(hdrPath);
const img = readImage(hdrPath);
const tris = lightmapTriangles(gltfPath, hdrName);
const W = img.width, H = img.height;
const E = (x, y, c) => img.data[3 * (Math.min(H - 1, Math.max(0, y)) * W + Math.min(W - 1, Math.max(0, x))) + c];
const expectSrgb = (e) => srgb(e * GAIN);
if (hdrPath !== imgPath) {
  // RGBE shares one exponent: a channel loses up to one 8-bit mantissa step of the brightest
  // channel (1/128 of it), and three's decoding (m x 2^(e-128) / 255) adds up to 1/255
  const exr = readImage(imgPath), bound = 1 / 128 + 1 / 255;
  let worst = 0;
  for (let i = 0; i < W * H; i++) {
    const m = Math.max(exr.data[3 * i], exr.data[3 * i + 1], exr.data[3 * i + 2]);
    for (let c = 0; c < 3; c++) worst = Math.max(worst, Math.abs(img.data[3 * i + c] - exr.data[3 * i + c]) / (m || 1));
  }
  check('.hdr holds the .exr within RGBE precision', exr.width === W && exr.height === H && worst <= bound,
    `${exr.width}x${exr.height} vs ${W}x${H}; worst |hdr - exr| = ${worst.toFixed(4)} x the texel's brightest channel (bound ${bound.toFixed(4)})`);
}
const cov = coverage(tris, W, H);
console.log(`reference ${imgPath}: ${W}x${H}; ${tris.length} lightmapped triangles use ${hdrName}; ${cov.covered} texel centres covered, ${cov.empty} far from every triangle`);

fs.mkdirSync(shotsDir, { recursive: true });
const srv = await startServer(gltfPath);
const browser = await launchBrowser();
let failedToLoad = false;
let page0 = null; // every view after the first is the same page with other parameters (showPreview)
async function view(name, params) {
  params = { lightmap: 'hdr', ...params }; // the .hdr, which the checks read, even beside a KTX2
  const v = page0 ? await showPreview(page0, params) : (page0 = await openPreview(browser, srv.url, params));
  const file = path.join(shotsDir, `preview-${name}.png`);
  v.png = decodePng(await v.page.screenshot({ path: file }));
  console.log(`shot ${file} (${v.url.replace(srv.url, '/')})`);
  return v;
}
const patch = (png, x, y, r = 2) => { // mean RGB of a (2r+1)^2 patch
  const s = [0, 0, 0]; let n = 0;
  for (let j = -r; j <= r; j++) for (let i = -r; i <= r; i++) { const p = png.at(Math.round(x) + i, Math.round(y) + j); s[0] += p[0]; s[1] += p[1]; s[2] += p[2]; n++; }
  return s.map((v) => v / n);
};
const dist = (a, b) => Math.max(...a.map((v, i) => Math.abs(v - b[i])));

try {
  // --- 3D views: lit and lightmap-only, front camera, EV -3, tonemap none
  const lit = await view('lit', { mode: 'lit', ev: EV, tonemap: 'none', view: 'front' });
  const atlasIndex = lit.info.atlases.findIndex((a) => path.basename(a.hdr || a.uri) === hdrName);
  check('page knows the atlas', atlasIndex >= 0 && lit.info.atlases[atlasIndex].width === W && lit.info.atlases[atlasIndex].height === H,
    `atlases ${JSON.stringify(lit.info.atlases.map((a) => [a.uri, a.width, a.height]))}, reference ${hdrName} ${W}x${H}`);
  const atlas = lit.info.atlases[atlasIndex].index;
  const lm = await view('lightmap', { mode: 'lightmap', ev: EV, tonemap: 'none', view: 'front' });

  // (a) the hotspot (the brightest texel) is brighter than the floor's corners
  let hot = 0;
  for (let i = 1; i < W * H; i++) if (luma([E(i % W, i / W | 0, 0), E(i % W, i / W | 0, 1), E(i % W, i / W | 0, 2)]) > luma([E(hot % W, hot / W | 0, 0), E(hot % W, hot / W | 0, 1), E(hot % W, hot / W | 0, 2)])) hot = i;
  const hx = hot % W, hy = hot / W | 0;
  const hs = await lm.page.evaluate(([a, x, y]) => window.lmbTexelToScreen(a, x, y), [atlas, hx, hy]);
  const b = lm.info.bounds, d = 0.03;
  const corners = [];
  for (const [fx, fz] of [[0, 0], [1, 0], [0, 1], [1, 1]]) {
    const p = [b.min[0] + (fx ? 1 - d : d) * (b.max[0] - b.min[0]), b.min[1], b.min[2] + (fz ? 1 - d : d) * (b.max[2] - b.min[2])];
    const s = await lm.page.evaluate(([x, y, z]) => { const s = window.lmbProject(x, y, z); return { s, pick: window.lmbPick(Math.floor(s.x), Math.floor(s.y)) }; }, p);
    const seen = s.pick && Math.abs(s.pick.point[1] - b.min[1]) < 1e-3 * (b.max[1] - b.min[1] + 1e-9);
    corners.push({ p, s: s.s, seen, object: s.pick && s.pick.object });
  }
  const seenCorners = corners.filter((c) => c.seen);
  console.log(`hotspot texel (${hx}, ${hy}) E = ${E(hx, hy, 0).toFixed(1)} lux -> pixel (${hs && hs.x.toFixed(1)}, ${hs && hs.y.toFixed(1)}) visible ${hs && hs.visible} on ${hs && hs.object}; floor corners seen: ${seenCorners.length}/4 (${corners.map((c) => c.seen ? 'floor' : 'hidden by ' + c.object).join(', ')})`);
  for (const v of [lit, lm]) {
    const hl = hs && hs.visible ? luma(patch(v.png, hs.x, hs.y)) : NaN;
    const cl = seenCorners.map((c) => luma(patch(v.png, c.s.x, c.s.y)));
    check(`(a) ${v.info.mode}: ceiling hotspot brighter than the floor corners`, hs && hs.visible && seenCorners.length >= 2 && cl.every((c) => hl > c + 10),
      `hotspot luma ${hl.toFixed(1)} vs corners ${cl.map((c) => c.toFixed(1)).join(', ')} (8-bit levels; needs > corner + 10)`);
  }
  // (b) the lit view is not black
  let sum = 0; for (let i = 0; i < lit.png.width * lit.png.height; i++) sum += luma(lit.png.at(i % lit.png.width, i / lit.png.width | 0));
  const mean = sum / (lit.png.width * lit.png.height);
  check('(b) lit view is not black', mean > 30, `mean luma ${mean.toFixed(1)} of 255 over the whole ${lit.png.width}x${lit.png.height} shot (black background included; needs > 30)`);

  // (c) lightmap-only view at texels seen on screen: the pixel = sRGB(min(1, E_bilinear(uv1) / pi x 2^EV)),
  // E bilinear from the reference at the uv1 the pixel centre sees (three samples it LinearFilter, no mipmaps)
  const rng = lcg(7), cand = [];
  for (let i = 0; i < 20000 && cand.length < 1500; i++) { const x = rng() * W | 0, y = rng() * H | 0; if (cov.cls[y * W + x] === 2 && cov.dBorder[y * W + x] >= 3) cand.push([x, y]); }
  const probes = await lm.page.evaluate(([a, cand]) => cand.map(([x, y]) => {
    const s = window.lmbTexelToScreen(a, x, y);
    if (!s || !s.visible) return null;
    const px = Math.floor(s.x), py = Math.floor(s.y), c = window.lmbPick(px, py);
    // the 4 neighbours see the same object within 1.5 texels (not an edge, not a grazing angle)
    const same = c && [[1, 0], [-1, 0], [0, 1], [0, -1]].every(([i, j]) => {
      const n = window.lmbPick(px + i, py + j);
      return n && n.object === c.object && n.texel && Math.hypot(n.texel[0] - c.texel[0], n.texel[1] - c.texel[1]) <= 1.5;
    });
    return same && c.atlas === a ? { texel: [x, y], px, py, uv1: c.uv1, object: c.object } : null;
  }), [atlas, cand]).then((r) => r.filter(Boolean));
  let worst = 0, bad = 0, first = null, n = 0; const skipped = { clip: 0, edge: 0 };
  for (const p of probes) {
    const ex = [0, 1, 2].map((c) => expectSrgb(bilinear(p.uv1[0], p.uv1[1], c))), got = lm.png.at(p.px, p.py), e = dist(ex, got);
    if (Math.max(...ex) > 250 || Math.max(...ex) < 5) { skipped.clip++; continue; } // clipped at 1, or black: says little
    const tp = taps(p.uv1[0], p.uv1[1]);
    // at a shadow edge a 1/50-texel difference between where the rasterizer and the pick ray
    // sample moves the pixel by several levels: check smooth places (taps within 16 levels)
    if (Math.max(...tp) - Math.min(...tp) > 16) { skipped.edge++; continue; }
    n++; worst = Math.max(worst, e); if (e > TOL) { bad++; console.log(`  probe off: texel (${p.texel}) ${p.object} pixel (${p.px}, ${p.py}) uv1 (${p.uv1.map((v) => (v * W).toFixed(3))} texels): expected ${ex.map((v) => v.toFixed(1))}, got ${got}`); }
    if (!first) first = `texel (${p.texel}) on ${p.object} -> pixel (${p.px}, ${p.py}), uv1 (${p.uv1.map((v) => v.toFixed(5))}): expected sRGB ${ex.map((v) => v.toFixed(1))}, screenshot ${got}`;
  }
  check('(c) lightmap view pixel = sRGB(E/pi x 2^EV) at known texels', n >= 20 && bad === 0,
    `${n} probes (${cand.length} chart-interior texels tried, ${probes.length} seen head-on, ${skipped.clip} clipped or black, ${skipped.edge} at shadow edges), ${bad} off by > ${TOL} levels, worst ${worst.toFixed(2)}; e.g. ${first}`);

  // (c') atlas view, texel for texel (zoom 1, texelFetch): every pixel = sRGB(E/pi x 2^EV)
  const al = await view('atlas-lightmap', { mode: 'atlas', layer: 'lightmap', atlas, zoom: 1, ev: EV, tonemap: 'none' });
  const av = al.info.atlasView;
  n = 0; worst = 0; bad = 0;
  forTexels(av, (x, y, px, py) => { const e = dist([0, 1, 2].map((c) => expectSrgb(E(x, y, c))), al.png.at(px, py)); n++; worst = Math.max(worst, e); if (e > TOL) bad++; });
  check("(c') atlas view pixel = sRGB(E/pi x 2^EV) for every texel on screen", n > 0 && bad === 0, `${n} texels at origin (${av.originX}, ${av.originY}), ${bad} off by > ${TOL} levels, worst ${worst.toFixed(2)}`);

  // (d) checker in the atlas view: chart texels vs empty texels, texel parity, chart borders
  const ck = await view('atlas-checker', { mode: 'atlas', layer: 'checker', atlas, zoom: 1 });
  const ca = ck.info.atlasView, st = { empty: [0, 0], inside: [0, 0], parity: [0, 0], border: [0, 0], notBorder: [0, 0] };
  forTexels(ca, (x, y, px, py) => {
    const i = y * W + x, p = ck.png.at(px, py);
    if (cov.cls[i] === 0) { st.empty[0]++; if (dist(p, BG) > 1) st.empty[1]++; return; }
    if (cov.cls[i] !== 2) return;
    const db = cov.dBorder[i];
    if (db >= 2.5) {
      st.inside[0]++; if (dist(p, BG) <= 10) st.inside[1]++;
      st.notBorder[0]++; if (dist(p, BORDER) <= 10) st.notBorder[1]++;
      if (x % 8 !== 7 && x + 1 < W && cov.cls[i + 1] === 2 && cov.dBorder[i + 1] >= 2.5 && px + 1 < VIEWPORT.width) {
        const here = luma(p), right = luma(ck.png.at(px + 1, py)), even = (x + y) % 2 === 0;
        st.parity[0]++; if (!(even ? here > right + 20 : right > here + 20)) st.parity[1]++;
      }
    } else if (db >= 0.75 && db <= 1.25) { st.border[0]++; if (dist(p, BORDER) > 3) st.border[1]++; }
  });
  check('(d) checker: texels no triangle comes near show the background', st.empty[0] > 0 && st.empty[1] === 0, `${st.empty[1]} of ${st.empty[0]} differ from sRGB ${BG}`);
  check('(d) checker: texels inside a chart are drawn', st.inside[0] > 0 && st.inside[1] === 0, `${st.inside[1]} of ${st.inside[0]} chart-interior texels (>= 2.5 texels from a border) look like the background`);
  check('(d) checker: even texels (x+y) are lighter than their odd right neighbour', st.parity[0] > 0 && st.parity[1] === 0, `${st.parity[1]} of ${st.parity[0]} pairs wrong (needs 20 levels of luma)`);
  check('(d) checker: chart borders drawn where the unwrap put them', st.border[0] > 0 && st.border[1] === 0 && st.notBorder[1] === 0,
    `${st.border[1]} of ${st.border[0]} texels 0.75-1.25 texel inside a chart border are not sRGB ${BORDER}; ${st.notBorder[1]} of ${st.notBorder[0]} interior texels are`);

  // (e) invalid-texel view: magenta exactly where the stored irradiance is exactly 0
  const iv = await view('atlas-invalid', { mode: 'atlas', layer: 'invalid', atlas, zoom: 1, ev: EV, tonemap: 'none' });
  let zeros = 0, miss = 0, extra = 0;
  forTexels(iv.info.atlasView, (x, y, px, py) => {
    const z = E(x, y, 0) === 0 && E(x, y, 1) === 0 && E(x, y, 2) === 0, m = dist(iv.png.at(px, py), MAGENTA) <= 1;
    if (z) { zeros++; if (!m) miss++; } else if (m) extra++;
  });
  check('(e) invalid view: magenta = texels with E exactly 0', zeros > 0 && miss === 0 && extra === 0, `${zeros} zero texels on screen, ${miss} not magenta, ${extra} non-zero texels magenta`);

  // the 3D checker and invalid views load and show borders / magenta (screenshots for people)
  const c3 = await view('checker', { mode: 'checker', view: 'front' });
  const i3 = await view('invalid', { mode: 'invalid', ev: EV, tonemap: 'none', view: 'front' });
  const count = (png, col, tol) => { let k = 0; for (let i = 0; i < png.width * png.height; i++) if (dist(png.at(i % png.width, i / png.width | 0), col) <= tol) k++; return k; };
  const nb = count(c3.png, BORDER, 3), nm = count(i3.png, MAGENTA, 1);
  check('3D checker view shows chart borders', nb > 500, `${nb} border-coloured pixels (needs > 500); the 3D invalid view shows ${nm} magenta pixels (zero texels under geometry are hidden)`);
  // (f) records view: every record of the glTF's records file is known to the page; a record
  // the camera sees (a pick at its dot lands within 0.3 texel of it) is drawn as a dot in its
  // ramp colour (reach, log scale), over the lightmap view
  const rv = await view('records', { mode: 'records', ev: EV, tonemap: 'none', view: 'front' });
  const ref = JSON.parse(fs.readFileSync(gltfPath, 'utf8')).asset.extras.lmbake.irradianceCacheRecords;
  const binSize = fs.statSync(path.join(path.dirname(gltfPath), ref.uri)).size;
  check('(f) records view loads every record of the file', rv.info.records.count === ref.count && binSize === 16 * ref.count && ref.count > 0,
    `page ${rv.info.records.count}, glTF ${ref.count}, file ${binSize} bytes (16 per record)`);
  const texel = Math.max(...rv.info.bounds.max.map((v, i) => v - rv.info.bounds.min[i])) / 64; // bake.yaml: 64 texels per unit
  let seen = 0, own = 0, onRamp = 0, greyBefore = 0;
  const step = Math.max(1, Math.floor(ref.count / 600));
  // a dot: a saturated pixel (the ramp's colours, or two overlapping dots blended at their
  // antialiased edges); the lightmap view is near-grey there
  const isDot = (p) => Math.max(...p) - Math.min(...p) >= 100;
  for (let i = 0; i < ref.count; i += step) {
    const r = await rv.page.evaluate((k) => window.lmbRecord(k), i);
    const sp = await rv.page.evaluate((q) => window.lmbProject(q[0], q[1], q[2]), r.point);
    if (!sp.inFront || sp.x < 3 || sp.y < 3 || sp.x >= VIEWPORT.width - 3 || sp.y >= VIEWPORT.height - 3) continue;
    const h = await rv.page.evaluate((q) => window.lmbPick(q[0], q[1]), [Math.floor(sp.x), Math.floor(sp.y)]);
    // hidden behind something (a pixel is ~0.1 texel here: a record at a contact, seen past an edge, lands farther)
    if (!h || Math.hypot(...h.point.map((v, k) => v - r.point[k])) > 0.3 * texel) continue;
    seen++;
    const px = rv.png.at(Math.floor(sp.x), Math.floor(sp.y));
    if (dist(px, r.colour) <= TOL) own++;
    if (isDot(px)) onRamp++;
    if (!isDot(lm.png.at(Math.floor(sp.x), Math.floor(sp.y)))) greyBefore++;
  }
  check('(f) records view: a dot in a reach colour at every visible record', seen >= 100 && onRamp === seen && greyBefore === seen && own >= 0.5 * seen,
    `${seen} visible records sampled: ${onRamp} show a dot (${greyBefore} grey there in the lightmap view), ${own} in their own ramp colour (dots overlap where records crowd)`);
  for (const v of [lit, lm, al, ck, iv, c3, i3, rv]) {
    const late = v.errors.filter((e) => !e.startsWith('note'));
    if (late.length) check(`no page errors in ${v.url}`, false, late.join('; '));
  }
  if (page0) await page0.context.close();
} catch (e) {
  failedToLoad = true;
  check('preview loads and renders', false, e.message);
} finally {
  await browser.close();
  await srv.close();
}

const failed = results.filter((r) => !r).length;
console.log(`preview e2e: ${results.length - failed} passed, ${failed} failed (${((Date.now() - t0) / 1000).toFixed(1)} s)${failedToLoad ? ' (the page did not load)' : ''}`);
process.exit(failed ? 1 : 0);

// ---- helpers
function lcg(seed) { let s = seed >>> 0; return () => ((s = (Math.imul(s, 1664525) + 1013904223) >>> 0) / 4294967296); }

// three's LinearFilter with ClampToEdge: texel centres at (i + 0.5) / W
// sRGB levels of the 4 texels three's bilinear filter reads at (u, v), channel 0
function taps(u, v) { const x = Math.floor(u * W - 0.5), y = Math.floor(v * H - 0.5); return [E(x, y, 0), E(x + 1, y, 0), E(x, y + 1, 0), E(x + 1, y + 1, 0)].map((e) => srgb(e * GAIN)); }
function bilinear(u, v, c) {
  const x = u * W - 0.5, y = v * H - 0.5, x0 = Math.floor(x), y0 = Math.floor(y), fx = x - x0, fy = y - y0;
  return (E(x0, y0, c) * (1 - fx) + E(x0 + 1, y0, c) * fx) * (1 - fy) + (E(x0, y0 + 1, c) * (1 - fx) + E(x0 + 1, y0 + 1, c) * fx) * fy;
}

// Calls f(x, y, px, py) for each texel whose zoom-1 pixel is on screen
function forTexels(av, f) {
  if (av.zoom !== 1) throw new Error(`atlas view zoom ${av.zoom}, the checks need 1`);
  for (let y = 0; y < H; y++) for (let x = 0; x < W; x++) {
    const px = av.originX + x, py = av.originY + y;
    if (px >= 0 && py >= 0 && px < VIEWPORT.width && py < VIEWPORT.height) f(x, y, px, py);
  }
}

// Texel classes from the UV1 triangles: cls 2 = centre inside a triangle, 0 = no triangle's
// bounding box within 2 texels, 1 = near; dBorder = distance (texels) from the centre to the
// nearest chart-border edge (an edge only one triangle uses, corners welded by position + uv).
function coverage(tris, W, H) {
  const cls = new Uint8Array(W * H), dBorder = new Float32Array(W * H).fill(Infinity);
  const ids = new Map(), vid = (t, k) => { const key = [...t.pos.slice(3 * k, 3 * k + 3), ...t.uv.slice(2 * k, 2 * k + 2)].map((v) => Math.round(v * 1e6)).join(); if (!ids.has(key)) ids.set(key, ids.size); return ids.get(key); };
  const edges = new Map();
  for (const t of tris) {
    const v = [vid(t, 0), vid(t, 1), vid(t, 2)];
    for (let k = 0; k < 3; k++) {
      const a = v[k], b = v[(k + 1) % 3], key = a < b ? `${a},${b}` : `${b},${a}`;
      const e = edges.get(key) || { n: 0, p: [t.uv[2 * k] * W, t.uv[2 * k + 1] * H, t.uv[2 * ((k + 1) % 3)] * W, t.uv[2 * ((k + 1) % 3) + 1] * H] };
      e.n++; edges.set(key, e);
    }
    const X = [0, 2, 4].map((i) => t.uv[i] * W), Y = [1, 3, 5].map((i) => t.uv[i] * H);
    const x0 = Math.max(0, Math.floor(Math.min(...X) - 2)), x1 = Math.min(W - 1, Math.ceil(Math.max(...X) + 2));
    const y0 = Math.max(0, Math.floor(Math.min(...Y) - 2)), y1 = Math.min(H - 1, Math.ceil(Math.max(...Y) + 2));
    const area = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]);
    for (let y = y0; y <= y1; y++) for (let x = x0; x <= x1; x++) {
      const cx = x + 0.5, cy = y + 0.5, i = y * W + x;
      const w0 = (X[1] - cx) * (Y[2] - cy) - (X[2] - cx) * (Y[1] - cy), w1 = (X[2] - cx) * (Y[0] - cy) - (X[0] - cx) * (Y[2] - cy), w2 = (X[0] - cx) * (Y[1] - cy) - (X[1] - cx) * (Y[0] - cy);
      const inside = area !== 0 && (area > 0 ? w0 > 0 && w1 > 0 && w2 > 0 : w0 < 0 && w1 < 0 && w2 < 0);
      if (inside) cls[i] = 2; else if (cls[i] === 0) cls[i] = 1;
    }
  }
  for (const e of edges.values()) {
    if (e.n !== 1) continue;
    const [ax, ay, bx, by] = e.p;
    const x0 = Math.max(0, Math.floor(Math.min(ax, bx) - 3)), x1 = Math.min(W - 1, Math.ceil(Math.max(ax, bx) + 3));
    const y0 = Math.max(0, Math.floor(Math.min(ay, by) - 3)), y1 = Math.min(H - 1, Math.ceil(Math.max(ay, by) + 3));
    const dx = bx - ax, dy = by - ay, l2 = dx * dx + dy * dy || 1;
    for (let y = y0; y <= y1; y++) for (let x = x0; x <= x1; x++) {
      const t = Math.max(0, Math.min(1, ((x + 0.5 - ax) * dx + (y + 0.5 - ay) * dy) / l2));
      const d = Math.hypot(x + 0.5 - ax - t * dx, y + 0.5 - ay - t * dy);
      if (d < dBorder[y * W + x]) dBorder[y * W + x] = d;
    }
  }
  let covered = 0, empty = 0;
  for (let i = 0; i < W * H; i++) { if (cls[i] === 2) covered++; else if (cls[i] === 0) empty++; }
  return { cls, dBorder, covered, empty };
}
