#!/usr/bin/env node
// The preview's lit view shows no seam line (issue 14). Opens two bakes of the seams scene
// (tools/make_scenes.py: a UV sphere and a smooth-normal cube), stitched and unstitched, in
// headless Chromium from the same camera, saves the screenshots, and measures every seam edge
// on screen: at points along the edge seen face-on, the 2 px step in brightness across it
// beyond the 2 px steps beside it (a line), each the mean of 3 px along the edge.
//   usage: node tests/preview/preview_seams.mjs STITCHED_GLTF UNSTITCHED_GLTF SHOTS_DIR
// Exit 0: on each object the stitched view's largest line is at most TOL levels (8-bit) and
// below the unstitched one; 1 otherwise. (LMB_SEAMS_VERBOSE=1 lists every point over 2 levels.)
import fs from 'node:fs';
import path from 'node:path';
import { startServer } from '../../tools/preview/server.mjs';
import { launchBrowser, openPreview } from '../../tools/preview/browser.mjs';
import { decodePng, lightmapTriangles, luma } from './lib.mjs';

const [stitched, unstitched, shotsDir] = process.argv.slice(2);
if (!shotsDir) { console.error('usage: node tests/preview/preview_seams.mjs STITCHED_GLTF UNSTITCHED_GLTF SHOTS_DIR'); process.exit(1); }
const PARAMS = { mode: 'lit', ev: -2, tonemap: 'none', cam: '0,1.6,3.4,0,1,0' };
const OFFSETS = [-3, -1, 1, 3]; // px across the edge (page evaluate repeats them)
const VIEW_HEIGHT = 720; // the viewport's height (browser.mjs; fov 45 degrees)
// 8-bit levels: rounding and half-float storage (2, as preview_e2e.mjs) plus one for points where
// three charts meet (measured: 2.3 at one such point on the sphere, unstitched 8.3)
const TOL = 3;

// Seam edges: a world edge two triangles of one object share with different lightmap UVs.
function seamEdges(gltf) {
  const hdr = path.basename(gltf).replace(/\.gltf$/, '-lightmap-0.hdr');
  const edges = new Map();
  for (const t of lightmapTriangles(gltf, hdr)) {
    const w = [0, 1, 2].map((k) => [0, 1, 2].map((c) => t.pos[3 * k + c] + t.translation[c]));
    for (let k = 0; k < 3; k++) {
      let a = { p: w[k], uv: t.uv.slice(2 * k, 2 * k + 2) }, b = { p: w[(k + 1) % 3], uv: t.uv.slice(2 * ((k + 1) % 3), 2 * ((k + 1) % 3) + 2) };
      const key = (q) => q.p.map((v) => v.toFixed(5)).join(',');
      if (key(b) < key(a)) [a, b] = [b, a];
      const id = t.node + '|' + key(a) + '|' + key(b);
      if (!edges.has(id)) edges.set(id, []);
      edges.get(id).push({ node: t.node, a, b });
    }
  }
  const out = [];
  for (const s of edges.values()) {
    if (s.length !== 2) continue;
    const d = Math.max(...[0, 1].map((i) => Math.abs(s[0].a.uv[i] - s[1].a.uv[i]) + Math.abs(s[0].b.uv[i] - s[1].b.uv[i])));
    if (d > 1e-6) out.push(s[0]);
  }
  return out;
}

