#!/usr/bin/env node
// The watch's composed quick picture (tools/preview/compose.mjs, docs/watch.md): on
// tools/make_scenes.py's cornell-point box with a second lamp low in a corner, baked final and
// quick (F1, Q1), then the second lamp moved across the floor and baked again (F2, Q2):
//   - a change of nothing, F1 + Q1 - Q1, gives F1's .hdr back texel for texel (as the page reads it);
//   - F1 + Q2 - Q1 is closer to F2 than the quick look Q2 alone (both read in F2's atlas, 9 x 9
//     texel box averages over the texels a triangle covers, rms of the luminance difference over
//     F2's mean), and within 5%;
//   - with the moved lamp's direct light alone (`bake --direct-of`) before and after, in both
//     layouts, F1 + Q2 - Q1 - (QD2 - QD1) + (D2 - D1) is closer to F2 still; a correction of
//     nothing (D1 - D1) leaves F1 texel for texel;
//   - a quick look of another layout (the texel density changed) is refused with a reason;
//   - a lamp made 3x as bright: its direct light baked again equals its direct light before times
//     3 (compose.mjs scaleBake) to the .hdr's rounding; the watch's powerScale (watch-inputs.mjs)
//     gives that factor for changes of intensity and colour alone and none for any other.
//   usage: node tests/preview/check_compose.mjs LMBAKE WORKDIR
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { compose, mapQuicks, readBake, readHdr, scaleBake } from '../../tools/preview/compose.mjs';
import { changedLights, fingerprint } from '../../tools/preview/watch-inputs.mjs';

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

function bakeState(tag, { quick = false, config = cfg, extra = [] } = {}) {
  const dir = path.join(work, tag);
  fs.mkdirSync(dir, { recursive: true });
  for (const b of doc.buffers) if (!b.uri.startsWith('data:')) fs.copyFileSync(path.join(work, 'scenes', b.uri), path.join(dir, b.uri));
  fs.writeFileSync(path.join(dir, `${stem}.gltf`), JSON.stringify(doc));
  const out = path.join(dir, 'out');
  execFileSync(lmbake, ['bake', path.join(dir, `${stem}.gltf`), '-c', config, '-o', out, '-q', ...(quick ? ['--quick'] : []), ...extra]);
  return out;
}
// the corner lamp's direct light alone (`--direct-of`), in the final's layout and the quick look's
const direct = (tag) => ({ final: bakeState(`d${tag}`, { extra: ['--direct-of', 'corner'] }), quick: bakeState(`qd${tag}`, { quick: true, extra: ['--direct-of', 'corner'] }) });
const F1 = bakeState('f1'), Q1 = bakeState('q1', { quick: true }), Q1again = bakeState('q1-again', { quick: true }), D1 = direct(1);
doc.nodes[doc.nodes.length - 1].translation = [0.8, 0.15, 0.75];
const F2 = bakeState('f2'), Q2 = bakeState('q2', { quick: true }), D2 = direct(2);

// a change of nothing: the final's .hdr back
const same = compose({ final: F1, quickBefore: Q1, quickAfter: Q1again, out: path.join(work, 'same'), stem });
const hdr = `${stem}-lightmap-0.hdr`;
const a = same.ok ? readHdr(path.join(work, 'same', hdr)) : null, b = readHdr(path.join(F1, hdr));
check(same.ok && a.width === b.width && a.height === b.height && a.data.every((x, i) => x === b.data[i]),
  `F1 + Q1 - Q1 is F1's .hdr texel for texel, as the page reads it (${same.ok ? `${same.ms} ms` : same.why})`);
const sameCorrected = compose({ final: F1, quickBefore: Q1, quickAfter: Q1again, out: path.join(work, 'same-corrected'), stem, correction: { directBefore: D1.final, directAfter: D1.final, quickDirectBefore: D1.quick, quickDirectAfter: D1.quick } });
const c = sameCorrected.ok ? readHdr(path.join(work, 'same-corrected', hdr)) : null;
check(sameCorrected.ok && c.data.every((x, i) => x === b.data[i]), `and with the lamp's direct light taken off and put back: F1 again (${sameCorrected.ok ? `${sameCorrected.ms} ms` : sameCorrected.why})`);
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
const ref = box9(final.data, 4, w, h);
const error = (values) => {
  const b = box9(values, 3, w, h);
  let se = 0, sum = 0, n = 0;
  for (let i = 0; i < w * h; i++) if (covered[i]) { se += (b[i] - ref[i]) ** 2; sum += ref[i]; n++; }
  return Math.sqrt(se / n) / (sum / n);
};
const eQuick = error(quickAlone.mapped.get(0).value), eComposed = error(composed.mapped.get(0).value);
check(eComposed < eQuick && eComposed <= 0.05, `the corner lamp moved: F1 + Q2 - Q1 is ${(100 * eComposed).toFixed(2)}% from F2, the quick look alone ${(100 * eQuick).toFixed(2)}% (9 x 9 rms; want below the quick look's and at most 5%)`);
// with the lamp's direct light at the final's resolution: F1 + Q2 - Q1 - (QD2 - QD1) + (D2 - D1)
const corrected = compose({ final: F1, quickBefore: Q1, quickAfter: Q2, out: path.join(work, 'corrected'), stem, correction: { directBefore: D1.final, directAfter: D2.final, quickDirectBefore: D1.quick, quickDirectAfter: D2.quick } });
const eCorrected = corrected.ok ? error(mapQuicks(f2, [{ g: readBake(path.join(work, 'corrected'), stem), weight: 1 }]).mapped.get(0).value) : 1;
check(corrected.ok && eCorrected < eComposed, `and with the lamp's direct light at the final's resolution: ${(100 * eCorrected).toFixed(2)}% from F2 (want below ${(100 * eComposed).toFixed(2)}%; ${corrected.ok ? `${corrected.ms} ms` : corrected.why})`);

