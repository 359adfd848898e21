// Headless Chromium for the preview (render.mjs and the e2e test): playwright-core driving
// Debian's /usr/bin/chromium (no browser download). WebGL 2 runs on SwiftShader: --disable-gpu
// plus --enable-unsafe-swiftshader; never --use-gl=swiftshader (it turns WebGL off).
// playwright-core already adds --no-sandbox, --disable-background-networking and friends
// (without them Chromium hangs on a closed network) and a fresh profile.
import fs from 'node:fs';
import { chromium } from 'playwright-core';

export const CHROMIUM = process.env.LMB_CHROMIUM || '/usr/bin/chromium';
export const VIEWPORT = { width: 960, height: 720 };

export async function launchBrowser() {
  if (!fs.existsSync(CHROMIUM)) throw new Error(`${CHROMIUM} not found: install Debian's chromium (tools/setup.sh does)`);
  return chromium.launch({
    executablePath: CHROMIUM, headless: true,
    args: ['--enable-unsafe-swiftshader', '--disable-gpu', '--force-color-profile=srgb', '--ignore-gpu-blocklist'],
  });
}

// Opens the preview at baseUrl with the query params; waits for window.lmbReady. Throws with
// the page's error (window.lmbInfo.error, page errors, console errors) if it never gets ready.
export async function openPreview(browser, baseUrl, params = {}, { timeout = 30000 } = {}) {
  const context = await browser.newContext({ viewport: VIEWPORT, deviceScaleFactor: 1 });
  const page = await context.newPage();
  const errors = [];
  page.on('pageerror', (e) => errors.push('page error: ' + e.message));
  page.on('console', (m) => { if (m.type() === 'error') errors.push('console error: ' + m.text()); });
  page.on('requestfailed', async (r) => {
    const resp = await r.response().catch(() => null); // Chromium reports some finished fetches as ERR_ABORTED
    if (!resp || resp.status() >= 400) errors.push(`request failed: ${r.url()} (${r.failure() && r.failure().errorText})`);
    else if (process.env.LMB_PREVIEW_VERBOSE) console.error(`note: ${r.url()}: ${r.failure().errorText} after HTTP ${resp.status()}`);
  });
  page.on('response', (r) => { if (r.status() >= 400) errors.push(`HTTP ${r.status()}: ${r.url()}`); });
  let onError; // a page error ends the wait at once (a broken module never sets lmbReady)
  const failed = new Promise((resolve) => { onError = resolve; page.on('pageerror', () => resolve()); });
  const url = baseUrl + '?' + new URLSearchParams({ ui: '0', ...params }).toString();
  await page.goto(url);
  try {
    await Promise.race([failed, page.waitForFunction(() => window.lmbReady === true || (window.lmbInfo && window.lmbInfo.error), null, { timeout, polling: 100 })]);
  } catch {
    errors.push(`not ready after ${timeout / 1000} s`);
  }
  onError();
  const info = await page.evaluate(() => window.lmbInfo || null).catch(() => null);
  if (info && info.error) errors.unshift('lmbInfo.error: ' + info.error);
  if (errors.length) {
    await context.close();
    throw new Error(`preview ${url}: ${errors.join('; ')}`);
  }
  return { page, context, info, url, errors, baseUrl, params };
}

// The page of a view openPreview (or this) returned, shown with other view parameters without a
// reload (the page's lmbSet): what openPreview(browser, baseUrl, params) would show, for ~0.3 s
// instead of a new page's ~2 s. The parameters read at load only must be as the page was opened.
const LOAD_ONLY = ['lightmap', 'directional', 'sphere', 'probes', 'ui', 'gen', 'kind', 'rev'];
export async function showPreview(v, params = {}) {
  for (const k of LOAD_ONLY)
    if (String(params[k] ?? '') !== String(v.params[k] ?? '')) throw new Error(`showPreview: '${k}' is read at load only (${v.url})`);
  const view = Object.fromEntries(Object.entries(params).filter(([k]) => !LOAD_ONLY.includes(k)).map(([k, x]) => [k, String(x)]));
  const url = v.baseUrl + '?' + new URLSearchParams({ ui: '0', ...params }).toString();
  const info = await v.page.evaluate((p) => window.lmbSet(p), view).catch((e) => { throw new Error(`preview ${url}: ${e.message}`); });
  if (info && info.error) throw new Error(`preview ${url}: lmbInfo.error: ${info.error}`);
  return { ...v, info, url, params };
}

// Open pages of one preview URL, one per set of load-only parameters: show(params) opens a page
// the first time its set is asked for and switches that page (showPreview) after. Views of one
// page share it: a view's page shows what the last show() on it asked for.
export function previewPages(browser, baseUrl) {
  const pages = new Map();
  return {
    async show(params) {
      const key = LOAD_ONLY.map((k) => String(params[k] ?? '')).join('\n'), v = pages.get(key);
      const w = v ? await showPreview(v, params) : await openPreview(browser, baseUrl, params);
      pages.set(key, w);
      return w;
    },
    async close() {
      for (const v of pages.values()) await v.context.close();
      pages.clear();
    },
  };
}
