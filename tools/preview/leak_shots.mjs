#!/usr/bin/env node
// The leak pictures in docs/leaks.md: the dark room of a two-room scene (tools/leak_scenes.py)
// seen in the preview from inside, with the probe-lit sphere 0.3 m from the wall, for a bake
// before the leak work and one after. Every shot uses one fixed exposure: the auto exposure the
// preview picks in the lit room of the first bake, so the dark room shows what leaks into it
// at the brightness the lit room is seen at.
//   usage: node tools/preview/leak_shots.mjs OUTDIR NAME=GLTF [NAME=GLTF ...]
// (docs: bake tools/leak_scenes.py's two-rooms-2.gltf with atlas.texels 157286 by both binaries
//  (tools/bench_leaks.sh does), then
//  node tools/preview/leak_shots.mjs docs/images before=B/two-rooms-2.gltf after=A/two-rooms-2.gltf)
import path from 'node:path';
import { startServer } from './server.mjs';
import { launchBrowser, openPreview } from './browser.mjs';

const WALL_X = 0.01; // the 2 cm wall's face on the dark side
const SPHERE = [WALL_X + 0.3, 1.2, 0];
const DARK_CAM = [3.6, 1.6, 1.4, WALL_X, 1.0, 0]; // in room B, looking at the wall
const LIT_CAM = [-3.6, 1.6, 1.4, -WALL_X, 1.0, 0]; // in room A, for the exposure

const [outDir, ...pairs] = process.argv.slice(2);
if (!pairs.length) { console.error('usage: node tools/preview/leak_shots.mjs OUTDIR NAME=GLTF [NAME=GLTF ...]'); process.exit(1); }
const browser = await launchBrowser();
let ev = null;
try {
  for (const pair of pairs) {
    const [name, gltf] = pair.split('=');
    const srv = await startServer(gltf);
    try {
      if (ev === null) {
        const v = await openPreview(browser, srv.url, { mode: 'lit', cam: LIT_CAM.join(',') });
        ev = v.info.ev;
        await v.context.close();
      }
      const v = await openPreview(browser, srv.url, { mode: 'lit', ev: String(ev), cam: DARK_CAM.join(','), sphere: SPHERE.join(',') });
      const file = path.join(outDir, `leaks-${name}.png`);
      await v.page.screenshot({ path: file });
      const sphere = await v.page.evaluate(() => window.lmbProbeSphere ? window.lmbProbeSphere([-1, 0, 0]) : null);
      console.log(`${file}: ev ${ev}, sphere at ${SPHERE.join(',')} (${sphere ? `${sphere.interpolation}; E toward the wall ${sphere.irradiance.map((e) => e.toFixed(2)).join(', ')} lux` : 'no probes'})`);
      await v.context.close();
    } finally {
      await srv.close();
    }
  }
} finally {
  await browser.close();
}
