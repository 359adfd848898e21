#!/usr/bin/env node
// The watch's composed quick picture (tools/preview/compose.mjs, docs/watch.md): on
// tools/make_scenes.py's cornell-point box with a second lamp low in a corner, baked final and
// quick (F1, Q1), then the second lamp moved across the floor and baked again (F2, Q2), every bake
// writing the light of its stages (`bake --stages-out`: the direct light DF1, DQ1, DF2, DQ2; the
// light the bounce passes reached, BF1, BF2):
//   - a change of nothing, F1 + Q1 - Q1, gives F1's .hdr back texel for texel (as the page reads it),
//     and so does its refinement with the direct light, F1 + Q1 - Q1 - (DQ1 - DQ1) + (DF1 - DF1);
//   - the composed picture, rho F1 + Q2 - rho Q1 (rho: how much of the final's detail the light
//     keeps, compose.mjs; 1 where the light rose, since it moved), is closer to F2 than the quick look Q2 alone and than the plain
//     difference F1 + Q2 - Q1 (all read in F2's atlas, 9 x 9 texel box averages over the texels a
//     triangle covers, rms of the luminance difference over F2's mean), and within 5%;
//   - refined with the direct light, F1 + Q2 - Q1 - (DQ2 - DQ1) + (DF2 - DF1) is closer to F2 still,
//     and with the bounced light, F1 + BF2 - BF1, closer again;
//   - composed as if no light had moved (moved: false: rho scales where the light rose too), the
//     moved lamp's picture is further from F2;
//   - the corner lamp made brighter where it was (F3, Q3, DF3, DQ3: no light moved): its first
//     picture is closer to F3 than composed as if a light had moved, and refined with the final's
//     detail besides the direct light scaled with rho (compose.mjs) is closer to F3 than the
//     first picture and no more than 10% further than with rho 1 where the light rose;
//   - a quick look of another layout (the texel density changed) is refused with a reason;
//   - `--stages-out` changes no output byte, and what it writes is the light in the lightmap's
//     units: with no bounces, the direct light is the lightmap itself to within its denoising,
//     and no bounces stage is written.
//   usage: node tests/preview/check_compose.mjs LMBAKE WORKDIR
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { compose, composeBounces } from '../../tools/preview/compose.mjs';
import { mapQuicks, readBake } from '../../tools/preview/bake-map.mjs';
import { readHdr } from '../../tools/preview/hdr.mjs';

const [lmbake, work] = process.argv.slice(2);
if (!work) { console.error('usage: node tests/preview/check_compose.mjs LMBAKE WORKDIR'); process.exit(1); }
const root = path.resolve(path.dirname(new URL(import.meta.url).pathname), '..', '..');
let failures = 0;
const check = (ok, msg) => { console.log(`${ok ? 'ok' : 'FAIL'}: ${msg}`); failures += !ok; };

fs.rmSync(work, { recursive: true, force: true });
execFileSync('python3', [path.join(root, 'tools', 'make_scenes.py'), path.join(work, 'scenes')], { stdio: 'ignore' });
const stem = 'cornell-point';
const doc = JSON.parse(fs.readFileSync(path.join(work, 'scenes', `${stem}.gltf`), 'utf8'));
// a second lamp, 2 cd, low in the back left corner
doc.extensions.KHR_lights_punctual.lights.push({ name: 'corner', type: 'point', intensity: 2, color: [1, 1, 1] });
doc.nodes.push({ name: 'corner lamp', translation: [0.2, 0.15, 0.25], extensions: { KHR_lights_punctual: { light: doc.extensions.KHR_lights_punctual.lights.length - 1 } } });
doc.scenes[doc.scene || 0].nodes.push(doc.nodes.length - 1);
const cfg = path.join(work, 'bake.yaml');
fs.writeFileSync(cfg, 'texel_density: 16\nsamples: {gather: 256}\n');

// The level as doc stands, baked into WORK/TAG/out, its stages into WORK/TAG/stages.
function bakeState(tag, { quick = false, config = cfg, extra = [] } = {}) {
  const dir = path.join(work, tag);
  fs.mkdirSync(dir, { recursive: true });
  for (const b of doc.buffers) if (!b.uri.startsWith('data:')) fs.copyFileSync(path.join(work, 'scenes', b.uri), path.join(dir, b.uri));
  fs.writeFileSync(path.join(dir, `${stem}.gltf`), JSON.stringify(doc));
  const out = path.join(dir, 'out');
  execFileSync(lmbake, ['bake', path.join(dir, `${stem}.gltf`), '-c', config, '-o', out, '-q', '--stages-out', path.join(dir, 'stages'), ...(quick ? ['--quick'] : []), ...extra]);
  return out;
}
const directOf = (out) => path.join(path.dirname(out), 'stages', 'direct');
const bouncesOf = (out) => path.join(path.dirname(out), 'stages', 'bounces');
const F1 = bakeState('f1'), Q1 = bakeState('q1', { quick: true }), Q1again = bakeState('q1-again', { quick: true });
doc.nodes[doc.nodes.length - 1].translation = [0.8, 0.15, 0.75];
const F2 = bakeState('f2'), Q2 = bakeState('q2', { quick: true });

