#!/usr/bin/env node
// Renders the preview's view modes of a bake headless: `node tools/preview/render.mjs
// OUT.gltf OUTDIR [--ev N|auto] [--tonemap none|agx|aces|neutral] [--modes lit,lightmap,...]
// [--view start|front] [--cam px,py,pz,tx,ty,tz] [--lightmap ktx2|hdr]` writes
// OUTDIR/preview-<mode>.png (960 x 720; the camera: --cam, else --view: start (default: the
// file's camera, a point inside the level, else the front view; page/start-view.js) or front;
// the atlas view shows atlas 0; --lightmap: the files read, the KTX2 ones the glTF names (the
// default; else the .hdr) or the .hdr).
// Exit 1: usage; 2: the glTF is missing or unreadable; 3: the browser or the page failed.
import fs from 'node:fs';
import path from 'node:path';
import { startServer, InputError } from './server.mjs';
import { launchBrowser, openPreview } from './browser.mjs';

const MODES = ['lit', 'lightmap', 'checker', 'invalid', 'atlas', 'records'];
const usage = 'usage: node tools/preview/render.mjs OUT.gltf OUTDIR [--ev N|auto] [--tonemap none|agx|aces|neutral] [--modes m1,m2,...] [--view start|front] [--cam px,py,pz,tx,ty,tz] [--lightmap ktx2|hdr]';
const args = process.argv.slice(2), pos = [];
const opt = { ev: 'auto', tonemap: 'agx', modes: MODES, view: 'start', cam: null, lightmap: 'ktx2' };
for (let i = 0; i < args.length; i++) {
  const a = args[i];
  if (a === '-h' || a === '--help') { console.log(usage); process.exit(0); }
  if (['--ev', '--tonemap', '--modes', '--view', '--cam', '--lightmap'].includes(a)) {
    const v = args[++i];
    if (v === undefined) { console.error(`render: ${a} needs a value\n${usage}`); process.exit(1); }
    opt[a.slice(2)] = a === '--modes' ? v.split(',') : v;
  } else if (a.startsWith('-') && a !== '-') { console.error(`render: unknown option '${a}'\n${usage}`); process.exit(1); }
  else pos.push(a);
}
if (pos.length !== 2) { console.error(usage); process.exit(1); }
const bad = opt.modes.filter((m) => !MODES.includes(m));
if (bad.length) { console.error(`render: unknown mode '${bad[0]}' (one of ${MODES.join(', ')})`); process.exit(1); }
if (opt.ev !== 'auto' && !Number.isFinite(Number(opt.ev))) { console.error(`render: --ev wants a number or auto, got '${opt.ev}'`); process.exit(1); }
if (!['ktx2', 'hdr'].includes(opt.lightmap)) { console.error(`render: --lightmap wants ktx2 or hdr, got '${opt.lightmap}'`); process.exit(1); }
if (!['start', 'front'].includes(opt.view)) { console.error(`render: --view wants start or front, got '${opt.view}'`); process.exit(1); }
if (opt.cam !== null && (opt.cam.split(',').length !== 6 || opt.cam.split(',').some((v) => !Number.isFinite(Number(v))))) {
  console.error(`render: --cam wants px,py,pz,tx,ty,tz (6 numbers), got '${opt.cam}'`); process.exit(1);
}

let srv;
try { srv = await startServer(pos[0]); } catch (e) {
  console.error(`render: error: ${e.message}`); process.exit(e instanceof InputError ? 2 : 3);
}
let code = 0, browser;
try {
  fs.mkdirSync(pos[1], { recursive: true });
  browser = await launchBrowser();
  for (const mode of opt.modes) {
    const t0 = Date.now();
    const camera = opt.cam !== null ? { cam: opt.cam } : { view: opt.view };
    const { page, context } = await openPreview(browser, srv.url, { mode, ev: opt.ev, tonemap: opt.tonemap, lightmap: opt.lightmap, ...camera });
    const file = path.join(pos[1], `preview-${mode}.png`);
    await page.screenshot({ path: file });
    await context.close();
    console.log(`render: ${file} (${((Date.now() - t0) / 1000).toFixed(1)} s)`);
  }
} catch (e) {
  console.error(`render: error: ${e.message}`); code = 3;
} finally {
  if (browser) await browser.close();
  await srv.close();
}
process.exit(code);
