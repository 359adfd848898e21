// Materials of the view modes other than `lit`, and the de-indexed geometry the checker needs
// (barycentrics, chart-boundary edge flags, a tint per chart).
//   lightmap: colour = E x intensity / pi x 2^EV, then tone mapping, then sRGB (three's
//             MeshBasicMaterial with a white colour does exactly E x intensity / pi; the
//             renderer applies 2^EV = toneMappingExposure and the tone mapping).
//   invalid:  the lightmap view, with texels whose stored irradiance is exactly 0 in magenta.
//   checker:  a texel checkerboard of the UV1 atlas (tinted per chart, darker every other 8x8
//             block), texel grid lines when zoomed in, chart borders in red-orange.
// The invalid and checker views read the atlas at uv1 x scale + offset, the mesh's lightmap
// rectangle (MOZ_lightmap's KHR_texture_transform or the node's extras.lightmap.scaleOffset;
// lmbake-three.js lightmapScaleOffset), as three's lightMap does for the lightmap and lit
// views. On an InstancedMesh with per-instance rectangles ({instanced: true}) each copy reads
// uv1 x scale_k + offset_k first (lmbake-three.js INSTANCE_RECT_ATTRIBUTES), and every
// copy is placed by its instance matrix.
import * as THREE from 'three';
import { INSTANCE_RECT_ATTRIBUTES } from '/loaders/three/lmbake-three.js';

export const INVALID_COLOR = new THREE.Color(1, 0, 1);       // magenta, linear = sRGB
export const BORDER_COLOR = new THREE.Color(1, 0.1, 0.0);    // linear; sRGB (255, 89, 0)

const [I_SCALE, I_OFFSET] = INSTANCE_RECT_ATTRIBUTES;
const VERT = /* glsl */`
uniform vec4 uvScaleOffset; // the lightmap rectangle: atlas uv = uv1 * xy + zw
varying vec2 vUv1;
#if defined( INSTANCE_RECT ) && defined( USE_INSTANCING )
attribute vec2 ${I_SCALE};  // the copy's own rectangle (per instance)
attribute vec2 ${I_OFFSET};
#endif
#ifdef CHECKER
attribute vec3 bary;
attribute vec3 edge;
attribute vec3 tint;
varying vec3 vBary;
varying vec3 vEdge;
varying vec3 vTint;
#endif
void main() {
  vec2 uv = uv1;
#if defined( INSTANCE_RECT ) && defined( USE_INSTANCING )
  uv = uv * ${I_SCALE} + ${I_OFFSET};
#endif
  vUv1 = uv * uvScaleOffset.xy + uvScaleOffset.zw;
#ifdef CHECKER
  vBary = bary; vEdge = edge; vTint = tint;
#endif
  vec4 p = vec4(position, 1.0);
#ifdef USE_INSTANCING
  p = instanceMatrix * p; // an InstancedMesh's copy
#endif
  gl_Position = projectionMatrix * modelViewMatrix * p;
}`;

// ATLAS_NEAREST: the 2D atlas view reads the texel itself (texelFetch), no filtering.
const INVALID_FRAG = /* glsl */`
uniform sampler2D lightMap;
uniform sampler2D invalidMask;
uniform float intensity;
uniform vec2 atlasSize;
uniform bool showInvalid;
varying vec2 vUv1;
void main() {
  ivec2 texel = ivec2(clamp(floor(vUv1 * atlasSize), vec2(0.0), atlasSize - 1.0));
#ifdef ATLAS_NEAREST
  vec3 e = texelFetch(lightMap, texel, 0).rgb;
#else
  vec3 e = texture2D(lightMap, vUv1).rgb;
#endif
  gl_FragColor = vec4(e * intensity * 0.3183098861837907, 1.0); // E / pi
  #include <tonemapping_fragment>
  if (showInvalid && texelFetch(invalidMask, texel, 0).r > 0.5) gl_FragColor.rgb = vec3(1.0, 0.0, 1.0);
  #include <colorspace_fragment>
}`;

