#!/usr/bin/env node
// The preview's light-group sliders (lmbake-three's loaders/three/lmbake-groups.js; docs/light-groups.md) in
// headless Chromium, on a bake with two groups (sun-lamps.gltf: the sun, and two lamps): the page
// finds the groups with the bake's scales as its weights; at weights (1, 0), (0, 1) and (0.3, 2)
// (lmbSet, what the sliders set) the lightmap view's pixel is sRGB(sum_g w_g E_g / pi x 2^EV), E_g
// read bilinearly from each group's .hdr at the uv1 the pixel sees, within 2 levels, at a grid of
// pixels away from edges; and the sum moves with the weights (each set's pixels differ from the
// others' where the groups differ); in the lit view (the glTF's materials, patched by lmbake-three's
// lightGroups as a game's are) all weights at 0 leave the lightmapped pixels black.
// With SOURCE ktx2 the page reads the lightmaps from their KTX2 files (the bake's formats list
// ktx2; output.ktx2_format e5b9g9r9): every group's texture must come from its own .ktx2 and the
// pixels match the .hdr's sums within the same 2 levels.
//   usage: node tests/preview/preview_groups.mjs BAKE_OUT_GLTF SHOTS_DIR [hdr|ktx2]
import fs from 'node:fs';
import path from 'node:path';
import { decodePng, readHdr } from './lib.mjs';
import { startServer } from '../../tools/preview/server.mjs';
import { launchBrowser, openPreview, showPreview } from '../../tools/preview/browser.mjs';

const [gltfPath, shotsDir, source = 'hdr'] = process.argv.slice(2);
if (!shotsDir) { console.error('usage: node tests/preview/preview_groups.mjs BAKE_OUT_GLTF SHOTS_DIR'); process.exit(1); }
const CAM = '0,8,7,0,0,0'; // above the ground, looking down at the cube: most of the picture is lightmapped
// 8-bit rounding, half-float textures, bilinear weights at finite precision (as preview_e2e.mjs);
// E5B9G9R9 texels (a channel within 2^-9 of the texel's largest) stay within it: worst 0.63 level
const TOL = 2;
let failures = 0;
const check = (ok, text) => { failures += !ok; console.log(`${ok ? 'PASS' : 'FAIL'} ${text}`); };
const srgb = (x) => { const v = Math.max(0, Math.min(1, x)); return 255 * (v <= 0.0031308 ? 12.92 * v : 1.055 * v ** (1 / 2.4) - 0.055); };

const doc = JSON.parse(fs.readFileSync(gltfPath, 'utf8')), dir = path.dirname(gltfPath);
const tex = doc.textures.find((t) => t.extras && t.extras.lightmap && t.extras.lightmap.groups);
if (!tex) { console.log('FAIL the bake names no light groups'); process.exit(1); }
const groups = tex.extras.lightmap.groups, atlas = tex.extras.lightmap.atlas;
// each group's light as a game reads it: its .hdr times its intensity (RGB: a group of one light
// holds it at 1 and names the light's intensity x colour)
const images = groups.map((g) => {
  const img = readHdr(path.join(dir, decodeURIComponent(g.files.hdr)));
  const k = Array.isArray(g.intensity) ? g.intensity : [1, 1, 1];
  for (let i = 0; i < img.data.length; i++) img.data[i] *= k[i % 3];
  return img;
});
const W = images[0].width, H = images[0].height;
// E of group g at atlas uv, bilinear over texel centres (three: LinearFilter, clamped, no mipmaps)
const at = (img, x, y, c) => img.data[3 * (Math.min(H - 1, Math.max(0, y)) * W + Math.min(W - 1, Math.max(0, x))) + c];
function bilinear(img, u, v, c) {
  const x = u * W - 0.5, y = v * H - 0.5, x0 = Math.floor(x), y0 = Math.floor(y), fx = x - x0, fy = y - y0;
  return (1 - fy) * ((1 - fx) * at(img, x0, y0, c) + fx * at(img, x0 + 1, y0, c)) + fy * ((1 - fx) * at(img, x0, y0 + 1, c) + fx * at(img, x0 + 1, y0 + 1, c));
}
const taps = (img, u, v, c) => { const x = Math.floor(u * W - 0.5), y = Math.floor(v * H - 0.5); return [at(img, x, y, c), at(img, x + 1, y, c), at(img, x, y + 1, c), at(img, x + 1, y + 1, c)]; };

