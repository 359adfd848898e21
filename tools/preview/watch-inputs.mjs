// What `lmbake preview --watch` watches and how it names a change (docs/watch.md): the level
// file, the buffers and images it names, the config and the sky image the config names. A
// snapshot (size and mtime of each) is cheap and polled; a fingerprint (the level's JSON cut into
// lights, materials and geometry, file hashes, the config's keys as `lmbake bake --print-config`
// writes them) is taken when a snapshot moved, and two fingerprints say what changed.
import crypto from 'node:crypto';
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';

// Config keys that decide the layout (unwrap, pack, texels): a change of any other key
// relights the same atlases.
const LAYOUT_KEYS = /^(texel_density|density_overrides|atlas\.|lightmap\.)/;

const hashBytes = (b) => crypto.createHash('sha256').update(b).digest('hex');
const hashFile = (f) => { try { return hashBytes(fs.readFileSync(f)); } catch { return 'missing'; } };
const isFileUri = (u) => typeof u === 'string' && !/^[a-z][a-z0-9+.-]*:/i.test(u);

// The level's glTF JSON (a .glb's JSON chunk) and its BIN chunk, or throws with the reason.
function readLevel(file) {
  try { return parseLevel(file); } catch (e) { throw new Error(`${file}: ${e.code === 'ENOENT' ? 'missing' : e.message}`); }
}
function parseLevel(file) {
  const bytes = fs.readFileSync(file);
  if (file.toLowerCase().endsWith('.glb')) {
    if (bytes.length < 20 || bytes.toString('latin1', 0, 4) !== 'glTF') throw new Error('not a .glb file');
    const jsonLength = bytes.readUInt32LE(12);
    const json = JSON.parse(bytes.toString('utf8', 20, 20 + jsonLength));
    return { json, bin: bytes.subarray(20 + jsonLength) };
  }
  return { json: JSON.parse(bytes.toString('utf8')), bin: null };
}

// The files a watch looks at: [{file, what}], the level first. A level that cannot be read
// gives itself only (the next good save names the rest).
export function watchedFiles(level, config, configKeys) {
  const out = [{ file: level, what: 'level' }];
  try {
    const { json } = readLevel(level);
    const dir = path.dirname(level);
    for (const [list, what] of [[json.buffers, 'buffer'], [json.images, 'image']]) {
      for (const x of list || []) if (isFileUri(x.uri)) out.push({ file: path.resolve(dir, decodeURIComponent(x.uri)), what });
    }
  } catch { /* reported by the bake */ }
  if (config) out.push({ file: config, what: 'config' });
  const sky = configKeys && configKeys['sky.image'];
  if (config && sky && sky !== '""') out.push({ file: path.resolve(path.dirname(config), sky.replace(/^"|"$/g, '')), what: 'sky image' });
  return out;
}

// size and mtime of each watched file ('-' when missing): a string that changes with any of them
export function snapshot(files) {
  return files.map(({ file }) => {
    try { const s = fs.statSync(file); return `${s.size}:${s.mtimeMs}`; } catch { return '-'; }
  }).join('|');
}

// The effective config as `lmbake bake --print-config` writes it, as {key.path: value text};
// throws with lmbake's message for a config it refuses. The same config's bytes give the same
// keys: a reader keeps its last answer, so a save of the level alone starts no process for it
// (35 ms of a relight's second).
export function configReader() {
  let last = null;
  return (lmbake, config) => {
    const bytes = config ? fs.readFileSync(config) : Buffer.alloc(0);
    if (last && last.lmbake === lmbake && last.config === config && last.bytes.equals(bytes)) return { ...last.keys };
    const keys = configKeys(lmbake, config);
    last = { lmbake, config, bytes, keys: { ...keys } };
    return keys;
  };
}

export function configKeys(lmbake, config) {
  let text;
  try {
    text = execFileSync(lmbake, ['bake', '--print-config', ...(config ? ['-c', config] : [])], { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });
  } catch (e) {
    throw new Error(String(e.stderr || e.message).trim().split('\n').pop());
  }
  const keys = {};
  let section = '';
  for (const line of text.split('\n')) {
    const m = /^( *)([A-Za-z_.0-9]+):(?: (.*))?$/.exec(line);
    if (!m || line.startsWith('#')) continue;
    if (m[1].length === 0 && m[3] === undefined) { section = m[2] + '.'; continue; }
    keys[(m[1].length ? section : '') + m[2]] = m[3] ?? '';
  }
  return keys;
}