// a change of nothing: the final's .hdr back
const same = compose({ final: F1, quickBefore: Q1, quickAfter: Q1again, out: path.join(work, 'same'), stem });
const hdr = `${stem}-lightmap-0.hdr`;
const a = same.ok ? readHdr(path.join(work, 'same', hdr)) : null, b = readHdr(path.join(F1, hdr));
check(same.ok && a.width === b.width && a.height === b.height && a.data.every((x, i) => x === b.data[i]),
  `F1 + Q1 - Q1 is F1's .hdr texel for texel, as the page reads it (${same.ok ? `${same.ms} ms` : same.why})`);
const sameRefined = compose({ final: F1, quickBefore: Q1, quickAfter: Q1again, out: path.join(work, 'same-refined'), stem, direct: { before: directOf(F1), after: directOf(F1), quickBefore: directOf(Q1), quickAfter: directOf(Q1again) } });
const c = sameRefined.ok ? readHdr(path.join(work, 'same-refined', hdr)) : null;
check(sameRefined.ok && c.data.every((x, i) => x === b.data[i]), `and refined with the direct light of the same bakes again: F1 again (${sameRefined.ok ? `${sameRefined.ms} ms` : sameRefined.why})`);
const gltf = JSON.parse(fs.readFileSync(path.join(work, 'same', `${stem}.gltf`), 'utf8'));
const files = gltf.textures.filter((t) => t.extras && t.extras.lightmap).map((t) => Object.keys(t.extras.lightmap.files).sort().join(','));
check(files.every((f) => f === 'hdr,png'), `the composed glTF names only its .hdr and .png (${files.join('; ')})`);

