// The `records` view: the irradiance cache's records of the final gather as a dot at each
// record's gather point, coloured by its reach (log scale, RECORD_RAMP: blue = the smallest
// reach in the bake, yellow = the largest), over the lightmap view. lmbake names the file in
// the glTF's asset.extras.lmbake.irradianceCacheRecords {uri, count, layout}: per record four
// little-endian float32, x y z (world) and the reach (world units).
import * as THREE from 'three';
import { RECORD_RAMP } from './record-ramp.js';
import { cloneWithPatches } from '/loaders/three/lmbake-three.js';

export { RECORD_RAMP };

// The records of the glTF at gltfUrl (its parsed JSON: json), or null when the bake has none
// (irradiance_cache.error: 0). Returns { points (THREE.Points), count, reachMin, reachMax,
// records: Float32Array (x y z reach), rampIndex(i) }.
export async function loadRecords(json, gltfUrl) {
  const ref = json.asset && json.asset.extras && json.asset.extras.lmbake && json.asset.extras.lmbake.irradianceCacheRecords;
  if (!ref) return null;
  const res = await fetch(new URL(ref.uri, new URL(gltfUrl, location.href)));
  if (!res.ok) throw new Error(`records file ${ref.uri}: HTTP ${res.status}`);
  const view = new DataView(await res.arrayBuffer());
  const count = Math.floor(view.byteLength / 16);
  if (count !== ref.count) throw new Error(`records file ${ref.uri}: ${count} records, the glTF says ${ref.count}`);
  const records = new Float32Array(4 * count);
  for (let i = 0; i < 4 * count; i++) records[i] = view.getFloat32(4 * i, true);
  let reachMin = Infinity, reachMax = 0;
  for (let i = 0; i < count; i++) { reachMin = Math.min(reachMin, records[4 * i + 3]); reachMax = Math.max(reachMax, records[4 * i + 3]); }
  const span = Math.log(reachMax / reachMin) || 1;
  const rampIndex = (i) => Math.round(255 * Math.min(1, Math.max(0, Math.log(records[4 * i + 3] / reachMin) / span)));
  const pos = new Float32Array(3 * count), col = new Float32Array(3 * count);
  const linear = (v) => { const c = new THREE.Color(); c.setRGB(v[0] / 255, v[1] / 255, v[2] / 255, THREE.SRGBColorSpace); return c; };
  for (let i = 0; i < count; i++) {
    pos.set(records.subarray(4 * i, 4 * i + 3), 3 * i);
    const c = linear(RECORD_RAMP[rampIndex(i)]);
    col.set([c.r, c.g, c.b], 3 * i);
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
  g.setAttribute('color', new THREE.BufferAttribute(col, 3));
  const m = new THREE.PointsMaterial({ size: 5, sizeAttenuation: false, vertexColors: true, toneMapped: false });
  const points = new THREE.Points(g, m);
  points.frustumCulled = false;
  return { points, count, reachMin, reachMax, records, rampIndex, uri: ref.uri };
}

// The mesh material under the dots: the lightmap view pushed back in depth, so that a dot on
// the surface is drawn over it and one behind a wall is not. (Its shader patches, an
// InstancedMesh's per-instance rectangles, kept.)
export function recordsBaseMaterial(lightmap) {
  return Object.assign(cloneWithPatches(lightmap), { polygonOffset: true, polygonOffsetFactor: 2, polygonOffsetUnits: 8 });
}
