#!/usr/bin/env node
// The probe-lit sphere's pictures in docs/preview.md: a bake with probes (bevy's Cornell box at
// defaults) in headless Chromium, the sphere at a point in the light and at one in the shadow of
// the tall box, seen from the front view's side, default tone mapping and auto exposure.
//   usage: node tools/preview/probe_shots.mjs GLTF OUTDIR LIT_X,Y,Z SHADOW_X,Y,Z
// (docs: lmbake bake assets/scenes/cornell-box-bevy/CornellBox.glb -o OUT, then
//  node tools/preview/probe_shots.mjs OUT/CornellBox.gltf docs/images -200,200,-40 -520,50,-300)
import path from 'node:path';
import { startServer } from './server.mjs';
import { launchBrowser, openPreview } from './browser.mjs';

const [gltf, outDir, lit, shadow] = process.argv.slice(2);
if (!shadow) { console.error('usage: node tools/preview/probe_shots.mjs GLTF OUTDIR LIT_X,Y,Z SHADOW_X,Y,Z'); process.exit(1); }
const browser = await launchBrowser();
const srv = await startServer(gltf);
try {
  for (const [name, at] of [['lit', lit], ['shadow', shadow]]) {
    const v = await openPreview(browser, srv.url, { mode: 'lit', view: 'front', sphere: at });
    const file = path.join(outDir, `preview-probe-${name}.png`);
    await v.page.screenshot({ path: file });
    console.log(`${file}: sphere at ${at}`);
    await v.context.close();
  }
} finally {
  await srv.close();
  await browser.close();
}
