// lmbake-probes: lmbake's light probes without an engine (README.md beside this file;
// docs/probes.md): the interpolation over the probes' tetrahedra and the irradiance an SH gives,
// shared by lmbake-three and lmbake-babylon, which read the probes from a glTF with their
// engine's loader and hand the engine its own form of the result.
// The bake's glTF holds the probes in asset.extras.lightmap.probes: positions, SH L2 irradiance
// (27 floats per probe, E in lux, or E / pi with scale "radiance") and the Delaunay tetrahedra.
// A probe set here is {count, positions (xyz), sh (27 per probe, E in lux), spacing, tetrahedra
// (4 probe indices each, or null)}.
// Interpolation: as Unity and Godot do, over the probes' tetrahedra: inside one, its four probes
// with the point's barycentric weights (a probe at the point itself has weight 1). Outside them
// all (beyond the probes' hull: below the lowest layer, near a wall): the tetrahedron the point is
// least outside (its smallest barycentric weight the largest), the weights clamped to >= 0 and
// renormalised, as Unity extrapolates from the hull: the probes of the point's own room (the
// nearest probes by distance may lie across a wall). With no tetrahedra in the file: the 8
// nearest probes weighted by 1 / d^2.

// The SH basis constants, in lmbake's order (l00; l1-1 ~ y, l10 ~ z, l11 ~ x; l2-2 ~ xy, l2-1 ~ yz,
// l20 ~ 3z^2 - 1, l21 ~ xz, l22 ~ x^2 - y^2), all positive (no Condon-Shortley sign).
export const SH_Y = [0.282095, 0.488603, 0.488603, 0.488603, 1.092548, 1.092548, 0.315392, 1.092548, 0.546274];

// The probe set of a glTF's asset.extras.lightmap.probes, given its arrays as the engine's loader
// read them: positions (the accessor's floats), sh (the buffer view's bytes as floats) and
// tetrahedra (the accessor's integers, or null). null when the glTF has no probes.
export function probeSet(json, { positions, sh, tetrahedra }) {
  const p = probesOf(json);
  if (!p) return null;
  const out = Float32Array.from(sh);
  const toLux = p.scale === 'radiance' ? Math.PI : 1; // E / pi stored: back to E
  if (toLux !== 1) for (let i = 0; i < out.length; i++) out[i] *= toLux;
  return { count: p.count, positions, sh: out, spacing: p.spacing || 0, tetrahedra: tetrahedra || null };
}

// The probes' entry of a glTF (asset.extras.lightmap.probes) or null
export function probesOf(json) {
  const p = json.asset && json.asset.extras && json.asset.extras.lightmap && json.asset.extras.lightmap.probes;
  return p && p.count ? p : null;
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
export const BAND_A = [Math.PI, (2 * Math.PI) / 3, (2 * Math.PI) / 3, (2 * Math.PI) / 3, Math.PI / 4, Math.PI / 4, Math.PI / 4, Math.PI / 4, Math.PI / 4];


// An irradiance SH as a quadratic form per channel: E(n) = c0 + b . n + n^T A n for unit n (A
// symmetric), what engines whose probes are polynomials (Babylon's SphericalPolynomial) take, and
// what turns with the frame: in a frame where n = R m (R orthogonal), b -> R^T b, A -> R^T A R.
// Returns [{c0, b: [x, y, z], A: [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]}] for r, g, b.
export function shQuadratic(sh) {
  return [0, 1, 2].map((c) => {
    const k = (i) => SH_Y[i] * sh[3 * i + c];
    const xy = k(4) / 2, yz = k(5) / 2, xz = k(7) / 2;
    return {
      c0: k(0) - k(6),
      b: [k(3), k(1), k(2)],
      A: [[k(8), xy, xz], [xy, -k(8), yz], [xz, yz, 3 * k(6)]],
    };
  });
}
