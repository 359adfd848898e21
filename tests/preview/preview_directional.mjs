#!/usr/bin/env node
// Directional lightmaps in the preview (issue 14): a normal-mapped plane under a low sun
// (tools/make_scenes.py dir-bumps, baked with output.directional: true), shot in the lit view
// with and without its directional lightmap (?directional=0). Without it a lightmap holds one
// irradiance per texel and the bumps are flat; with it they are shaded.
//   usage: node tests/preview/preview_directional.mjs BAKE_GLTF SHOTS_DIR
// Exit 0 when the page uses the directional lightmap, the bumps' brightness spread (standard
// deviation of 8-bit luma over the plane's pixels) is at least 5 levels with it and under a
// fifth of that without it; 1 otherwise.
import fs from 'node:fs';
import path from 'node:path';
import { startServer } from '../../tools/preview/server.mjs';
import { launchBrowser, openPreview } from '../../tools/preview/browser.mjs';
import { decodePng, luma } from './lib.mjs';

const [gltf, shotsDir] = process.argv.slice(2);
if (!shotsDir) { console.error('usage: node tests/preview/preview_directional.mjs BAKE_GLTF SHOTS_DIR'); process.exit(1); }
const PARAMS = { mode: 'lit', ev: -9, tonemap: 'none', cam: '0,2.2,2.2,0,0,0' };

async function spread(browser, url, name, directional) {
  const v = await openPreview(browser, url, directional ? PARAMS : { ...PARAMS, directional: '0' });
  const file = path.join(shotsDir, `preview-directional-${name}.png`);
  const png = decodePng(await v.page.screenshot({ path: file }));
  console.log(`shot ${file}`);
  // the plane's pixels: a grid over the middle of the view, each picked to be on the plane
  const grid = [];
  for (let y = 200; y < 520; y += 4) for (let x = 240; x < 720; x += 4) grid.push([x, y]);
  const onPlane = await v.page.evaluate((g) => g.map(([x, y]) => { const h = window.lmbPick(x, y); return !!h && h.object === 'plane'; }), grid);
  const values = grid.filter((_, i) => onPlane[i]).map(([x, y]) => luma(png.at(x, y)));
  const mean = values.reduce((s, x) => s + x, 0) / values.length;
  const sd = Math.sqrt(values.reduce((s, x) => s + (x - mean) ** 2, 0) / values.length);
  const used = v.info.directionalMaterials;
  await v.context.close();
  return { sd, mean, n: values.length, used };
}

fs.mkdirSync(shotsDir, { recursive: true });
const srv = await startServer(gltf);
const browser = await launchBrowser();
let ok = false;
try {
  const on = await spread(browser, srv.url, 'on', true), off = await spread(browser, srv.url, 'off', false);
  ok = on.used >= 1 && off.used === 0 && on.n > 1000 && on.sd >= 5 && off.sd * 5 <= on.sd;
  console.log(`${ok ? 'PASS' : 'FAIL'} bumps' brightness spread over ${on.n} plane pixels: ${on.sd.toFixed(2)} levels with the directional lightmap ` +
    `(${on.used} material(s); mean ${on.mean.toFixed(1)}), ${off.sd.toFixed(2)} without (mean ${off.mean.toFixed(1)}); need >= 5 and 5x`);
} catch (e) {
  console.log('FAIL ' + e.message);
} finally {
  await browser.close();
  await srv.close();
}
process.exit(ok ? 0 : 1);
