#!/usr/bin/env node
// The preview's start view (tools/preview/page/start-view.js) on two bakes:
//   an open Cornell box (cornell-point): not enclosed, so the front view (lmbInfo.startView 'front');
//   a closed 2 m room (sealed-room, the box -1..1 x 0..2 x -1..1): 'inside', the camera inside
//   the room at eye height a third of the way up (2/3), looking horizontally.
//   the same room with a glTF camera at (0.3, 1.2, 0.4): 'camera', from there along -z;
//   bevy's Cornell box (the demo, in centimetres): its inside point passes the enclosure rule
//   (its 1.7-unit eye sits on the floor before the green wall), and the views are judged by what
//   they show: 'front', which sees most of the box's surface and its five objects.
//   usage: node tests/preview/preview_start.mjs OPEN_GLTF CLOSED_GLTF CAMERA_GLTF BEVY_CORNELL_GLTF
import { startServer } from '../../tools/preview/server.mjs';
import { launchBrowser, openPreview } from '../../tools/preview/browser.mjs';

const [open, closed, withCamera, bevy] = process.argv.slice(2);
if (!bevy) { console.error('usage: node tests/preview/preview_start.mjs OPEN_GLTF CLOSED_GLTF CAMERA_GLTF BEVY_CORNELL_GLTF'); process.exit(1); }
const browser = await launchBrowser();
let ok = true;
async function start(gltf) {
  const srv = await startServer(gltf);
  try {
    const v = await openPreview(browser, srv.url, { mode: 'lit' });
    const cam = await v.page.evaluate(() => window.lmbInfo.camera);
    const from = await v.page.evaluate(() => window.lmbInfo.startView);
    const scores = await v.page.evaluate(() => window.lmbInfo.startScores);
    await v.context.close();
    return { from, cam, scores };
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
const c = await start(withCamera);
const [cx, cy, cz] = c.cam.position, [ux, uy, uz] = c.cam.target;
const good3 = c.from === 'camera' && Math.hypot(cx - 0.3, cy - 1.2, cz - 0.4) < 1e-4 &&
  Math.abs(ux - 0.3) < 1e-4 && Math.abs(uy - 1.2) < 1e-4 && uz < cz;
ok &&= good3;
console.log(`room with a camera: start view '${c.from}', camera (${c.cam.position.map((x) => x.toFixed(3))}) looking at (${c.cam.target.map((x) => x.toFixed(3))}) (want the file's camera at 0.3,1.2,0.4 along -z)  ${good3 ? 'ok' : 'FAIL'}`);
const d = await start(bevy);
const f = (x) => (x ? `seen ${x.seen.toFixed(3)}, ${x.objects} objects, score ${x.score.toFixed(3)}` : 'none');
const good4 = d.from === 'front' && d.scores && d.scores.front.score > d.scores.inside.score;
ok &&= good4;
console.log(`bevy's Cornell box: start view '${d.from}' (want front); inside ${f(d.scores && d.scores.inside)}; front ${f(d.scores && d.scores.front)}  ${good4 ? 'ok' : 'FAIL'}`);
await browser.close();
process.exit(ok ? 0 : 1);
