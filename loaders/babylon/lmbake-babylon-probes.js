// lmbake-babylon's light probes: objects without lightmaps (characters, props lit by probes) lit as
// the bake's probes say, through Babylon's own environment lighting (README.md beside this file;
// docs/probes.md).
//   const probes = lmbakeProbes(result.meshes[0]);          // the probes registerLmbakeLightmaps read
//   applyProbeLight(character, probes, result.meshes[0]);   // its PBR material lit by the probe at its position
// Babylon's PBR material lights a surface from its reflection texture's spherical polynomial: the
// diffuse light is albedo x the polynomial at the world normal, the polynomial holding E / pi
// (Lambertian radiance, as Babylon makes it from an environment map). applyProbeLight gives the
// object's material a reflection texture of its own: a black 1 x 1 cube (no specular reflections:
// the bake stores none) whose polynomial is the probes' irradiance at the object's position,
// interpolated over their tetrahedra (lmbake-probes), turned from the glTF's frame into the
// scene's (Babylon's glTF loader puts the level under a root node that flips glTF's right-handed
// frame) and divided by pi.
import { SphericalHarmonics, SphericalPolynomial } from '@babylonjs/core/Maths/sphericalPolynomial.js';
import { RawCubeTexture } from '@babylonjs/core/Materials/Textures/rawCubeTexture.js';
import { Matrix, Vector3 } from '@babylonjs/core/Maths/math.vector.js';
import '@babylonjs/core/Materials/Textures/baseTexture.polynomial.js';
import { ArrayItem } from '@babylonjs/loaders/glTF/2.0/glTFLoader.js';
import { interpolateSH, probeSet, probesOf, shQuadratic } from 'lmbake-probes';

// The bake's probes through a Babylon glTF loader (lmbake-probes' probe set), or null.
export async function loadProbes(loader) {
  const json = loader.gltf, p = probesOf(json);
  if (!p) return null;
  const context = '/asset/extras/lightmap/probes';
  const positionsAccessor = ArrayItem.Get(`${context}/positions`, json.accessors, p.positions);
  const positions = await loader._loadFloatAccessorAsync(`/accessors/${positionsAccessor.index}`, positionsAccessor);
  const view = ArrayItem.Get(`${context}/sh`, json.bufferViews, p.sh);
  const bytes = await loader.loadBufferViewAsync(`/bufferViews/${view.index}`, view);
  const sh = new Float32Array(bytes.slice().buffer, 0, bytes.byteLength >> 2); // a copy: 4-byte aligned
  let tetrahedra = null;
  if (p.tetrahedra !== undefined) {
    const a = ArrayItem.Get(`${context}/tetrahedra`, json.accessors, p.tetrahedra);
    tetrahedra = await loader._loadIndicesAccessorAsync(`/accessors/${a.index}`, a);
  }
  return probeSet(json, { positions, sh, tetrahedra });
}

// The probes lmbake-babylon read with a bake (on its root mesh's metadata), or null
export function lmbakeProbes(root) {
  return (root && root.metadata && root.metadata.lmbake && root.metadata.lmbake.probes) || null;
}

// The glTF frame of a loaded bake: scene -> glTF for points (the root's inverse world matrix)
// and the rotation part R (columns normalised) with n_glTF = R n_scene for directions.
function gltfFrame(root) {
  const toGltf = root ? Matrix.Invert(root.computeWorldMatrix(true)) : Matrix.Identity();
  const m = toGltf.m, R = [[0, 0, 0], [0, 0, 0], [0, 0, 0]];
  for (let col = 0; col < 3; col++) { // Babylon's matrices are row-vector: row `col` maps the scene's axis `col`
    const len = Math.hypot(m[4 * col], m[4 * col + 1], m[4 * col + 2]) || 1;
    for (let row = 0; row < 3; row++) R[row][col] = m[4 * col + row] / len;
  }
  return { toGltf, R };
}

