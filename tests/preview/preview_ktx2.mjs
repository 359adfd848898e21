#!/usr/bin/env node
// KTX2 lightmaps and lightmap rectangles in the preview (loaders/three/lmbake-three.js):
//   usage: node tests/preview/preview_ktx2.mjs BAKE_GLTF KEEP_UV1_GLTF SHOTS_DIR
// BAKE_GLTF: a bake with output.formats [..., hdr, ktx2], whose lightmap textures name both
// files in extras.lightmap.files. The lit and lightmap views are shot with ?lightmap=hdr and
// ?lightmap=ktx2 from one camera and must agree (8-bit, bounds below); the page must say it
// read the KTX2 files with three's KTX2Loader (lmbInfo.atlases[i].loader, format "... (KTX2Loader)",
// gpu: the loader's texture or half floats), loaded KTX2Loader.js from node_modules and fetched
// no Basis transcoder (libs/basis/) and nothing off the server; the float texels it decoded from
// the loader's texture must equal the .hdr's within both formats' precision (E5B9G9R9: 2^-7 +
// 2^-9 of the texel's largest channel; below). A copy of the bake whose KTX2 says vkFormat 0
// (Basis) must fall back to the .hdr, fetching no transcoder either.
// KEEP_UV1_GLTF: a bake with atlas.keep_uv1, every node a rectangle of a shared atlas (node
// extras.lightmap.scaleOffset = its material's MOZ_lightmap KHR_texture_transform). At pixels of
// the lightmap view the colour must be sRGB(E x intensity / pi x 2^EV), E read bilinearly from
// the .hdr at uv1 x scale + offset (the rectangle from the glTF, not from the page); the page's
// pick must name that texel, the invalid view must show the same colour there, lmbTexelToScreen
// must find the texel on its node, and the atlas view's checker must draw it as the 3D checker
// view draws the pixel (both place the node's triangles at its rectangle).
// Exit 0: every check passed; 1: a check failed (or a page did not load).
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { startServer } from '../../tools/preview/server.mjs';
import { launchBrowser, openPreview, previewPages } from '../../tools/preview/browser.mjs';
import { decodePng, readHdr, srgb } from './lib.mjs';

const [bakeGltf, keepGltf, shotsDir] = process.argv.slice(2);
if (!shotsDir) { console.error('usage: node tests/preview/preview_ktx2.mjs BAKE_GLTF KEEP_UV1_GLTF SHOTS_DIR'); process.exit(1); }
// Shots from the two sources, per pixel and channel (8-bit). On a texel's largest channel the
// two files differ by under 2^-8 + 2^-9 of it (RGBE: an 8-bit mantissa, truncated, decoded by
// three as m/255; E5B9G9R9: 9 bits, rounded), about 0.6%: through sRGB (255 x 1.055/2.4 x^0.42
// levels per relative unit, <= 112) that is under 0.7 level, plus one level where the two land
// on either side of an 8-bit rounding point: within PIX_TOL = 2. A channel far below the
// texel's largest one (green and blue beside a red wall's red) shares its exponent and is off by
// up to 2^-7 + 2^-9 of the largest one (see the texels below), which near black in sRGB (slope
// 12.92 x 255) is several levels (about 25 at worst, a saturated primary beside 0). Those
// pixels are few. Measured on bevy's Cornell box: lit view at most 2 levels; lightmap view 4 on
// a dim channel, 0.03% of pixels over 2 (keep_uv1 bake: 6, 0.05%). Bounds: at most PIX_FRAC of
// the pixels over PIX_TOL, none over PIX_MAX.
const PIX_TOL = 2, PIX_FRAC = 0.002, PIX_MAX = 8;
// Texels, per channel: |ktx2 - hdr| <= 2^-7 x M (M the texel's largest channel) + the KTX2
// format's rounding. The .hdr's part: RGBE truncates to 8-bit mantissas of M's exponent (M's
// mantissa >= 128) and three decodes m x 2^(e-128) / 255, so a channel is off by up to one
// step, 2^-8 x 2^(e-128) <= 2^-7 x M (a channel just under one step read as 0). The KTX2's,
// rounded to nearest: E5B9G9R9 half a step of 9 bits, <= 2^-9 x M (M's mantissa >= 256);
// B10G11R11 half a step of its own 6/6/5-bit mantissa, 2^-7 / 2^-7 / 2^-6 x the channel;
// RGBA16F 2^-11 x the channel. Texels whose M is below FLOOR lux are not compared (E5B9G9R9's
// smallest exponent, steps of 2^-24, and the small floats' subnormals lose those bits), but
// exactly 0 in the .hdr (an invalid texel) must be exactly 0 in the KTX2.
const FLOOR = 2 ** -10;
const ktxRounding = (format, c, v, m) => /^E5B9G9R9/.test(format) ? 2 ** -9 * m : /^B10G11R11/.test(format) ? (c === 2 ? 2 ** -6 : 2 ** -7) * v : 2 ** -11 * v;
// The keep_uv1 probes: as preview_e2e.mjs (8-bit rounding 0.5; half floats on the GPU and the
// filter's precision stay under 0.5 more)
const TOL = 2;
const ATLAS_BG = [20, 20, 40]; // atlas-view.js ATLAS_BACKGROUND, sRGB

