// The page of `lmbake preview --watch` (tools/preview/watch.mjs): polls /status; when a newer
// bake is ready (quick or final) it opens it in a hidden frame of the preview page, from the
// shown frame's camera, view mode, exposure and tone mapping, and swaps the frames once the new
// one has drawn: no reload, no blank moment. The bar says what is shown (quick or final, which
// bake, how old, what changed) and what is baking; a bake that failed shows its error and the
// last good bake stays. Hooks for tests: window.lmbWatch (the last /status), lmbWatchShown
// ({generation, kind, revision} of the frame on screen: a quick bake's revision 1 is it refined
// with the direct light at the final's resolution, 2 with all the light the final's bounce
// passes reached), lmbWatchFrame() (its window).
const q = new URLSearchParams(location.search);
const $ = (id) => document.getElementById(id);
let shownFrame = null, shownKey = null, loadingKey = null;
window.lmbWatchShown = null;
window.lmbWatchFrame = () => (shownFrame ? shownFrame.contentWindow : null);
const keyOf = (s) => `${s.generation}:${s.kind}:${s.revision || 0}`;

// The view to open the next bake with: the page's own query, then what the shown frame has now.
function viewParams() {
  const p = new URLSearchParams(q);
  const w = window.lmbWatchFrame();
  if (w && w.lmbReady && w.lmbCamera) {
    const c = w.lmbCamera();
    p.set('cam', [...c.position, ...c.target].join(','));
    p.delete('view');
    const info = w.lmbInfo || {};
    for (const k of ['mode', 'ev', 'tonemap']) if (info[k] !== undefined) p.set(k, info[k]);
  }
  return p;
}

function show(s) {
  const key = keyOf(s);
  loadingKey = key;
  const p = viewParams();
  p.set('gen', s.generation);
  p.set('kind', s.kind);
  p.set('rev', s.revision || 0);
  const frame = document.createElement('iframe');
  frame.className = 'pending';
  frame.src = '/index.html?' + p.toString();
  $('frames').append(frame);
  const started = Date.now();
  const wait = () => {
    const w = frame.contentWindow;
    const error = w && w.lmbInfo && w.lmbInfo.error;
    if (loadingKey !== key) return frame.remove(); // a newer bake came first
    if (w && (w.lmbReady || error)) {
      if (error) console.error(`lmbake watch: bake ${key}: ${error}`);
      frame.className = '';
      if (shownFrame) shownFrame.remove();
      shownFrame = frame;
      shownKey = key;
      loadingKey = null;
      window.lmbWatchShown = { generation: s.generation, kind: s.kind, revision: s.revision || 0 };
      return;
    }
    if (Date.now() - started > 120000) { loadingKey = null; frame.remove(); return; }
    setTimeout(wait, 50);
  };
  frame.addEventListener('load', wait, { once: true });
}

const age = (ms) => (ms < 60000 ? `${Math.round(ms / 1000)} s` : `${Math.round(ms / 60000)} min`);
function bar(s) {
  const sh = s.shown;
  $('shown').innerHTML = sh ? `<b class="${sh.kind}">${sh.kind} bake ${sh.generation}</b>, ${age(s.now - sh.readyAt)} old (${sh.changed.join('; ')}; ready ${sh.seconds.toFixed(1)} s after the change${sh.layoutKept ? ', layout kept' : ''}${sh.composedOn ? `; the last final bake ${sh.composedOn} plus the change at the quick look's resolution${sh.refined === 'bounces' ? ' (all the light at full resolution, from the final bake\'s bounce passes)' : sh.refined === 'direct' ? ' (the direct light at full resolution; refining: the bounced light next)' : s.baking && s.baking.kind === 'final' && s.baking.generation === sh.generation ? ' (refining: the direct light at full resolution next)' : ''}` : ''})` : 'waiting for the first bake';
  const b = s.baking;
  $('next').textContent = b ? `baking: ${b.kind} bake ${b.generation}, ${b.stage} ${b.percent}%` : s.state === 'idle' ? 'up to date' : s.state;
  $('werror').textContent = s.error ? `lmbake: ${s.error}\n${sh ? `(bake ${sh.generation} stays on screen until the next good save)` : ''}` : '';
  $('werror').style.display = s.error ? 'block' : 'none';
  if (q.get('ui') === '0') $('bar').classList.add('hidden');
}

async function poll() {
  try {
    const s = await (await fetch('/status', { cache: 'no-store' })).json();
    window.lmbWatch = s;
    bar(s);
    if (s.shown && keyOf(s.shown) !== shownKey && keyOf(s.shown) !== loadingKey) show(s.shown);
  } catch (e) {
    $('next').textContent = `the watch is not answering (${e.message})`;
  }
  setTimeout(poll, 250);
}
poll();
