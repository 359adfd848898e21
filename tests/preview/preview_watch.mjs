#!/usr/bin/env node
// `lmbake preview --watch` in headless Chromium (docs/watch.md). The watch bakes a copy of
// tools/make_scenes.py's cornell-point.gltf; the page shows bake 1 (final) from a fixed camera
// and exposure, tone mapping "none". The test triples the light's intensity in the file: at five
// points of the picture (floor, walls, ceiling, a block) the page's pixels change to bake 2's
// quick values, then to its final ones, without a reload (a marker on the page's window
// survives) and with the camera unchanged. Bake 2's final pixels are 3x bake 1's in linear light
// (the bake is linear in the light; 3% and 2 levels allowed for the 8-bit screenshot). Its quick
// picture is shown three times: first what the plain preview shows of bake 1's final composed with
// the two files' quick looks (`lmbake bake --quick`), then, once bake 2's final bake has its direct
// light, that refined with the direct light of both files' final and quick bakes (and, since no
// light moved, the final's other detail scaled with the light), then, once it
// has run its bounce passes, bake 1's final plus the change of the light both final bakes' bounce
// passes reached (`--stages-out`, tools/preview/compose.mjs). The final bake waits (the watch
// runs it through held_lmbake.sh) while each is read. Then a
// half-written level: the page shows the error and keeps bake 2's pixels exactly. Screenshots in
// SHOTS_DIR (preview-watch-*.png).
//   usage: node tests/preview/preview_watch.mjs LMBAKE WORKDIR SHOTS_DIR
import fs from 'node:fs';
import path from 'node:path';
import { spawn, execFileSync } from 'node:child_process';
import { launchBrowser, openPreview, VIEWPORT } from '../../tools/preview/browser.mjs';
import { startServer } from '../../tools/preview/server.mjs';
import { compose, composeBounces } from '../../tools/preview/compose.mjs';
import { decodePng, srgb } from './lib.mjs';

const [lmbake, work, shots] = process.argv.slice(2);
if (!shots) { console.error('usage: node tests/preview/preview_watch.mjs LMBAKE WORKDIR SHOTS_DIR'); process.exit(1); }
const root = path.resolve(path.dirname(new URL(import.meta.url).pathname), '..', '..');
const linear = (c) => { c /= 255; return c <= 0.04045 ? c / 12.92 : Math.pow((c + 0.055) / 1.055, 2.4); };

// the level: cornell-point.gltf and its buffer, copied; a config with bounce passes (4 bounces:
// the second refinement comes from them) and few rays (the holds below, not the bake's length,
// keep each picture on screen while it is read)
fs.rmSync(work, { recursive: true, force: true });
execFileSync('python3', [path.join(root, 'tools', 'make_scenes.py'), path.join(work, 'scenes')], { stdio: 'ignore' });
const dir = path.join(work, 'level');
fs.mkdirSync(dir, { recursive: true });
fs.mkdirSync(shots, { recursive: true });
const level = path.join(dir, 'cornell-point.gltf');
const doc = JSON.parse(fs.readFileSync(path.join(work, 'scenes', 'cornell-point.gltf'), 'utf8'));
for (const b of doc.buffers || []) if (b.uri && !b.uri.startsWith('data:')) fs.copyFileSync(path.join(work, 'scenes', b.uri), path.join(dir, b.uri));
const save = () => fs.writeFileSync(level, JSON.stringify(doc, null, 1));
save();
const cfg = path.join(dir, 'bake.yaml');
fs.writeFileSync(cfg, 'texel_density: 16\nbounces: 4\nsamples: {gather: 256, bounce: 256}\n');

