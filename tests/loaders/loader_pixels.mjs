#!/usr/bin/env node
// Loader example pages (loaders/three/example, loaders/babylon/example) in headless Chromium on
// bakes: each page's window.lmbProbe() (each pixel's lightmap value, lightmap coordinates and
// atlas, rendered as the loader set the materials up) written as JSON, with the page's own
// report (which file each lightmap came from); with probeLight (Babylon), window.lmbProbeLight
// (0..2) instead: a probe-lit sphere's irradiance against lmbake-probes' at three points.
// tests/loaders/check_loader_pixels.py compares the values with the lightmap files. One browser,
// one context and one server for every page (the engines' modules fetched once).
//   usage: node tests/loaders/loader_pixels.mjs three|babylon BAKE.gltf OUT.json [source] [--probe-light]
//          node tests/loaders/loader_pixels.mjs --jobs JOBS.json   ([{loader, gltf, out, source, probeLight}])
import fs from 'node:fs';
import path from 'node:path';
import { launchBrowser } from '../../tools/preview/browser.mjs';
import { startServer } from '../../tools/preview/server.mjs';

function jobsFromArgs(argv) {
  if (argv[0] === '--jobs') return JSON.parse(fs.readFileSync(argv[1], 'utf8'));
  const args = argv.filter((a) => a !== '--probe-light');
  const [loader, gltf, out, source = 'ktx2'] = args;
  if (!out) { console.error('usage: node tests/loaders/loader_pixels.mjs three|babylon BAKE.gltf OUT.json [source] [--probe-light] | --jobs JOBS.json'); process.exit(2); }
  return [{ loader, gltf, out, source, probeLight: argv.includes('--probe-light') }];
}

// One page: the example of `loader` on the bake at gltf (served under the server's /bake/ root).
async function runJob(context, srv, root, { loader, gltf, out, source = 'ktx2', probeLight = false, groups = null }) {
  const page = await context.newPage();
  try {
    const errors = [], logs = [];
    page.on('pageerror', (e) => errors.push(e.message));
    page.on('console', (m) => (m.type() === 'error' ? errors : logs).push(m.text()));
    const rel = path.relative(root, path.resolve(gltf)).split(path.sep).map(encodeURIComponent).join('/');
    const url = `${srv.url}loaders/${loader}/example/index.html?` + new URLSearchParams({ gltf: '/bake/' + rel, source, probe: '1', ...(groups ? { groups } : {}) });
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
      console.log(`${loader} on ${path.basename(gltf)}: ${probe.width}x${probe.height} probed; ${logs.filter((l) => /atlas|copies/.test(l)).join(' | ')}`);
    }
  } finally {
    await page.close();
  }
}

// The folder holding every job's bake (served at /bake/)
function commonRoot(files) {
  let root = path.dirname(path.resolve(files[0]));
  while (!files.every((f) => path.resolve(f).startsWith(root + path.sep))) root = path.dirname(root);
  return root;
}

const jobs = jobsFromArgs(process.argv.slice(2));
const root = commonRoot(jobs.map((j) => j.gltf));
const srv = await startServer(jobs[0].gltf, { bakeRoot: root, cacheModules: true });
const browser = await launchBrowser();
const context = await browser.newContext({ viewport: { width: 640, height: 480 } });
let code = 0;
try {
  for (const job of jobs) {
    const t0 = Date.now();
    await runJob(context, srv, root, job);
    console.log(`  (${((Date.now() - t0) / 1000).toFixed(1)} s)`);
  }
} catch (e) {
  console.error(String(e.stack || e));
  code = 1;
} finally {
  await browser.close();
  await srv.close();
}
process.exit(code);
