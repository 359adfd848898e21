#!/usr/bin/env node
// Props lit by the probes in the preview (docs/preview.md#meshes-without-a-lightmap): opens the
// bake of scale_probe_lit (60 instanced props with no lightmap) in headless Chromium and checks
//   - the page lights the instancing node's 60 copies by the probes (lmbInfo.probeLit);
//   - each copy's SH is a blend of the probes near it: its E(+Y) lies within the least and the
//     most E(+Y) of the probes within 1.5 spacings of its centre, read from the glTF here;
//   - a pixel on two copies seen from above (tone mapping none, an exposure near
//     mid-grey) shows albedo / pi x E(n) of that copy's SH for the picked triangle's normal n
//     within 2%, in the lit view and (albedo 1) in the lightmap view; the copies differ.
//   usage: node tests/preview/preview_probe_lit.mjs GLTF SHOTS_DIR
import fs from 'node:fs';
import path from 'node:path';
import { startServer } from '../../tools/preview/server.mjs';
import { launchBrowser, openPreview, showPreview } from '../../tools/preview/browser.mjs';
import { decodePng, readProbes } from './lib.mjs';

const [gltfFile, shotsDir] = process.argv.slice(2);
if (!shotsDir) { console.error('usage: node tests/preview/preview_probe_lit.mjs GLTF SHOTS_DIR'); process.exit(1); }
const TOL = 0.02;

// E(+Y) of an SH (27 floats, offset o): Y00, Y1-1 = 0.488603 y, Y20 = 0.315392 (3z^2 - 1) = -0.315392, Y22 = -0.546274
const eUpY = (sh, o) => [0, 1, 2].map((c) => 0.282095 * sh[o + c] + 0.488603 * sh[o + 3 + c] - 0.315392 * sh[o + 18 + c] - 0.546274 * sh[o + 24 + c]);
const lum = (e) => 0.2126 * e[0] + 0.7152 * e[1] + 0.0722 * e[2];
const linear = (v) => { v /= 255; return v <= 0.04045 ? v / 12.92 : ((v + 0.055) / 1.055) ** 2.4; };

const probes = readProbes(gltfFile);
fs.mkdirSync(shotsDir, { recursive: true });
const browser = await launchBrowser();
const srv = await startServer(gltfFile);
let failures = 0;
const report = (ok, text) => { failures += !ok; console.log(`${ok ? 'ok' : 'FAIL'}: ${text}`); };
try {
  const opened = await openPreview(browser, srv.url, { mode: 'lit', tonemap: 'none', ev: 0 }), { page, context, info } = opened;
  const props = info.probeLit.find((p) => p.copies === 60);
  report(!!props, `probe-lit meshes: ${JSON.stringify(info.probeLit)}`);
  if (props) {
    let within = 0, bad = [];
    const tops = [];
    for (let k = 0; k < 60; k++) {
      const c = await page.evaluate(([o, i]) => window.lmbProbeLit(o, i, [0, 1, 0]), [props.object, k]);
      const near = [];
      for (let i = 0; i < probes.count; i++) {
        const d = Math.hypot(...[0, 1, 2].map((j) => probes.positions[3 * i + j] - c.centre[j]));
        if (d <= 1.5 * probes.spacing) near.push(lum(eUpY(probes.sh, 27 * i)));
      }
      const e = lum(c.irradiance), lo = Math.min(...near), hi = Math.max(...near);
      if (near.length && e >= lo * (1 - 1e-5) && e <= hi * (1 + 1e-5)) within++;
      else bad.push(`copy ${k}: ${e} not in [${lo}, ${hi}] (${near.length} probes)`);
      tops.push({ k, c, e });
    }
    report(within === 60, `every copy's E(+Y) within its near probes' (${within} of 60) ${bad.slice(0, 3).join('; ')}`);
    // two copies: the brightest and the dimmest from above
    tops.sort((a, b) => b.e - a.e);
    const picks = [tops[0], tops[tops.length - 1]];
    report(picks[0].e > 1.05 * picks[1].e, `the copies' light differs: E(+Y) ${picks[0].e.toFixed(4)} and ${picks[1].e.toFixed(4)}`);
    for (const mode of ['lit', 'lightmap']) {
      const view = mode === 'lit' ? { page } : await showPreview(opened, { mode, tonemap: 'none', ev: 0 }); // the same page
      for (const { k, c } of picks) {
        // from above, a little to the side of the pole (the triangle fan there leans every way)
        const top = [c.centre[0] + 0.3, c.centre[1] + 4, c.centre[2] + 0.2];
        const pg = view.page;
        await pg.evaluate(([cam]) => window.lmbSetView(cam, 0), [[...top, ...c.centre].join(',')]);
        // a pixel 30 to the side of the centre's: away from the pole, on one triangle
        const s = await pg.evaluate(([x, y, z]) => window.lmbProject(x, y, z), c.centre);
        const px = Math.round(s.x) + 30, py = Math.round(s.y) + 30;
        const hit = await pg.evaluate(([x, y]) => window.lmbPick(x, y), [px, py]);
        const at = hit && hit.faceNormal ? await pg.evaluate(([o, i, n]) => window.lmbProbeLit(o, i, n), [props.object, k, hit.faceNormal]) : c;
        const want = mode === 'lit' ? at.linear : at.irradiance.map((x) => Math.max(0, x) / Math.PI);
        const ev = Math.log2(0.18 / Math.max(...want));
        await pg.evaluate(([cam, e]) => window.lmbSetView(cam, e), [[...top, ...c.centre].join(','), ev]);
        const file = path.join(shotsDir, `preview-probe-lit-${mode}-${k}.png`);
        const png = decodePng(await pg.screenshot({ path: file }));
        const got = png.at(px, py).map((v) => linear(v) / 2 ** ev);
        const off = Math.max(...got.map((g, j) => Math.abs(g / want[j] - 1)));
        report(hit && hit.object === props.object && hit.instance === k && off <= TOL,
          `${mode}: copy ${k} from above: pixel ${got.map((x) => x.toFixed(4)).join(' ')} against albedo / pi x E(n) ${want.map((x) => x.toFixed(4)).join(' ')} ` +
          `(off ${(100 * off).toFixed(1)}%, bound ${100 * TOL}%; picked ${hit ? `${hit.object} #${hit.instance}` : 'nothing'}); shot ${file}`);
      }
    }
  }
  await context.close();
} finally {
  await srv.close();
  await browser.close();
}
process.exit(failures ? 1 : 0);
