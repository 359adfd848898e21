#!/usr/bin/env node
// The preview's probe-lit sphere (docs/probes.md): opens a bake with light probes in headless
// Chromium with the sphere placed exactly at a probe (sphere=x,y,z), seen face-on from +Z, and
// checks the pixel at the sphere's centre (normal +Z) against albedo / pi x E(+Z) of that
// probe's SH, computed here from the glTF's own buffer (not the page's code): tone mapping
// "none" at an exposure that puts it near mid-grey, sRGB, within 2 levels (8-bit). Then moves the
// sphere to a second probe without reloading and checks it again. Two probes: the brightest
// toward +Z (a lit spot) and the dimmest with at least 2% of its light (in shadow); their
// screenshots are saved. Last, the sphere at a tetrahedron's centroid: the mean of its four
// probes' SH.
//   usage: node tests/preview/preview_probes.mjs GLTF SHOTS_DIR
import fs from 'node:fs';
import path from 'node:path';
import { startServer } from '../../tools/preview/server.mjs';
import { launchBrowser, openPreview } from '../../tools/preview/browser.mjs';
import { decodePng, srgb, readProbes } from './lib.mjs';

const [gltfFile, shotsDir] = process.argv.slice(2);
if (!shotsDir) { console.error('usage: node tests/preview/preview_probes.mjs GLTF SHOTS_DIR'); process.exit(1); }
const ALBEDO = 0.8; // probes-view.js's sphere
const TOL = 2;

// E(+Z) of probe i: the SH at n = (0, 0, 1): Y00, Y10 = 0.488603 z, Y20 = 0.315392 (3z^2 - 1)
const eUpZ = (pr, i) => [0, 1, 2].map((c) => 0.282095 * pr.sh[27 * i + c] + 0.488603 * pr.sh[27 * i + 6 + c] + 0.630784 * pr.sh[27 * i + 18 + c]);
const lum = (e) => 0.2126 * e[0] + 0.7152 * e[1] + 0.0722 * e[2];

const probes = readProbes(gltfFile);
const order = [...Array(probes.count).keys()].filter((i) => lum(eUpZ(probes, i)) > 0).sort((a, b) => lum(eUpZ(probes, b)) - lum(eUpZ(probes, a)));
const radius = 0.35 * probes.spacing;
fs.mkdirSync(shotsDir, { recursive: true });

const browser = await launchBrowser();
const srv = await startServer(gltfFile);
let failures = 0;
try {
  // the sphere at probe i: what its centre pixel should show, and an exposure near mid-grey
  const target = (i) => {
    const at = Array.from(probes.positions.subarray(3 * i, 3 * i + 3));
    const want = eUpZ(probes, i).map((x) => x * ALBEDO / Math.PI);
    return { at, want, ev: Math.log2(0.5 / Math.max(...want)) };
  };
  let done = 0;
  let page = null, context = null;
  // in shadow: the dimmest with at least 2% of the brightest's light (dimmer, the SH's own
  // rounding near 0 decides the pixel, not the light)
  const floor = 0.02 * lum(eUpZ(probes, order[0]));
  const dim = order.filter((i) => lum(eUpZ(probes, i)) >= floor).reverse();
  for (const [name, list] of [['lit', order], ['shadow', dim]]) {
    for (const i of list.slice(0, 40)) {
      const t = target(i); // the camera 2.5 radii in front of it (+Z); a probe whose view is blocked is skipped
      const cam = [t.at[0], t.at[1], t.at[2] + 2.5 * radius, ...t.at].join(',');
      if (!page) {
        const v = await openPreview(browser, srv.url, { mode: 'lit', tonemap: 'none', ev: t.ev, cam, sphere: t.at.join(',') });
        page = v.page; context = v.context;
      } else { // the same page: move the sphere and the camera, no reload
        await page.evaluate(([a, c, ev]) => { window.lmbMoveProbeSphere(...a); window.lmbSetView(c, ev); }, [t.at, cam, t.ev]);
        const moved = await page.evaluate(() => window.lmbProbeSphere(null).at);
        if (moved.some((x, k) => Math.abs(x - t.at[k]) > 1e-6)) { console.log(`FAIL: the sphere did not move to ${t.at}`); failures++; }
      }
      const s = await page.evaluate(([x, y, z]) => window.lmbProject(x, y, z), t.at);
      const hit = await page.evaluate(([x, y]) => window.lmbPick(x, y), [Math.round(s.x), Math.round(s.y)]);
      if (hit && hit.distance < 1.5 * radius) continue; // level geometry in front of the sphere: the next probe
      const file = path.join(shotsDir, `preview-probes-${name}.png`);
      const png = decodePng(await page.screenshot({ path: file }));
      const got = png.at(Math.round(s.x - 0.5), Math.round(s.y - 0.5));
      const want = t.want.map((x) => srgb(x * 2 ** t.ev));
      const diff = Math.max(...got.map((g, k) => Math.abs(g - want[k])));
      const ok = diff <= TOL;
      failures += !ok;
      console.log(`${ok ? 'ok' : 'FAIL'}: ${name}: sphere at probe ${i} (${t.at.map((x) => x.toFixed(3)).join(', ')}), ev ${t.ev.toFixed(2)}: ` +
                  `pixel ${got.join(' ')}, from the probe's SH ${want.map((x) => x.toFixed(1)).join(' ')} (largest difference ${diff.toFixed(1)}, bound ${TOL}); shot ${file}`);
      done++;
      break;
    }
  }
  if (done < 2) { console.log(`FAIL: ${done} of 2 probes could be looked at`); failures++; }
  // between probes: the sphere at a tetrahedron's centroid takes the mean of its four probes' SH
  // (barycentric weights 1/4 each), as Unity and Godot interpolate
  if (!probes.tetrahedra || !probes.tetrahedra.length) { console.log('FAIL: the bake has no tetrahedra'); failures++; }
  else if (page) {
    const t = Array.from(probes.tetrahedra.subarray(0, 4));
    const at = [0, 1, 2].map((c) => t.reduce((s, i) => s + probes.positions[3 * i + c], 0) / 4);
    await page.evaluate((a) => window.lmbMoveProbeSphere(...a), at);
    const got = await page.evaluate(() => window.lmbProbeSphere(null));
    const want = Array.from({ length: 27 }, (_, k) => t.reduce((s, i) => s + probes.sh[27 * i + k], 0) / 4);
    const scaleSh = Math.max(...want.map(Math.abs));
    const off = Math.max(...want.map((w, k) => Math.abs(got.sh[k] - w))) / scaleSh;
    const ok = got.interpolation === 'tetrahedron' && off <= 1e-4;
    failures += !ok;
    console.log(`${ok ? 'ok' : 'FAIL'}: the sphere at tetrahedron 0's centroid (probes ${t.join(', ')}): ${got.interpolation}, its SH the mean of theirs within ${off.toExponential(1)} of the largest coefficient (bound 1e-4)`);
  }
  if (context) await context.close();
} finally {
  await srv.close();
  await browser.close();
}
process.exit(failures ? 1 : 0);
