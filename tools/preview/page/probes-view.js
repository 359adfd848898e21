// Light probes in the preview (docs/probes.md): a diffuse sphere the artist moves through the
// level, lit by the probes interpolated at its centre, and the probes themselves as small
// spheres. The probes come from the bake's glTF (asset.extras.lightmap.probes: positions, SH L2
// irradiance). The sphere's shader evaluates the interpolated irradiance SH at each normal and
// shows albedo / pi x E, the same light a lightmapped surface shows; it gets no other light,
// and nothing else gets the probes' light.
// Interpolation: as Unity and Godot do, over the probes' tetrahedra (the bake's Delaunay
// tetrahedra): inside one, its four probes with the point's barycentric weights (a probe at the
// centre itself has weight 1, so a test can read one probe's light exactly). Outside them all
// (beyond the probes' hull: below the lowest layer of probes, near a wall): the tetrahedron the
// point is least outside (its smallest barycentric weight the largest), the weights clamped to
// >= 0 and renormalised, as Unity extrapolates from the hull: the probes of the point's own room
// (the nearest probes by distance may lie across a wall, docs/leaks.md). With no tetrahedra in
// the file: the 8 nearest probes weighted by 1 / d^2.
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

// E(n) from an irradiance SH in GLSL (the basis of SH_Y above), for the materials below.
const SH_GLSL = /* glsl */`
  vec3 shIrradiance(vec3 sh[9], vec3 n) {
    return sh[0] * 0.282095 + sh[1] * 0.488603 * n.y + sh[2] * 0.488603 * n.z + sh[3] * 0.488603 * n.x
      + sh[4] * 1.092548 * n.x * n.y + sh[5] * 1.092548 * n.y * n.z + sh[6] * 0.315392 * (3.0 * n.z * n.z - 1.0)
      + sh[7] * 1.092548 * n.x * n.z + sh[8] * 0.546274 * (n.x * n.x - n.y * n.y);
  }`;

// A material showing albedo / pi x E(n) for the SH in its uniform (tone-mapped like the level).
function shMaterial(albedo) {
  return new THREE.ShaderMaterial({
    uniforms: { sh: { value: Array.from({ length: 9 }, () => new THREE.Vector3()) }, albedo: { value: albedo } },
    vertexShader: `
      varying vec3 vNormal;
      void main() {
        vNormal = normalize(mat3(modelMatrix) * normal);
        gl_Position = projectionMatrix * viewMatrix * modelMatrix * vec4(position, 1.0);
      }`,
    fragmentShader: `
      uniform vec3 sh[9];
      uniform float albedo;
      varying vec3 vNormal;
      ${SH_GLSL}
      void main() {
        vec3 n = normalize(vNormal);
        gl_FragColor = vec4(max(shIrradiance(sh, n), vec3(0.0)) * albedo / 3.14159265358979, 1.0);
        #include <tonemapping_fragment>
        #include <colorspace_fragment>
      }`,
    toneMapped: true,
  });
}

export const SPHERE_ALBEDO = 0.8;

// The moving sphere and the probes' markers. radius: the sphere's, world units.
export class ProbesView {
  constructor(probes, radius) {
    this.probes = probes;
    this.material = shMaterial(SPHERE_ALBEDO);
    this.sphere = new THREE.Mesh(new THREE.SphereGeometry(radius, 48, 24), this.material);
    this.sphere.name = 'lmbake probe sphere';
    this.sphere.visible = false;
    const marker = new THREE.SphereGeometry(radius * 0.15, 8, 6);
    this.markers = new THREE.InstancedMesh(marker, new THREE.MeshBasicMaterial({ toneMapped: true }), probes.count);
    this.markers.name = 'lmbake probes';
    this.markers.visible = false;
    const m = new THREE.Matrix4(), c = new THREE.Color();
    for (let i = 0; i < probes.count; i++) {
      m.makeTranslation(probes.positions[3 * i], probes.positions[3 * i + 1], probes.positions[3 * i + 2]);
      this.markers.setMatrixAt(i, m);
      const e = 0.282095 / Math.PI * SPHERE_ALBEDO; // the mean irradiance's share: sh[0] x Y00 = mean E
      c.setRGB(probes.sh[27 * i] * e, probes.sh[27 * i + 1] * e, probes.sh[27 * i + 2] * e);
      this.markers.setColorAt(i, c);
    }
    this.at = null;
    this.used = [];
  }

  // Puts the sphere at x (world) and lights it from the probes there.
  moveTo(x) {
    const { sh, probes, how } = interpolateSH(this.probes, x);
    this.how = how;
    for (let k = 0; k < 9; k++) this.material.uniforms.sh.value[k].set(sh[3 * k], sh[3 * k + 1], sh[3 * k + 2]);
    this.sphere.position.set(x[0], x[1], x[2]);
    this.sphere.visible = true;
    this.at = x.slice();
    this.sh = sh;
    this.used = probes;
  }
}

