#!/usr/bin/env node
// lmbake-three's lightProbeAt (loaders/three/lmbake-probes.js): the THREE.LightProbe it makes
// from the bake's irradiance SH gives, through three's own irradiance evaluation
// (SphericalHarmonics3.getIrradianceAt, what three's shaders compute), the irradiance lmbake's SH
// gives (shIrradiance): for random probes and normals, at a probe and between four probes of a
// tetrahedron, within 1e-5 relative. Exit 1 on a mismatch.
import * as THREE from 'three';
import { lightProbeAt, shIrradiance, interpolateSH } from '../../loaders/three/lmbake-probes.js';

let seed = 7;
const rand = () => ((seed = (seed * 1103515245 + 12345) % 2147483648) / 2147483648);
const probes = {
  count: 4, spacing: 1, positions: new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1]),
  sh: Float32Array.from({ length: 4 * 27 }, (_, i) => (i % 27 < 3 ? 5 + 5 * rand() : 2 * rand() - 1)),
  tetrahedra: new Uint32Array([0, 1, 2, 3]),
};
let worst = 0, checks = 0;
for (const point of [[0, 0, 0], [0.2, 0.3, 0.1], [1, 0, 0]]) {
  const probe = lightProbeAt(probes, point);
  const { sh } = interpolateSH(probes, point);
  for (let k = 0; k < 64; k++) {
    const n = new THREE.Vector3(2 * rand() - 1, 2 * rand() - 1, 2 * rand() - 1).normalize();
    const e3 = probe.sh.getIrradianceAt(n, new THREE.Vector3());
    const e = shIrradiance(sh, [n.x, n.y, n.z]);
    for (let c = 0; c < 3; c++) worst = Math.max(worst, Math.abs(e3.getComponent(c) - e[c]) / Math.max(1e-6, Math.abs(e[c])));
    checks++;
  }
}
console.log(`lightProbeAt: ${checks} normals at 3 points; three's irradiance against lmbake's SH: worst ${worst.toExponential(2)} relative (bound 1e-5)`);
process.exit(worst <= 1e-5 ? 0 : 1);
