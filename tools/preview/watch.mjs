#!/usr/bin/env node
// `lmbake preview --watch LEVEL [-c CONFIG] [-o OUTDIR] [--port N] [--lightmap ktx2|hdr]`
// (docs/watch.md): bakes the level, serves the preview on 127.0.0.1 and bakes again whenever the
// level, its buffers and images, the config or its sky image change. Each change is baked twice:
// a quick look first (`lmbake bake --quick` into a private folder, never OUTDIR), then the real
// bake into OUTDIR exactly as `lmbake bake` writes it. A change during a bake stops that bake
// (SIGTERM; lmbake's output folder is swapped in whole or not at all) and the newest state is
// baked; a save that does not bake (a parse error, a bad key) leaves the last good bake on
// screen and the error on the page, in the log and at /status. The page (page/watch.html)
// shows each new bake in place, from the same camera.
// Exit 1: usage error; 2: the level is missing at the start; 3: the server could not start.
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import { spawn } from 'node:child_process';
import { projectRoot, resolveFile, TYPES } from './server.mjs';
import { watchedFiles, snapshot, configReader, fingerprint, compare } from './watch-inputs.mjs';
import { createComposer } from './compose.mjs';

const usage = 'usage: lmbake preview --watch LEVEL.gltf|glb [-c CONFIG] [-o OUTDIR] [--port N] [--lightmap ktx2|hdr]';
const POLL_MS = 100; // how often the files' sizes and times are looked at (and on every inotify event)
const SETTLE_MS = 30; // a change is baked once the files have stood still this long (a bake that read a save half-way is stopped and baked again)

function parseArgs(args) {
  const o = { level: null, config: null, outdir: 'lmbake-out', port: 0, lightmap: null, lmbake: process.env.LMBAKE || path.join(projectRoot, 'build', 'lmbake'), quick: true };
  for (let i = 0; i < args.length; i++) {
    const a = args[i], value = () => { if (i + 1 >= args.length) throw new Error(`${a} needs a value`); return args[++i]; };
    if (a === '-h' || a === '--help') { console.log(usage); process.exit(0); }
    else if (a === '-c' || a === '--config') o.config = path.resolve(value());
    else if (a === '-o' || a === '--output') o.outdir = value();
    else if (a === '--port') { o.port = Number(value()); if (!Number.isInteger(o.port) || o.port < 0 || o.port > 65535) throw new Error('--port wants 0..65535'); }
    else if (a === '--lightmap') { o.lightmap = value(); if (!['ktx2', 'hdr'].includes(o.lightmap)) throw new Error('--lightmap wants ktx2 or hdr'); }
    else if (a === '--lmbake') o.lmbake = value();
    else if (a === '--no-quick') o.quick = false;
    else if (a.startsWith('-')) throw new Error(`unknown option '${a}'`);
    else if (o.level === null) o.level = path.resolve(a);
    else throw new Error(`one level only ('${a}')`);
  }
  if (!o.level) throw new Error('no level given');
  o.outdir = path.resolve(o.outdir);
  return o;
}

let opts;
try { opts = parseArgs(process.argv.slice(2)); } catch (e) { console.error(`preview: ${e.message}\n${usage}`); process.exit(1); }
if (!fs.existsSync(opts.level)) { console.error(`preview: error: cannot open '${opts.level}' to watch`); process.exit(2); }
const stem = path.basename(opts.level).replace(/\.(gltf|glb)$/i, '');
const quickRoot = fs.mkdtempSync(path.join(os.tmpdir(), 'lmbake-watch-'));
// Layouts kept between bakes (lmbake bake --layout-cache): a change of lights, materials, sky or
// sampling keys reads the layout back instead of unwrapping and packing again.
const layoutRoot = path.join(quickRoot, 'layouts');
const say = (line) => console.log(`watch: ${line}`);
// The composed quick picture's maker: it keeps the last final bake's map to the quick layout
// (built while idle after each final bake) and the last few lightmaps it read.
const composer = createComposer();
const readConfig = configReader(); // the config's keys, kept while its bytes stand

