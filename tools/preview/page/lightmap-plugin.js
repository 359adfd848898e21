// GLTFLoader plugin for lmbake's lightmaps: MOZ_lightmap on materials ({index, texCoord,
// intensity} -> material.lightMap / lightMapIntensity, its KHR_texture_transform -> the
// texture's offset / repeat) and, on the lightmap texture, either the KTX2 file its
// extras.lightmap.files.ktx2 names (read as three's KTX2Loader reads raw formats: ktx-parse and
// its Zstandard decoder) or MOZ_texture_rgbe (a Radiance .hdr read with three's HDRLoader),
// both holding linear irradiance E in lux (or E/pi with extras.lightmap.scale "radiance" and
// MOZ_lightmap.intensity pi). Every lightmap becomes an "atlas" record in `atlases`, with its
// float data kept for the CPU (hover values, invalid-texel mask).
import * as THREE from 'three';
import { HDRLoader } from 'three/addons/loaders/HDRLoader.js';
import { read as readKtx2, KHR_SUPERCOMPRESSION_NONE, KHR_SUPERCOMPRESSION_ZSTD } from 'three/addons/libs/ktx-parse.module.js';
import { ZSTDDecoder } from 'three/addons/libs/zstddec.module.js';

export const LIGHTMAP_SOURCES = ['ktx2', 'hdr'];
const VK_FORMATS = { 123: 'E5B9G9R9_UFLOAT_PACK32', 122: 'B10G11R11_UFLOAT_PACK32', 97: 'R16G16B16A16_SFLOAT' };

// Returns a function to pass to GLTFLoader.register(); `atlases` is filled while loading.
// source: 'ktx2' (the default: the KTX2 file when the glTF names one, else the .hdr) or 'hdr'.
export function lightmapPlugin(atlases, { source = 'ktx2' } = {}) {
  if (!LIGHTMAP_SOURCES.includes(source)) throw new Error(`unknown lightmap source '${source}' (one of ${LIGHTMAP_SOURCES.join(', ')})`);
  return (parser) => new LightmapPlugin(parser, atlases, source);
}

// The lightmap rectangle of a lightmap texture as [scaleU, scaleV, offsetU, offsetV]: the atlas
// is sampled at uv1 * scale + offset (glTF's KHR_texture_transform without rotation).
export function lightmapScaleOffset(tex) {
  return tex ? [tex.repeat.x, tex.repeat.y, tex.offset.x, tex.offset.y] : [1, 1, 0, 0];
}

class LightmapPlugin {
  constructor(parser, atlases, source) {
    this.parser = parser;
    this.atlases = atlases;
    this.source = source;
    this.name = 'MOZ_lightmap';
    this.byTexture = new Map(); // texture index -> Promise<THREE.Texture>
    this.byTransform = new Map(); // texture index + rectangle -> Promise<THREE.Texture> (a clone)
    // Atlas numbers: the textures' extras.lightmap.atlas when every lightmap texture has a
    // distinct one, else the lightmap texture indices in increasing order (not load order)
    const json = parser.json, used = new Set();
    for (const m of json.materials || []) if (m.extensions && m.extensions.MOZ_lightmap) used.add(m.extensions.MOZ_lightmap.index);
    this.order = [...used].sort((a, b) => a - b);
    const named = this.order.map((i) => { const x = lightmapExtras(json, i); return x && Number.isInteger(x.atlas) && x.atlas >= 0 ? x.atlas : -1; });
    this.atlasNumbers = !named.includes(-1) && new Set(named).size === named.length ? named : this.order.map((_, k) => k);
  }

  extendMaterialParams(materialIndex, params) {
    const def = this.parser.json.materials[materialIndex];
    const ext = def.extensions && def.extensions.MOZ_lightmap;
    if (!ext) return null;
    const tt = ext.extensions && ext.extensions.KHR_texture_transform;
    return (tt ? this.transformedTexture(ext.index, tt) : this.lightmapTexture(ext.index)).then((tex) => {
      if (!tex) return;
      tex.channel = (tt && tt.texCoord) ?? ext.texCoord ?? 1; // TEXCOORD_1 is three's uv1: channel 1
      params.lightMap = tex;
      params.lightMapIntensity = ext.intensity ?? 1;
    });
  }

  lightmapTexture(textureIndex) {
    if (!this.byTexture.has(textureIndex)) this.byTexture.set(textureIndex, this.loadLightmap(textureIndex));
    return this.byTexture.get(textureIndex);
  }

