#!/usr/bin/env node
// The watch's reading of a change (tools/preview/watch-inputs.mjs fingerprint and compare): on a
// small level of a floor, a point light, a spot light and an emissive material, each edit is named
// ("lights", "materials", "geometry", a config key) and says whether it moved no light
// (placesKept: only lights' intensities or colours and materials' factors changed, which the
// composed quick picture scales the final's detail by, compose.mjs) or might have (a light moved,
// turned, reshaped, turned on or off, a material that starts or stops emitting, a texture, a
// config key, geometry).
//   usage: node tests/preview/check_watch_inputs.mjs WORKDIR
import fs from 'node:fs';
import path from 'node:path';
import { compare, fingerprint } from '../../tools/preview/watch-inputs.mjs';

const [work] = process.argv.slice(2);
if (!work) { console.error('usage: node tests/preview/check_watch_inputs.mjs WORKDIR'); process.exit(1); }
fs.rmSync(work, { recursive: true, force: true });
fs.mkdirSync(work, { recursive: true });
let failures = 0;
const check = (ok, msg) => { console.log(`${ok ? 'ok' : 'FAIL'}: ${msg}`); failures += !ok; };

// a floor quad (positions and indices in a data: buffer), a point light, a spot light, two materials
const positions = new Float32Array([0, 0, 0, 1, 0, 0, 1, 0, 1, 0, 0, 1]), indices = new Uint16Array([0, 1, 2, 0, 2, 3]);
const bytes = Buffer.concat([Buffer.from(positions.buffer), Buffer.from(indices.buffer)]);
const base = () => ({
  asset: { version: '2.0' },
  buffers: [{ byteLength: bytes.length, uri: `data:application/octet-stream;base64,${bytes.toString('base64')}` }],
  bufferViews: [{ buffer: 0, byteOffset: 0, byteLength: 48 }, { buffer: 0, byteOffset: 48, byteLength: 12 }],
  accessors: [{ bufferView: 0, componentType: 5126, count: 4, type: 'VEC3', min: [0, 0, 0], max: [1, 0, 1] },
    { bufferView: 1, componentType: 5123, count: 6, type: 'SCALAR' }],
  materials: [{ name: 'floor', pbrMetallicRoughness: { baseColorFactor: [0.8, 0.8, 0.8, 1] } },
    { name: 'lamp', emissiveFactor: [1, 1, 1], extensions: { KHR_materials_emissive_strength: { emissiveStrength: 5 } } },
    { name: 'dark', emissiveFactor: [0, 0, 0] }],
  meshes: [{ primitives: [{ attributes: { POSITION: 0 }, indices: 1, material: 0 }] }],
  extensions: { KHR_lights_punctual: { lights: [{ name: 'bulb', type: 'point', intensity: 10 }, { name: 'spot', type: 'spot', intensity: 20, spot: { outerConeAngle: 0.6 } }] } },
  extensionsUsed: ['KHR_lights_punctual', 'KHR_materials_emissive_strength'],
  nodes: [{ mesh: 0 }, { name: 'bulb', translation: [0.5, 1, 0.5], extensions: { KHR_lights_punctual: { light: 0 } } },
    { name: 'spot', translation: [0.2, 1, 0.2], extensions: { KHR_lights_punctual: { light: 1 } } }],
  scenes: [{ nodes: [0, 1, 2] }],
});
const printOf = (doc, keys = {}) => {
  const file = path.join(work, 'level.gltf');
  fs.writeFileSync(file, JSON.stringify(doc));
  return fingerprint(file, [], keys);
};
const before = printOf(base());
const cases = [
  ['the point light x 3', (d) => { d.extensions.KHR_lights_punctual.lights[0].intensity *= 3; }, ['lights'], true],
  ['the spot light coloured', (d) => { d.extensions.KHR_lights_punctual.lights[1].color = [1, 0.5, 0.2]; }, ['lights'], true],
  ['the floor darker, the lamp material brighter', (d) => { d.materials[0].pbrMetallicRoughness.baseColorFactor = [0.4, 0.4, 0.4, 1]; d.materials[1].extensions.KHR_materials_emissive_strength.emissiveStrength = 9; }, ['materials'], true],
  ['the point light moved', (d) => { d.nodes[1].translation = [0.7, 1, 0.5]; }, ['lights'], false],
  ['the spot light turned', (d) => { d.nodes[2].rotation = [0.2588, 0, 0, 0.9659]; }, ['lights'], false],
  ['the spot light\'s cone widened', (d) => { d.extensions.KHR_lights_punctual.lights[1].spot.outerConeAngle = 0.7; }, ['lights'], false],
  ['the point light turned off', (d) => { d.extensions.KHR_lights_punctual.lights[0].intensity = 0; }, ['lights'], false],
  ['a dark material made to emit', (d) => { d.materials[2].emissiveFactor = [1, 0.9, 0.8]; }, ['materials'], false],
  ['the point light brighter and the spot light moved', (d) => { d.extensions.KHR_lights_punctual.lights[0].intensity = 12; d.nodes[2].translation = [0.3, 1, 0.2]; }, ['lights'], false],
  ['the floor moved', (d) => { d.nodes[0].translation = [0, 0.1, 0]; }, ['geometry'], false],
];
for (const [what, edit, named, kept] of cases) {
  const doc = base();
  edit(doc);
  const c = compare(before, printOf(doc));
  check(JSON.stringify(c.what) === JSON.stringify(named) && c.placesKept === kept,
    `${what}: named ${JSON.stringify(c.what)} (want ${JSON.stringify(named)}), placesKept ${c.placesKept} (want ${kept})`);
}
const keyed = compare(printOf(base(), { 'sky.intensity': '1' }), printOf(base(), { 'sky.intensity': '2' }));
check(keyed.what.join() === 'config sky.intensity' && keyed.placesKept === false, `a config key changed: named ${JSON.stringify(keyed.what)}, placesKept ${keyed.placesKept} (want false: the watch does not read what a key does)`);
const same = compare(before, printOf(base()));
check(same.placesKept === true && same.what[0].startsWith('nothing'), `saved unchanged: ${JSON.stringify(same.what)}, placesKept ${same.placesKept}`);
process.exit(failures ? 1 : 0);