const results = [];
const check = (name, ok, detail) => { results.push(ok); console.log(`${ok ? 'PASS' : 'FAIL'} ${name}: ${detail}`); };
const t0 = Date.now();
fs.mkdirSync(shotsDir, { recursive: true });
const browser = await launchBrowser();
let failedToLoad = false;
try {
  await sourcesAgree(bakeGltf);
  await rectangles(keepGltf);
} catch (e) {
  failedToLoad = true;
  check('preview loads and renders', false, e.stack || e.message);
} finally {
  await browser.close();
}
const failed = results.filter((r) => !r).length;
console.log(`preview ktx2: ${results.length - failed} passed, ${failed} failed (${((Date.now() - t0) / 1000).toFixed(1)} s)${failedToLoad ? ' (a page did not load)' : ''}`);
process.exit(failed ? 1 : 0);

// ---- case 1: the .hdr and the KTX2 of one bake look the same
async function sourcesAgree(gltfPath) {
  const g = JSON.parse(fs.readFileSync(gltfPath, 'utf8'));
  const lm = lightmapTextures(g);
  const named = lm.filter((t) => t.extras && t.extras.files && t.extras.files.ktx2 && t.extras.files.hdr);
  check('the glTF names a .hdr and a KTX2 per lightmap texture (extras.lightmap.files)', lm.length > 0 && named.length === lm.length,
    `${named.length} of ${lm.length} lightmap textures (${lm.map((t) => `texture ${t.index}: ${JSON.stringify(t.extras && t.extras.files)}`).join('; ')})`);
  if (!named.length) return;
  const srv = await startServer(gltfPath);
  try {
    const pages = previewPages(browser, srv.url); // a page per lightmap source
    const first = await pages.show({ mode: 'lightmap', tonemap: 'none', view: 'front', lightmap: 'hdr' });
    const ev = first.info.ev; // ev auto of the .hdr, for every shot
    const shots = {};
    for (const mode of ['lit', 'lightmap']) for (const src of ['hdr', 'ktx2']) {
      const v = await pages.show({ mode, ev, tonemap: 'none', view: 'front', lightmap: src });
      const file = path.join(shotsDir, `preview-ktx2-${mode}-${src}.png`);
      shots[`${mode}-${src}`] = { ...v, png: decodePng(await v.page.screenshot({ path: file })) };
      console.log(`shot ${file} (${v.url.replace(srv.url, '/')})`);
    }
    // the page says which files it read, and with which three.js loader
    for (const src of ['hdr', 'ktx2']) {
      const a = shots[`lit-${src}`].info.atlases;
      const want = named.map((t) => ({ atlas: t.extras.atlas, uri: t.extras.files[src] }));
      const loader = src === 'ktx2' ? 'KTX2Loader' : 'HDRLoader';
      const ok = a.length === named.length && a.every((x) => x.source === src && want.some((w) => w.uri === x.uri) &&
        x.loader === loader && x.format.endsWith(`(${loader})`) && !x.fallback);
      check(`lightmap=${src}: the page read the ${src === 'ktx2' ? 'KTX2' : '.hdr'} files with ${loader}`, ok,
        `lmbInfo.lightmap ${shots[`lit-${src}`].info.lightmap}; atlases ${JSON.stringify(a.map((x) => ({ index: x.index, source: x.source, uri: x.uri, format: x.format, loader: x.loader, gpu: x.gpu, fallback: x.fallback })))}`);
    }
    for (const mode of ['lit', 'lightmap']) await ktx2LoaderOnly(shots[`${mode}-ktx2`], srv.url, `lightmap=ktx2 ${mode} view`, true);
    // the shots agree
    for (const mode of ['lit', 'lightmap']) {
      const d = diff(shots[`${mode}-hdr`].png, shots[`${mode}-ktx2`].png);
      check(`${mode} view: lightmap=ktx2 shot = lightmap=hdr shot`, d.over <= PIX_FRAC * d.n && d.max.every((m) => m <= PIX_MAX),
        `EV ${ev}, tonemap none, ${d.n} pixels; per channel R G B: max |diff| ${d.max.join(' ')}, mean ${d.mean.map((m) => m.toFixed(4)).join(' ')} levels; ` +
        `${d.over} pixels (${(100 * d.over / d.n).toFixed(3)}%) off by > ${PIX_TOL} (allowed ${(100 * PIX_FRAC).toFixed(1)}%, none > ${PIX_MAX})${d.worst ? `; worst at (${d.worst.x}, ${d.worst.y}): hdr ${d.worst.a}, ktx2 ${d.worst.b}` : ''}`);
    }
    // the float texels agree
    const hp = shots['lit-hdr'].page, kp = shots['lit-ktx2'].page;
    for (const a of shots['lit-ktx2'].info.atlases) {
      const h = await atlasData(hp, a.index), k = await atlasData(kp, a.index);
      let n = 0, bad = 0, worst = 0, worstRel = 0, zeroHdr = 0, zeroMiss = 0, tiny = 0, first = null;
      if (h.width === k.width && h.height === k.height) {
        for (let i = 0; i < h.width * h.height; i++) {
          const o = 4 * i, m = Math.max(h.data[o], h.data[o + 1], h.data[o + 2]);
          if (m === 0) { zeroHdr++; if (k.data[o] || k.data[o + 1] || k.data[o + 2]) zeroMiss++; continue; }
          if (m < FLOOR) { tiny++; continue; }
          n++;
          for (let c = 0; c < 3; c++) {
            const d = Math.abs(k.data[o + c] - h.data[o + c]), bound = 2 ** -7 * m + ktxRounding(a.format, c, h.data[o + c], m);
            if (d / bound > worst) { worst = d / bound; worstRel = d / m; }
            if (d > bound) { bad++; first ||= `texel (${i % h.width}, ${i / h.width | 0}): hdr ${Array.from(h.data.subarray(o, o + 3))}, ktx2 ${Array.from(k.data.subarray(o, o + 3))}`; }
          }
        }
      }
      check(`atlas ${a.index}: KTX2 texels = .hdr texels within both formats' precision`, h.width === k.width && h.height === k.height && n > 0 && bad === 0 && zeroMiss === 0,
        `${k.uri} (${a.format}) ${k.width}x${k.height} vs ${h.uri} ${h.width}x${h.height}: ${n} texels >= ${FLOOR} lux; worst |ktx2 - hdr| = ${worst.toFixed(3)} x the bound ` +
        `(2^-7 x the largest channel + the KTX2's rounding), there 2^${Math.log2(worstRel || 2 ** -99).toFixed(2)} x the largest channel; ${bad} channels over${first ? ' (first ' + first + ')' : ''}; ` +
        `${zeroHdr} texels 0 in the .hdr (${zeroMiss} not 0 in the KTX2), ${tiny} below the floor`);
    }
    await pages.close();
  } finally {
    await srv.close();
  }
  await fallback(gltfPath, named);
}