// Meshes without a lightmap (props a bake lit by its probes, meshes the config excluded) in the
// lit and lightmap views, lit as an engine lights them: each copy by the probes interpolated at
// its centre (its bounding box's, in world space), showing albedo / pi x E(n) for the SH there
// (albedo 1 in the lightmap view, like the lightmaps' E / pi). An InstancedMesh's copies each read
// their own SH: 9 RGBA float texels per copy in a data texture, PER_ROW copies to a row, found by
// gl_InstanceID.
const PER_ROW = 64;

// The SH (27 floats) at each copy of mesh: {sh: Float32Array(27 x copies), centres, how: counts}.
export function probeLitCopies(probes, mesh) {
  const g = mesh.geometry;
  if (!g.boundingBox) g.computeBoundingBox();
  const centre = g.boundingBox.getCenter(new THREE.Vector3()), im = new THREE.Matrix4();
  const copies = mesh.isInstancedMesh ? mesh.count : 1;
  const sh = new Float32Array(27 * copies), centres = [], how = { tetrahedron: 0, nearest: 0 };
  mesh.updateWorldMatrix(true, false);
  for (let k = 0; k < copies; k++) {
    const c = centre.clone();
    if (mesh.isInstancedMesh) c.applyMatrix4(mesh.getMatrixAt(k, im));
    c.applyMatrix4(mesh.matrixWorld);
    const r = interpolateSH(probes, c.toArray());
    sh.set(r.sh, 27 * k);
    centres.push(c.toArray());
    how[r.how]++;
  }
  return { sh, centres, how, copies };
}

// The material for copies (probeLitCopies) with the given linear albedo (THREE.Color). normals:
// the geometry has a NORMAL attribute; without one (flat shading, glTF) the face normal comes
// from the world position's derivatives, as three's own flat shading does.
export function probeLitMaterial(copies, albedo, normals) {
  const rows = Math.ceil(copies.copies / PER_ROW), data = new Float32Array(9 * PER_ROW * rows * 4);
  for (let k = 0; k < copies.copies; k++)
    for (let j = 0; j < 9; j++) {
      const t = 4 * ((Math.floor(k / PER_ROW) * 9 * PER_ROW) + 9 * (k % PER_ROW) + j);
      data.set(copies.sh.subarray(27 * k + 3 * j, 27 * k + 3 * j + 3), t);
    }
  const tex = new THREE.DataTexture(data, 9 * PER_ROW, rows, THREE.RGBAFormat, THREE.FloatType);
  tex.needsUpdate = true;
  return new THREE.ShaderMaterial({
    name: 'lmbake probe-lit',
    defines: normals ? { LMB_VERTEX_NORMALS: 1 } : {},
    uniforms: { shTex: { value: tex }, albedo: { value: albedo.clone() } },
    vertexShader: `
      varying vec3 vWorld;
      varying vec3 vNormal;
      flat varying int vCopy;
      void main() {
        mat4 m = modelMatrix;
        vCopy = 0;
        #ifdef USE_INSTANCING
          m = modelMatrix * instanceMatrix;
          vCopy = gl_InstanceID;
        #endif
        #ifdef LMB_VERTEX_NORMALS
          vNormal = mat3(m) * normal;
        #else
          vNormal = vec3(0.0);
        #endif
        vec4 w = m * vec4(position, 1.0);
        vWorld = w.xyz;
        gl_Position = projectionMatrix * viewMatrix * w;
      }`,
    fragmentShader: `
      uniform highp sampler2D shTex;
      uniform vec3 albedo;
      varying vec3 vWorld;
      varying vec3 vNormal;
      flat varying int vCopy;
      ${SH_GLSL}
      void main() {
        #ifdef LMB_VERTEX_NORMALS
          vec3 n = normalize(vNormal) * (gl_FrontFacing ? 1.0 : -1.0);
        #else
          vec3 n = normalize(cross(dFdx(vWorld), dFdy(vWorld)));
        #endif
        ivec2 at = ivec2(9 * (vCopy % ${PER_ROW}), vCopy / ${PER_ROW});
        vec3 sh[9];
        for (int k = 0; k < 9; k++) sh[k] = texelFetch(shTex, at + ivec2(k, 0), 0).rgb;
        gl_FragColor = vec4(max(shIrradiance(sh, n), vec3(0.0)) * albedo / 3.14159265358979, 1.0);
        #include <tonemapping_fragment>
        #include <colorspace_fragment>
      }`,
    toneMapped: true,
  });
}
