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
  return { page, context, info, url, errors };
}