// The watch as `lmbake preview --watch` starts it (check_watch.py runs that command itself), its
// bakes run through held_lmbake.sh: bake 2's final bake waits while its first quick picture is
// read and stops at each stage the quick picture is refined from, until the test lets it go on
// (it removes that hold file), however fast the bake or loaded the machine.
const holds = path.join(work, 'holds');
fs.mkdirSync(holds, { recursive: true });
const hold = (name) => fs.writeFileSync(path.join(holds, name), '');
const release = (name) => fs.rmSync(path.join(holds, name), { force: true });
const watch = spawn('node', [path.join(root, 'tools', 'preview', 'watch.mjs'), level, '--lmbake', path.join(root, 'tests', 'preview', 'held_lmbake.sh'), '-c', cfg, '-o', path.join(work, 'out')],
  { stdio: ['ignore', 'pipe', 'inherit'], env: { ...process.env, LMBAKE_REAL: path.resolve(lmbake), LMBAKE_HOLD_DIR: holds } });
let log = '';
const url = await new Promise((resolve, reject) => {
  watch.stdout.on('data', (d) => {
    log += d;
    const m = /preview: (http:\/\/127\.0\.0\.1:\d+\/)/.exec(log);
    if (m) resolve(m[1]);
  });
  watch.on('exit', (c) => reject(new Error(`the watch exited (${c}): ${log}`)));
});