// Babylon's SphericalPolynomial for the probes' light at a point of the scene (a Vector3 in the
// scene's frame; root: the bake's root mesh, result.meshes[0]): at a unit normal n of the scene,
// x nx + y ny + z nz + xx nx^2 + yy ny^2 + zz nz^2 + xy nx ny + yz ny nz + zx nz nx = E(n) / pi.
export function sphericalPolynomialAt(probes, point, root) {
  const { toGltf, R } = gltfFrame(root);
  const p = Vector3.TransformCoordinates(point, toGltf);
  const { sh } = interpolateSH(probes, [p.x, p.y, p.z]);
  const rows = Array.from({ length: 9 }, () => [0, 0, 0]); // x, y, z, xx, yy, zz, yz, zx, xy
  shQuadratic(sh).forEach(({ c0, b, A }, c) => {
    // in the scene's frame: b' = R^T b, A' = R^T A R; the constant folded into the squares (|n| = 1)
    const bs = [0, 1, 2].map((i) => R[0][i] * b[0] + R[1][i] * b[1] + R[2][i] * b[2]);
    const As = [0, 1, 2].map((i) => [0, 1, 2].map((j) => {
      let s = 0;
      for (let k = 0; k < 3; k++) for (let l = 0; l < 3; l++) s += R[k][i] * A[k][l] * R[l][j];
      return s;
    }));
    const v = [bs[0], bs[1], bs[2], As[0][0] + c0, As[1][1] + c0, As[2][2] + c0, 2 * As[1][2], 2 * As[2][0], 2 * As[0][1]];
    v.forEach((x, k) => { rows[k][c] = x / Math.PI; });
  });
  const poly = SphericalPolynomial.FromArray(rows);
  // Babylon's shaders evaluate either the polynomial or, with SPHERICAL_HARMONICS, the
  // polynomial's harmonics (preScaledHarmonics, made from _harmonics when set): the same
  // function in Babylon's SH basis, given here exactly (its own FromPolynomial assumes the
  // polynomial came from radiance harmonics and would not give it back).
  poly._harmonics = harmonicsOf(rows);
  return poly;
}

// The SH L2 coefficients, in Babylon's basis (SphericalHarmonics: Y_lm = c_lm x (1, -y, z, -x,
// xy, -yz, 3z^2 - 1, -xz, x^2 - y^2)), of the function a polynomial's rows (x, y, z, xx, yy, zz,
// yz, zx, xy) take on the unit sphere: with x^2 + y^2 + z^2 = 1 the squares are
// a + b (x^2 - y^2) + g (3 z^2 - 1), a = (xx + yy + zz) / 3, b = (xx - yy) / 2, g = (2 zz - xx - yy) / 6.
function harmonicsOf(rows) {
  const k = (a) => Math.sqrt(a / Math.PI), [c0, c1, c2, c3, c4] = [k(1 / 4), k(3 / 4), k(15 / 4), k(5 / 16), k(15 / 16)];
  const [x, y, z, xx, yy, zz, yz, zx, xy] = rows;
  const l = [0, 1, 2].map((c) => [
    (xx[c] + yy[c] + zz[c]) / 3 / c0, -y[c] / c1, z[c] / c1, -x[c] / c1, xy[c] / c2, -yz[c] / c2,
    (2 * zz[c] - xx[c] - yy[c]) / 6 / c3, -zx[c] / c2, (xx[c] - yy[c]) / 2 / c4]);
  return SphericalHarmonics.FromArray([0, 1, 2, 3, 4, 5, 6, 7, 8].map((i) => [l[0][i], l[1][i], l[2][i]]));
}

// A reflection texture that lights a PBR material as the probes do at a point: a black 1 x 1
// cube carrying sphericalPolynomialAt's polynomial.
export function probeLightTexture(probes, point, root, scene) {
  const black = new Uint8Array(4);
  const tex = new RawCubeTexture(scene, [black, black, black, black, black, black], 1);
  tex.name = 'lmbake probe light';
  tex.sphericalPolynomial = sphericalPolynomialAt(probes, point, root);
  return tex;
}

// Lights mesh (a PBR material) by the probes at its bounding box's centre: its material is
// cloned (other meshes sharing it keep theirs) and given probeLightTexture as its reflection
// texture, evaluated per pixel. Returns the texture (call again when the mesh moves).
export function applyProbeLight(mesh, probes, root) {
  const centre = mesh.getBoundingInfo().boundingBox.centerWorld;
  const scene = mesh.getScene();
  const tex = probeLightTexture(probes, centre, root, scene);
  if (!mesh.material || mesh.material.reflectionTexture === undefined) throw new Error(`lmbake-babylon: mesh '${mesh.name}' has no PBR material to light by probes`);
  if (!mesh.metadata || !mesh.metadata.lmbakeProbeMaterial) {
    mesh.material = mesh.material.clone(`${mesh.material.name} (probe-lit)`);
    mesh.metadata = { ...(mesh.metadata || {}), lmbakeProbeMaterial: true };
  }
  if (mesh.material.reflectionTexture) mesh.material.reflectionTexture.dispose();
  mesh.material.reflectionTexture = tex;
  // per pixel: Babylon evaluates the polynomial per vertex by default, off by up to 2% between
  // the vertices of a 32-segment sphere
  mesh.material.forceIrradianceInFragment = true;
  return tex;
}
