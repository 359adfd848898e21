#!/usr/bin/env node
// Lightmap rectangles the preview puts on objects itself (loaders/three/lmbake-three.js
// applyLightmapRectangles), in headless Chromium:
//   usage: node tests/preview/preview_instancing.mjs INSTANCED_GLTF SEAMS_GLTF SHOTS_DIR
// INSTANCED_GLTF: a bake of tools/make_scenes.py's instanced-boxes.gltf (576 copies of one box
// through an EXT_mesh_gpu_instancing node, every other one 1.5 x larger, a roof over x < 0):
// each copy reads the atlas at uv1 x scale_k + offset_k, the node's per-instance attributes
// _LIGHTMAP_SCALE and _LIGHTMAP_OFFSET (docs/output.md). The page must build an InstancedMesh of
// every copy carrying both attributes (lmbInfo.instancedMeshes), with its own clone of the
// material patched (and no other mesh's). At a grid of pixels on the copies, from a camera under
// the roof's edge that sees copies under the roof and in the open, both sizes: the lightmap
// view's colour is sRGB(E x intensity / pi x 2^EV), E read bilinearly from the .hdr at uv1 x
// scale_k + offset_k (the rectangle from the glTF's accessors, k the copy the pick names); the
// pick names k, a copy whose box (from the glTF's TRANSLATION and SCALE) holds the picked point,
// and the texel at that atlas uv; the invalid view shows the same colour; lmbTexelToScreen finds
// the texel on the same copy; the atlas view's checker draws the texel as the 3D checker view
// draws the pixel; in the lit view the top of every copy under the roof is darker than the top
// of every copy in the open.
// SEAMS_GLTF: a bake of make_scenes.py's seams.gltf. With atlas.share_meshes the nodes tile and
// tile_b share the mesh "tile" (one TEXCOORD_1 layout), each node's extras.lightmap.scaleOffset
// its rectangle, the material's MOZ_lightmap without KHR_texture_transform; the bake is used as
// it is. A bake without share_meshes (each node its own mesh) is turned into one by hand in a
// temporary copy: the tile mesh's TEXCOORD_1 becomes its chart's layout in [0, 1] (a new
// accessor), tile_b uses that mesh, and each node's scaleOffset is its own chart's rectangle in
// the atlas (tile_b's chart is tile's moved, which the test checks), so the copy must look like
// the original bake. Either way, at pixels on both nodes the lightmap view shows E at uv1 x
// the node's scale + offset, the pick and the invalid, checker and atlas views agree, and (the
// hand-made copy) the lightmap and lit shots equal the original bake's.
// Exit 0: every check passed; 1: a check failed (or a page did not load).
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { startServer } from '../../tools/preview/server.mjs';
import { launchBrowser, openPreview, showPreview } from '../../tools/preview/browser.mjs';
import { decodePng, readImage, gltfAccessors, srgb, luma } from './lib.mjs';

const [instGltf, seamsGltf, shotsDir] = process.argv.slice(2);
if (!shotsDir) { console.error('usage: node tests/preview/preview_instancing.mjs INSTANCED_GLTF SEAMS_GLTF SHOTS_DIR'); process.exit(1); }
// 8-bit levels, as preview_e2e.mjs: rounding 0.5, half floats on the GPU and the filter's
// precision under 0.5 more
const TOL = 2;
const ATLAS_BG = [20, 20, 40], BORDER = [255, 89, 0]; // atlas-view.js ATLAS_BACKGROUND, materials.js BORDER_COLOR, sRGB
// instanced-boxes: under the roof's edge (the roof: y 3 over x < 0), looking along -z, slightly down
const INST_CAM = '0.5,2.2,7,0.5,0,-4';
const INST_EV = -9; // the tops in the open (about 1100 lux) at 0.7, those under the roof well above black
// seams: the floor tiles from the front, above the lamp's side
const SEAMS_CAM = '0,1.9,2.4,0,0,-0.1';

const results = [];
const check = (name, ok, detail) => { results.push(ok); console.log(`${ok ? 'PASS' : 'FAIL'} ${name}: ${detail}`); };
const t0 = Date.now();
fs.mkdirSync(shotsDir, { recursive: true });
const browser = await launchBrowser();
let failedToLoad = false;
try {
  await instanced(instGltf);
  await sharedMesh(seamsGltf);
} catch (e) {
  failedToLoad = true;
  check('preview loads and renders', false, e.stack || e.message);
} finally {
  await browser.close();
}
const failed = results.filter((r) => !r).length;
console.log(`preview instancing: ${results.length - failed} passed, ${failed} failed (${((Date.now() - t0) / 1000).toFixed(1)} s)${failedToLoad ? ' (a page did not load)' : ''}`);
process.exit(failed ? 1 : 0);

