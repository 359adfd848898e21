// lmbake-three's light groups (docs/light-groups.md): a bake with output.light_groups writes each
// group's lightmap beside the level's, which is their sum at the groups' scales times their
// intensities (RGB: a group of one light holds its light at intensity 1 and names the light's
// intensity x colour; other groups 1 1 1). lightGroups() reads each group's .hdr per atlas and
// patches the lightmapped materials so that where three's lightMap read the bake's sum they read
// sum_g w_g x intensity_g x group_g, with one weight per group that the game sets at run time
// (day and night, lamps on and off, a flickering torch): setWeight(name, w). lmbake's preview
// draws its sliders with the two steps below it (loadLightGroups, patchLightGroups).
import * as THREE from 'three';
import { HDRLoader } from 'three/addons/loaders/HDRLoader.js';
import { addShaderPatch } from './lmbake-three.js';

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
// the bake's scales, weights (one uniform each, shared by every patched material), intensities
// (one vec3 uniform each) and per atlas the groups' textures.
export async function loadLightGroups(json, gltfUrl, atlases) {
  let names = null, scales = null, intensities = null;
  const perAtlas = [];
  for (const a of atlases) {
    if (!a) continue;
    const lm = json.textures && json.textures[a.textureIndex] && json.textures[a.textureIndex].extras
      ? json.textures[a.textureIndex].extras.lightmap : null;
    const groups = lm && Array.isArray(lm.groups) && lm.groups.length ? lm.groups : null;
    if (!groups) return null;
    const these = groups.map((g) => g.name);
    if (!names) {
      names = these;
      scales = groups.map((g) => Number(g.scale));
      intensities = groups.map((g) => new THREE.Vector3(...(Array.isArray(g.intensity) && g.intensity.length === 3 ? g.intensity.map(Number) : [1, 1, 1])));
    }
    else if (these.join('\n') !== names.join('\n')) throw new Error(`atlas ${a.index} names light groups ${these} where atlas 0 names ${names}`);
    perAtlas[a.index] = await Promise.all(groups.map((g) => groupTexture(new URL(g.files.hdr, new URL(gltfUrl, location.href)))));
  }
  if (!names) return null;
  return { names, scales, weights: scales.map((s) => ({ value: s })), intensities: intensities.map((v) => ({ value: v })), perAtlas };
}

// The material reads its lightMap as sum_g w_g x intensity_g x group_g of its atlas (three's MeshStandardMaterial
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
      shader.uniforms[`lmbGroupIntensity${g}`] = groups.intensities[g];
    }
    const decl = Array.from({ length: n }, (_, g) => `uniform sampler2D lmbGroup${g};\nuniform float lmbGroupWeight${g};\nuniform vec3 lmbGroupIntensity${g};`).join('\n');
    const sum = Array.from({ length: n }, (_, g) => `lmbGroupWeight${g} * lmbGroupIntensity${g} * texture2D( lmbGroup${g}, uv ).rgb`).join(' + ');
    let fs = shader.fragmentShader.replace('#include <lights_fragment_maps>', THREE.ShaderChunk.lights_fragment_maps);
    if (!fs.includes('texture2D( lightMap, vLightMapUv )')) throw new Error('light groups: no lightMap lookup to patch in this material');
    fs = fs.split('texture2D( lightMap, vLightMapUv )').join('lmbGroupsSample( vLightMapUv )');
    shader.fragmentShader = `${decl}\nvec4 lmbGroupsSample( vec2 uv ) { return vec4( ${sum}, 1.0 ); }\n${fs}`;
  });
}

// The groups of a bake loaded with lmbakeLightmaps({ atlases }) (gltfUrl: where it was loaded
// from), every lightmapped material of gltf.scene patched; null when the bake has no groups.
// weights start at the bake's scales; setWeight(group name or index, w) changes one at once.
export async function lightGroups(gltf, gltfUrl, atlases) {
  const groups = await loadLightGroups(gltf.parser.json, gltfUrl, atlases);
  if (!groups) return null;
  const done = new Set();
  gltf.scene.traverse((o) => {
    if (!o.isMesh) return;
    for (const m of Array.isArray(o.material) ? o.material : [o.material]) {
      const atlas = m && m.lightMap && m.lightMap.userData ? m.lightMap.userData.atlas : undefined;
      if (atlas === undefined || done.has(m)) continue;
      done.add(m);
      patchLightGroups(m, groups, atlas);
    }
  });
  groups.setWeight = (g, w) => {
    const k = typeof g === 'number' ? g : groups.names.indexOf(g);
    if (!(k >= 0 && k < groups.names.length)) throw new Error(`no light group ${g} (${groups.names.join(', ')})`);
    groups.weights[k].value = w;
  };
  return groups;
}
