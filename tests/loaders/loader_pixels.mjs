#!/usr/bin/env node
// One loader's example page (loaders/three/example, loaders/babylon/example) in headless
// Chromium on a bake: its window.lmbProbe() (each pixel's lightmap value and lightmap
// coordinates, rendered as the loader set the materials up) written as JSON to OUT, with the
// page's own report (which file each lightmap came from). tests/loaders/check_loader_pixels.py
// compares the values with the lightmap files.
// With --probe-light (Babylon): the page's window.lmbProbeLight(0..2) instead: a probe-lit
// sphere's irradiance against lmbake-probes' at three points of the level.
//   usage: node tests/loaders/loader_pixels.mjs three|babylon BAKE.gltf OUT.json [source] [--probe-light]
import fs from 'node:fs';
import path from 'node:path';
import { launchBrowser } from '../../tools/preview/browser.mjs';
import { startServer } from '../../tools/preview/server.mjs';

const args = process.argv.slice(2).filter((a) => a !== '--probe-light'), probeLight = process.argv.includes('--probe-light');
const [loader, gltf, out, source = 'ktx2'] = args;
if (!out) { console.error('usage: node tests/loaders/loader_pixels.mjs three|babylon BAKE.gltf OUT.json [source]'); process.exit(2); }
const srv = await startServer(gltf);
const browser = await launchBrowser();
let code = 0;
try {
  const page = await browser.newPage({ viewport: { width: 640, height: 480 } });
  const errors = [], logs = [];
  page.on('pageerror', (e) => errors.push(e.message));
  page.on('console', (m) => (m.type() === 'error' ? errors : logs).push(m.text()));
  const url = `${srv.url}loaders/${loader}/example/index.html?` + new URLSearchParams({ gltf: '/bake/' + encodeURIComponent(path.basename(gltf)), source, probe: '1' });
  await page.goto(url);
  await page.waitForFunction(() => window.lmbReady === true, null, { timeout: 60000, polling: 100 }).catch(() => errors.push('not ready after 60 s'));
  if (errors.length) throw new Error(`${url}: ${errors.join('; ')}`);
  if (probeLight) {
    const spheres = [];
    for (const which of [0, 1, 2]) spheres.push(await page.evaluate((k) => window.lmbProbeLight(k), which));
    fs.writeFileSync(out, JSON.stringify({ spheres, logs }));
    console.log(`${loader}: ${spheres.length} probe-lit spheres; ${logs.filter((l) => /probes/.test(l)).join(' | ')}`);
  } else {
    const probe = await page.evaluate(() => window.lmbProbe());
    fs.writeFileSync(out, JSON.stringify({ ...probe, logs }));
    console.log(`${loader}: ${probe.width}x${probe.height} probed; ${logs.filter((l) => /atlas|copies/.test(l)).join(' | ')}`);
  }
} catch (e) {
  console.error(String(e.stack || e));
  code = 1;
} finally {
  await browser.close();
  await srv.close();
}
process.exit(code);