// ---- case 1: EXT_mesh_gpu_instancing copies, a rectangle per copy
async function instanced(gltfPath) {
  const { json: g, dir, read } = gltfAccessors(gltfPath);
  const nodeIndex = g.nodes.findIndex((n) => n.extensions && n.extensions.EXT_mesh_gpu_instancing && n.extensions.EXT_mesh_gpu_instancing.attributes._LIGHTMAP_SCALE !== undefined);
  const node = g.nodes[nodeIndex];
  const attrs = node ? node.extensions.EXT_mesh_gpu_instancing.attributes : {};
  const x = node && node.extras && node.extras.lightmap;
  check('the bake has an instanced node with _LIGHTMAP_SCALE and _LIGHTMAP_OFFSET, extras.lightmap.perInstance', !!node && attrs._LIGHTMAP_OFFSET !== undefined && !!x && !!x.perInstance && !x.scaleOffset &&
    !node.translation && !node.rotation && !node.scale && !node.matrix && attrs.ROTATION === undefined,
    node ? `node ${nodeIndex} '${node.name}': attributes ${Object.keys(attrs).join(', ')}; extras.lightmap ${JSON.stringify(x && { perInstance: x.perInstance, scaleOffset: x.scaleOffset })}` : 'none');
  if (!node) return;
  const S = read(attrs._LIGHTMAP_SCALE), O = read(attrs._LIGHTMAP_OFFSET), T = read(attrs.TRANSLATION), Z = attrs.SCALE !== undefined ? read(attrs.SCALE) : null;
  const count = T.length / 3;
  const rect = (k) => [S[2 * k], S[2 * k + 1], O[2 * k], O[2 * k + 1]];
  const size = (k) => (Z ? Z[3 * k] : 1);
  const prim = g.meshes[node.mesh].primitives[0], mat = g.materials[prim.material], ext = mat.extensions.MOZ_lightmap;
  const intensity = ext.intensity ?? 1;
  const P = read(prim.attributes.POSITION), bmin = [0, 1, 2].map((c) => Math.min(...P.filter((_, i) => i % 3 === c))), bmax = [0, 1, 2].map((c) => Math.max(...P.filter((_, i) => i % 3 === c)));
  // the copy whose box holds a world point (the node has no transform, the copies no rotation)
  const holds = (k, p) => [0, 1, 2].every((c) => { const l = (p[c] - T[3 * k + c]) / size(k); return l >= bmin[c] - 1e-3 && l <= bmax[c] + 1e-3; });
  const img = reference(g, dir, ext.index);
  const roof = (k) => T[3 * k] < 0, big = (k) => size(k) > 1.2;
  const tris = primitiveTriangles(read, prim); // the TEXCOORD_1 layout every copy shares
  console.log(`${path.basename(gltfPath)}: node ${nodeIndex} '${node.name}', ${count} copies (sizes ${[...new Set(Array.from({ length: count }, (_, k) => size(k)))].join(', ')}), ` +
    `material ${prim.material} '${mat.name}' MOZ_lightmap texture ${ext.index}${ext.extensions && ext.extensions.KHR_texture_transform ? ' with KHR_texture_transform' : ''}, atlas ${img.uri} ${img.width}x${img.height}`);

  const srv = await startServer(gltfPath);
  try {
    const views = await shootModes(srv.url, () => ({ ev: INST_EV, tonemap: 'none', cam: INST_CAM, lightmap: 'hdr' }), 'preview-instancing');
    const lm = views.lightmap, ev = lm.info.ev, gain = intensity * 2 ** ev / Math.PI;
    // the page's InstancedMesh: every copy, both attributes per instance, its own patched material
    const im = lm.info.instancedMeshes || [];
    const mine = im.find((m) => m.node === nodeIndex);
    const attrOk = (n) => mine && mine.instanceAttributes.some((a) => a.name === n && a.itemSize === 2 && a.count === count);
    check('the page builds an InstancedMesh of every copy with _LIGHTMAP_SCALE and _LIGHTMAP_OFFSET per instance, its material patched', im.length === 1 && !!mine &&
      mine.count === count && attrOk('_LIGHTMAP_SCALE') && attrOk('_LIGHTMAP_OFFSET') && mine.rectangles && mine.litPatched && !mine.sharesMaterial && lm.info.patchedOthers === 0,
      `${JSON.stringify(im)}; meshes other than InstancedMeshes with the patch: ${lm.info.patchedOthers}`);

    // probes: a grid of pixels on the copies, away from edges (the 4 neighbours see the same copy within 1.5 texels)
    const probes = await gridProbes(lm.page, [nodeIndex], 8);
    let n = 0, bad = 0, worst = 0, texelOff = 0, instanceOff = 0, invalidOff = 0, ignoring = 0, neighbour = 0, first = null;
    const skipped = { clip: 0, edge: 0 }, cats = new Map(), copies = new Map(), probed = [];
    for (const p of probes) {
      const k = p.instance;
      if (!(k >= 0 && k < count) || !holds(k, p.point)) { instanceOff++; if (instanceOff <= 3) console.log(`  pick names copy ${k} at (${p.point.map((v) => v.toFixed(3))}), not the copy there`); continue; }
      const [su, sv, ou, ov] = rect(k), u = p.uv1[0] * su + ou, v = p.uv1[1] * sv + ov;
      const ex = [0, 1, 2].map((c) => srgb(bilinear(img, u, v, c) * gain)), got = lm.png.at(p.px, p.py);
      if (Math.max(...ex) > 250 || Math.max(...ex) < 5) { skipped.clip++; continue; }
      const tp = taps(img, u, v).map((e) => srgb(e * gain));
      if (Math.max(...tp) - Math.min(...tp) > 16) { skipped.edge++; continue; }
      n++; probed.push({ ...p, u, v });
      const cat = `${roof(k) ? 'under the roof' : 'in the open'}, ${big(k) ? '1.5x' : '1x'}`;
      const c = cats.get(cat) || { probes: 0, copies: new Set() }; c.probes++; c.copies.add(k); cats.set(cat, c);
      const e = dist(ex, got);
      worst = Math.max(worst, e);
      if (e > TOL) { bad++; if (bad <= 5) console.log(`  probe off: pixel (${p.px}, ${p.py}) copy ${k} uv1 (${p.uv1.map((q) => q.toFixed(5))}) -> atlas uv (${u.toFixed(5)}, ${v.toFixed(5)}): expected ${ex.map((q) => q.toFixed(1))}, got ${got}`); }
      const tx = Math.min(img.width - 1, Math.floor(u * img.width)), ty = Math.min(img.height - 1, Math.floor(v * img.height));
      if (p.texel[0] !== tx || p.texel[1] !== ty) texelOff++;
      if (dist(views.invalid.png.at(p.px, p.py), got) > TOL) invalidOff++;
      // would a preview that ignored the rectangles, or gave every copy its neighbour's, fail here?
      if (dist([0, 1, 2].map((q) => srgb(bilinear(img, p.uv1[0], p.uv1[1], q) * gain)), got) > TOL) ignoring++;
      const [nu, nv, no, np] = rect((k + 1) % count);
      if (dist([0, 1, 2].map((q) => srgb(bilinear(img, p.uv1[0] * nu + no, p.uv1[1] * nv + np, q) * gain)), got) > TOL) neighbour++;
      // the top face (its lit brightness per copy, below)
      if (Math.abs(p.point[1] - T[3 * k + 1] - bmax[1] * size(k)) < 1e-3) {
        const t = copies.get(k) || { lit: [], lm: [] }; t.lit.push(luma(views.lit.png.at(p.px, p.py))); t.lm.push(luma(got)); copies.set(k, t);
      }
      first ||= `copy ${k} pixel (${p.px}, ${p.py}) uv1 (${p.uv1.map((q) => q.toFixed(4))}) -> texel (${tx}, ${ty}): expected ${ex.map((q) => q.toFixed(1))}, got ${got}`;
    }
    const catText = [...cats].map(([k, c]) => `${k}: ${c.probes} probes on ${c.copies.size} copies`).join('; ');
    const allCats = ['under the roof, 1x', 'under the roof, 1.5x', 'in the open, 1x', 'in the open, 1.5x'].every((k) => cats.has(k) && cats.get(k).copies.size >= 3 && cats.get(k).probes >= 20);
    check('copies: lightmap view pixel = sRGB(E(uv1 x scale_k + offset_k) x intensity / pi x 2^EV)', n >= 200 && bad === 0 && allCats,
      `EV ${ev}; ${n} probes (${catText}); ${bad} off by > ${TOL} levels, worst ${worst.toFixed(2)}; ${skipped.clip} clipped or black, ${skipped.edge} at shadow edges; ` +
      `${ignoring} of ${n} would be off if the rectangles were ignored, ${neighbour} if each copy had the next copy's; e.g. ${first}`);
    check('copies: the pick names the copy there (its box holds the point) and the texel at uv1 x scale_k + offset_k', probes.length > 0 && instanceOff === 0 && texelOff === 0,
      `${probes.length} picks: ${instanceOff} name a copy whose box does not hold the point; ${texelOff} of ${n} probes name another texel`);
    check('copies: the invalid view shows the same texels', n > 0 && invalidOff === 0, `${invalidOff} of ${n} probes differ by > ${TOL} levels from the lightmap view`);
    await roundTrip(lm.page, probed.filter((p) => texelOnFace(tris, rect(p.instance), img, p.texel)), 'instance', 'copies', n);
    await checkerAgrees(lm, views.checker.png, probed, 'copies', 'preview-instancing', [img.width, img.height]);
    // lit: the top of every copy under the roof darker than the top of every copy in the open
    const top = [...copies].map(([k, t]) => ({ k, roof: roof(k), lit: median(t.lit), lm: median(t.lm) }));
    const under = top.filter((t) => t.roof), open = top.filter((t) => !t.roof);
    const maxUnder = Math.max(...under.map((t) => t.lit)), minOpen = Math.min(...open.map((t) => t.lit));
    check('copies: in the lit view every copy\'s top under the roof is darker than every copy\'s top in the open', under.length >= 3 && open.length >= 3 && maxUnder < minOpen,
      `tops seen: ${under.length} under the roof, lit luma ${range(under.map((t) => t.lit))} (lightmap view ${range(under.map((t) => t.lm))}); ` +
      `${open.length} in the open, lit ${range(open.map((t) => t.lit))} (lightmap view ${range(open.map((t) => t.lm))}); 8-bit levels`);
    await lm.context.close();
  } finally {
    await srv.close();
  }
}