fs.mkdirSync(shotsDir, { recursive: true });
const srv = await startServer(gltfPath);
const browser = await launchBrowser();
try {
  const v0 = await openPreview(browser, srv.url, { mode: 'lightmap', tonemap: 'none', cam: CAM, lightmap: source });
  const g = v0.info.groups, ev = v0.info.ev, gain = 2 ** ev / Math.PI;
  check(g && g.names.join() === groups.map((x) => x.name).join() && g.weights.join() === groups.map((x) => x.scale).join(),
    `the page finds the bake's light groups at their scales: ${JSON.stringify(g)}`);
  check(g && g.sources && g.sources[atlas] && g.sources[atlas].every((x) => x === source) &&
    (source !== 'ktx2' || groups.every((x) => x.files.ktx2)),
    `each group's lightmap read from its ${source === 'ktx2' ? '.ktx2 (extras.lightmap.groups[].files.ktx2)' : '.hdr'}: ${JSON.stringify(g && g.sources)}`);
  // pixels on the lightmapped surfaces, away from edges: what each sees (uv1 in the atlas)
  const grid = [];
  for (let y = 6; y < 720 - 6; y += 12) for (let x = 6; x < 960 - 6; x += 12) grid.push([x, y]);
  const picks = (await v0.page.evaluate((grid) => grid.map(([px, py]) => {
    const c = window.lmbPick(px, py);
    if (!c || !c.lightmapUv) return null;
    const same = [[2, 0], [-2, 0], [0, 2], [0, -2]].every(([i, j]) => { const n = window.lmbPick(px + i, py + j); return n && n.object === c.object; });
    return same ? { px, py, uv: c.lightmapUv, atlas: c.atlas } : null;
  }), grid)).filter((p) => p && p.atlas === atlas);
  const shots = [];
  for (const w of [[1, 0], [0, 1], [0.3, 2]]) {
    const v = await showPreview(v0, { mode: 'lightmap', tonemap: 'none', cam: CAM, lightmap: source, ev, groups: w.join(',') });
    const file = path.join(shotsDir, `preview-groups-${source}-${w.join('-')}.png`);
    const png = decodePng(await v.page.screenshot({ path: file }));
    shots.push(png);
    let n = 0, bad = 0, worst = 0, skipped = 0, first = null;
    for (const p of picks) {
      const E = [0, 1, 2].map((c) => w.reduce((s, wg, k) => s + wg * bilinear(images[k], p.uv[0], p.uv[1], c), 0));
      const ex = E.map((e) => srgb(e * gain)), got = png.at(p.px, p.py);
      const tp = [0, 1, 2].map((c) => taps(images[0], p.uv[0], p.uv[1], c).map((e, i) => srgb((w[0] * e + w[1] * taps(images[1], p.uv[0], p.uv[1], c)[i]) * gain)));
      if (Math.max(...ex) > 250 || Math.max(...ex) < 5 || tp.some((t) => Math.max(...t) - Math.min(...t) > 16)) { skipped++; continue; }
      const e = Math.max(...ex.map((x, c) => Math.abs(x - got[c])));
      n++; worst = Math.max(worst, e);
      if (e > TOL) { bad++; first ||= `pixel (${p.px}, ${p.py}) uv (${p.uv.map((x) => x.toFixed(4))}): expected ${ex.map((x) => x.toFixed(1))}, got ${got}`; }
    }
    check(v.info.groups.weights.join() === w.join() && n >= 200 && bad === 0,
      `weights (${w}): lightmap view pixel = sRGB(sum_g w_g E_g / pi x 2^EV) at ${n} pixels (${skipped} clipped, black or at edges), ` +
      `${bad} off by > ${TOL} levels, worst ${worst.toFixed(2)}${first ? '; e.g. ' + first : ''}; EV ${ev}; shot ${file}`);
  }
  // the sliders move the picture: the three shots differ where the groups' light differs
  const differ = (a, b) => { let k = 0; for (const p of picks) if (Math.max(...a.at(p.px, p.py).map((x, c) => Math.abs(x - b.at(p.px, p.py)[c]))) > 8) k++; return k; };
  check(differ(shots[0], shots[1]) > 50 && differ(shots[1], shots[2]) > 50,
    `the weights change the picture: (1,0) vs (0,1) at ${differ(shots[0], shots[1])} pixels, (0,1) vs (0.3,2) at ${differ(shots[1], shots[2])} (by > 8 levels)`);
  // the lit view (the glTF's own materials, patched by lmbake-three's lightGroups as a game's are):
  // all groups at 0 is black where the lightmap is the only light, the bake's scales are not
  const lit = async (w) => decodePng(await (await showPreview(v0, { mode: 'lit', tonemap: 'none', cam: CAM, lightmap: source, ev, groups: w })).page.screenshot());
  const off = await lit('0,0'), on = await lit(groups.map((x) => x.scale).join(','));
  const lum = (png, p) => Math.max(...png.at(p.px, p.py));
  const darkOff = picks.filter((p) => lum(off, p) <= 1).length, brightOn = picks.filter((p) => lum(on, p) > 8).length;
  check(darkOff === picks.length && brightOn > 0.5 * picks.length,
    `lit view: every group at 0 leaves ${darkOff} of ${picks.length} lightmapped pixels black; at the bake's scales ${brightOn} are lit`);
  const late = v0.errors.filter((e) => !e.startsWith('note'));
  check(!late.length, `no page errors${late.length ? ': ' + late.join('; ') : ''}`);
  await v0.context.close();
} catch (e) {
  check(false, `preview loads and renders: ${e.message}`);
} finally {
  await browser.close();
  await srv.close();
}
console.log(failures ? `${failures} failed` : 'all passed');
process.exit(failures ? 1 : 0);