// What the page and /status see.
const status = {
  state: 'starting', level: opts.level, config: opts.config, outdir: opts.outdir,
  generation: 0, // the newest change taken up (1: the first bake)
  shown: null, // {generation, kind: quick|final, readyAt (ms), seconds (from the change seen), changed, layout, placesKept}
  baking: null, // {generation, kind, stage, percent, startedAt}
  changed: [], layout: false, error: null, cancelled: 0, history: [],
};

let files = [], lastSnapshot = null, movedAt = 0, dirty = true, child = null, goodPrint = null;
let lastGroups = { quick: null, final: null }; // each kind's last bake's light groups (groupsOf)
let dying = 0; // stopped bakes not yet gone: the next one waits for them (one writer of OUTDIR at a time)

function stopChild(why) {
  if (!child) return;
  say(`${status.baking.kind} bake ${status.baking.generation} stopped (${why})`);
  status.cancelled++;
  child.cancelled = true;
  dying++;
  child.once('close', () => { dying--; safeTick(); });
  child.kill('SIGTERM');
  child = null;
  status.baking = null;
}

// One `lmbake bake` of the newest state: quick into QUICK/N, final into OUTDIR, each with the
// light of its stages written to QUICK/N-stages-KIND/STAGE (`--stages-out`; onStage(STAGE) is
// called once the bake says a stage's files are whole: direct, bounces). Resolves to {ok,
// seconds} or {ok: false, error}; a cancelled bake resolves {cancelled: true}.
const stageDir = (generation, kind, stage) => path.join(quickRoot, `${generation}-stages-${kind}`, stage);
function bake(kind, generation, onStage = null, extra = []) {
  const out = kind === 'quick' ? path.join(quickRoot, String(generation)) : opts.outdir;
  const stages = path.dirname(stageDir(generation, kind, 'direct'));
  fs.rmSync(stages, { recursive: true, force: true });
  const args = ['bake', opts.level, '-o', out, '--layout-cache', layoutRoot, '--stages-out', stages, ...(opts.config ? ['-c', opts.config] : []), ...(kind === 'quick' ? ['--quick'] : []), ...extra];
  return new Promise((resolve) => {
    const p = spawn(opts.lmbake, args, { stdio: ['ignore', 'pipe', 'pipe'] });
    child = p;
    status.baking = { generation, kind, stage: 'load', percent: 0, startedAt: Date.now(), pid: p.pid };
    let stderr = '', pending = '', stdout = '', outPending = '';
    p.stdout.on('data', (d) => {
      if (stdout.length < 65536) stdout += d;
      outPending += d;
      const lines = outPending.split('\n');
      outPending = lines.pop();
      for (const l of lines) {
        const m = /^stages: (\w+) written to /.exec(l);
        if (m && onStage && child === p && !p.cancelled) onStage(m[1]);
      }
    });
    p.stderr.on('data', (d) => {
      stderr += d;
      pending += d;
      const lines = pending.split(/[\r\n]/);
      pending = lines.pop();
      for (const l of lines) {
        const m = /^([a-zA-Z][^:]*): +(\d+)%/.exec(l);
        if (m && child === p) Object.assign(status.baking, { stage: m[1], percent: Number(m[2]) });
      }
    });
    p.on('error', (e) => resolve({ ok: false, error: `cannot run ${opts.lmbake}: ${e.message}` }));
    p.on('close', (code) => {
      if (p.cancelled) return resolve({ cancelled: true });
      if (child === p) { child = null; status.baking = null; }
      if (code === 0) return resolve({ ok: true, dir: out, layoutKept: /^layout: read back/m.test(stdout), groups: groupsOf(stdout) });
      const errors = stderr.split('\n').filter((l) => /error:/.test(l));
      resolve({ ok: false, code, error: (errors.length ? errors.join('\n') : stderr.trim().split('\n').slice(-3).join('\n')) || `lmbake exited ${code}` });
    });
  });
}