// ---- case 2: nodes sharing one mesh, a rectangle per node
async function sharedMesh(gltfPath) {
  let file = gltfPath, tmp = null, made = null;
  const { json: g0 } = gltfAccessors(gltfPath);
  if (!sharedGroups(g0).length) {
    tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'lmb-shared-mesh-'));
    made = shareByHand(gltfPath, tmp, 'tile', 'tile_b');
    file = made.file;
    console.log(`${path.basename(gltfPath)}: no nodes share a mesh (a bake without atlas.share_meshes); made by hand in ${file}: ${made.text}`);
  }
  try {
    const { json: g, dir, read } = gltfAccessors(file);
    const groups = sharedGroups(g);
    const nodes = new Map(); // node index -> {name, so, texture, intensity}
    let withTransform = 0;
    for (const grp of groups) for (const i of grp) {
      const node = g.nodes[i];
      for (const p of g.meshes[node.mesh].primitives) {
        const m = p.material !== undefined && g.materials[p.material], ext = m && m.extensions && m.extensions.MOZ_lightmap;
        if (!ext) continue;
        if (ext.extensions && ext.extensions.KHR_texture_transform) withTransform++;
        nodes.set(i, { name: node.name, so: node.extras.lightmap.scaleOffset, texture: ext.index, intensity: ext.intensity ?? 1 });
      }
    }
    check(`shared mesh (${made ? 'made by hand' : 'atlas.share_meshes bake'}): nodes share a lightmapped mesh, each its own scaleOffset, no KHR_texture_transform`,
      groups.length > 0 && nodes.size >= 2 && withTransform === 0 && new Set([...nodes.values()].map((r) => r.so.join())).size === nodes.size,
      groups.map((grp) => `mesh ${g.nodes[grp[0]].mesh}: ${grp.map((i) => `node ${i} '${g.nodes[i].name}' ${JSON.stringify(g.nodes[i].extras.lightmap.scaleOffset)}`).join(', ')}`).join('; ') +
      `; ${withTransform} of their materials have KHR_texture_transform`);
    if (!nodes.size) return;
    const texture = [...nodes.values()][0].texture, img = reference(g, dir, texture);
    const srv = await startServer(file);
    try {
      const views = await shootModes(srv.url, (lm) => ({ ev: lm ? lm.info.ev : 'auto', tonemap: 'none', cam: SEAMS_CAM, lightmap: 'hdr' }), 'preview-shared-mesh');
      const lm = views.lightmap, ev = lm.info.ev;
      const pr = lm.info.perNodeRectangles || [];
      check('shared mesh: the page gives each node its own rectangle (lmbInfo.perNodeRectangles)',
        [...nodes].every(([i, r]) => pr.some((q) => q.node === i && q.scaleOffset.every((v, k) => Math.abs(v - r.so[k]) < 1e-9))),
        JSON.stringify(pr));
      const probes = await gridProbes(lm.page, [...nodes.keys()], 5);
      let n = 0, bad = 0, worst = 0, texelOff = 0, invalidOff = 0, other = 0, first = null;
      const skipped = { clip: 0, edge: 0 }, perNode = new Map(), probed = [];
      for (const p of probes) {
        const r = nodes.get(p.node), k = r.intensity * 2 ** ev / Math.PI;
        const u = p.uv1[0] * r.so[0] + r.so[2], v = p.uv1[1] * r.so[1] + r.so[3];
        const ex = [0, 1, 2].map((c) => srgb(bilinear(img, u, v, c) * k)), got = lm.png.at(p.px, p.py);
        if (Math.max(...ex) > 250 || Math.max(...ex) < 5) { skipped.clip++; continue; }
        const tp = taps(img, u, v).map((e) => srgb(e * k));
        if (Math.max(...tp) - Math.min(...tp) > 16) { skipped.edge++; continue; }
        n++; probed.push(p); perNode.set(r.name, (perNode.get(r.name) || 0) + 1);
        const e = dist(ex, got);
        worst = Math.max(worst, e);
        if (e > TOL) { bad++; if (bad <= 5) console.log(`  probe off: pixel (${p.px}, ${p.py}) node '${r.name}' uv1 (${p.uv1.map((q) => q.toFixed(5))}) -> atlas uv (${u.toFixed(5)}, ${v.toFixed(5)}): expected ${ex.map((q) => q.toFixed(1))}, got ${got}`); }
        const tx = Math.min(img.width - 1, Math.floor(u * img.width)), ty = Math.min(img.height - 1, Math.floor(v * img.height));
        if (p.texel[0] !== tx || p.texel[1] !== ty) texelOff++;
        if (dist(views.invalid.png.at(p.px, p.py), got) > TOL) invalidOff++;
        // would the other node's rectangle (one material, one texture for both) fail here?
        const o = [...nodes].find(([i]) => i !== p.node)[1];
        if (dist([0, 1, 2].map((c) => srgb(bilinear(img, p.uv1[0] * o.so[0] + o.so[2], p.uv1[1] * o.so[1] + o.so[3], c) * k)), got) > TOL) other++;
        first ||= `node '${r.name}' pixel (${p.px}, ${p.py}) uv1 (${p.uv1.map((q) => q.toFixed(4))}) -> texel (${tx}, ${ty}): expected ${ex.map((q) => q.toFixed(1))}, got ${got}`;
      }
      check('shared mesh: lightmap view pixel = sRGB(E(uv1 x the node\'s scale + offset) x intensity / pi x 2^EV) on every node', n >= 100 && bad === 0 && [...nodes.values()].every((r) => (perNode.get(r.name) || 0) >= 30),
        `EV ${ev}; ${n} probes (${[...perNode].map(([k, c]) => `${k} ${c}`).join(', ')}); ${bad} off by > ${TOL} levels, worst ${worst.toFixed(2)}; ${skipped.clip} clipped or black, ${skipped.edge} at shadow edges; ` +
        `${other} of ${n} would be off with the other node's rectangle; e.g. ${first}`);
      check('shared mesh: the pick names the texel at uv1 x the node\'s scale + offset', n > 0 && texelOff === 0, `${texelOff} of ${n} probes name another texel`);
      check('shared mesh: the invalid view shows the same texels', n > 0 && invalidOff === 0, `${invalidOff} of ${n} probes differ by > ${TOL} levels from the lightmap view`);
      const tris = new Map([...nodes.keys()].map((i) => [i, primitiveTriangles(read, g.meshes[g.nodes[i].mesh].primitives[0])]));
      await roundTrip(lm.page, probed.filter((p) => texelOnFace(tris.get(p.node), nodes.get(p.node).so, img, p.texel)), 'node', 'shared mesh', n);
      await checkerAgrees(lm, views.checker.png, probed, 'shared mesh', 'preview-shared-mesh', [img.width, img.height]);
      // made by hand from a bake: the same texels on the same triangles, so the same pictures
      if (made && made.exact) {
        const ref = await startServer(gltfPath);
        try {
          let v = null;
          for (const mode of ['lightmap', 'lit']) {
            const params = { mode, ev, tonemap: 'none', cam: SEAMS_CAM, lightmap: 'hdr' };
            v = v ? await showPreview(v, params) : await openPreview(browser, ref.url, params);
            const png = decodePng(await v.page.screenshot({ path: path.join(shotsDir, `preview-shared-mesh-${mode}-original.png`) }));
            const d = diff(png, views[mode].png);
            check(`shared mesh made by hand: its ${mode} shot = the original bake's`, d.max <= TOL,
              `max |diff| ${d.max} levels, ${d.over} pixels over 0${d.worst ? `, worst at (${d.worst.x}, ${d.worst.y}): ${d.worst.a} vs ${d.worst.b}` : ''}`);
          }
          await v.context.close();
        } finally {
          await ref.close();
        }
      }
      await lm.context.close();
    } finally {
      await srv.close();
    }
  } finally {
    if (tmp) fs.rmSync(tmp, { recursive: true, force: true });
  }
}