// the lamp moved: composed against the quick look alone, both against F2
const moved = compose({ final: F1, quickBefore: Q1, quickAfter: Q2, out: path.join(work, 'moved'), stem });
check(moved.ok, `F1 + Q2 - Q1 composed (${moved.ok ? `${moved.ms} ms` : moved.why})`);
const f2 = readBake(F2, stem);
const quickAlone = mapQuicks(f2, [{ g: readBake(Q2, stem), weight: 1 }]);
const composed = mapQuicks(f2, [{ g: readBake(path.join(work, 'moved'), stem), weight: 1 }]); // same layout: texel for texel
const final = quickAlone.atlases.get(0), { covered } = quickAlone.mapped.get(0);
const lum = (a, i, stride) => 0.2126 * a[stride * i] + 0.7152 * a[stride * i + 1] + 0.0722 * a[stride * i + 2];
function box9(values, stride, w, h) { // mean luminance over the covered texels of each 9 x 9 box
  const out = new Float64Array(w * h);
  for (let y = 0; y < h; y++) {
    for (let x = 0; x < w; x++) {
      let s = 0, n = 0;
      for (let dy = -4; dy <= 4; dy++) for (let dx = -4; dx <= 4; dx++) {
        const xx = x + dx, yy = y + dy;
        if (xx < 0 || yy < 0 || xx >= w || yy >= h || !covered[yy * w + xx]) continue;
        s += lum(values, yy * w + xx, stride); n++;
      }
      out[y * w + x] = n ? s / n : 0;
    }
  }
  return out;
}
const { width: w, height: h } = final;
// the 9 x 9 rms error against a final bake of the layout (F2's atlas), over its mean
const errorAgainst = (finalImg) => {
  const ref = box9(finalImg.data, 4, w, h);
  return (values) => {
    const b = box9(values, 3, w, h);
    let se = 0, sum = 0, n = 0;
    for (let i = 0; i < w * h; i++) if (covered[i]) { se += (b[i] - ref[i]) ** 2; sum += ref[i]; n++; }
    return Math.sqrt(se / n) / (sum / n);
  };
};
const error = errorAgainst(final);
const eQuick = error(quickAlone.mapped.get(0).value), eComposed = error(composed.mapped.get(0).value);
// the plain difference, F1 + Q2 - Q1 texel for texel (rho = 1 everywhere), at least 0 as composed
const difference = mapQuicks(f2, [{ g: readBake(Q2, stem), weight: 1 }, { g: readBake(Q1, stem), weight: -1 }]).mapped.get(0).value;
const f1 = readHdr(path.join(F1, `${stem}-lightmap-0.hdr`));
const plainDifference = difference.map((d, i) => Math.max(f1.data[4 * Math.floor(i / 3) + (i % 3)] + d, 0));
const ePlain = error(plainDifference);
check(eComposed < eQuick && eComposed < ePlain && eComposed <= 0.05, `the corner lamp moved: rho F1 + Q2 - rho Q1 is ${(100 * eComposed).toFixed(2)}% from F2, the plain difference F1 + Q2 - Q1 ${(100 * ePlain).toFixed(2)}%, the quick look alone ${(100 * eQuick).toFixed(2)}% (9 x 9 rms; want below both and at most 5%)`);
// told that no light moved, rho would scale the detail where the light rose too: further from F2
const unmoved = compose({ final: F1, quickBefore: Q1, quickAfter: Q2, out: path.join(work, 'moved-as-unmoved'), stem, moved: false });
const eUnmoved = unmoved.ok ? error(mapQuicks(f2, [{ g: readBake(path.join(work, 'moved-as-unmoved'), stem), weight: 1 }]).mapped.get(0).value) : 0;
check(eComposed < eUnmoved, `composed as a moved light (rho 1 where the light rose) ${(100 * eComposed).toFixed(2)}% from F2, as if no light had moved ${(100 * eUnmoved).toFixed(2)}% (want below)`);
// refined with the direct light at the final's resolution: F1 + Q2 - Q1 - (DQ2 - DQ1) + (DF2 - DF1)
const refined = compose({ final: F1, quickBefore: Q1, quickAfter: Q2, out: path.join(work, 'refined'), stem, direct: { before: directOf(F1), after: directOf(F2), quickBefore: directOf(Q1), quickAfter: directOf(Q2) } });
const eRefined = refined.ok ? error(mapQuicks(f2, [{ g: readBake(path.join(work, 'refined'), stem), weight: 1 }]).mapped.get(0).value) : 1;
check(refined.ok && eRefined < eComposed, `and refined with the direct light at the final's resolution: ${(100 * eRefined).toFixed(2)}% from F2 (want below ${(100 * eComposed).toFixed(2)}%; ${refined.ok ? `${refined.ms} ms` : refined.why})`);
// refined with the bounced light at the final's resolution: F1 + BF2 - BF1
const bounced = composeBounces({ final: F1, out: path.join(work, 'bounced'), stem, before: bouncesOf(F1), after: bouncesOf(F2) });
const eBounced = bounced.ok ? error(mapQuicks(f2, [{ g: readBake(path.join(work, 'bounced'), stem), weight: 1 }]).mapped.get(0).value) : 1;
check(bounced.ok && eBounced < eRefined, `and refined with the bounced light at the final's resolution: ${(100 * eBounced).toFixed(2)}% from F2 (want below ${(100 * eRefined).toFixed(2)}%; ${bounced.ok ? `${bounced.ms} ms` : bounced.why})`);
const sameBounced = composeBounces({ final: F1, out: path.join(work, 'same-bounced'), stem, before: bouncesOf(F1), after: bouncesOf(F1) });
const sb = sameBounced.ok ? readHdr(path.join(work, 'same-bounced', hdr)) : null;
check(sameBounced.ok && sb.data.every((x, i) => x === b.data[i]), `the bounced light of the same bake twice gives F1 back texel for texel (${sameBounced.ok ? `${sameBounced.ms} ms` : sameBounced.why})`);
// the corner lamp back where it was and twice as bright (F3, Q3: a change that moves no light,
// composed with moved: false as the watch does then): its first picture is closer to F3 than
// composed as a moved light, and refined with the direct light and the final's other detail
// scaled with rho it is closer than the first picture and about as close as with rho 1 where the
// light rose (as for a moved light)
const corner = doc.nodes[doc.nodes.length - 1], cornerLight = doc.extensions.KHR_lights_punctual.lights[corner.extensions.KHR_lights_punctual.light];
const movedTo = corner.translation;
corner.translation = [0.2, 0.15, 0.25];
cornerLight.intensity *= 2;
const F3 = bakeState('f3'), Q3 = bakeState('q3', { quick: true });
corner.translation = movedTo; // the level as F2 baked it again, for the checks below
cornerLight.intensity /= 2;
const f3 = readBake(F3, stem), error3 = errorAgainst(mapQuicks(f3, [{ g: readBake(Q3, stem), weight: 1 }]).atlases.get(0));
const brighter = (tag, direct, moved) => {
  const r = compose({ final: F1, quickBefore: Q1, quickAfter: Q3, out: path.join(work, tag), stem, direct, moved });
  return r.ok ? error3(mapQuicks(f3, [{ g: readBake(path.join(work, tag), stem), weight: 1 }]).mapped.get(0).value) : 1;
};
const directTo3 = { before: directOf(F1), after: directOf(F3), quickBefore: directOf(Q1), quickAfter: directOf(Q3) };
const eFirst3 = brighter('brighter', null, false), eFirstMoved3 = brighter('brighter-as-moved', null, true), eRefined3 = brighter('brighter-refined', directTo3, true), eScaled3 = brighter('brighter-scaled', directTo3, false);
// (2% until the leak work, docs/leaks.md: texels beside geometry read only their own side, which
// brought the quick looks closer to the finals, the unscaled refinement most: 2.04% -> 1.83%,
// the scaled one 2.03% -> 2.00%. Which of the two the watch should use is open: docs/watch.md)
check(eScaled3 < eFirst3 && eScaled3 <= 1.10 * eRefined3, `the corner lamp x 2: refined with the final's detail scaled where the light rose ${(100 * eScaled3).toFixed(2)}% from F3, not scaled there (as for a moved light) ${(100 * eRefined3).toFixed(2)}%, the first picture ${(100 * eFirst3).toFixed(2)}% (want below the first picture and at most 10% above the other: rho from the whole quick looks was 15% above it here)`);
check(eFirst3 < eFirstMoved3, `and its first picture ${(100 * eFirst3).toFixed(2)}% from F3, composed as if a light had moved (rho 1 where the light rose) ${(100 * eFirstMoved3).toFixed(2)}% (want below)`);
const missing = compose({ final: F1, quickBefore: Q1, quickAfter: Q2, out: path.join(work, 'missing'), stem, direct: { before: directOf(F1), after: path.join(work, 'nowhere'), quickBefore: directOf(Q1), quickAfter: directOf(Q2) } });
check(!missing.ok && /direct light/.test(missing.why) && !fs.existsSync(path.join(work, 'missing')), `a direct light not written is refused, nothing written: ${missing.why}`);