// What a bake with light groups did with each group (docs/light-groups.md): read back from the
// layout cache (a scale, or a unit group's weight: the sum only) or lit, and what each group
// weighs in the sum (its scale x a unit group's weight, per channel; `light` names a group's
// one light); null without groups.
function groupsOf(log) {
  const read = (log.match(/^light group '[^']*' \(\d+ of \d+\): read back/gm) || []).length;
  const litNames = [...log.matchAll(/^light group '([^']*)' \(\d+ of \d+\): lighting/gm)].map((m) => m[1]);
  const weights = {};
  for (const m of log.matchAll(/^light group '([^']*)': (\d+) light\(s\)(?: \('(.*?)'(, \.\.\.)?\))?(?:, the sky)?(?:, the emissive surfaces)?, scale ([^ ,()\n]+)(.*)$/gm)) {
    const unit = /: \[([^\]]*)\]\)$/.exec(m[6]);
    const w = unit ? unit[1].split(',').map(Number) : [1, 1, 1];
    weights[m[1]] = { light: m[2] === '1' && !m[4] ? m[3] : null, w: w.map((x) => x * Number(m[5])) };
  }
  return read + litNames.length ? { read, lit: litNames.length, litNames, weights } : null;
}

// What changed in the light groups from one bake to the next, in words: 'Lamp 0 x 2', 'group
// lamps x 0.5', 'sun tinted', 'Lamp 3 off', 'lit again: lamps'.
function relitOf(before, after) {
  if (!before || !after) return [];
  const said = [];
  for (const [name, g] of Object.entries(after.weights)) {
    const was = before.weights[name];
    if (!was || g.w.every((x, c) => x === was.w[c]) || after.litNames.includes(name)) continue;
    const label = g.light || `group ${name}`;
    const ratios = g.w.map((x, c) => (was.w[c] ? x / was.w[c] : NaN));
    if (g.w.every((x) => x === 0)) said.push(`${label} off`);
    else if (was.w.every((x) => x === 0)) said.push(`${label} on`);
    else if (ratios.every((r) => Math.abs(r - ratios[0]) <= 1e-4 * Math.abs(ratios[0]))) said.push(`${label} x ${Number(ratios[0].toPrecision(3))}`);
    else said.push(`${label} tinted`);
  }
  if (after.litNames.length) said.push(`lit again: ${after.litNames.join(', ')}`);
  return said;
}