// The resources a page fetched (performance entries, the page's own module scripts included):
// KTX2Loader.js from node_modules through the server, no Basis transcoder, nothing elsewhere
async function ktx2LoaderOnly(v, base, what, wantKtx2) {
  const urls = await v.page.evaluate(() => [location.href, ...performance.getEntriesByType('resource').map((e) => e.name)]);
  const origin = new URL(base).origin;
  const foreign = urls.filter((u) => !u.startsWith(origin + '/') && !u.startsWith('data:') && !u.startsWith('blob:'));
  const basis = urls.filter((u) => /\/libs\/basis\//.test(u));
  const loaderJs = urls.some((u) => u === origin + '/three/examples/jsm/loaders/KTX2Loader.js');
  const ktx2 = urls.filter((u) => /\.ktx2$/.test(u));
  check(`${what}: KTX2Loader.js from node_modules, ${wantKtx2 ? 'the KTX2 read, ' : ''}no Basis transcoder, nothing from elsewhere`,
    loaderJs && basis.length === 0 && foreign.length === 0 && (ktx2.length > 0) === wantKtx2 && v.info.atlases.every((a) => !a.gpu || /^(RGB9_E5|R11F_G11F_B10F|RGBA16F)\b/.test(a.gpu)),
    `${urls.length} resources; KTX2Loader.js ${loaderJs ? 'loaded' : 'NOT loaded'}; KTX2 files ${ktx2.map((u) => path.basename(u)).join(', ') || 'none'}; ` +
    `transcoder files ${basis.join(', ') || 'none'}; off the server ${foreign.join(', ') || 'none'}; on the GPU ${v.info.atlases.map((a) => a.gpu).join(', ')}`);
}

// A copy of the bake whose KTX2 files say vkFormat 0 (Basis, which KTX2Loader would transcode
// with its worker): the page must not hand them to the loader but fall back to the .hdr
async function fallback(gltfPath, named) {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'lmb-ktx2-fallback-'));
  try {
    fs.cpSync(path.dirname(gltfPath), dir, { recursive: true });
    for (const t of named) {
      const f = path.join(dir, decodeURIComponent(t.extras.files.ktx2)), b = fs.readFileSync(f);
      b.writeUInt32LE(0, 12); // vkFormat: VK_FORMAT_UNDEFINED (Basis Universal)
      fs.writeFileSync(f, b);
    }
    const srv = await startServer(path.join(dir, path.basename(gltfPath)));
    try {
      const v = await openPreview(browser, srv.url, { mode: 'lightmap', tonemap: 'none', view: 'front', lightmap: 'ktx2' });
      const a = v.info.atlases;
      check('lightmap=ktx2, a KTX2 of vkFormat 0: the page falls back to the .hdr', a.length === named.length &&
        a.every((x) => x.source === 'hdr' && x.loader === 'HDRLoader' && /vkFormat 0 is not a lightmap format/.test(x.fallback || '')),
        `atlases ${JSON.stringify(a.map((x) => ({ index: x.index, source: x.source, uri: x.uri, loader: x.loader, fallback: x.fallback })))}`);
      await ktx2LoaderOnly(v, srv.url, 'lightmap=ktx2, a KTX2 of vkFormat 0', true);
      await v.context.close();
    } finally {
      await srv.close();
    }
  } finally {
    fs.rmSync(dir, { recursive: true, force: true });
  }
}