// Node index lists, one per mesh that two or more nodes with extras.lightmap.scaleOffset use
function sharedGroups(g) {
  const byMesh = new Map();
  g.nodes.forEach((n, i) => {
    if (n.mesh === undefined || !(n.extras && n.extras.lightmap && Array.isArray(n.extras.lightmap.scaleOffset))) return;
    if (!byMesh.has(n.mesh)) byMesh.set(n.mesh, []);
    byMesh.get(n.mesh).push(i);
  });
  return [...byMesh.values()].filter((l) => l.length >= 2);
}

// A copy of a bake (in dir) where node b uses node a's mesh: that mesh's TEXCOORD_1 (atlas
// space) becomes its chart's layout in [0, 1] (a new accessor in a new buffer; TEXCOORD_0 keeps
// the old one), node a's scaleOffset the rectangle that chart had, node b's the rectangle of its
// own mesh's TEXCOORD_1. exact: b's mesh is a's (same positions) with its TEXCOORD_1 moved and
// scaled (within 1e-6), so the copy shows every node on the same texels as the bake does.
function shareByHand(gltfPath, dir, a, b) {
  fs.cpSync(path.dirname(gltfPath), dir, { recursive: true });
  const { json: g, read } = gltfAccessors(gltfPath);
  const na = g.nodes.find((n) => n.name === a), nb = g.nodes.find((n) => n.name === b);
  if (!na || !nb || na.mesh === undefined || nb.mesh === undefined) throw new Error(`${gltfPath}: no nodes '${a}' and '${b}' with meshes`);
  const pa = g.meshes[na.mesh].primitives, pb = g.meshes[nb.mesh].primitives;
  if (pa.length !== 1 || pb.length !== 1) throw new Error(`meshes of '${a}' and '${b}': one primitive each expected`);
  const ua = read(pa[0].attributes.TEXCOORD_1), ub = read(pb[0].attributes.TEXCOORD_1);
  const box = (uv) => { const u = uv.filter((_, i) => i % 2 === 0), v = uv.filter((_, i) => i % 2 === 1); return [Math.min(...u), Math.min(...v), Math.max(...u), Math.max(...v)]; };
  const A = box(ua), B = box(ub);
  const soA = [A[2] - A[0], A[3] - A[1], A[0], A[1]], soB = [B[2] - B[0], B[3] - B[1], B[0], B[1]];
  const layout = new Float32Array(ua.length);
  for (let i = 0; i < ua.length; i += 2) { layout[i] = (ua[i] - A[0]) / soA[0]; layout[i + 1] = (ua[i + 1] - A[1]) / soA[1]; }
  const posA = read(pa[0].attributes.POSITION), posB = read(pb[0].attributes.POSITION);
  const idxA = pa[0].indices !== undefined ? read(pa[0].indices) : null, idxB = pb[0].indices !== undefined ? read(pb[0].indices) : null;
  let worst = 0;
  const exact = posA.length === posB.length && posA.every((v, i) => Math.abs(v - posB[i]) < 1e-6) && JSON.stringify(idxA) === JSON.stringify(idxB) &&
    ub.every((v, i) => { const d = Math.abs(layout[i] * soB[i % 2] + soB[2 + (i % 2)] - v); worst = Math.max(worst, d); return d < 1e-6; });
  const bin = 'shared-mesh-uv1.bin';
  fs.writeFileSync(path.join(dir, bin), Buffer.from(layout.buffer));
  g.buffers.push({ uri: bin, byteLength: layout.byteLength });
  g.bufferViews.push({ buffer: g.buffers.length - 1, byteOffset: 0, byteLength: layout.byteLength });
  const lu = layout.filter((_, i) => i % 2 === 0), lv = layout.filter((_, i) => i % 2 === 1);
  g.accessors.push({ bufferView: g.bufferViews.length - 1, componentType: 5126, count: layout.length / 2, type: 'VEC2', min: [Math.min(...lu), Math.min(...lv)], max: [Math.max(...lu), Math.max(...lv)] });
  pa[0].attributes.TEXCOORD_1 = g.accessors.length - 1;
  const oldMesh = nb.mesh;
  nb.mesh = na.mesh;
  na.extras.lightmap.scaleOffset = soA;
  nb.extras.lightmap.scaleOffset = soB;
  const file = path.join(dir, path.basename(gltfPath));
  fs.writeFileSync(file, JSON.stringify(g, null, 1));
  return {
    file, exact,
    text: `node '${b}' uses mesh ${na.mesh} (not ${oldMesh}), whose TEXCOORD_1 is now in [0, 1]; '${a}' at ${fmt(soA)}, '${b}' at ${fmt(soB)}; ` +
      `'${b}''s own TEXCOORD_1 ${exact ? 'is' : 'is NOT'} '${a}''s moved (worst ${worst.toExponential(1)})`,
  };
}