  // The lightmap texture with the rectangle of a KHR_texture_transform: a clone (it shares the
  // image and the GPU texture) with offset / repeat, which three's lightMap applies
  // (vLightMapUv = lightMapTransform x uv1; a directional lightmap reads the same vLightMapUv).
  transformedTexture(textureIndex, tt) {
    const offset = tt.offset || [0, 0], scale = tt.scale || [1, 1];
    if (tt.rotation) console.warn(`MOZ_lightmap: texture ${textureIndex}: KHR_texture_transform rotation ${tt.rotation} ignored (lmbake writes none)`);
    const key = `${textureIndex}:${scale}:${offset}`;
    if (!this.byTransform.has(key)) {
      this.byTransform.set(key, this.lightmapTexture(textureIndex).then((base) => {
        if (!base) return base;
        const tex = base.clone();
        tex.offset.fromArray(offset);
        tex.repeat.fromArray(scale);
        tex.updateMatrix();
        return tex;
      }));
    }
    return this.byTransform.get(key);
  }

  async loadLightmap(textureIndex) {
    const json = this.parser.json;
    const texDef = json.textures[textureIndex];
    if (!texDef) throw new Error(`MOZ_lightmap: texture ${textureIndex} does not exist`);
    const extras = lightmapExtras(json, textureIndex) || {};
    const files = extras.files || {};
    const rgbe = texDef.extensions && texDef.extensions.MOZ_texture_rgbe;
    const index = this.atlasNumbers[this.order.indexOf(textureIndex)];
    let decoded = null, why = '';
    if (this.source === 'ktx2' && files.ktx2) {
      try {
        decoded = await this.readKtx2(files.ktx2);
      } catch (e) {
        if (!rgbe) throw e;
        why = `${files.ktx2}: ${e.message}; `;
        console.warn(`lmbake preview: atlas ${index}: ${why}falling back to the .hdr`);
      }
    } else if (this.source === 'ktx2') why = 'the glTF names no KTX2 file; ';
    if (!decoded && rgbe) decoded = await this.readHdr(rgbe.source);
    if (!decoded) {
      // Only the tonemapped PNG: shown, but it is not irradiance; values are meaningless.
      console.warn(`MOZ_lightmap: texture ${textureIndex} has no MOZ_texture_rgbe .hdr; showing its PNG (not linear irradiance)`);
      const tex = await this.parser.getDependency('texture', textureIndex);
      tex.colorSpace = THREE.SRGBColorSpace;
      return tex;
    }
    const { width, height, data, uri } = decoded;
    if (extras.width !== undefined && (extras.width !== width || extras.height !== height)) {
      throw new Error(`lightmap ${uri}: ${width}x${height}, the glTF's extras.lightmap says ${extras.width}x${extras.height}`);
    }
    // Upload as half float (always filterable in WebGL 2), whatever the file held; glTF UVs
    // have v down: no flip.
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

    const hdrUri = rgbe && json.images[rgbe.source] ? json.images[rgbe.source].uri ?? null : null;
    const atlas = {
      index, textureIndex, uri, source: decoded.source, format: decoded.format, hdr: hdrUri, files,
      fallback: why ? why.replace(/; $/, '') : null, // why the KTX2 file was not used, when asked for
      // radiance: the files hold E/pi (MOZ_lightmap.intensity is pi); toLux makes a texel E
      scale: extras.scale || 'irradiance', toLux: extras.scale === 'radiance' ? Math.PI : 1,
      width, height, data, texture: tex, maskTexture: maskTex, zeroTexels: zero,
    };
    this.atlases[atlas.index] = atlas;
    tex.userData.atlas = atlas.index;
    console.log(`lmbake preview: atlas ${index} from ${uri} (${decoded.format}${atlas.fallback ? '; not KTX2: ' + atlas.fallback : ''})`);
    return tex;
  }

  // Radiance .hdr (MOZ_texture_rgbe's image): {width, height, data (RGBA float32, row 0 = top), uri}
  async readHdr(imageIndex) {
    const img = this.parser.json.images[imageIndex];
    if (!img) throw new Error(`MOZ_texture_rgbe: image ${imageIndex} does not exist`);
    let buffer, uri;
    if (img.bufferView !== undefined) {
      buffer = await this.parser.getDependency('bufferView', img.bufferView);
      uri = `bufferView ${img.bufferView}`;
    } else {
      uri = img.uri;
      buffer = await this.fetchFile(uri);
    }
    const { width, height, data } = new HDRLoader().setDataType(THREE.FloatType).parse(buffer);
    return { width, height, data, uri, source: 'hdr', format: 'RGBE' };
  }