const CHECKER_FRAG = /* glsl */`
uniform vec2 atlasSize;
uniform vec3 borderColor;
varying vec2 vUv1;
varying vec3 vBary;
varying vec3 vEdge;
varying vec3 vTint;
void main() {
  vec2 t = vUv1 * atlasSize;                 // texel coordinates, x right, y down the image
  vec2 cell = floor(t);
  bool odd = mod(cell.x + cell.y, 2.0) > 0.5;
  vec3 c = vTint * (odd ? 0.30 : 0.80);
  vec2 block = floor(cell / 8.0);            // 8 x 8 texel blocks: density visible from afar
  if (mod(block.x + block.y, 2.0) > 0.5) c *= 0.8;
  vec2 tpp = fwidth(t);                      // texels per pixel
  vec2 distPx = fract(t) / max(tpp, vec2(1e-6)); // pixels past the texel's top-left edge
  if (max(tpp.x, tpp.y) < 0.25 && min(distPx.x, distPx.y) < 1.0) c *= 0.4; // texel grid, 1 px
  vec3 d = vBary / max(fwidth(vBary), vec3(1e-6)); // distance to each edge, in pixels
  float db = 1e9;
  if (vEdge.x > 0.5) db = min(db, d.x);
  if (vEdge.y > 0.5) db = min(db, d.y);
  if (vEdge.z > 0.5) db = min(db, d.z);
  if (db < 1.5) c = borderColor;             // chart border
  gl_FragColor = vec4(c, 1.0);
  #include <colorspace_fragment>
}`;

export function lightmapMaterial(tex, intensity) {
  return new THREE.MeshBasicMaterial({ color: 0xffffff, lightMap: tex, lightMapIntensity: intensity, side: THREE.FrontSide });
}

// scaleOffset: [scaleU, scaleV, offsetU, offsetV], the mesh's lightmap rectangle in the atlas;
// instanced: an InstancedMesh with per-instance rectangles (applied before scaleOffset)
export function invalidMaterial(atlas, intensity, { nearest = false, showInvalid = true, scaleOffset = [1, 1, 0, 0], instanced = false } = {}) {
  const defines = { USE_UV1: '' };
  if (nearest) defines.ATLAS_NEAREST = '';
  if (instanced) defines.INSTANCE_RECT = '';
  return new THREE.ShaderMaterial({
    defines,
    uniforms: {
      lightMap: { value: atlas.texture }, invalidMask: { value: atlas.maskTexture },
      intensity: { value: intensity }, atlasSize: { value: new THREE.Vector2(atlas.width, atlas.height) },
      showInvalid: { value: showInvalid }, uvScaleOffset: { value: new THREE.Vector4(...scaleOffset) },
    },
    vertexShader: VERT, fragmentShader: INVALID_FRAG,
  });
}

export function checkerMaterial(atlas, scaleOffset = [1, 1, 0, 0], { instanced = false } = {}) {
  return new THREE.ShaderMaterial({
    defines: instanced ? { USE_UV1: '', CHECKER: '', INSTANCE_RECT: '' } : { USE_UV1: '', CHECKER: '' },
    uniforms: {
      atlasSize: { value: new THREE.Vector2(atlas.width, atlas.height) }, borderColor: { value: BORDER_COLOR },
      uvScaleOffset: { value: new THREE.Vector4(...scaleOffset) },
    },
    vertexShader: VERT, fragmentShader: CHECKER_FRAG, toneMapped: false, side: THREE.DoubleSide,
  });
}