// another layout: refused, with the reason
const cfg32 = path.join(work, 'bake32.yaml');
fs.writeFileSync(cfg32, 'texel_density: 32\nsamples: {gather: 256}\n');
const Q32 = bakeState('q32', { quick: true, config: cfg32 });
const other = compose({ final: F2, quickBefore: Q2, quickAfter: Q32, out: path.join(work, 'other'), stem });
check(!other.ok && /layout|atlas/.test(other.why), `a quick look of another layout is refused: ${other.why}`);
// the corner lamp (moved) 3x as bright: its direct light baked, against the one before times 3
doc.extensions.KHR_lights_punctual.lights[doc.extensions.KHR_lights_punctual.lights.length - 1].intensity *= 3;
const D3 = bakeState('d3', { extra: ['--direct-of', 'corner'] });
scaleBake(D2.final, path.join(work, 'd2x3'), [3, 3, 3]);
const baked = readHdr(path.join(D3, hdr)), scaled = readHdr(path.join(work, 'd2x3', hdr));
let worst = 0, sumB = 0, sumS = 0;
for (let i = 0; i < baked.data.length; i++) {
  if (i % 4 === 3) continue;
  worst = Math.max(worst, Math.abs(baked.data[i] - scaled.data[i]) / Math.max(baked.data[i], 1e-3));
  sumB += baked.data[i]; sumS += scaled.data[i];
}
check(sumB > 0 && worst <= 1 / 64 && Math.abs(sumS / sumB - 1) < 1e-3, `a lamp 3x as bright: its direct light before times 3 is the baked one within ${(100 * worst).toFixed(2)}% a texel (want at most 1.6%, the .hdr's rounding), ${(100 * (sumS / sumB - 1)).toFixed(4)}% in all`);
// powerScale: the factor for intensity and colour alone, none for anything else
const lightLevel = (edit) => {
  const d = { asset: { version: '2.0' }, extensions: { KHR_lights_punctual: { lights: [{ name: 'a', type: 'point', intensity: 2 }, { name: 'b', type: 'spot', intensity: 4, color: [1, 1, 1], spot: { outerConeAngle: 0.5 } }] } }, nodes: [{ name: 'lamp a', translation: [0, 1, 0], extensions: { KHR_lights_punctual: { light: 0 } } }, { name: 'lamp b', extensions: { KHR_lights_punctual: { light: 1 } } }], scenes: [{ nodes: [0, 1] }], scene: 0 };
  edit(d);
  const file = path.join(work, 'lights.gltf');
  fs.writeFileSync(file, JSON.stringify(d));
  return fingerprint(file, [], {});
};
const base = lightLevel(() => {});
const scaleOf = (edit) => { const r = changedLights(base, lightLevel(edit)); return r.why ? r.why : JSON.stringify(r.scale); };
const cases = [
  ['a 2x', (d) => { d.extensions.KHR_lights_punctual.lights[0].intensity = 4; }, '[2,2,2]'],
  ['a recoloured', (d) => { d.extensions.KHR_lights_punctual.lights[0].color = [1, 0.5, 0.25]; }, '[1,0.5,0.25]'],
  ['a and b 3x', (d) => { d.extensions.KHR_lights_punctual.lights[0].intensity = 6; d.extensions.KHR_lights_punctual.lights[1].intensity = 12; }, '[3,3,3]'],
  ['a 2x, b 3x', (d) => { d.extensions.KHR_lights_punctual.lights[0].intensity = 4; d.extensions.KHR_lights_punctual.lights[1].intensity = 12; }, 'null'],
  ['a moved', (d) => { d.nodes[0].translation = [1, 1, 0]; }, 'null'],
  ['a 2x and given a range', (d) => { Object.assign(d.extensions.KHR_lights_punctual.lights[0], { intensity: 4, range: 5 }); }, 'null'],
  ["b's cone", (d) => { d.extensions.KHR_lights_punctual.lights[1].spot.outerConeAngle = 0.6; }, 'null'],
  ['a off', (d) => { d.extensions.KHR_lights_punctual.lights[0].intensity = 0; }, '[0,0,0]'],
];
for (const [what, edit, want] of cases) {
  const got = scaleOf(edit);
  check(got === want, `powerScale, ${what}: ${got} (want ${want})`);
}
const off = lightLevel((d) => { d.extensions.KHR_lights_punctual.lights[0].intensity = 0; });
const on = changedLights(off, base);
check(on.scale === null, `powerScale, a from off to on: ${JSON.stringify(on.scale)} (want null: nothing to scale)`);
process.exit(failures ? 1 : 0);