// ---- shared helpers

// A primitive's TEXCOORD_1 triangles and normals: {uv, idx, nrm} (flat arrays)
function primitiveTriangles(read, prim) {
  const uv = read(prim.attributes.TEXCOORD_1);
  return { uv, idx: prim.indices !== undefined ? read(prim.indices) : uv.map((_, i) => i).slice(0, uv.length / 2), nrm: read(prim.attributes.NORMAL) };
}

// Does texel (x, y) lie on one face of a mesh placed at rectangle so: its centre and its 4
// corners on triangles of the normal the centre's triangle has? (lmbTexelToScreen finds the
// surface point of a texel's centre; one near a face's edge may be hidden where the probe's
// pixel, inside the face, is not.)
function texelOnFace({ uv, idx, nrm }, [su, sv, ou, ov], img, [x, y]) {
  const tri = (t) => [0, 1, 2].map((j) => [uv[2 * idx[t + j]] * su + ou, uv[2 * idx[t + j] + 1] * sv + ov]);
  const face = (t) => [0, 1, 2].map((c) => nrm[3 * idx[t] + c].toFixed(3)).join();
  const on = (px, py) => { for (let t = 0; t < idx.length; t += 3) if (inTriangle([px / img.width, py / img.height], ...tri(t))) return face(t); return null; };
  const f = on(x + 0.5, y + 0.5);
  return f !== null && [[0, 0], [1, 0], [0, 1], [1, 1]].every(([i, j]) => on(x + i, y + j) === f);
}