let failures = 0;
const check = (ok, msg) => { console.log(`${ok ? 'ok' : 'FAIL'}: ${msg}`); failures += !ok; };
const browser = await launchBrowser();
try {
  const context = await browser.newContext({ viewport: VIEWPORT, deviceScaleFactor: 1 });
  const page = await context.newPage();
  page.on('pageerror', (e) => check(false, 'page error: ' + e.message));
  // a camera inside the box looking at the back wall, over the floor
  await page.goto(url + '?' + new URLSearchParams({ ui: '0', mode: 'lit', tonemap: 'none', ev: '-7', cam: '0.5,0.5,2.2,0.5,0.45,0' }));
  const shown = (g, kind, revision = 0) => page.waitForFunction(([g, kind, revision]) => window.lmbWatchShown && window.lmbWatchShown.generation === g && window.lmbWatchShown.kind === kind && window.lmbWatchShown.revision === revision, [g, kind, revision], { timeout: 240000, polling: 50 });
  await shown(1, 'final');
  await page.evaluate(() => { window.lmbTestMarker = 'no reload'; });
  // the points: pixels of the floor (in front of the blocks), back wall, left and right walls, ceiling
  const points = [[0.75, 0, 0.85], [0.5, 0.5, 0], [0, 0.5, 0.6], [1, 0.5, 0.6], [0.2, 1, 0.8]];
  const pixels = async (name) => {
    const f = page.frames().filter((x) => x !== page.mainFrame()).pop();
    const at = [];
    for (const p of points) at.push(await f.evaluate((p) => window.lmbProject(...p), p));
    const png = decodePng(await page.screenshot({ path: path.join(shots, `preview-watch-${name}.png`) }));
    return at.map((s) => png.at(Math.round(s.x - 0.5), Math.round(s.y - 0.5)));
  };
  const camera = async () => (await page.frames().filter((x) => x !== page.mainFrame()).pop().evaluate(() => window.lmbCamera()));
  const b1 = await pixels('bake1'), cam1 = await camera();
  check(b1.every((px) => Math.max(...px) > 8 && Math.max(...px) < 150), `bake 1 shown; pixels ${JSON.stringify(b1)}`);
  // what bake 2's quick picture is composed from: bake 1's final (OUTDIR, copied now), the quick
  // look of bake 1's file and the stages of both (baked here as the watch did)
  const final1 = path.join(work, 'final1'), quick1 = path.join(work, 'quick1');
  fs.cpSync(path.join(work, 'out'), final1, { recursive: true });
  execFileSync(lmbake, ['bake', level, '-c', cfg, '-o', quick1, '--quick', '-q']);
  const stagesOf = (tag) => ['final', 'quick'].map((k) => {
    const out = path.join(work, `stages-${k}${tag}`);
    execFileSync(lmbake, ['bake', level, '-c', cfg, '-o', `${out}-bake`, '--stages-out', out, ...(k === 'quick' ? ['--quick'] : []), '-q']);
    return out;
  });
  const [stages1, qstages1] = stagesOf(1);

  for (const h of ['final', 'direct', 'bounces']) hold(h);
  doc.extensions.KHR_lights_punctual.lights[0].intensity *= 3;
  save();
  const status = async () => (await fetch(url + 'status')).json();
  const finalBaking = (st) => !!(st.baking && st.baking.generation === 2 && st.baking.kind === 'final');
  await shown(2, 'quick', 0);
  const q2 = await pixels('bake2-quick'), camQ = await camera(), statusQ = await status();
  check(finalBaking(statusQ), `bake 2's final bake waits to start while the first quick picture is read (/status baking: ${JSON.stringify(statusQ.baking)})`);
  release('final');
  await shown(2, 'quick', 1); // revision 1: refined with the direct light at the final's resolution
  const q2r = await pixels('bake2-quick-refined'), statusR = await status();
  check(finalBaking(statusR), `bake 2's final bake waits after its direct stage while the refined picture is read (/status baking: ${JSON.stringify(statusR.baking)})`);
  release('direct');
  await shown(2, 'quick', 2); // revision 2: all the light the bounce passes reached, at the final's resolution
  const q2b = await pixels('bake2-quick-bounced'), statusB = await status();
  check(finalBaking(statusB), `bake 2's final bake waits after its bounce passes while that picture is read (/status baking: ${JSON.stringify(statusB.baking)})`);
  release('bounces');
  await shown(2, 'final');
  const f2 = await pixels('bake2-final'), cam2 = await camera();
  for (let i = 0; i < points.length; i++) {
    for (let c = 0; c < 3; c++) {
      const want = 3 * linear(b1[i][c]);
      const okFinal = Math.abs(linear(f2[i][c]) - want) <= 0.03 * want || Math.abs(f2[i][c] - srgb(want)) <= 2;
      if (!okFinal) check(false, `point ${i} channel ${c}: final ${f2[i][c]}, want sRGB ${srgb(want).toFixed(1)} (3 x bake 1's ${b1[i][c]})`);
    }
  }
  // the quick picture: bake 1's final plus the change at the quick look's resolution (bake 2's
  // quick look less bake 1's, compose.mjs; its values are checked in watch_compose), then refined
  // with the direct light's change at the final's: what the plain preview shows of those composed
  // here, from the same camera, within a level
  const quickDir = path.join(work, 'quick2');
  execFileSync(lmbake, ['bake', level, '-c', cfg, '-o', quickDir, '--quick', '-q']);
  const [stages2, qstages2] = stagesOf(2);
  const plainPixels = async (composedDir) => {
    const srv = await startServer(path.join(composedDir, 'cornell-point.gltf'));
    const v = await openPreview(browser, srv.url, { mode: 'lit', tonemap: 'none', ev: '-7', cam: '0.5,0.5,2.2,0.5,0.45,0' });
    const png = decodePng(await v.page.screenshot());
    const at = [];
    for (const p of points) { const s = await v.page.evaluate((p) => window.lmbProject(...p), p); at.push(png.at(Math.round(s.x - 0.5), Math.round(s.y - 0.5))); }
    await v.context.close();
    await srv.close();
    return at;
  };
  const largest = (a, b) => Math.max(...a.flatMap((px, i) => px.map((x, c) => Math.abs(x - b[i][c]))));
  const composed = compose({ final: final1, quickBefore: quick1, quickAfter: quickDir, out: path.join(work, 'composed2'), stem: 'cornell-point', moved: false });
  check(composed.ok && statusQ.shown.composedOn === 1 && statusQ.shown.revision === 0, `bake 2's quick picture composed on final bake 1 (/status: ${JSON.stringify(statusQ.shown.composedOn)}, revision ${statusQ.shown.revision}; here: ${composed.ok || composed.why})`);
  const wantQuick = composed.ok ? await plainPixels(path.join(work, 'composed2')) : [];
  check(composed.ok && largest(q2, wantQuick) <= 1, `bake 2's quick picture is the composed one: ${JSON.stringify(q2)} against ${JSON.stringify(wantQuick)}`);
  const refined = compose({ final: final1, quickBefore: quick1, quickAfter: quickDir, out: path.join(work, 'refined2'), stem: 'cornell-point', direct: { before: path.join(stages1, 'direct'), after: path.join(stages2, 'direct'), quickBefore: path.join(qstages1, 'direct'), quickAfter: path.join(qstages2, 'direct') }, moved: false });
  check(refined.ok && statusR.shown.refined === 'direct' && statusR.shown.composedOn === 1 && statusR.shown.placesKept === true, `then refined with the direct light at the final's resolution, the final's other detail scaled (no light moved) (/status refined: ${JSON.stringify(statusR.shown.refined)}, placesKept ${statusR.shown.placesKept}; here: ${refined.ok || refined.why})`);
  const wantRefined = refined.ok ? await plainPixels(path.join(work, 'refined2')) : [];
  check(refined.ok && largest(q2r, wantRefined) <= 1, `bake 2's refined quick picture is the refined composition: ${JSON.stringify(q2r)} against ${JSON.stringify(wantRefined)}`);
  const bounced = composeBounces({ final: final1, out: path.join(work, 'bounced2'), stem: 'cornell-point', before: path.join(stages1, 'bounces'), after: path.join(stages2, 'bounces') });
  check(bounced.ok && statusB.shown.refined === 'bounces' && statusB.shown.composedOn === 1, `then refined with the bounced light at the final's resolution (/status refined: ${JSON.stringify(statusB.shown.refined)}; here: ${bounced.ok || bounced.why})`);
  const wantBounced = bounced.ok ? await plainPixels(path.join(work, 'bounced2')) : [];
  check(bounced.ok && largest(q2b, wantBounced) <= 1, `bake 2's quick picture refined with the bounced light is that composition: ${JSON.stringify(q2b)} against ${JSON.stringify(wantBounced)}`);
  check(true, `bake 2 (light x 3): quick ${JSON.stringify(q2)} then final ${JSON.stringify(f2)} against bake 1 ${JSON.stringify(b1)}`);
  const same = (a, b) => a.position.every((v, k) => Math.abs(v - b.position[k]) < 1e-9) && a.target.every((v, k) => Math.abs(v - b.target[k]) < 1e-9);
  check(same(cam1, camQ) && same(cam1, cam2), `the camera stayed where it was (${cam2.position.map((v) => v.toFixed(3))})`);
  check(await page.evaluate(() => window.lmbTestMarker) === 'no reload', 'no reload: the page is the same page');

  // a half-written level: the error on the page, bake 2's pixels kept
  const text = JSON.stringify(doc, null, 1);
  fs.writeFileSync(level, text.slice(0, text.length >> 1));
  await page.waitForFunction(() => window.lmbWatch && window.lmbWatch.state === 'error', null, { timeout: 60000, polling: 50 });
  await page.waitForTimeout(600);
  const errorText = await page.evaluate(() => document.getElementById('werror').textContent);
  await page.screenshot({ path: path.join(shots, 'preview-watch-error.png') });
  await page.evaluate(() => { document.getElementById('werror').style.visibility = 'hidden'; }); // the frame's pixels under it
  const e2 = await pixels('error-frame');
  await page.evaluate(() => { document.getElementById('werror').style.visibility = ''; });
  check(errorText.includes('cornell-point.gltf') && await page.evaluate(() => document.getElementById('werror').style.display) === 'block', `the error is on the page: ${errorText.split('\n')[0].slice(0, 140)}`);
  check(JSON.stringify(e2) === JSON.stringify(f2) && (await page.evaluate(() => window.lmbWatchShown.generation)) === 2, 'bake 2 stays on screen, pixel for pixel');
  await context.close();
} catch (e) {
  check(false, e.stack || String(e));
} finally {
  for (const h of ['final', 'direct', 'bounces']) release(h); // a held bake goes on (and ends with the watch)
  await browser.close();
  watch.kill('SIGTERM');
}
console.log(log.split('\n').filter((l) => l.startsWith('watch:')).join('\n'));
process.exit(failures ? 1 : 0);