// another layout: refused, with the reason
const cfg32 = path.join(work, 'bake32.yaml');
fs.writeFileSync(cfg32, 'texel_density: 32\nsamples: {gather: 256}\n');
const Q32 = bakeState('q32', { quick: true, config: cfg32 });
const other = compose({ final: F2, quickBefore: Q2, quickAfter: Q32, out: path.join(work, 'other'), stem });
check(!other.ok && /layout|atlas/.test(other.why), `a quick look of another layout is refused: ${other.why}`);
// --stages-out: the same output; with no bounces, the direct light is the lightmap (in the same
// units) and no bounces stage is written
const cfg0 = path.join(work, 'bake0.yaml');
fs.writeFileSync(cfg0, 'texel_density: 16\nbounces: 0\noutput: {scale: radiance}\n');
const plain = path.join(work, 'plain0');
execFileSync(lmbake, ['bake', path.join(work, 'f2', `${stem}.gltf`), '-c', cfg0, '-o', plain, '-q']);
const withDirect = bakeState('f2-direct0', { config: cfg0 });
const names = fs.readdirSync(plain).sort();
const differ = names.filter((n) => !fs.readFileSync(path.join(plain, n)).equals(fs.readFileSync(path.join(withDirect, n))));
check(names.length > 3 && differ.length === 0 && fs.readdirSync(withDirect).length === names.length && !fs.existsSync(bouncesOf(withDirect)), `--stages-out changes no output file and writes no bounces stage without bounce passes (${names.length} files; differ: ${differ.join(', ') || 'none'})`);
const lightmap = readHdr(path.join(withDirect, hdr)), written = readHdr(path.join(directOf(withDirect), hdr));
let se = 0, sum = 0, n = 0;
for (let i = 0; i < lightmap.width * lightmap.height; i++) {
  if (!covered[i] || lightmap.width !== final.width) continue;
  const l = lum(lightmap.data, i, 4), d = lum(written.data, i, 4);
  se += (l - d) ** 2; sum += l; n++;
}
const rel = n ? Math.sqrt(se / n) / (sum / n) : 1;
check(written.width === lightmap.width && written.height === lightmap.height && n > 1000 && rel < 0.02, `with no bounces the direct light written is the lightmap (radiance units) within ${(100 * rel).toFixed(3)}% rms a texel over ${n} texels (want below 2%: the denoiser and the direct refinement)`);
process.exit(failures ? 1 : 0);
