// Light groups in the preview (docs/light-groups.md): a bake with output.light_groups writes each
// group's lightmap beside the level's, which is their sum at the groups' scales. Here each group's
// .hdr is read per atlas and the lightmapped materials (lit and lightmap views) get a shader patch
// that reads sum_g w_g x group_g where three's lightMap read the bake's sum; the page's sliders
// (and lmbSet({groups})) set the w_g, starting at the bake's scales: the sum a game draws.
import * as THREE from 'three';
import { HDRLoader } from 'three/addons/loaders/HDRLoader.js';
import { addShaderPatch } from '/loaders/three/lmbake-three.js';

// A group's .hdr as the lightmap plugin makes its textures: half floats, bilinear, no mipmaps,
// clamped, linear, not flipped (glTF UVs have v down, row 0 on top)
async function groupTexture(url) {
  const res = await fetch(url);
  if (!res.ok) throw new Error(`light group lightmap ${url}: HTTP ${res.status}`);
  const { width, height, data } = new HDRLoader().setDataType(THREE.FloatType).parse(await res.arrayBuffer());
  const half = new Uint16Array(data.length);
  for (let i = 0; i < data.length; i++) half[i] = THREE.DataUtils.toHalfFloat(data[i]);
  const tex = new THREE.DataTexture(half, width, height, THREE.RGBAFormat, THREE.HalfFloatType);
  Object.assign(tex, { colorSpace: THREE.LinearSRGBColorSpace, flipY: false, magFilter: THREE.LinearFilter,
    minFilter: THREE.LinearFilter, generateMipmaps: false, wrapS: THREE.ClampToEdgeWrapping, wrapT: THREE.ClampToEdgeWrapping });
  tex.needsUpdate = true;
  return tex;
}

// The groups every atlas's texture names in extras.lightmap.groups, or null (no groups): names,
// the bake's scales, weights (one uniform each, shared by every patched material) and per atlas
// the groups' textures.
export async function loadLightGroups(json, gltfUrl, atlases) {
  let names = null, scales = null;
  const perAtlas = [];
  for (const a of atlases) {
    if (!a) continue;
    const lm = json.textures && json.textures[a.textureIndex] && json.textures[a.textureIndex].extras
      ? json.textures[a.textureIndex].extras.lightmap : null;
    const groups = lm && Array.isArray(lm.groups) && lm.groups.length ? lm.groups : null;
    if (!groups) return null;
    const these = groups.map((g) => g.name);
    if (!names) { names = these; scales = groups.map((g) => Number(g.scale)); }
    else if (these.join('\n') !== names.join('\n')) throw new Error(`atlas ${a.index} names light groups ${these} where atlas 0 names ${names}`);
    perAtlas[a.index] = await Promise.all(groups.map((g) => groupTexture(new URL(g.files.hdr, new URL(gltfUrl, location.href)))));
  }
  if (!names) return null;
  return { names, scales, weights: scales.map((s) => ({ value: s })), perAtlas };
}

// The material reads its lightMap as sum_g w_g x group_g of its atlas (three's MeshStandardMaterial
// through lights_fragment_maps, MeshBasicMaterial in its own shader: both sample
// `texture2D( lightMap, vLightMapUv )`); returns it.
export function patchLightGroups(material, groups, atlas) {
  const tex = groups && groups.perAtlas[atlas];
  if (!tex) return material;
  const n = tex.length;
  return addShaderPatch(material, `lmbake-groups-${n}`, (shader) => {
    for (let g = 0; g < n; g++) {
      shader.uniforms[`lmbGroup${g}`] = { value: tex[g] };
      shader.uniforms[`lmbGroupWeight${g}`] = groups.weights[g];
    }
    const decl = Array.from({ length: n }, (_, g) => `uniform sampler2D lmbGroup${g};\nuniform float lmbGroupWeight${g};`).join('\n');
    const sum = Array.from({ length: n }, (_, g) => `lmbGroupWeight${g} * texture2D( lmbGroup${g}, uv ).rgb`).join(' + ');
    let fs = shader.fragmentShader.replace('#include <lights_fragment_maps>', THREE.ShaderChunk.lights_fragment_maps);
    if (!fs.includes('texture2D( lightMap, vLightMapUv )')) throw new Error('light groups: no lightMap lookup to patch in this material');
    fs = fs.split('texture2D( lightMap, vLightMapUv )').join('lmbGroupsSample( vLightMapUv )');
    shader.fragmentShader = `${decl}\nvec4 lmbGroupsSample( vec2 uv ) { return vec4( ${sum}, 1.0 ); }\n${fs}`;
  });
}
