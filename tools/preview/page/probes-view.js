// Light probes in the preview (docs/probes.md): a diffuse sphere the artist moves through the
// level, lit by the probes interpolated at its centre, and the probes themselves as small
// spheres. The probes come from the bake's glTF (asset.extras.lightmap.probes: positions, SH L2
// irradiance). The sphere's shader evaluates the interpolated irradiance SH at each normal and
// shows albedo / pi x E, the same light a lightmapped surface shows; it gets no other light,
// and nothing else gets the probes' light. Reading the probes is lmbake's three.js module's
// (loaders/three/lmbake-probes.js), interpolating them lmbake-probes' (loaders/probes), which
// engine projects use too.
import * as THREE from 'three';
import { loadProbes, findTetrahedron, interpolateSH, shIrradiance } from '/loaders/three/lmbake-probes.js';

export { loadProbes, findTetrahedron, interpolateSH, shIrradiance };

// E(n) from an irradiance SH in GLSL (lmbake-probes' basis, loaders/probes/probe-field.js), for the materials below.
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