// A fingerprint of what a bake reads: {lights, materials, geometry, keys, files} (hashes and
// the config's keys); throws when the level cannot be read.
export function fingerprint(level, files, keys) {
  const { json, bin } = readLevel(level);
  const lightNodes = (json.nodes || []).map((n, i) => (n.extensions && n.extensions.KHR_lights_punctual && n.mesh === undefined ? i : -1)).filter((i) => i >= 0);
  const nodes = (json.nodes || []).map((n, i) => (lightNodes.includes(i) ? { light: n.extensions.KHR_lights_punctual, children: n.children } : n));
  const lights = { ext: json.extensions && json.extensions.KHR_lights_punctual, nodes: lightNodes.map((i) => json.nodes[i]) };
  const materials = { materials: json.materials, textures: json.textures, images: json.images, samplers: json.samplers };
  const rest = { ...json, nodes, materials: undefined, textures: undefined, images: undefined, samplers: undefined, extensions: { ...(json.extensions || {}), KHR_lights_punctual: undefined } };
  const fileHash = {};
  for (const f of files) if (f.what !== 'level' && f.what !== 'config') fileHash[f.file] = { what: f.what, hash: hashFile(f.file) };
  // where the light comes from and its shape: the lights' nodes and everything of the lights
  // but their intensity and colour, save whether each is on (a light turned on is a light placed),
  const on = (l) => (l.intensity === undefined || l.intensity > 0) && !(l.color && l.color.every((c) => c <= 0));
  const shapes = ((lights.ext && lights.ext.lights) || []).map((l) => ({ ...l, intensity: undefined, color: undefined, on: on(l) }));
  // and the materials without their factors and strengths, save whether each emits
  const placeOf = (k, v) => {
    if (k === 'emissiveFactor') return Array.isArray(v) && v.some((c) => c > 0);
    if (k === 'emissiveStrength') return v > 0;
    return /(Factor|Strength)$/.test(k) ? undefined : v;
  };
  const places = { shapes, nodes: lights.nodes, materials: JSON.stringify(materials, placeOf) };
  return {
    lights: hashBytes(JSON.stringify(lights)), lightPlaces: hashBytes(JSON.stringify(places)), materials: hashBytes(JSON.stringify(materials)),
    geometry: hashBytes(JSON.stringify(rest) + (bin ? hashBytes(bin) : '')), keys, files: fileHash,
  };
}

// What changed between two fingerprints: {what: ['lights', 'config samples.gather', ...],
// layout: true when the layout must be made again (geometry, buffers, layout keys), placesKept:
// true when only the lights' intensities or colours and the materials' factors changed (no light
// moved, turned, changed its shape or was turned on or off, no material started or stopped
// emitting; no file or config key changed): the light then falls where it fell, only stronger or
// weaker, which the composed picture uses (compose.mjs, `moved`)}.
export function compare(before, after) {
  if (!before) return { what: ['first bake'], layout: true, placesKept: false };
  const what = [];
  let layout = false;
  if (before.geometry !== after.geometry) { what.push('geometry'); layout = true; }
  if (before.lights !== after.lights) what.push('lights');
  if (before.materials !== after.materials) what.push('materials');
  for (const [file, f] of Object.entries(after.files)) {
    if (!before.files[file] || before.files[file].hash !== f.hash) {
      what.push(`${f.what} ${path.basename(file)}`);
      if (f.what === 'buffer') layout = true;
    }
  }
  const keys = new Set([...Object.keys(before.keys), ...Object.keys(after.keys)]);
  const changedKeys = [...keys].filter((k) => before.keys[k] !== after.keys[k]);
  for (const k of changedKeys) if (LAYOUT_KEYS.test(k)) layout = true;
  if (changedKeys.length) what.push('config ' + changedKeys.join(', '));
  const placesKept = what.every((w) => w === 'lights' || w === 'materials') && before.lightPlaces === after.lightPlaces;
  if (!what.length) what.push('nothing a bake reads (saved unchanged)');
  return { what, layout, placesKept };
}
