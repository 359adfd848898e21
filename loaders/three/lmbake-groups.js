// lmbake-three's light groups (docs/light-groups.md): a bake with output.light_groups writes each
// group's lightmap beside the level's, which is their sum at the groups' scales times their
// intensities (RGB: a group of one light holds its light at intensity 1 and names the light's
// intensity x colour; other groups 1 1 1). lightGroups() reads each group's lightmap per atlas
// (its .ktx2 where the atlas itself came from its KTX2 and the glTF names one, on the GPU as the
// file holds it: BC6H 1 byte per texel; else its .hdr as half floats, 8 bytes per texel) and
// patches the lightmapped materials so that where three's lightMap read the bake's sum they read
// sum_g w_g x intensity_g x group_g, with one weight per group that the game sets at run time
// (day and night, lamps on and off, a flickering torch): setWeight(name, w). lmbake's preview
// draws its sliders with the two steps below it (loadLightGroups, patchLightGroups).
import * as THREE from 'three';
import { HDRLoader } from 'three/addons/loaders/HDRLoader.js';
import { addShaderPatch } from './lmbake-three.js';

// Sampled as the lightmap plugin samples its textures: bilinear, no mipmaps, clamped, linear, not
// flipped (glTF UVs have v down, row 0 on top)
function asLightmap(tex, name) {
  Object.assign(tex, { colorSpace: THREE.LinearSRGBColorSpace, flipY: false, magFilter: THREE.LinearFilter,
    minFilter: THREE.LinearFilter, generateMipmaps: false, wrapS: THREE.ClampToEdgeWrapping, wrapT: THREE.ClampToEdgeWrapping, name });
  tex.needsUpdate = true;
  return tex;
}

// A group's .hdr as half floats
async function hdrTexture(url) {
  const res = await fetch(url);
  if (!res.ok) throw new Error(`light group lightmap ${url}: HTTP ${res.status}`);
  const { width, height, data } = new HDRLoader().setDataType(THREE.FloatType).parse(await res.arrayBuffer());
  const half = new Uint16Array(data.length);
  for (let i = 0; i < data.length; i++) half[i] = THREE.DataUtils.toHalfFloat(data[i]);
  return asLightmap(new THREE.DataTexture(half, width, height, THREE.RGBAFormat, THREE.HalfFloatType), url.pathname);
}

// Group g's lightmap of atlas a: its .ktx2 when the atlas was read from its own KTX2 (the
// format the GPU was found to sample) and the glTF names one, else its .hdr. Returns
// {texture, source: 'ktx2' | 'hdr', format}.
async function groupTexture(a, g, base) {
  if (a.source === 'ktx2' && a.readKtx2 && g.files.ktx2) {
    const d = await a.readKtx2(g.files.ktx2);
    return { texture: asLightmap(d.texture, g.files.ktx2), source: 'ktx2', format: d.format };
  }
  return { texture: await hdrTexture(new URL(g.files.hdr, base)), source: 'hdr', format: 'RGBE (HDRLoader)' };
}

// The groups every atlas's texture names in extras.lightmap.groups, or null (no groups): names,
// the bake's scales, weights (one uniform each, shared by every patched material), intensities
// (one vec3 uniform each), per atlas the groups' textures and where each came from
// (sources[atlas][g]: 'ktx2' or 'hdr').
export async function loadLightGroups(json, gltfUrl, atlases) {
  let names = null, scales = null, intensities = null;
  const perAtlas = [], sources = [];
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
    const read = await Promise.all(groups.map((g) => groupTexture(a, g, new URL(gltfUrl, location.href))));
    perAtlas[a.index] = read.map((r) => r.texture);
    sources[a.index] = read.map((r) => r.source);
  }
  if (!names) return null;
  return { names, scales, weights: scales.map((s) => ({ value: s })), intensities: intensities.map((v) => ({ value: v })), perAtlas, sources };
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