// Non-indexed copy of a geometry with uv1, plus the checker attributes. Corners are welded
// by (position, uv1) value (lmbake writes every corner as its own vertex); an edge is a chart
// border when only one triangle uses it, and charts are the connected components. Per-instance
// attributes (an InstancedMesh's) are carried over as they are.
export function checkerGeometry(source, firstChart = 0) {
  const perInstance = Object.entries(source.attributes).filter(([, a]) => a.isInstancedBufferAttribute);
  let geom = source;
  if (perInstance.length) { // toNonIndexed() would expand them per vertex
    geom = new THREE.BufferGeometry();
    for (const [k, a] of Object.entries(source.attributes)) if (!a.isInstancedBufferAttribute) geom.setAttribute(k, a);
    if (source.index) geom.setIndex(source.index);
  }
  const pos = geom.attributes.position, uv = geom.attributes.uv1;
  const n = pos.count;
  const raw = geom.index ? Array.from(geom.index.array) : Array.from({ length: n }, (_, i) => i);
  const weld = new Map(), id = new Int32Array(n);
  for (let i = 0; i < n; i++) {
    const k = [pos.getX(i), pos.getY(i), pos.getZ(i), uv.getX(i), uv.getY(i)].map((v) => Math.round(v * 1e6)).join(',');
    if (!weld.has(k)) weld.set(k, weld.size);
    id[i] = weld.get(k);
  }
  const index = raw.map((i) => id[i]);
  const w = weld.size;
  const edgeUse = new Map();
  const key = (a, b) => (a < b ? a * w + b : b * w + a);
  for (let t = 0; t < index.length; t += 3) {
    for (let k = 0; k < 3; k++) {
      const e = key(index[t + k], index[t + (k + 1) % 3]);
      edgeUse.set(e, (edgeUse.get(e) || 0) + 1);
    }
  }
  const parent = Int32Array.from({ length: w }, (_, i) => i);
  const find = (x) => { while (parent[x] !== x) x = parent[x] = parent[parent[x]]; return x; };
  for (let t = 0; t < index.length; t += 3) {
    parent[find(index[t + 1])] = find(index[t]);
    parent[find(index[t + 2])] = find(index[t]);
  }
  const chartOf = new Map();
  const out = geom.index ? geom.toNonIndexed() : geom.clone();
  const m = index.length;
  const bary = new Float32Array(m * 3), edge = new Float32Array(m * 3), tint = new Float32Array(m * 3);
  const col = new THREE.Color();
  for (let t = 0; t < m; t += 3) {
    const root = find(index[t]);
    if (!chartOf.has(root)) chartOf.set(root, chartOf.size);
    col.setHSL(((firstChart + chartOf.get(root)) * 0.618034 + 0.25) % 1, 0.55, 0.72, THREE.SRGBColorSpace);
    // edge opposite vertex k joins vertices k+1 and k+2
    const flags = [0, 1, 2].map((k) => (edgeUse.get(key(index[t + (k + 1) % 3], index[t + (k + 2) % 3])) === 1 ? 1 : 0));
    for (let k = 0; k < 3; k++) {
      const o = 3 * (t + k);
      bary[o + k] = 1;
      edge.set(flags, o);
      tint[o] = col.r; tint[o + 1] = col.g; tint[o + 2] = col.b;
    }
  }
  out.setAttribute('bary', new THREE.BufferAttribute(bary, 3));
  out.setAttribute('edge', new THREE.BufferAttribute(edge, 3));
  out.setAttribute('tint', new THREE.BufferAttribute(tint, 3));
  for (const [k, a] of perInstance) out.setAttribute(k, a);
  out.userData.charts = chartOf.size;
  return out;
}

// The same triangles laid out flat in the atlas: x = u * width, y = -v * height (texel units),
// (u, v) = uv1 x scale + offset (the mesh's lightmap rectangle); uv1 becomes (u, v) too, so the
// checker material draws it with the identity rectangle. rects: one [su, sv, ou, ov] or a list
// of them (an InstancedMesh's copies: the triangles once per copy, at its rectangle).
export function atlasLayoutGeometry(checkerGeom, atlas, rects = [1, 1, 0, 0]) {
  const list = Array.isArray(rects[0]) ? rects : [rects];
  const n = checkerGeom.attributes.uv1.count, copies = list.length;
  const g = new THREE.BufferGeometry();
  for (const k of ['bary', 'edge', 'tint']) { // checkerGeometry's own (plain Float32Arrays), repeated per copy
    const a = checkerGeom.attributes[k], src = a.array, arr = new Float32Array(src.length * copies);
    for (let c = 0; c < copies; c++) arr.set(src, c * src.length);
    g.setAttribute(k, new THREE.BufferAttribute(arr, a.itemSize));
  }
  const uv = checkerGeom.attributes.uv1;
  const pos = new Float32Array(n * copies * 3), auv = new Float32Array(n * copies * 2);
  list.forEach(([su, sv, ou, ov], c) => {
    for (let i = 0; i < n; i++) {
      const j = c * n + i;
      auv[2 * j] = uv.getX(i) * su + ou;
      auv[2 * j + 1] = uv.getY(i) * sv + ov;
      pos[3 * j] = auv[2 * j] * atlas.width;
      pos[3 * j + 1] = -auv[2 * j + 1] * atlas.height;
    }
  });
  g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
  g.setAttribute('uv1', new THREE.BufferAttribute(auv, 2));
  return g;
}
