// lmbake-probes: lmbake's light probes in three.js (README.md beside this file; docs/probes.md).
// The bake's glTF holds them in asset.extras.lightmap.probes: positions, SH L2 irradiance (27
// floats per probe, E in lux, or E / pi with scale "radiance") and the Delaunay tetrahedra.
//   const probes = await loadProbes(gltf.parser);
//   scene.add(lightProbeAt(probes, mesh.position));  // a THREE.LightProbe lighting like the lightmap
// Interpolation: as Unity and Godot do, over the probes' tetrahedra: inside one, its four probes
// with the point's barycentric weights (a probe at the point itself has weight 1). Outside them
// all (beyond the probes' hull: below the lowest layer, near a wall): the tetrahedron the point is
// least outside (its smallest barycentric weight the largest), the weights clamped to >= 0 and
// renormalised, as Unity extrapolates from the hull: the probes of the point's own room (the
// nearest probes by distance may lie across a wall). With no tetrahedra in the file: the 8
// nearest probes weighted by 1 / d^2.
import * as THREE from 'three';

const SH_Y = [0.282095, 0.488603, 0.488603, 0.488603, 1.092548, 1.092548, 0.315392, 1.092548, 0.546274];

// The bake's probes, or null when it has none: {count, positions (Float32Array xyz), sh
// (Float32Array, 27 per probe, E in lux), spacing}.
export async function loadProbes(parser) {
  const p = parser.json.asset && parser.json.asset.extras && parser.json.asset.extras.lightmap &&
    parser.json.asset.extras.lightmap.probes;
  if (!p || !p.count) return null;
  const positions = (await parser.getDependency('accessor', p.positions)).array;
  const sh = new Float32Array(await parser.getDependency('bufferView', p.sh));
  const toLux = p.scale === 'radiance' ? Math.PI : 1; // E / pi stored: back to E
  if (toLux !== 1) for (let i = 0; i < sh.length; i++) sh[i] *= toLux;
  const tetrahedra = p.tetrahedra !== undefined ? (await parser.getDependency('accessor', p.tetrahedra)).array : null;
  return { count: p.count, positions, sh, spacing: p.spacing || 0, tetrahedra };
}

// The tetrahedron holding x and x's barycentric weights in it; beyond them all, the one x is
// least outside with its weights clamped and renormalised (outside: true); null: no tetrahedra.
export function findTetrahedron(probes, x) {
  const t = probes.tetrahedra, P = probes.positions;
  if (!t) return null;
  const eps = 1e-7;
  let best = null, bestLeast = -Infinity;
  for (let k = 0; k < t.length; k += 4) {
    const a = 3 * t[k], v = [0, 1, 2].map((j) => [P[3 * t[k + j + 1]] - P[a], P[3 * t[k + j + 1] + 1] - P[a + 1], P[3 * t[k + j + 1] + 2] - P[a + 2]]);
    const q = [x[0] - P[a], x[1] - P[a + 1], x[2] - P[a + 2]];
    const det = (u, w, z) => u[0] * (w[1] * z[2] - w[2] * z[1]) - u[1] * (w[0] * z[2] - w[2] * z[0]) + u[2] * (w[0] * z[1] - w[1] * z[0]);
    const d = det(v[0], v[1], v[2]);
    if (!(d > 0)) continue;
    const b1 = det(q, v[1], v[2]) / d, b2 = det(v[0], q, v[2]) / d, b3 = det(v[0], v[1], q) / d, b0 = 1 - b1 - b2 - b3;
    if (b0 >= -eps && b1 >= -eps && b2 >= -eps && b3 >= -eps) return { probes: [t[k], t[k + 1], t[k + 2], t[k + 3]], weights: [b0, b1, b2, b3] };
    const least = Math.min(b0, b1, b2, b3);
    if (least > bestLeast) {
      bestLeast = least;
      best = { probes: [t[k], t[k + 1], t[k + 2], t[k + 3]], weights: [b0, b1, b2, b3] };
    }
  }
  if (!best) return null;
  const clamped = best.weights.map((w) => Math.max(0, w)), sum = clamped.reduce((a, b) => a + b, 0);
  return { probes: best.probes, weights: clamped.map((w) => w / sum), outside: true };
}

// The irradiance SH (27 floats) at point x: barycentric in its tetrahedron (or the nearest one,
// beyond the hull), else (no tetrahedra) IDW over the 8 nearest probes. {sh, probes (those used),
// how: 'tetrahedron', 'hull' or 'nearest'}.
export function interpolateSH(probes, x) {
  const tet = findTetrahedron(probes, x);
  if (tet) {
    const out = new Float32Array(27);
    tet.probes.forEach((i, j) => { for (let k = 0; k < 27; k++) out[k] += tet.weights[j] * probes.sh[27 * i + k]; });
    const used = tet.probes.filter((_, j) => tet.weights[j] > 1e-6);
    return { sh: out, probes: used, weights: tet.weights, how: tet.outside ? 'hull' : 'tetrahedron' };
  }
  const near = [];
  for (let i = 0; i < probes.count; i++) {
    const dx = probes.positions[3 * i] - x[0], dy = probes.positions[3 * i + 1] - x[1], dz = probes.positions[3 * i + 2] - x[2];
    const d2 = dx * dx + dy * dy + dz * dz;
    if (near.length < 8 || d2 < near[near.length - 1].d2) {
      near.push({ i, d2 });
      near.sort((a, b) => a.d2 - b.d2);
      if (near.length > 8) near.pop();
    }
  }
  const out = new Float32Array(27);
  if (!near.length) return { sh: out, probes: [], how: 'nearest' };
  const exact = near[0].d2 <= 1e-12 * Math.max(1, probes.spacing * probes.spacing);
  const used = exact ? [near[0]] : near;
  let total = 0;
  for (const n of used) {
    const w = exact ? 1 : 1 / n.d2;
    total += w;
    for (let k = 0; k < 27; k++) out[k] += w * probes.sh[27 * n.i + k];
  }
  for (let k = 0; k < 27; k++) out[k] /= total;
  return { sh: out, probes: used.map((n) => n.i), how: 'nearest' };
}

// E for unit normal n from an irradiance SH (RGB).
export function shIrradiance(sh, n) {
  const [x, y, z] = n;
  const b = [SH_Y[0], SH_Y[1] * y, SH_Y[2] * z, SH_Y[3] * x, SH_Y[4] * x * y, SH_Y[5] * y * z, SH_Y[6] * (3 * z * z - 1),
    SH_Y[7] * x * z, SH_Y[8] * (x * x - y * y)];
  return [0, 1, 2].map((c) => b.reduce((s, v, k) => s + v * sh[3 * k + c], 0));
}

// Irradiance SH band factors A_l (Ramamoorthi and Hanrahan 2001): E_lm = A_l L_lm.
const BAND_A = [Math.PI, (2 * Math.PI) / 3, (2 * Math.PI) / 3, (2 * Math.PI) / 3, Math.PI / 4, Math.PI / 4, Math.PI / 4, Math.PI / 4, Math.PI / 4];

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
