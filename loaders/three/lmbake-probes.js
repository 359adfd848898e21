// lmbake-probes: lmbake's light probes in three.js (README.md beside this file; docs/probes.md).
// The bake's glTF holds them in asset.extras.lightmap.probes: positions, SH L2 irradiance (27
// floats per probe, E in lux, or E / pi with scale "radiance") and the Delaunay tetrahedra.
//   const probes = await loadProbes(gltf.parser);
//   scene.add(lightProbeAt(probes, mesh.position));  // a THREE.LightProbe lighting like the lightmap
// Interpolation over the probes' tetrahedra: lmbake-probes (loaders/probes), shared with
// lmbake-babylon.
import * as THREE from 'three';
import { BAND_A, probeSet, probesOf, interpolateSH } from 'lmbake-probes';

export { findTetrahedron, interpolateSH, shIrradiance } from 'lmbake-probes';

// The bake's probes (lmbake-probes' probe set), or null when it has none.
export async function loadProbes(parser) {
  const p = probesOf(parser.json);
  if (!p) return null;
  const positions = (await parser.getDependency('accessor', p.positions)).array;
  const sh = new Float32Array(await parser.getDependency('bufferView', p.sh));
  const tetrahedra = p.tetrahedra !== undefined ? (await parser.getDependency('accessor', p.tetrahedra)).array : null;
  return probeSet(parser.json, { positions, sh, tetrahedra });
}

// A THREE.LightProbe lighting like the probes at point x (a THREE.Vector3 or [x, y, z]). three's
// LightProbe holds the radiance's SH coefficients L_lm in the same basis and order as lmbake's
// irradiance SH, and its shader turns them into irradiance (x A_l) and into a diffuse surface's
// light (x albedo / pi): lmbake's E_lm / A_l give back E, the light a lightmapped surface shows.
export function lightProbeAt(probes, x, probe = new THREE.LightProbe()) {
  const p = Array.isArray(x) ? x : [x.x, x.y, x.z];
  const { sh } = interpolateSH(probes, p);
  for (let k = 0; k < 9; k++) probe.sh.coefficients[k].set(sh[3 * k] / BAND_A[k], sh[3 * k + 1] / BAND_A[k], sh[3 * k + 2] / BAND_A[k]);
  probe.intensity = 1;
  return probe;
}
