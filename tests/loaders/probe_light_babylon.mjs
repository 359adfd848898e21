#!/usr/bin/env node
// lmbake-babylon's probe light (loaders/babylon/lmbake-babylon-probes.js): the SphericalPolynomial
// sphericalPolynomialAt makes, evaluated both ways Babylon's PBR shaders do (the polynomial, and
// with SPHERICAL_HARMONICS its pre-scaled harmonics), against lmbake-probes' irradiance E / pi at
// the same normal taken to glTF's frame, under the root node Babylon's glTF loader puts a level in
// (a half turn about y and z mirrored: glTF's (x, y, z) is the scene's (-x, y, z)) and under a
// turned, scaled root. Random SH, 200 normals each. Bound: 1e-6 absolute on E of order 1 (Babylon's
// matrices are 32-bit floats).
// ctest loaders_probe_light_babylon; the same light rendered on a sphere in Chromium is
// tests/loaders/check_loader_pixels.py's probe_light().
import { NullEngine } from '@babylonjs/core/Engines/nullEngine.js';
import { Scene } from '@babylonjs/core/scene.js';
import { TransformNode } from '@babylonjs/core/Meshes/transformNode.js';
import { Quaternion, Vector3 } from '@babylonjs/core/Maths/math.vector.js';
import { Logger } from '@babylonjs/core/Misc/logger.js';
import { sphericalPolynomialAt } from '../../loaders/babylon/lmbake-babylon-probes.js';
import { shIrradiance } from 'lmbake-probes';

Logger.LogLevels = Logger.NoneLogLevel;
const scene = new Scene(new NullEngine());
let seed = 12345;
const rand = () => ((seed = (seed * 1103515245 + 12345) % 2147483648) / 2147483648);
const unit = () => { const z = 2 * rand() - 1, p = 2 * Math.PI * rand(), s = Math.sqrt(1 - z * z); return [s * Math.cos(p), s * Math.sin(p), z]; };

const roots = [
  ['glTF loader root', Quaternion.RotationAxis(new Vector3(0, 1, 0), Math.PI), new Vector3(1, 1, -1)],
  ['turned and scaled', Quaternion.RotationAxis(new Vector3(0.3, 1, -0.2).normalize(), 0.7), new Vector3(2, 2, -2)],
];
let worst = 0;
for (const [name, q, scaling] of roots) {
  const root = new TransformNode(name, scene);
  root.rotationQuaternion = q;
  root.scaling = scaling;
  const world = root.computeWorldMatrix(true);
  const sh = Float32Array.from({ length: 27 }, (_, i) => (i < 3 ? 2 : 0.6) * (rand() - 0.3));
  const probes = { count: 1, positions: new Float32Array([0, 0, 0]), sh, spacing: 1, tetrahedra: null };
  const poly = sphericalPolynomialAt(probes, Vector3.TransformCoordinates(Vector3.Zero(), world), root);
  const h = poly.preScaledHarmonics;
  let w = 0;
  for (let k = 0; k < 200; k++) {
    const nb = unit(); // a normal in the scene; in glTF's frame: the root's inverse, normalised
    const g = Vector3.TransformNormal(new Vector3(...nb), world.clone().invert()).normalize();
    const want = shIrradiance(sh, [g.x, g.y, g.z]).map((e) => e / Math.PI);
    const [x, y, z] = nb;
    for (let c = 0; c < 3; c++) {
      const C = ['x', 'y', 'z'][c];
      const p = poly.x[C] * x + poly.y[C] * y + poly.z[C] * z + poly.xx[C] * x * x + poly.yy[C] * y * y + poly.zz[C] * z * z +
        poly.xy[C] * x * y + poly.yz[C] * y * z + poly.zx[C] * z * x;
      const s = h.l00[C] + h.l1_1[C] * y + h.l10[C] * z + h.l11[C] * x + h.l2_2[C] * y * x + h.l2_1[C] * y * z +
        h.l20[C] * (3 * z * z - 1) + h.l21[C] * z * x + h.l22[C] * (x * x - y * y);
      w = Math.max(w, Math.abs(p - want[c]), Math.abs(s - want[c]));
    }
  }
  console.log(`${name}: polynomial and pre-scaled harmonics against lmbake-probes' E / pi at 200 normals: worst ${w.toExponential(2)} absolute`);
  worst = Math.max(worst, w);
}
const ok = worst <= 1e-6;
console.log(`lmbake-babylon probe light: worst ${worst.toExponential(2)} (bound 1e-6): ${ok ? 'ok' : 'FAIL'}`);
process.exit(ok ? 0 : 1);