  // A KTX2 lightmap, decoded to RGBA float32 (alpha 1) like the .hdr: one 2D level of vkFormat
  // 123, 122 or 97, zstd-supercompressed or not. KTX2Loader.parse() refuses to run before
  // detectSupport(renderer), so this is its raw-format path (createRawTexture) without the loader.
  async readKtx2(uri) {
    const c = readKtx2(new Uint8Array(await this.fetchFile(uri)));
    const format = VK_FORMATS[c.vkFormat];
    if (!format) throw new Error(`vkFormat ${c.vkFormat} is not a lightmap format (123, 122 or 97)`);
    if (c.pixelDepth > 0 || c.layerCount > 1 || c.faceCount !== 1 || !c.levels.length) throw new Error('not a single 2D image');
    const level = c.levels[0];
    let bytes = level.levelData;
    if (c.supercompressionScheme === KHR_SUPERCOMPRESSION_ZSTD) bytes = (await zstd()).decode(bytes, level.uncompressedByteLength);
    else if (c.supercompressionScheme !== KHR_SUPERCOMPRESSION_NONE) throw new Error(`supercompression scheme ${c.supercompressionScheme} (only none and zstd)`);
    const width = c.pixelWidth, height = Math.max(1, c.pixelHeight), n = width * height;
    if (bytes.byteLength < n * (c.vkFormat === 97 ? 8 : 4)) throw new Error(`level 0 holds ${bytes.byteLength} bytes, ${width}x${height} needs ${n * (c.vkFormat === 97 ? 8 : 4)}`);
    const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    const data = new Float32Array(4 * n);
    let orient = c.keyValue.KTXorientation || 'rd'; // absent: KTX2's default, rows top to bottom as glTF's
    if (typeof orient !== 'string') orient = new TextDecoder().decode(orient);
    const up = orient[1] === 'u'; // rows bottom to top: flipped here
    for (let y = 0; y < height; y++) {
      const row = up ? height - 1 - y : y;
      for (let x = 0; x < width; x++) {
        const i = row * width + x, o = 4 * (y * width + x);
        decodeTexel(c.vkFormat, view, i, data, o);
        data[o + 3] = 1;
      }
    }
    return { width, height, data, uri, source: 'ktx2', format: format + (c.supercompressionScheme === KHR_SUPERCOMPRESSION_ZSTD ? ' zstd' : '') };
  }

  async fetchFile(uri) {
    const url = THREE.LoaderUtils.resolveURL(uri, this.parser.options.path);
    const res = await fetch(url);
    if (!res.ok) throw new Error(`lightmap ${uri}: HTTP ${res.status}`);
    return res.arrayBuffer();
  }
}

// extras.lightmap of a glTF texture ({atlas, width, height, scale, files}), or null
function lightmapExtras(json, textureIndex) {
  const t = json.textures && json.textures[textureIndex];
  return t && t.extras && t.extras.lightmap && typeof t.extras.lightmap === 'object' ? t.extras.lightmap : null;
}

let zstdPending = null; // one decoder (WebAssembly from a data: URL, no network) for every file
function zstd() {
  if (!zstdPending) { const z = new ZSTDDecoder(); zstdPending = z.init().then(() => z); }
  return zstdPending;
}

// Unsigned float of a 5-bit exponent (bias 15) and m mantissa bits (Vulkan's 11/10-bit floats)
function ufloat(v, m) {
  const e = v >> m, f = v & ((1 << m) - 1);
  if (e === 0) return f * 2 ** (-14 - m);
  if (e === 31) return f ? NaN : Infinity;
  return (1 + f / (1 << m)) * 2 ** (e - 15);
}

// Texel i of a level into out[o..o+2], per the Vulkan specification's formats:
//   123 E5B9G9R9: R, G, B 9-bit mantissas at bits 0, 9, 18, shared exponent at 27 (bias 15):
//       value = mantissa x 2^(exponent - 15 - 9)
//   122 B10G11R11: R 11 bits at 0, G 11 at 11, B 10 at 22 (5-bit exponent, 6/6/5-bit mantissa)
//    97 R16G16B16A16_SFLOAT: half floats
function decodeTexel(vkFormat, view, i, out, o) {
  if (vkFormat === 123) {
    const v = view.getUint32(4 * i, true), s = 2 ** ((v >>> 27) - 24);
    out[o] = (v & 511) * s; out[o + 1] = ((v >>> 9) & 511) * s; out[o + 2] = ((v >>> 18) & 511) * s;
  } else if (vkFormat === 122) {
    const v = view.getUint32(4 * i, true);
    out[o] = ufloat(v & 0x7ff, 6); out[o + 1] = ufloat((v >>> 11) & 0x7ff, 6); out[o + 2] = ufloat((v >>> 22) & 0x3ff, 5);
  } else {
    for (let k = 0; k < 3; k++) out[o + k] = THREE.DataUtils.fromHalfFloat(view.getUint16(8 * i + 2 * k, true));
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