// The newest state of the files, baked: fingerprint, quick bake, final bake; any step may
// find the files moved again (then it returns and the loop starts over).
async function bakeNewest() {
  dirty = false;
  if (!fs.existsSync(opts.level)) { status.state = 'waiting'; status.error = `${opts.level}: missing; waiting for it`; say(status.error); return; }
  if (opts.config && !fs.existsSync(opts.config)) { status.state = 'waiting'; status.error = `${opts.config}: missing; waiting for it`; say(status.error); return; }
  let print, fp;
  try {
    print = readConfig(opts.lmbake, opts.config);
    files = watchedFiles(opts.level, opts.config, print);
    lastSnapshot = snapshot(files);
    fp = fingerprint(opts.level, files, print);
  } catch (e) {
    files = watchedFiles(opts.level, opts.config, goodPrint);
    lastSnapshot = snapshot(files);
    return failed(`${e.message}`);
  }
  const change = compare(status.lastGood ? status.lastGood.fp : null, fp);
  const generation = ++status.generation;
  Object.assign(status, { state: 'baking', changed: change.what, layout: change.layout, placesKept: change.placesKept });
  say(`bake ${generation}: ${change.what.join('; ')} (${change.layout ? 'layout and lighting' : 'lighting only'})`);
  const seen = movedAt || Date.now(), started = lastSnapshot;
  const base = status.lastGood;
  // With light groups, a change that keeps the layout may only weigh the kept groups anew (a
  // scale, a lamp's intensity or colour): then the final bake is about a second and comes
  // first, with no quick look (`--relight-only` stops at once, exit 4, when a group is to be lit).
  if (opts.quick && !change.layout && lastGroups.final && base) {
    const r = await bake('final', generation, null, ['--relight-only']);
    if (r.cancelled || dirty) return;
    if (!r.ok && r.code !== 4 && snapshot(files) !== started) return superseded('final', generation);
    if (!r.ok && r.code !== 4) return failed(r.error);
    if (r.ok) {
      r.groups.relit = relitOf(lastGroups.final, r.groups);
      lastGroups = { quick: null, final: r.groups };
      showBake({ generation, kind: 'final', revision: 0, seen, change, layoutKept: r.layoutKept, composed: null, refined: null, groups: r.groups });
      return finished(fp, print, generation, null);
    }
  }
  let composed = null, quickLayoutKept = false;
  for (const kind of opts.quick ? ['quick', 'final'] : ['final']) {
    // A composed quick picture is refined while the final bake runs: once it has its direct light
    // (the direct light's change at the final's resolution: revision 1 of the quick bake), and
    // again once it has run its bounce passes (all the light's change at the final's resolution:
    // revision 2).
    const refine = kind === 'final' && composed !== null && base.stages ? (stage) => {
      if (dirty) return;
      let refined = null;
      if (stage === 'direct') refined = composeQuick(generation, change, { before: base.stages.final.direct, after: stageDir(generation, 'final', 'direct'), quickBefore: base.stages.quick.direct, quickAfter: stageDir(generation, 'quick', 'direct') });
      else if (stage === 'bounces') refined = composeBounced(generation, change, { before: base.stages.final.bounces, after: stageDir(generation, 'final', 'bounces') });
      else return;
      if (refined !== null) showBake({ generation, kind: 'quick', revision: stage === 'direct' ? 1 : 2, seen, change, layoutKept: quickLayoutKept, composed: refined, refined: stage });
    } : null;
    const r = await bake(kind, generation, refine);
    if (r.cancelled || dirty) return;
    if (!r.ok && snapshot(files) !== started) return superseded(kind, generation); // it read a save half-way
    if (!r.ok) return failed(r.error);
    // A quick look is shown at once, composed on the last final where it can be.
    composed = kind === 'quick' ? composeQuick(generation, change, null) : null;
    quickLayoutKept = r.layoutKept;
    if (r.groups) r.groups.relit = relitOf(lastGroups[kind], r.groups);
    lastGroups[kind] = r.groups;
    showBake({ generation, kind, revision: 0, seen, change, layoutKept: r.layoutKept, composed, refined: null, groups: r.groups });
  }
  finished(fp, print, generation, opts.quick ? path.join(quickRoot, String(generation)) : null);
}

// Generation N's final bake is in OUTDIR: the last good state (with its quick look's folder, or
// null when it had none), what the next change composes on.
function finished(fp, print, generation, quick) {
  const stagesOf = (kind) => ({ direct: stageDir(generation, kind, 'direct'), bounces: stageDir(generation, kind, 'bounces') });
  status.lastGood = { fp, generation, outdir: outdirStamp(), quick, stages: quick ? { quick: stagesOf('quick'), final: stagesOf('final') } : null };
  goodPrint = print;
  status.state = 'idle';
  tidyQuickDirs();
  // while the artist looks: what composing the next change on this final reads again
  if (status.lastGood.quick && fs.existsSync(status.lastGood.quick)) composer.prepare({ final: opts.outdir, quickBefore: status.lastGood.quick, stem });
}

// A bake (or a revision of one) on screen: /status, the history, the log line, the tidying.
function showBake({ generation, kind, revision, seen, change, layoutKept, composed, refined, groups = null }) {
  const seconds = (Date.now() - seen) / 1000;
  status.shown = { generation, kind, revision, readyAt: Date.now(), seconds, changed: change.what, layout: change.layout, placesKept: change.placesKept, layoutKept, composedOn: composed, refined, groups };
  status.history.push({ generation, kind, revision, seconds, changed: change.what });
  if (status.history.length > 50) status.history.shift();
  status.error = null;
  const relit = !groups || !groups.read ? '' : `${groups.relit.length ? `; relit: ${groups.relit.join(', ')}` : ''}; light groups: ${groups.read} read back${groups.lit ? `, ${groups.lit} lit` : ', none lit'}`;
  const what = `${change.what.join('; ')}${generation === 1 ? '' : ' changed'}${layoutKept ? '; layout kept' : ''}${relit}`;
  if (revision) say(`quick bake ${generation} refined in ${seconds.toFixed(1)} s (${refined === 'direct' ? 'the direct light' : 'the bounced light'} at the final's resolution, from final bake ${generation}'s ${refined === 'direct' ? 'direct stage' : 'bounce passes'})`);
  else say(`${kind} bake ${generation} ready in ${seconds.toFixed(1)} s (${what}${composed !== null ? `; composed on final bake ${composed}` : ''})`);
  tidyQuickDirs();
  tidyLayouts();
}