// lmbTexelToScreen on up to 200 probes' texels: the texel's centre on the probe's copy or node
// (key: 'instance' or 'node'), seen there (a pick names it), or hidden behind something nearer
// (another copy's edge: the probe saw part of the texel), or off screen (a probe at the view's
// edge); at least 90% seen.
// The page in the lightmap, invalid, lit and checker modes, one page (showPreview): each mode's
// screenshot (png) and view; paramsOf(lightmap view or null) gives the other parameters. The page
// is left in the lightmap mode (its picks, projections and info: views.lightmap).
async function shootModes(url, paramsOf, prefix) {
  const views = {};
  let v = null;
  for (const mode of ['lightmap', 'invalid', 'lit', 'checker']) {
    const params = { mode, ...paramsOf(views.lightmap || null) };
    v = v ? await showPreview(v, params) : await openPreview(browser, url, params);
    const file = path.join(shotsDir, `${prefix}-${mode}.png`);
    views[mode] = { ...v, png: decodePng(await v.page.screenshot({ path: file })) };
    console.log(`shot ${file} (${v.url.replace(url, '/')})`);
  }
  const lm = views.lightmap;
  views.lightmap = { ...(await showPreview(v, lm.params)), png: lm.png };
  return views;
}

async function roundTrip(page, inside, key, what, n) {
  const round = await page.evaluate(([ps, key]) => ps.map((p) => {
    const s = window.lmbTexelToScreen(p.atlas, p.texel[0], p.texel[1]);
    if (!s) return { texel: p.texel, [key]: p[key], how: 'not found' };
    const h = window.lmbPick(Math.floor(s.x), Math.floor(s.y)), eye = window.lmbInfo.camera.position;
    const far = Math.hypot(...s.point.map((v, i) => v - eye[i]));
    const off = s.x < 0 || s.y < 0 || s.x >= innerWidth || s.y >= innerHeight;
    const mine = (q) => (key === 'instance' ? q.instance === p.instance : !!h && h.node === p.node);
    const how = key === 'instance' && s.instance !== p.instance ? 'another copy' : off ? 'off screen' : s.visible && h && mine(h) ? 'seen' : h && h.distance < far - 1e-4 ? 'hidden' : 'lost';
    return { texel: p.texel, [key]: p[key], how, s, h: h && { instance: h.instance, node: h.node, texel: h.texel, distance: h.distance }, far };
  }), [inside.filter((_, i) => i % Math.max(1, Math.floor(inside.length / 200)) === 0), key]);
  const how = (w) => round.filter((r) => r.how === w).length, lost = round.filter((r) => !['seen', 'hidden', 'off screen'].includes(r.how));
  const whose = key === 'instance' ? 'copy' : 'node';
  check(`${what}: lmbTexelToScreen finds each probe texel on its ${whose} (seen there, hidden behind something nearer, or just off screen)`, round.length > 0 && lost.length === 0 && how('seen') >= 0.9 * round.length,
    `of ${round.length}: ${how('seen')} seen on the ${whose}, ${how('hidden')} behind something nearer, ${how('off screen')} off screen, ` +
    `${lost.length} not found, on another ${whose} or not seen${lost.length ? ', e.g. ' + JSON.stringify(lost.slice(0, 3)) : ''} ` +
    `(probes whose whole texel lies on one face: ${inside.length} of ${n})`);
}