// ---- case 2: a keep_uv1 bake's nodes show their own rectangle of the shared atlas
async function rectangles(gltfPath) {
  const g = JSON.parse(fs.readFileSync(gltfPath, 'utf8')), dir = path.dirname(gltfPath);
  const texById = new Map(lightmapTextures(g).map((t) => [t.index, t]));
  // node -> {scaleOffset, atlas texture, intensity}; its materials' transform must be the same rectangle
  const nodes = new Map(); const mismatch = [];
  g.nodes.forEach((node, i) => {
    const x = node.extras && node.extras.lightmap;
    if (!x || node.mesh === undefined) return;
    for (const p of g.meshes[node.mesh].primitives) {
      const m = p.material !== undefined && g.materials[p.material], ext = m && m.extensions && m.extensions.MOZ_lightmap;
      if (!ext) continue;
      const tt = (ext.extensions && ext.extensions.KHR_texture_transform) || {};
      const so = [...(tt.scale || [1, 1]), ...(tt.offset || [0, 0])];
      if (so.some((v, k) => Math.abs(v - x.scaleOffset[k]) > 1e-9)) mismatch.push(`node ${i} '${node.name}': extras ${x.scaleOffset}, material ${p.material} ${so}`);
      nodes.set(i, { name: node.name, so: x.scaleOffset, texture: ext.index, intensity: ext.intensity ?? 1 });
    }
  });
  const rects = [...nodes.values()];
  const shared = rects.filter((r) => r.so.join() !== '1,1,0,0' && rects.some((q) => q !== r && q.texture === r.texture));
  check('keep_uv1 bake: nodes are rectangles of a shared atlas, node extras = material KHR_texture_transform', shared.length >= 2 && mismatch.length === 0,
    `${nodes.size} nodes with extras.lightmap, ${shared.length} share an atlas with another at a rectangle other than the whole; ${mismatch.length ? 'mismatch: ' + mismatch.join('; ') : 'every material agrees'}`);
  if (!shared.length) return;
  const hdrs = new Map();
  for (const t of texById.values()) {
    const uri = t.extras && t.extras.files && t.extras.files.hdr;
    if (uri) hdrs.set(t.index, { ...readHdr(path.join(dir, decodeURIComponent(uri))), uri });
  }
  const srv = await startServer(gltfPath);
  try {
    const views = {}, pages = previewPages(browser, srv.url); // a page per lightmap source
    for (const [name, params] of [['lightmap-hdr', { mode: 'lightmap', lightmap: 'hdr' }], ['lightmap-ktx2', { mode: 'lightmap', lightmap: 'ktx2' }], ['invalid-hdr', { mode: 'invalid', lightmap: 'hdr' }]]) {
      const ev = views['lightmap-hdr'] ? views['lightmap-hdr'].info.ev : 'auto';
      const v = await pages.show({ ...params, ev, tonemap: 'none', view: 'front' });
      const file = path.join(shotsDir, `preview-keep-uv1-${name}.png`);
      views[name] = { ...v, png: decodePng(await v.page.screenshot({ path: file })) };
      console.log(`shot ${file} (${v.url.replace(srv.url, '/')})`);
    }
    // the .hdr page back in the lightmap view, for the picks and projections below
    const lm = { ...(await pages.show(views['lightmap-hdr'].params)), png: views['lightmap-hdr'].png }, ev = lm.info.ev, gain = 2 ** ev / Math.PI;
    // probes: a grid of pixels on lightmapped nodes, away from edges (the 4 neighbours see the same object within 1.5 texels)
    const grid = [];
    for (let y = 4; y < lm.png.height - 4; y += 9) for (let x = 4; x < lm.png.width - 4; x += 9) grid.push([x, y]);
    const picks = await lm.page.evaluate((grid) => grid.map(([px, py]) => {
      const c = window.lmbPick(px, py);
      if (!c || !c.texel) return null;
      const same = [[1, 0], [-1, 0], [0, 1], [0, -1]].every(([i, j]) => {
        const n = window.lmbPick(px + i, py + j);
        return n && n.object === c.object && n.texel && Math.hypot(n.texel[0] - c.texel[0], n.texel[1] - c.texel[1]) <= 1.5;
      });
      return same ? { px, py, node: c.node, object: c.object, uv1: c.uv1, texel: c.texel, atlas: c.atlas } : null;
    }), grid).then((r) => r.filter(Boolean));
    let n = 0, bad = 0, worst = 0, texelOff = 0, invalidOff = 0, ignoring = 0, first = null;
    const skipped = { clip: 0, edge: 0, noNode: 0 }, perNode = new Map(), probed = [];
    for (const p of picks) {
      const r = nodes.get(p.node), img = r && hdrs.get(r.texture);
      if (!r || !img) { skipped.noNode++; continue; }
      const u = p.uv1[0] * r.so[0] + r.so[2], v = p.uv1[1] * r.so[1] + r.so[3];
      const k = r.intensity * gain;
      const ex = [0, 1, 2].map((c) => srgb(bilinear(img, u, v, c) * k)), got = lm.png.at(p.px, p.py);
      if (Math.max(...ex) > 250 || Math.max(...ex) < 5) { skipped.clip++; continue; }
      const tp = taps(img, u, v).map((e) => srgb(e * k));
      if (Math.max(...tp) - Math.min(...tp) > 16) { skipped.edge++; continue; }
      n++; perNode.set(r.name, (perNode.get(r.name) || 0) + 1); probed.push(p);
      const e = dist(ex, got);
      worst = Math.max(worst, e);
      if (e > TOL) { bad++; if (bad <= 5) console.log(`  probe off: pixel (${p.px}, ${p.py}) node '${r.name}' uv1 (${p.uv1.map((x) => x.toFixed(5))}) -> atlas uv (${u.toFixed(5)}, ${v.toFixed(5)}): expected ${ex.map((x) => x.toFixed(1))}, got ${got}`); }
      // the page's pick names the texel at uv1 x scale + offset
      const tx = Math.min(img.width - 1, Math.floor(u * img.width)), ty = Math.min(img.height - 1, Math.floor(v * img.height));
      if (p.texel[0] !== tx || p.texel[1] !== ty) texelOff++;
      // the invalid view reads the same texels (no magenta here: E > 0)
      if (dist(views['invalid-hdr'].png.at(p.px, p.py), got) > TOL) invalidOff++;
      // would a preview that ignored the rectangle (uv1 read as atlas uv) fail here?
      if (dist([0, 1, 2].map((c) => srgb(bilinear(img, p.uv1[0], p.uv1[1], c) * k)), got) > TOL) ignoring++;
      first ||= `node '${r.name}' pixel (${p.px}, ${p.py}) uv1 (${p.uv1.map((x) => x.toFixed(4))}) -> texel (${tx}, ${ty}): expected ${ex.map((x) => x.toFixed(1))}, got ${got}`;
    }
    const seenNodes = [...perNode.keys()];
    check('keep_uv1: lightmap view pixel = sRGB(E(uv1 x scale + offset) x intensity / pi x 2^EV)', n >= 100 && bad === 0 && seenNodes.length >= 2,
      `EV ${ev}; ${n} probes on ${seenNodes.length} nodes (${[...perNode].map(([k, c]) => `${k} ${c}`).join(', ')}); ${bad} off by > ${TOL} levels, worst ${worst.toFixed(2)}; ` +
      `${skipped.clip} clipped or black, ${skipped.edge} at shadow edges, ${skipped.noNode} not on a node with extras.lightmap; ${ignoring} of ${n} would be off if the rectangle were ignored; e.g. ${first}`);
    check('keep_uv1: the page picks the texel at uv1 x scale + offset', n > 0 && texelOff === 0, `${texelOff} of ${n} probes name another texel`);
    check('keep_uv1: the invalid view shows the same texels', n > 0 && invalidOff === 0, `${invalidOff} of ${n} probes differ by > ${TOL} levels from the lightmap view`);
    // the page's texel -> screen mapping finds the probes' texels where they are
    const round = await lm.page.evaluate((ps) => ps.map((p) => { const s = window.lmbTexelToScreen(p.atlas, p.texel[0], p.texel[1]); return s && s.visible && window.lmbPick(Math.floor(s.x), Math.floor(s.y)).node === p.node; }),
      probed.slice(0, 200));
    check('keep_uv1: lmbTexelToScreen finds each probe texel on its node', round.length > 0 && round.every(Boolean), `${round.filter((r) => !r).length} of ${round.length} not found or on another node`);
    // the checker, in 3D and in the atlas view (zoom 1), colours a texel by its chart's tint, its
    // parity and its 8x8 block: a probe's pixel in 3D and its texel's pixel in the atlas view
    // match when both place the node's triangles at its rectangle (chart borders are drawn
    // within 1.5 pixels of a chart's edge in each, at different places: a few may differ)
    const c3 = await pages.show({ mode: 'checker', tonemap: 'none', view: 'front', lightmap: 'hdr' });
    const c3Png = decodePng(await c3.page.screenshot({ path: path.join(shotsDir, 'preview-keep-uv1-checker.png') }));
    const ck = await pages.show({ mode: 'atlas', layer: 'checker', atlas: probed.length ? probed[0].atlas : 0, zoom: 1, lightmap: 'hdr' });
    const ckPng = decodePng(await ck.page.screenshot({ path: path.join(shotsDir, 'preview-keep-uv1-atlas-checker.png') }));
    const av = ck.info.atlasView;
    let onScreen = 0, differ = 0, background = 0;
    for (const p of probed) {
      if (p.atlas !== av.atlas) continue;
      const x = av.originX + p.texel[0], y = av.originY + p.texel[1];
      if (x < 0 || y < 0 || x >= ckPng.width || y >= ckPng.height) continue;
      onScreen++;
      if (dist(ckPng.at(x, y), ATLAS_BG) <= 3) background++;
      if (dist(ckPng.at(x, y), c3Png.at(p.px, p.py)) > 3) differ++;
    }
    check('keep_uv1: the atlas checker view draws a probe\'s texel as the 3D checker view draws its pixel', onScreen >= 100 && differ <= 0.05 * onScreen,
      `${differ} of ${onScreen} probe texels on screen (zoom 1) differ by > 3 levels (allowed 5%: chart borders), ${background} show the background`);
    const d = diff(lm.png, views['lightmap-ktx2'].png);
    check('keep_uv1: lightmap=ktx2 shot = lightmap=hdr shot', views['lightmap-ktx2'].info.atlases.every((a) => a.source === 'ktx2' && a.loader === 'KTX2Loader') && d.over <= PIX_FRAC * d.n && d.max.every((m) => m <= PIX_MAX),
      `sources ${views['lightmap-ktx2'].info.atlases.map((a) => `${a.uri} ${a.source} ${a.loader}, ${a.gpu}`).join('; ')}; max |diff| ${d.max.join(' ')}, mean ${d.mean.map((m) => m.toFixed(4)).join(' ')}; ${d.over} pixels off by > ${PIX_TOL}`);
    await pages.close();
  } finally {
    await srv.close();
  }
}