// OUTDIR's glTF as it stands (inode and time): the composed picture's base must be the final
// bake lastGood names, not one a stopped bake swapped in as it was stopped.
function outdirStamp() {
  try { const st = fs.statSync(path.join(opts.outdir, `${stem}.gltf`)); return `${st.ino}:${st.mtimeMs}`; } catch { return null; }
}

// After quick bake N of a change that keeps the layout (and the output's units): the picture
// shown is the last final bake plus the difference of the two quick looks, in the final's atlas
// (compose.mjs), refined with the direct light's change at the final's resolution when `direct`
// names the four direct-light folders ({before, after, quickBefore, quickAfter}), written to
// QUICK/N/composed (QUICK/N/composed-direct when refined). Returns the final bake's generation it
// was composed on, or null (then the quick look is shown as baked, or the first composition
// stays, and the log says why).
function composeQuick(generation, change, direct) {
  const base = status.lastGood;
  if (!base || !base.quick || change.layout || change.what.some((w) => /^config .*\boutput\./.test(w))) return null;
  const dir = path.join(quickRoot, String(generation)), out = path.join(dir, direct ? 'composed-direct' : 'composed');
  let r;
  if (!fs.existsSync(base.quick)) r = { ok: false, why: `its quick look is gone` };
  else if (outdirStamp() !== base.outdir) r = { ok: false, why: `${opts.outdir} holds another bake` };
  else {
    try {
      r = composer.compose({ final: opts.outdir, quickBefore: base.quick, quickAfter: dir, out, stem, direct, moved: !change.placesKept });
    } catch (e) {
      r = { ok: false, why: e.message };
    }
  }
  if (r.ok) return base.generation;
  fs.rmSync(out, { recursive: true, force: true }); // a half-written one is never served
  say(`quick bake ${generation}: ${direct ? 'not refined with the direct light' : `shown as baked, not composed on final bake ${base.generation}`} (${r.why})`);
  return null;
}

// After final bake N's bounce passes (a change that keeps the layout, composed first): the last
// final bake plus the change of the light the two final bakes' bounce passes reached, texel for
// texel (compose.mjs composeBounces), written to QUICK/N/composed-bounces. Returns the final
// bake's generation it was composed on, or null (the picture before stays; the log says why).
function composeBounced(generation, change, bounces) {
  const base = status.lastGood, out = path.join(quickRoot, String(generation), 'composed-bounces');
  let r;
  if (outdirStamp() !== base.outdir) r = { ok: false, why: `${opts.outdir} holds another bake` };
  else if (!fs.existsSync(bounces.before)) r = { ok: false, why: `final bake ${base.generation} ran no bounce passes` };
  else {
    try { r = composer.composeBounces({ final: opts.outdir, out, stem, ...bounces }); } catch (e) { r = { ok: false, why: e.message }; }
  }
  if (r.ok) return base.generation;
  fs.rmSync(out, { recursive: true, force: true });
  say(`quick bake ${generation}: not refined with the bounced light (${r.why})`);
  return null;
}

// A bake that failed while the files moved under it (a save it read half-way, before the poll
// saw the save) is a stopped bake, not an error: the newest state is baked once it settles.
function superseded(kind, generation) {
  say(`${kind} bake ${generation} stopped (the files changed while it read them)`);
  status.cancelled++;
  lastSnapshot = snapshot(files);
  movedAt = Date.now();
  dirty = true;
}