// A lightmap texture's .hdr (the page reads it with lightmap=hdr), checked against its .exr
// when the bake wrote one: RGBE keeps each channel within 1/128 + 1/255 of the texel's largest,
// and the EXR's half floats are 2^-24 apart near 0 (subnormals; texels of 1e-7 lux in corners)
function reference(g, dir, textureIndex) {
  const files = (g.textures[textureIndex].extras && g.textures[textureIndex].extras.lightmap && g.textures[textureIndex].extras.lightmap.files) || {};
  if (!files.hdr) throw new Error(`texture ${textureIndex} names no .hdr`);
  const hdr = readImage(path.join(dir, decodeURIComponent(files.hdr)));
  if (files.exr) {
    const exr = readImage(path.join(dir, decodeURIComponent(files.exr))), bound = 1 / 128 + 1 / 255;
    let worst = 0;
    for (let i = 0; i < hdr.width * hdr.height; i++) {
      const m = Math.max(exr.data[3 * i], exr.data[3 * i + 1], exr.data[3 * i + 2]);
      for (let c = 0; c < 3; c++) worst = Math.max(worst, Math.max(0, Math.abs(hdr.data[3 * i + c] - exr.data[3 * i + c]) - 2 ** -24) / (m || 1));
    }
    check(`${files.hdr} holds ${files.exr} within RGBE precision`, exr.width === hdr.width && exr.height === hdr.height && worst <= bound,
      `${hdr.width}x${hdr.height}; worst |hdr - exr| - 2^-24 = ${worst.toFixed(4)} x the texel's brightest channel (bound ${bound.toFixed(4)})`);
  }
  return { ...hdr, uri: files.hdr };
}

// Pixels of a grid (every `step`) that see one of the glTF nodes `nodes` away from edges: the 4
// neighbours see the same object (and copy) within 1.5 texels. {px, py, node, instance, object, uv1, texel, atlas, point}
function gridProbes(page, nodes, step) {
  return page.evaluate(([nodes, step]) => {
    const out = [];
    for (let py = 4; py < innerHeight - 4; py += step) for (let px = 4; px < innerWidth - 4; px += step) {
      const c = window.lmbPick(px, py);
      if (!c || !c.texel || !nodes.includes(c.node)) continue;
      const nb = [[1, 0], [-1, 0], [0, 1], [0, -1]].map(([i, j]) => window.lmbPick(px + i, py + j));
      const same = nb.every((q) => q && q.object === c.object && q.instance === c.instance && q.texel && Math.hypot(q.texel[0] - c.texel[0], q.texel[1] - c.texel[1]) <= 1.5);
      if (!same) continue;
      // texels per pixel along the atlas's x and y (as the checker's fwidth: |d/dx| + |d/dy|)
      const tpp = [0, 1].map((a) => (Math.abs(nb[0].lightmapUv[a] - nb[1].lightmapUv[a]) + Math.abs(nb[2].lightmapUv[a] - nb[3].lightmapUv[a])) / 2);
      out.push({ px, py, node: c.node, instance: c.instance, object: c.object, uv1: c.uv1, lightmapUv: c.lightmapUv, tppUv: tpp, texel: c.texel, atlas: c.atlas, point: c.point });
    }
    return out;
  }, [nodes, step]);
}

