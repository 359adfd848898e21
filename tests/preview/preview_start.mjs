#!/usr/bin/env node
// The preview's start view (tools/preview/page/start-view.js) on two bakes:
//   an open Cornell box (cornell-point): not enclosed, so the front view (lmbInfo.startView 'front');
//   a closed 2 m room (sealed-room, the box -1..1 x 0..2 x -1..1): 'inside', the camera inside
//   the room at eye height a third of the way up (2/3), looking horizontally.
//   usage: node tests/preview/preview_start.mjs OPEN_GLTF CLOSED_GLTF
import { startServer } from '../../tools/preview/server.mjs';
import { launchBrowser, openPreview } from '../../tools/preview/browser.mjs';

const [open, closed] = process.argv.slice(2);
if (!closed) { console.error('usage: node tests/preview/preview_start.mjs OPEN_GLTF CLOSED_GLTF'); process.exit(1); }
const browser = await launchBrowser();
let ok = true;
async function start(gltf) {
  const srv = await startServer(gltf);
  try {
    const v = await openPreview(browser, srv.url, { mode: 'lit' });
    const cam = await v.page.evaluate(() => window.lmbInfo.camera);
    const from = await v.page.evaluate(() => window.lmbInfo.startView);
    await v.context.close();
    return { from, cam };
  } finally { await srv.close(); }
}
const a = await start(open);
const good1 = a.from === 'front';
ok &&= good1;
console.log(`open Cornell box: start view '${a.from}' (want front)  ${good1 ? 'ok' : 'FAIL'}`);
const b = await start(closed);
const [px, py, pz] = b.cam.position, [tx, ty, tz] = b.cam.target;
const inside = Math.abs(px) < 1 && Math.abs(pz) < 1 && Math.abs(py - 2 / 3) < 1e-3 && Math.abs(ty - py) < 1e-6;
const good2 = b.from === 'inside' && inside;
ok &&= good2;
console.log(`closed room: start view '${b.from}', camera (${b.cam.position.map((x) => x.toFixed(3))}) looking at (${b.cam.target.map((x) => x.toFixed(3))}) (want inside at eye height 0.667, level)  ${good2 ? 'ok' : 'FAIL'}`);
await browser.close();
process.exit(ok ? 0 : 1);