async function measure(browser, gltf, name) {
  const srv = await startServer(gltf);
  try {
    const v = await openPreview(browser, srv.url, PARAMS);
    const file = path.join(shotsDir, `preview-seams-${name}.png`);
    const png = decodePng(await v.page.screenshot({ path: file }));
    console.log(`shot ${file}`);
    let ex = 0, ey = 0; // along the edge on screen: L averages 3 pixels along it
    const L = (x, y) => [-1, 0, 1].reduce((s, o) => s + luma(png.at(Math.round(x + o * ex), Math.round(y + o * ey))), 0) / 3;
    const worst = {};
    let points = 0;
    // 7 points along every seam edge; projected, then picked, in one round trip each
    const samples = [];
    for (const e of seamEdges(gltf))
      for (let k = 1; k < 8; k++) {
        const t = k / 8, p = [0, 1, 2].map((c) => e.a.p[c] + t * (e.b.p[c] - e.a.p[c]));
        const q = [0, 1, 2].map((c) => e.a.p[c] + (t + 0.01) * (e.b.p[c] - e.a.p[c]));
        samples.push({ e, t, p, q });
      }
    const projected = await v.page.evaluate((pq) => pq.map(([p, q]) => [window.lmbProject(...p), window.lmbProject(...q)]),
      samples.map((x) => [x.p, x.q]));
    const across = [];
    samples.forEach((x, i) => {
      const [s, s2] = projected[i];
      const dx = s2.x - s.x, dy = s2.y - s.y, len = Math.hypot(dx, dy);
      if (!s.inFront || len < 1e-3) return;
      across.push({ ...x, s, dx: dx / len, dy: dy / len, nx: -dy / len, ny: dx / len }); // (nx, ny): across the edge on screen
    });
    // every sample must see this object close to the edge point (not occluded, not the background)
    // and so must the pixels 3 px around each (away from the silhouette, whose pixels blend
    // with the background)
    const picked = await v.page.evaluate((pts) => pts.map(([x, y, nx, ny]) => {
      const at = [-3, -1, 1, 3].map((o) => [Math.round(x + o * nx), Math.round(y + o * ny)]);
      return [at.map(([px, py]) => window.lmbPick(px, py)),
        at.flatMap(([px, py]) => [[-3, -3], [3, -3], [-3, 3], [3, 3]].map(([i, j]) => window.lmbPick(px + i, py + j)))];
    }), across.map((x) => [x.s.x, x.s.y, x.nx, x.ny]));
    across.forEach((x, i) => {
      const { e, t, s, nx, ny } = x;
      const [picks, around] = picked[i];
      ex = x.dx; ey = x.dy;
      if (picks.concat(around).some((h) => !h || h.object !== e.node)) return;
      // seen face-on enough: 6 px across the edge span under twice the surface a face-on view
      // would show (near the silhouette a few pixels cross much of the surface and its shading)
      const faceOn = 6 * 2 * picks[1].distance * Math.tan(Math.PI / 8) / VIEW_HEIGHT;
      if (Math.hypot(...[0, 1, 2].map((c) => picks[3].point[c] - picks[0].point[c])) > 2 * faceOn) return;
      const l = OFFSETS.map((o) => L(s.x + o * nx, s.y + o * ny));
      // a line: the 2 px step across the edge beyond the 2 px steps beside it (0 for a smooth
      // gradient, at most 0 for a crease where facets meet or a flattened gradient; a seam line's
      // height for a step in value)
      const excess = Math.abs(l[2] - l[1]) - Math.max(Math.abs(l[1] - l[0]), Math.abs(l[3] - l[2]));
      if (process.env.LMB_SEAMS_VERBOSE && excess > 2) console.log(`  ${name} ${e.node} (${s.x.toFixed(0)}, ${s.y.toFixed(0)}): ${l.map((v) => v.toFixed(1)).join(' ')}; edge ${JSON.stringify([e.a, e.b])} at ${t}`);
      worst[e.node] = Math.max(worst[e.node] ?? -Infinity, excess);
      points++;
    });
    await v.context.close();
    return { worst, points };
  } finally {
    await srv.close();
  }
}

fs.mkdirSync(shotsDir, { recursive: true });
const browser = await launchBrowser();
let ok = true;
try {
  const on = await measure(browser, stitched, 'stitched'), off = await measure(browser, unstitched, 'unstitched');
  for (const node of ['sphere', 'cube']) {
    const a = on.worst[node], b = off.worst[node];
    const good = a !== undefined && b !== undefined && a <= TOL && a < b;
    console.log(`${good ? 'PASS' : 'FAIL'} ${node}: largest step in brightness at a seam ${a} levels stitched, ${b} unstitched (bound ${TOL}); ${on.points} / ${off.points} points seen`);
    ok &&= good;
  }
} catch (e) {
  console.log('FAIL ' + e.message);
  ok = false;
} finally {
  await browser.close();
}
process.exit(ok ? 0 : 1);