// ---- helpers

// The lightmap textures the materials use: {index, extras (extras.lightmap or null)}
function lightmapTextures(g) {
  const used = new Set();
  for (const m of g.materials || []) if (m.extensions && m.extensions.MOZ_lightmap) used.add(m.extensions.MOZ_lightmap.index);
  return [...used].sort((a, b) => a - b).map((i) => ({ index: i, extras: (g.textures[i].extras && g.textures[i].extras.lightmap) || null }));
}

async function atlasData(page, index) {
  const r = await page.evaluate((i) => window.lmbAtlasData(i), index);
  const b = Buffer.from(r.base64, 'base64');
  return { ...r, data: new Float32Array(b.buffer, b.byteOffset, b.byteLength / 4) };
}

// Per-channel differences of two screenshots (8-bit levels)
function diff(a, b) {
  const n = a.width * a.height, max = [0, 0, 0], sum = [0, 0, 0];
  let over = 0, worst = null, wd = 0;
  for (let i = 0; i < n; i++) {
    let pm = 0;
    for (let c = 0; c < 3; c++) {
      const d = Math.abs(a.rgb[3 * i + c] - b.rgb[3 * i + c]);
      sum[c] += d; if (d > max[c]) max[c] = d; if (d > pm) pm = d;
    }
    if (pm > PIX_TOL) over++;
    if (pm > wd) { wd = pm; worst = { x: i % a.width, y: i / a.width | 0, a: a.at(i % a.width, i / a.width | 0), b: b.at(i % a.width, i / a.width | 0) }; }
  }
  return { n, max, mean: sum.map((s) => s / n), over, worst };
}

function dist(a, b) { return Math.max(...a.map((v, i) => Math.abs(v - b[i]))); }
function at(img, x, y, c) { return img.data[3 * (Math.min(img.height - 1, Math.max(0, y)) * img.width + Math.min(img.width - 1, Math.max(0, x))) + c]; }
// three's LinearFilter with ClampToEdge: texel centres at (i + 0.5) / W
function bilinear(img, u, v, c) {
  const x = u * img.width - 0.5, y = v * img.height - 0.5, x0 = Math.floor(x), y0 = Math.floor(y), fx = x - x0, fy = y - y0;
  return (at(img, x0, y0, c) * (1 - fx) + at(img, x0 + 1, y0, c) * fx) * (1 - fy) + (at(img, x0, y0 + 1, c) * (1 - fx) + at(img, x0 + 1, y0 + 1, c) * fx) * fy;
}
// the 4 texels the filter reads at (u, v), channel 0
function taps(img, u, v) { const x = Math.floor(u * img.width - 0.5), y = Math.floor(v * img.height - 0.5); return [at(img, x, y, 0), at(img, x + 1, y, 0), at(img, x, y + 1, 0), at(img, x + 1, y + 1, 0)]; }