function failed(message) {
  status.state = 'error';
  status.error = message;
  say(`error: ${message.split('\n').join(' / ')}; ${status.shown ? `bake ${status.shown.generation} stays on screen` : 'nothing baked yet'}; waiting for the next save`);
}

// Quick folders (and their direct light) no page can still want: all but the shown
// generation's, the newest and the last good final's (the next composed picture's "before").
function tidyQuickDirs() {
  for (const d of fs.readdirSync(quickRoot)) {
    const m = /^(\d+)(-stages-(quick|final))?$/.exec(d);
    if (!m) continue; // the layouts
    const g = Number(m[1]);
    const base = status.lastGood && status.lastGood.generation === g;
    if (g !== status.generation && !base && !(status.shown && status.shown.generation === g && status.shown.kind === 'quick')) fs.rmSync(path.join(quickRoot, d), { recursive: true, force: true });
  }
}

// Layouts: the four used last (a quick and a final one, before and after a change of layout);
// lmbake touches a layout it reads back. The gather points' validity kept with a layout
// (layout-KEY-seedN.lmbv) and the probes placed with it (layout-KEY-probes.lmbq) go with it.
function tidyLayouts() {
  let names = [];
  try { names = fs.readdirSync(layoutRoot); } catch { return; }
  const kept = names.filter((f) => f.endsWith('.lmbp')).map((f) => ({ f, t: fs.statSync(path.join(layoutRoot, f)).mtimeMs }));
  kept.sort((a, b) => b.t - a.t);
  for (const { f } of kept.slice(4)) {
    const key = f.slice(0, -'.lmbp'.length);
    for (const g of names) if (g === f || g.startsWith(`${key}-`)) fs.rmSync(path.join(layoutRoot, g), { force: true });
  }
}

// The loop: poll sizes and times; a move stops the running bake at once and, once the files
// have settled, bakes the newest state.
let running = false;
function tick() {
  const watched = files.length ? files : [{ file: opts.level }];
  listen(watched);
  const now = snapshot(watched);
  if (lastSnapshot !== null && now !== lastSnapshot) {
    lastSnapshot = now;
    movedAt = Date.now();
    dirty = true;
    stopChild('the files changed');
    setTimeout(() => safeTick(), SETTLE_MS + 1); // baked as soon as it has settled, not at the next poll
  }
  if (dirty && !running && !dying && Date.now() - movedAt >= SETTLE_MS) { // not awaited: the polling goes on during the bake
    running = true;
    bakeNewest().catch((e) => failed(String((e && e.stack) || e))).finally(() => { running = false; });
  }
}

function safeTick() {
  try { tick(); } catch (e) { failed(String((e && e.stack) || e)); }
}

// inotify (fs.watch) on the folders of the watched files: a save is seen at once rather than at
// the next poll. Events name files; only the watched names tick (the output or an editor's swap
// file beside the level do not). The polling stays: it is what sees a change where inotify is
// not there (a network file system).
const listening = new Map(); // folder -> {watcher, names}
function listen(watched) {
  const want = new Map();
  for (const { file } of watched) {
    const dir = path.dirname(file);
    if (!want.has(dir)) want.set(dir, new Set());
    want.get(dir).add(path.basename(file));
  }
  for (const [dir, l] of listening) if (!want.has(dir)) { l.watcher.close(); listening.delete(dir); }
  for (const [dir, names] of want) {
    if (listening.has(dir)) { listening.get(dir).names = names; continue; }
    try {
      const l = { names, watcher: null };
      l.watcher = fs.watch(dir, { persistent: false }, (_, name) => { if (!name || l.names.has(String(name))) safeTick(); });
      l.watcher.on('error', () => { l.watcher.close(); listening.delete(dir); }); // listened to again at the next tick
      listening.set(dir, l);
    } catch { /* polled only */ }
  }
}

