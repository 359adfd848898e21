// GLTFLoader plugin for lmbake's lightmaps: MOZ_lightmap on materials ({index, texCoord,
// intensity} -> material.lightMap / lightMapIntensity) and MOZ_texture_rgbe on textures
// (a Radiance .hdr holding linear irradiance E in lux, read with three's HDRLoader).
// Every lightmap becomes an "atlas" record in `atlases`, with its float data kept for the
// CPU (hover values, invalid-texel mask).
import * as THREE from 'three';
import { HDRLoader } from 'three/addons/loaders/HDRLoader.js';

// Returns a function to pass to GLTFLoader.register(); `atlases` is filled while loading.
export function lightmapPlugin(atlases) {
  return (parser) => new LightmapPlugin(parser, atlases);
}

class LightmapPlugin {
  constructor(parser, atlases) {
    this.parser = parser;
    this.atlases = atlases;
    this.name = 'MOZ_lightmap';
    this.byTexture = new Map(); // texture index -> Promise<THREE.Texture>
    // Atlas numbers follow the lightmap texture indices in increasing order (not load order)
    const used = new Set();
    for (const m of parser.json.materials || []) if (m.extensions && m.extensions.MOZ_lightmap) used.add(m.extensions.MOZ_lightmap.index);
    this.order = [...used].sort((a, b) => a - b);
  }

  extendMaterialParams(materialIndex, params) {
    const def = this.parser.json.materials[materialIndex];
    const ext = def.extensions && def.extensions.MOZ_lightmap;
    if (!ext) return null;
    return this.lightmapTexture(ext.index).then((tex) => {
      if (!tex) return;
      tex.channel = ext.texCoord ?? 1; // TEXCOORD_1 is three's uv1: channel 1
      params.lightMap = tex;
      params.lightMapIntensity = ext.intensity ?? 1;
    });
  }

  lightmapTexture(textureIndex) {
    if (!this.byTexture.has(textureIndex)) this.byTexture.set(textureIndex, this.loadLightmap(textureIndex));
    return this.byTexture.get(textureIndex);
  }

  async loadLightmap(textureIndex) {
    const json = this.parser.json;
    const texDef = json.textures[textureIndex];
    if (!texDef) throw new Error(`MOZ_lightmap: texture ${textureIndex} does not exist`);
    const rgbe = texDef.extensions && texDef.extensions.MOZ_texture_rgbe;
    if (!rgbe) {
      // Only the tonemapped PNG: shown, but it is not irradiance; values are meaningless.
      console.warn(`MOZ_lightmap: texture ${textureIndex} has no MOZ_texture_rgbe .hdr; showing its PNG (not linear irradiance)`);
      const tex = await this.parser.getDependency('texture', textureIndex);
      tex.colorSpace = THREE.SRGBColorSpace;
      return tex;
    }
    const img = json.images[rgbe.source];
    if (!img) throw new Error(`MOZ_texture_rgbe: image ${rgbe.source} does not exist`);
    let buffer, uri;
    if (img.bufferView !== undefined) {
      buffer = await this.parser.getDependency('bufferView', img.bufferView);
      uri = `bufferView ${img.bufferView}`;
    } else {
      uri = img.uri;
      const url = THREE.LoaderUtils.resolveURL(uri, this.parser.options.path);
      const res = await fetch(url);
      if (!res.ok) throw new Error(`lightmap ${uri}: HTTP ${res.status}`);
      buffer = await res.arrayBuffer();
    }
    const hdr = new HDRLoader().setDataType(THREE.FloatType).parse(buffer);
    const { width, height, data } = hdr; // RGBA float32, row 0 = top of the image
    // Upload as half float (always filterable in WebGL 2); glTF UVs have v down: no flip.
    const half = new Uint16Array(data.length);
    for (let i = 0; i < data.length; i++) half[i] = THREE.DataUtils.toHalfFloat(data[i]);
    const tex = new THREE.DataTexture(half, width, height, THREE.RGBAFormat, THREE.HalfFloatType);
    tex.colorSpace = THREE.LinearSRGBColorSpace;
    tex.flipY = false;
    tex.magFilter = THREE.LinearFilter;
    tex.minFilter = THREE.LinearFilter; // no mipmaps: they would blur across charts
    tex.generateMipmaps = false;
    tex.wrapS = tex.wrapT = THREE.ClampToEdgeWrapping;
    tex.name = uri;
    tex.needsUpdate = true;

    // Invalid texels: lmbake writes texels inside geometry as exactly 0 (RGBE exponent 0).
    const mask = new Uint8Array(width * height);
    let zero = 0;
    for (let i = 0; i < width * height; i++) {
      if (data[4 * i] === 0 && data[4 * i + 1] === 0 && data[4 * i + 2] === 0) { mask[i] = 255; zero++; }
    }
    const maskTex = new THREE.DataTexture(mask, width, height, THREE.RedFormat, THREE.UnsignedByteType);
    maskTex.flipY = false;
    maskTex.magFilter = maskTex.minFilter = THREE.NearestFilter;
    maskTex.needsUpdate = true;

    const atlas = { index: this.order.indexOf(textureIndex), textureIndex, uri, width, height, data, texture: tex, maskTexture: maskTex, zeroTexels: zero };
    this.atlases[atlas.index] = atlas;
    tex.userData.atlas = atlas.index;
    return tex;
  }
}