// The checker in 3D and in the atlas view colours a texel by its chart's tint, its parity and
// its 8x8 block: a probe's pixel in 3D and the pixel at its atlas uv in the atlas view (zoom 8,
// views centred on the probes) match when both place the triangles at the rectangle. Left out:
// probes within 0.15 texel of a texel's edge (the two pixels' centres are up to 1/16 texel apart,
// and the atlas view draws a 1-pixel grid line at a texel's top-left edge), 3D pixels the
// checker darkens as a grid line (within 1.5 px of a texel's top-left edge where a texel spans
// 3 px or more) or draws as a chart border; atlas-view pixels drawn as a chart border (within
// 1.5 px, 0.19 texel, of a chart's edge: a chart of a few texels has many) are counted apart.
async function checkerAgrees(lm, c3Png, probed, what, prefix, atlasSize) {
  const ZOOM = 8, VIEW = [960, 720]; // browser.mjs VIEWPORT
  const atlas = probed.length ? probed[0].atlas : 0;
  const todo = probed.filter((p) => {
    const t = [0, 1].map((a) => p.lightmapUv[a] * atlasSize[a]), tpp = [0, 1].map((a) => p.tppUv[a] * atlasSize[a]), f = t.map((v) => v - Math.floor(v));
    const grid = Math.max(...tpp) < 0.34 && Math.min(...[0, 1].map((a) => f[a] / Math.max(tpp[a], 1e-6))) < 1.5;
    return p.atlas === atlas && !grid && f.every((v) => v > 0.15 && v < 0.85) && dist(c3Png.at(p.px, p.py), BORDER) > 30;
  });
  let onScreen = 0, differ = 0, background = 0, border = 0, shots = 0, first = null;
  const left = new Set(todo);
  while (left.size && shots < 4) {
    // centre on the probe with the most others left within the view (120 x 90 texels at zoom 8)
    const rest = [...left], cand = rest.filter((_, i) => i % Math.max(1, Math.floor(rest.length / 400)) === 0);
    const near = (c) => rest.reduce((k, p) => k + (Math.abs(p.texel[0] - c.texel[0]) < VIEW[0] / ZOOM / 2 - 1 && Math.abs(p.texel[1] - c.texel[1]) < VIEW[1] / ZOOM / 2 - 1), 0);
    const c = cand.reduce((best, q) => { const k = near(q); return k > best.k ? { q, k } : best; }, { q: cand[0], k: -1 }).q;
    const ck = await showPreview(lm, { mode: 'atlas', layer: 'checker', atlas, zoom: ZOOM, at: c.texel.join(','), lightmap: lm.params.lightmap });
    const ckPng = decodePng(await ck.page.screenshot({ path: path.join(shotsDir, `${prefix}-atlas-checker-${shots}.png`) }));
    shots++;
    const av = ck.info.atlasView;
    for (const p of [...left]) {
      const x = Math.floor(av.originX + p.lightmapUv[0] * atlasSize[0] * av.zoom), y = Math.floor(av.originY + p.lightmapUv[1] * atlasSize[1] * av.zoom);
      if (x < 0 || y < 0 || x >= VIEW[0] || y >= VIEW[1]) continue;
      left.delete(p);
      const a = ckPng.at(x, y);
      if (dist(a, BORDER) <= 3) { border++; continue; }
      onScreen++;
      if (dist(a, ATLAS_BG) <= 3) background++;
      if (dist(a, c3Png.at(p.px, p.py)) > 3) { differ++; first ||= `probe pixel (${p.px}, ${p.py}) ${c3Png.at(p.px, p.py)}, atlas view (${x}, ${y}) ${a}`; }
    }
  }
  check(`${what}: the atlas checker view draws a probe's atlas uv as the 3D checker view draws its pixel`, onScreen >= 50 && differ <= 0.01 * onScreen && background === 0,
    `atlas ${atlas}, zoom ${ZOOM}, ${shots} views: ${differ} of ${onScreen} probes differ by > 3 levels (allowed 1%)${first ? ', e.g. ' + first : ''}; ${background} show the background; ` +
    `${border} more on a chart border in the atlas view; of ${probed.length} probes ${todo.length} away from 3D grid lines, borders and texel edges`);
}

// Largest per-channel difference of two screenshots (8-bit levels), pixels that differ at all
function diff(a, b) {
  let max = 0, over = 0, worst = null;
  for (let i = 0; i < a.width * a.height; i++) {
    let pm = 0;
    for (let c = 0; c < 3; c++) pm = Math.max(pm, Math.abs(a.rgb[3 * i + c] - b.rgb[3 * i + c]));
    if (pm > 0) over++;
    if (pm > max) { max = pm; worst = { x: i % a.width, y: i / a.width | 0, a: a.at(i % a.width, i / a.width | 0), b: b.at(i % a.width, i / a.width | 0) }; }
  }
  return { max, over, worst };
}

function inTriangle([px, py], [ax, ay], [bx, by], [cx, cy]) {
  const d1 = (px - bx) * (ay - by) - (ax - bx) * (py - by), d2 = (px - cx) * (by - cy) - (bx - cx) * (py - cy), d3 = (px - ax) * (cy - ay) - (cx - ax) * (py - ay);
  return !((d1 < 0 || d2 < 0 || d3 < 0) && (d1 > 0 || d2 > 0 || d3 > 0));
}
function fmt(so) { return `[${so.map((v) => v.toFixed(6)).join(', ')}]`; }
function median(a) { const s = [...a].sort((x, y) => x - y); return s[s.length >> 1]; }
function range(a) { return a.length ? `${Math.min(...a).toFixed(1)}..${Math.max(...a).toFixed(1)}` : 'none'; }
function dist(a, b) { return Math.max(...a.map((v, i) => Math.abs(v - b[i]))); }
function at(img, x, y, c) { return img.data[3 * (Math.min(img.height - 1, Math.max(0, y)) * img.width + Math.min(img.width - 1, Math.max(0, x))) + c]; }
// three's LinearFilter with ClampToEdge: texel centres at (i + 0.5) / W
function bilinear(img, u, v, c) {
  const x = u * img.width - 0.5, y = v * img.height - 0.5, x0 = Math.floor(x), y0 = Math.floor(y), fx = x - x0, fy = y - y0;
  return (at(img, x0, y0, c) * (1 - fx) + at(img, x0 + 1, y0, c) * fx) * (1 - fy) + (at(img, x0, y0 + 1, c) * (1 - fx) + at(img, x0 + 1, y0 + 1, c) * fx) * fy;
}
// the 4 texels the filter reads at (u, v), channel 0
function taps(img, u, v) { const x = Math.floor(u * img.width - 0.5), y = Math.floor(v * img.height - 0.5); return [at(img, x, y, 0), at(img, x + 1, y, 0), at(img, x, y + 1, 0), at(img, x + 1, y + 1, 0)]; }