// HTTP: the watch page, the preview page in its frame, each bake's files, /status.
const three = path.join(projectRoot, 'node_modules', 'three');
const pageRoot = path.join(projectRoot, 'tools', 'preview', 'page');
const staticRoots = [['/page/', pageRoot], ['/loaders/', path.join(projectRoot, 'loaders')], ['/three/build/', path.join(three, 'build')], ['/three/examples/jsm/', path.join(three, 'examples', 'jsm')]];
const server = http.createServer((req, res) => {
  const send = (code, type, body) => {
    res.writeHead(code, { 'Content-Type': type, 'Cache-Control': 'no-store', 'X-Content-Type-Options': 'nosniff' });
    res.end(req.method === 'HEAD' ? undefined : body);
  };
  if (req.method !== 'GET' && req.method !== 'HEAD') return send(405, 'text/plain', 'read-only\n');
  const url = new URL(req.url, 'http://127.0.0.1');
  const file = (f) => fs.readFile(f, (err, data) => (err ? send(404, 'text/plain', 'not found\n') : send(200, TYPES[path.extname(f).toLowerCase()] || 'application/octet-stream', data)));
  if (url.pathname === '/' || url.pathname === '/watch.html') return file(path.join(pageRoot, 'watch.html'));
  if (url.pathname === '/index.html') return file(path.join(pageRoot, 'index.html'));
  if (url.pathname === '/status') {
    const { lastGood, ...view } = status; // eslint-disable-line no-unused-vars
    return send(200, 'application/json', JSON.stringify({ ...view, now: Date.now(), watching: files.map((f) => f.file) }));
  }
  if (url.pathname === '/scene.json') {
    // rev: a quick bake's revision (0: as shown first, 1: refined with the direct light, 2: with
    // the bounced light); the newest there is (up to rev) when it is not given
    const kind = url.searchParams.get('kind'), gen = url.searchParams.get('gen'), rev = url.searchParams.get('rev');
    if (!['quick', 'final'].includes(kind) || !/^\d+$/.test(gen || '') || (rev !== null && !['0', '1', '2'].includes(rev))) return send(404, 'text/plain', 'no such bake\n');
    const has = (d) => fs.existsSync(path.join(quickRoot, gen, d, `${stem}.gltf`));
    const upTo = rev === null ? 2 : Number(rev);
    const composed = kind !== 'quick' ? '' : upTo >= 2 && has('composed-bounces') ? 'composed-bounces/' : upTo >= 1 && has('composed-direct') ? 'composed-direct/' : has('composed') ? 'composed/' : '';
    const name = { 'composed-bounces/': ', composed on the last final, all the light at full resolution', 'composed-direct/': ', composed on the last final, the direct light at full resolution', 'composed/': ', composed on the last final' }[composed] || '';
    return send(200, 'application/json', JSON.stringify({ gltf: `/bake/${kind}/${gen}/${composed}${encodeURIComponent(stem)}.gltf`, name: `${stem}.gltf (${kind} bake ${gen}${name})` }));
  }
  const m = /^\/bake\/(quick|final)\/(\d+)\//.exec(url.pathname);
  const roots = m ? [[m[0], m[1] === 'quick' ? path.join(quickRoot, m[2]) : opts.outdir]] : staticRoots;
  const f = resolveFile(roots, url.pathname);
  return f ? file(f) : send(404, 'text/plain', 'not found\n');
});
server.once('error', (e) => { console.error(`preview: error: ${e.message}`); process.exit(3); });
server.listen(opts.port, '127.0.0.1', () => {
  console.log(`preview: http://127.0.0.1:${server.address().port}/${opts.lightmap ? '?lightmap=' + opts.lightmap : ''}`);
  say(`watching ${opts.level}${opts.config ? ' and ' + opts.config : ''}; final bakes go to ${opts.outdir}; Ctrl-C stops`);
  const loop = () => { safeTick(); setTimeout(loop, POLL_MS); };
  loop();
});
const stop = () => {
  for (const l of listening.values()) l.watcher.close();
  if (child) { child.cancelled = true; child.kill('SIGTERM'); }
  fs.rmSync(quickRoot, { recursive: true, force: true });
  server.closeAllConnections();
  server.close(() => process.exit(0));
  setTimeout(() => process.exit(0), 1000).unref();
};
process.on('SIGINT', stop);
process.on('SIGTERM', stop);