// Directional lightmaps (lmbake's output.directional; docs/artists.md): a
// material's extras.lightmap_directional names a PNG holding (D + 1) / 2, D the light's mean
// direction (world space). The lit view then shades with the material's normal map:
//   E(n') = E max(0, 1 + 1.5 D.n') / (1 + 1.5 D.n)
// n' the normal-mapped normal, n the interpolated vertex normal (three's nonPerturbedNormal),
// both in view space as is D after the view matrix. Returns how many materials use one.
export async function applyDirectionalLightmaps(gltf) {
  const materials = new Set();
  gltf.scene.traverse((o) => {
    if (!o.isMesh) return;
    for (const m of Array.isArray(o.material) ? o.material : [o.material]) if (m.userData && m.userData.lightmap_directional && m.lightMap) materials.add(m);
  });
  for (const m of materials) {
    const ref = m.userData.lightmap_directional;
    const tex = (await gltf.parser.getDependency('texture', ref.index)).clone();
    tex.channel = ref.texCoord ?? 1;
    tex.colorSpace = THREE.NoColorSpace; // data, not colour
    tex.flipY = false;
    tex.magFilter = THREE.LinearFilter;
    tex.minFilter = THREE.LinearFilter; // no mipmaps: they would blur across charts
    tex.generateMipmaps = false;
    tex.needsUpdate = true;
    m.onBeforeCompile = (shader) => {
      shader.uniforms.lightDirectionMap = { value: tex };
      shader.fragmentShader = 'uniform sampler2D lightDirectionMap;\n' + shader.fragmentShader.replace(
        '#include <lights_fragment_maps>',
        THREE.ShaderChunk.lights_fragment_maps.replace('vec3 lightMapIrradiance = lightMapTexel.rgb * lightMapIntensity;', `
    vec3 lightMapIrradiance = lightMapTexel.rgb * lightMapIntensity;
    vec3 lmDir = (viewMatrix * vec4(texture2D(lightDirectionMap, vLightMapUv).rgb * 2.0 - 1.0, 0.0)).xyz;
    lightMapIrradiance *= max(0.0, 1.0 + 1.5 * dot(lmDir, normal)) / max(1e-3, 1.0 + 1.5 * dot(lmDir, nonPerturbedNormal));`));
    };
    m.customProgramCacheKey = () => 'lmbake-directional';
    m.needsUpdate = true;
  }
  return materials.size;
}
