// lmbake-three: lmbake's lightmaps and light probes in three.js, as a GLTFLoader plugin
// (README.md beside this file; docs/output.md says what the files hold). The lmbake preview is
// built on it.
//   const loader = new GLTFLoader().register(lmbakeLightmaps({ renderer }));
//   const gltf = await loader.loadAsync('level.gltf');   // every lightmapped material lit
//   scene.add(gltf.scene);
// What it reads: MOZ_lightmap on materials ({index, texCoord, intensity} -> material.lightMap /
// lightMapIntensity, its KHR_texture_transform -> the texture's offset / repeat); on the lightmap
// texture, the KTX2 file its extras.lightmap.files.ktx2 names when the GPU can sample its format
// (E5B9G9R9, B10G11R11 and RGBA16F through three's KTX2Loader, Zstandard decoded; BC6H with
// EXT_texture_compression_bptc; ASTC 4x4 HDR with WEBGL_compressed_texture_astc's hdr profile),
// else MOZ_texture_rgbe (the Radiance .hdr, three's HDRLoader); both hold linear irradiance E in
// lux (or E/pi with extras.lightmap.scale "radiance" and MOZ_lightmap.intensity pi). After
// loading, per-copy rectangles of EXT_mesh_gpu_instancing (_LIGHTMAP_SCALE / _LIGHTMAP_OFFSET)
// and per-node rectangles (extras.lightmap.scaleOffset) are put on the objects. Probes
// (asset.extras.lightmap.probes): lmbake-probes.js.
import * as THREE from 'three';
import { HDRLoader } from 'three/addons/loaders/HDRLoader.js';
import { KTX2Loader } from 'three/addons/loaders/KTX2Loader.js';
import { read as readKtx2Header, KHR_SUPERCOMPRESSION_NONE, KHR_SUPERCOMPRESSION_ZSTD } from 'three/addons/libs/ktx-parse.module.js';
import { ZSTDDecoder } from 'three/addons/libs/zstddec.module.js';

export const LIGHTMAP_SOURCES = ['ktx2', 'hdr'];
// The KTX2 lightmap formats (docs/output.md#ktx2): the vkFormat, the three.js type and format
// KTX2Loader gives its texture (createRawTexture), and the WebGL 2 internal format three
// uploads it as (all three filterable)
const KTX2_FORMATS = {
  123: { name: 'E5B9G9R9_UFLOAT_PACK32', type: THREE.UnsignedInt5999Type, format: THREE.RGBFormat, gl: 'RGB9_E5' },
  122: { name: 'B10G11R11_UFLOAT_PACK32', type: THREE.UnsignedInt101111Type, format: THREE.RGBFormat, gl: 'R11F_G11F_B10F' },
  97: { name: 'R16G16B16A16_SFLOAT', type: THREE.HalfFloatType, format: THREE.RGBAFormat, gl: 'RGBA16F' },
};
// The block formats (1 byte per texel on the GPU): three's own format constants; BC6H is built
// here (KTX2Loader reads it only through Basis), ASTC HDR through KTX2Loader's raw path.
const KTX2_BLOCK_FORMATS = {
  143: { name: 'BC6H_UFLOAT_BLOCK', format: THREE.RGB_BPTC_UNSIGNED_Format, gl: 'COMPRESSED_RGB_BPTC_UNSIGNED_FLOAT_EXT' },
  1000066000: { name: 'ASTC_4x4_SFLOAT_BLOCK', format: THREE.RGBA_ASTC_4x4_Format, gl: 'COMPRESSED_RGBA_ASTC_4x4_KHR (hdr profile)' },
};

// Whether the renderer's GPU samples a KTX2 block format (vkFormat) natively.
export function gpuSamples(renderer, vkFormat) {
  if (vkFormat === 143) return renderer.extensions.has('EXT_texture_compression_bptc');
  if (vkFormat === 1000066000) {
    const astc = renderer.getContext().getExtension('WEBGL_compressed_texture_astc');
    return !!astc && astc.getSupportedProfiles().includes('hdr');
  }
  return vkFormat in KTX2_FORMATS;
}

// The GLTFLoader plugin an engine project registers: every lightmapped material gets its
// lightMap, and after loading, the lightmap rectangles are put on the objects
// (applyLightmapRectangles; its result in gltf.userData.lmbakeRectangles).
//   renderer: the page's WebGLRenderer (KTX2Loader.detectSupport(), the block formats' support);
//   source: 'ktx2' (the default: the KTX2 file when the GPU samples its format, else the .hdr)
//           or 'hdr';
//   atlases: an array filled with one record per lightmap (format, size, CPU texels when read).
export function lmbakeLightmaps({ renderer, source = 'ktx2', atlases = [] } = {}) {
  if (!renderer) throw new Error('lmbakeLightmaps: pass { renderer } (the WebGLRenderer the lightmaps are for)');
  const make = lightmapPlugin(atlases, { source, renderer, keepData: false });
  return (parser) => {
    const plugin = make(parser);
    plugin.afterRoot = (gltf) => { gltf.userData.lmbakeRectangles = applyLightmapRectangles(gltf); };
    return plugin;
  };
}

// Returns a function to pass to GLTFLoader.register(); `atlases` is filled while loading.
// source: 'ktx2' (the default: the KTX2 file when the glTF names one, else the .hdr) or 'hdr'.
// renderer: the page's WebGLRenderer, for KTX2Loader.detectSupport() (parse() refuses to run
// without it); without one a KTX2 cannot be loaded and the .hdr is used.
export function lightmapPlugin(atlases, { source = 'ktx2', renderer = null, keepData = true } = {}) {
  if (!LIGHTMAP_SOURCES.includes(source)) throw new Error(`unknown lightmap source '${source}' (one of ${LIGHTMAP_SOURCES.join(', ')})`);
  // One KTX2Loader for every lightmap of the page. Its Basis transcoder (a worker fetching
  // libs/basis/) starts only for vkFormat 0 (and Basis's own ASTC HDR, DFD colour model 0xA7),
  // which readKtx2 never passes it: raw formats go through createRawTexture, so no transcoder
  // path is set.
  const ktx2Loader = source === 'ktx2' && renderer ? new KTX2Loader().detectSupport(renderer) : null;
  return (parser) => new LightmapPlugin(parser, atlases, source, ktx2Loader, renderer, keepData);
}

// The lightmap rectangle of a lightmap texture as [scaleU, scaleV, offsetU, offsetV]: the atlas
// is sampled at uv1 * scale + offset (glTF's KHR_texture_transform without rotation).
export function lightmapScaleOffset(tex) {
  return tex ? [tex.repeat.x, tex.repeat.y, tex.offset.x, tex.offset.y] : [1, 1, 0, 0];
}

// Per-instance lightmap rectangles of an EXT_mesh_gpu_instancing node (docs/output.md): the
// extension's attributes _LIGHTMAP_SCALE and _LIGHTMAP_OFFSET (VEC2, one per copy), which three's
// GLTFMeshGpuInstancing puts on the InstancedMesh's geometry as InstancedBufferAttributes under
// those names. The page's shaders read them under the names INSTANCE_RECT_ATTRIBUTES gives them.
export const INSTANCE_RECT_SOURCES = ['_LIGHTMAP_SCALE', '_LIGHTMAP_OFFSET'];
export const INSTANCE_RECT_ATTRIBUTES = ['lmbLightmapScale', 'lmbLightmapOffset'];

// Adds a shader patch to a material, after any it already has (onBeforeCompile chains; the
// program cache key names every patch, so a patched material never shares an unpatched program).
export function addShaderPatch(material, key, patch) {
  const prev = material.onBeforeCompile, prevKey = material.customProgramCacheKey();
  material.onBeforeCompile = function (shader, renderer) { prev.call(this, shader, renderer); patch(shader, renderer); };
  material.customProgramCacheKey = () => `${prevKey}|${key}`;
  material.needsUpdate = true;
  return material;
}

// A clone of a material that keeps its shader patches (Material.clone() drops them)
export function cloneWithPatches(material) {
  const m = material.clone();
  if (Object.prototype.hasOwnProperty.call(material, 'onBeforeCompile')) m.onBeforeCompile = material.onBeforeCompile;
  if (Object.prototype.hasOwnProperty.call(material, 'customProgramCacheKey')) m.customProgramCacheKey = material.customProgramCacheKey;
  return m;
}

// The patch that makes three's lightMap (lit and lightmap views) read an InstancedMesh's copy at
// its own rectangle: vLightMapUv = lightMapTransform x (uv1 x scale_k + offset_k), k the instance
// (three's uv_vertex computes it from uv1 alone). A directional lightmap reads the same vLightMapUv.
export function patchInstanceRectangles(material) {
  const [scale, offset] = INSTANCE_RECT_ATTRIBUTES;
  return addShaderPatch(material, 'lmbake-instance-rect', (shader) => {
    if (!shader.vertexShader.includes('#include <uv_vertex>')) throw new Error(`lmbake: ${material.type} has no uv_vertex to patch for per-instance lightmap rectangles`);
    shader.vertexShader = `#ifdef USE_INSTANCING\nattribute vec2 ${scale};\nattribute vec2 ${offset};\n#endif\n` + shader.vertexShader.replace('#include <uv_vertex>', `#include <uv_vertex>
#if defined( USE_LIGHTMAP ) && defined( USE_INSTANCING )
  vLightMapUv = ( lightMapTransform * vec3( LIGHTMAP_UV * ${scale} + ${offset}, 1 ) ).xy;
#endif`);
  });
}

// The glTF node index a three.js object belongs to (a multi-primitive mesh's meshes are children
// of the node's group; GLTFLoader's parser.associations maps each node's object, clones of a
// shared mesh and InstancedMeshes included, to {nodes: index}), or -1
export function gltfNodeIndex(parser, o) {
  for (; o; o = o.parent) { const a = parser.associations.get(o); if (a && a.nodes !== undefined) return a.nodes; }
  return -1;
}

const validScaleOffset = (so) => Array.isArray(so) && so.length === 4 && so.every(Number.isFinite) && so[0] > 0 && so[1] > 0;

// Lightmap rectangles that the lightMap textures GLTFLoader made do not carry, put on the
// objects (call once, after loading, before anything copies the materials):
//  - an InstancedMesh whose geometry has _LIGHTMAP_SCALE and _LIGHTMAP_OFFSET: its own clone of
//    the material (a material it shares with other meshes stays as it is for them) with
//    patchInstanceRectangles; the attributes are also set under INSTANCE_RECT_ATTRIBUTES'
//    names. object.userData.lightmapInstances = {count, scale, offset} (Float32Arrays, 2 per copy).
//  - a mesh whose glTF node has extras.lightmap.scaleOffset other than the rectangle its
//    lightMap texture carries (atlas.share_meshes: several nodes share one mesh and one
//    material, the material has no KHR_texture_transform): a clone of the material per
//    (material, rectangle) with a clone of the texture at that offset / repeat, as
//    KHR_texture_transform does. When both say a rectangle they are the same (keep_uv1 bakes);
//    the node's is used.
// Returns {instanced: [{object, node, count}], perNode: [{object, node, scaleOffset}]}.
export function applyLightmapRectangles(gltf) {
  const parser = gltf.parser, json = parser.json;
  const meshes = [];
  gltf.scene.traverse((o) => { if (o.isMesh && !Array.isArray(o.material) && o.material && o.material.lightMap) meshes.push(o); });
  const out = { instanced: [], perNode: [] };
  const clones = new Map(); // material uuid + rectangle -> the clone for nodes at that rectangle
  for (const o of meshes) {
    const g = o.geometry, node = gltfNodeIndex(parser, o), mat = o.material;
    const [sa, oa] = INSTANCE_RECT_SOURCES.map((n) => g.getAttribute(n));
    if (o.isInstancedMesh && sa && oa) {
      if (!sa.isInstancedBufferAttribute || !oa.isInstancedBufferAttribute || sa.itemSize !== 2 || oa.itemSize !== 2 || sa.count < o.count || oa.count < o.count) {
        throw new Error(`node ${node} '${o.name}': ${INSTANCE_RECT_SOURCES.join(' and ')} must be VEC2 per-instance attributes, one per copy (${o.count})`);
      }
      INSTANCE_RECT_ATTRIBUTES.forEach((n, k) => g.setAttribute(n, [sa, oa][k]));
      const get = (a) => Float32Array.from({ length: 2 * o.count }, (_, i) => (i & 1 ? a.getY(i >> 1) : a.getX(i >> 1)));
      o.userData.lightmapInstances = { count: o.count, scale: get(sa), offset: get(oa) };
      o.material = patchInstanceRectangles(mat.clone());
      out.instanced.push({ object: o, node, count: o.count });
      continue;
    }
    const x = node >= 0 && json.nodes[node].extras && json.nodes[node].extras.lightmap;
    const so = x && validScaleOffset(x.scaleOffset) ? x.scaleOffset.map(Number) : null;
    if (!so) continue;
    const cur = lightmapScaleOffset(mat.lightMap);
    if (so.every((v, k) => Math.abs(v - cur[k]) <= 1e-7 * Math.max(1, Math.abs(v)))) continue;
    const key = `${mat.uuid}:${so}`;
    if (!clones.has(key)) {
      const tex = mat.lightMap.clone(); // shares the image and the GPU texture
      tex.offset.set(so[2], so[3]);
      tex.repeat.set(so[0], so[1]);
      tex.updateMatrix();
      const m = mat.clone();
      m.lightMap = tex;
      clones.set(key, m);
    }
    o.material = clones.get(key);
    out.perNode.push({ object: o, node, scaleOffset: so });
  }
  return out;
}

class LightmapPlugin {
  constructor(parser, atlases, source, ktx2Loader, renderer, keepData) {
    this.renderer = renderer;
    this.keepData = keepData; // the texels as floats on the CPU too (the .hdr's for a block format)
    this.parser = parser;
    this.atlases = atlases;
    this.source = source;
    this.ktx2Loader = ktx2Loader;
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
        console.warn(`lmbake: atlas ${index}: ${why}falling back to the .hdr`);
      }
    } else if (this.source === 'ktx2') why = 'the glTF names no KTX2 file; ';
    if (!decoded && rgbe) decoded = await this.readHdr(rgbe.source);
    // A block format's texels are not decoded on the CPU: the .hdr gives them when they are kept
    if (decoded && !decoded.data && this.keepData && rgbe) decoded.data = (await this.readHdr(rgbe.source)).data;
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
    // The GPU texture: KTX2Loader's own (its texels as the file holds them), else the floats as
    // half floats (always filterable in WebGL 2). Either way bilinear without mipmaps (they would
    // blur across charts), clamped, linear, and not flipped: glTF UVs have v down, row 0 on top.
    const tex = decoded.texture || halfFloatTexture(data, width, height);
    tex.colorSpace = THREE.LinearSRGBColorSpace;
    tex.flipY = false;
    tex.magFilter = THREE.LinearFilter;
    tex.minFilter = THREE.LinearFilter;
    tex.generateMipmaps = false;
    tex.wrapS = tex.wrapT = THREE.ClampToEdgeWrapping;
    tex.name = uri;
    tex.needsUpdate = true;

    // Invalid texels: lmbake writes texels inside geometry as exactly 0 (RGBE exponent 0).
    const mask = new Uint8Array(width * height);
    let zero = 0;
    for (let i = 0; data && i < width * height; i++) {
      if (data[4 * i] === 0 && data[4 * i + 1] === 0 && data[4 * i + 2] === 0) { mask[i] = 255; zero++; }
    }
    const maskTex = new THREE.DataTexture(mask, width, height, THREE.RedFormat, THREE.UnsignedByteType);
    maskTex.flipY = false;
    maskTex.magFilter = maskTex.minFilter = THREE.NearestFilter;
    maskTex.needsUpdate = true;

    const hdrUri = rgbe && json.images[rgbe.source] ? json.images[rgbe.source].uri ?? null : null;
    const atlas = {
      index, textureIndex, uri, source: decoded.source, format: decoded.format, hdr: hdrUri, files,
      loader: decoded.loader, // the three.js loader that read the file: KTX2Loader or HDRLoader
      gpu: decoded.texture ? `${decoded.gpu} (the ${decoded.loader} texture)` : 'RGBA16F (half floats from the decoded texels)',
      fallback: why ? why.replace(/; $/, '') : null, // why the KTX2 file was not used, when asked for
      // radiance: the files hold E/pi (MOZ_lightmap.intensity is pi); toLux makes a texel E
      scale: extras.scale || 'irradiance', toLux: extras.scale === 'radiance' ? Math.PI : 1,
      width, height, data, texture: tex, maskTexture: maskTex, zeroTexels: zero,
      // a light group's KTX2 (extras.lightmap.groups[].files.ktx2) read as this atlas's was
      // (lmbake-groups.js): {texture, gpu, format}; throws where this atlas's could not be read
      readKtx2: (groupUri) => this.readKtx2(groupUri),
    };
    this.atlases[atlas.index] = atlas;
    tex.userData.atlas = atlas.index;
    console.log(`lmbake: atlas ${index} from ${uri} (${decoded.format}, on the GPU ${atlas.gpu}${atlas.fallback ? '; not KTX2: ' + atlas.fallback : ''})`);
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
    return { width, height, data, uri, source: 'hdr', format: 'RGBE (HDRLoader)', loader: 'HDRLoader' };
  }

  // A KTX2 lightmap through three's KTX2Loader: {width, height, data (RGBA float32 decoded from
  // the loader's texels, alpha 1, row 0 = top), texture (the loader's DataTexture), uri, ...}.
  // One 2D level of vkFormat 123, 122 or 97, zstd-supercompressed or not. The header is looked
  // at first (ktx-parse, the loader's own reader) for what the loader's texture does not say:
  // that the format is one of those (anything else, Basis above all, would make the loader fetch
  // its transcoder, or is no lightmap), the supercompression and KTXorientation.
  async readKtx2(uri) {
    if (!this.ktx2Loader) throw new Error('no renderer for KTX2Loader.detectSupport()');
    const buffer = await this.fetchFile(uri);
    const c = readKtx2Header(new Uint8Array(buffer));
    if (c.vkFormat in KTX2_BLOCK_FORMATS) return this.readKtx2Blocks(uri, buffer, c);
    const f = KTX2_FORMATS[c.vkFormat];
    if (!f) throw new Error(`vkFormat ${c.vkFormat} is not a lightmap format (123, 122, 97, 143 or 1000066000)`);
    if (c.pixelDepth > 0 || c.layerCount > 1 || c.faceCount !== 1) throw new Error('not a single 2D image');
    if (c.supercompressionScheme !== KHR_SUPERCOMPRESSION_NONE && c.supercompressionScheme !== KHR_SUPERCOMPRESSION_ZSTD) throw new Error(`supercompression scheme ${c.supercompressionScheme} (only none and zstd)`);
    const tex = await new Promise((resolve, reject) => this.ktx2Loader.parse(buffer, resolve, (e) => reject(e instanceof Error ? e : new Error(String(e)))));
    if (!tex.isDataTexture || tex.type !== f.type || tex.format !== f.format || !tex.mipmaps.length) {
      throw new Error(`KTX2Loader made a ${tex.constructor.name} of type ${tex.type}, format ${tex.format}, ${tex.mipmaps.length} levels; expected a DataTexture of type ${f.type}, format ${f.format}`);
    }
    const width = tex.image.width, height = tex.image.height, n = width * height, src = tex.mipmaps[0].data;
    const per = c.vkFormat === 97 ? 4 : 1; // array elements per texel: Uint16Array RGBA, Uint32Array packed
    if (src.length < n * per) throw new Error(`level 0 holds ${src.length} values, ${width}x${height} needs ${n * per}`);
    tex.mipmaps = [tex.mipmaps[0]]; // level 0 only (bilinear, no mipmaps)
    // KTX2Loader keeps the file's row order (it reads no KTXorientation): row 0 first, uploaded
    // unflipped at v = 0, glTF's top. lmbake writes "rd" (rows down, as glTF); rows written
    // bottom to top ("ru") are reversed here, in the loader's texture and thus on the GPU too.
    const orient = typeof c.keyValue.KTXorientation === 'string' ? c.keyValue.KTXorientation : 'rd'; // absent: KTX2's default, rd
    if (orient[1] === 'u') flipRows(src, width * per, height);
    const data = new Float32Array(4 * n);
    decodeTexels(c.vkFormat, src, n, data);
    const zstd = c.supercompressionScheme === KHR_SUPERCOMPRESSION_ZSTD ? ' zstd' : '';
    return { width, height, data, uri, texture: tex, gpu: f.gl, source: 'ktx2', format: `${f.name}${zstd} (KTX2Loader)`, loader: 'KTX2Loader' };
  }

  // A block-format KTX2 (BC6H, ASTC 4x4 HDR) as the GPU samples it: level 0's blocks in a
  // CompressedTexture (mip levels are not used: lightmaps are sampled bilinearly, as above);
  // no CPU texels (data null). Throws when the GPU cannot sample the format (the caller falls
  // back to the .hdr).
  async readKtx2Blocks(uri, buffer, c) {
    const f = KTX2_BLOCK_FORMATS[c.vkFormat];
    if (!gpuSamples(this.renderer, c.vkFormat)) throw new Error(`this GPU cannot sample ${f.name} (${f.gl})`);
    if (c.pixelDepth > 0 || c.layerCount > 1 || c.faceCount !== 1) throw new Error('not a single 2D image');
    const orient = typeof c.keyValue.KTXorientation === 'string' ? c.keyValue.KTXorientation : 'rd';
    if (orient[1] !== 'd') throw new Error(`KTXorientation ${orient}: block rows cannot be flipped`);
    const width = c.pixelWidth, height = c.pixelHeight, level = c.levels[0];
    let blocks = level.levelData;
    if (c.supercompressionScheme === KHR_SUPERCOMPRESSION_ZSTD) {
      if (!this.zstd) { this.zstd = new ZSTDDecoder(); await this.zstd.init(); }
      blocks = this.zstd.decode(blocks, level.uncompressedByteLength);
    } else if (c.supercompressionScheme !== KHR_SUPERCOMPRESSION_NONE) throw new Error(`supercompression scheme ${c.supercompressionScheme} (only none and zstd)`);
    const expect = Math.ceil(width / 4) * Math.ceil(height / 4) * 16;
    if (blocks.byteLength !== expect) throw new Error(`level 0 holds ${blocks.byteLength} bytes, ${width}x${height} in 4x4 blocks needs ${expect}`);
    const tex = new THREE.CompressedTexture([{ data: new Uint8Array(blocks), width, height }], width, height, f.format, THREE.HalfFloatType);
    const zstd = c.supercompressionScheme === KHR_SUPERCOMPRESSION_ZSTD ? ' zstd' : '';
    return { width, height, data: null, uri, texture: tex, gpu: f.gl, source: 'ktx2', format: `${f.name}${zstd} (lmbake-three)`, loader: 'lmbake-three' };
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

// RGBA float32 texels as a half-float texture (the .hdr's GPU copy)
function halfFloatTexture(data, width, height) {
  const half = new Uint16Array(data.length);
  for (let i = 0; i < data.length; i++) half[i] = THREE.DataUtils.toHalfFloat(data[i]);
  return new THREE.DataTexture(half, width, height, THREE.RGBAFormat, THREE.HalfFloatType);
}

// Reverses the order of `height` rows of `stride` elements, in place
function flipRows(a, stride, height) {
  const tmp = a.slice(0, stride);
  for (let y = 0, z = height - 1; y < z; y++, z--) {
    tmp.set(a.subarray(y * stride, (y + 1) * stride));
    a.copyWithin(y * stride, z * stride, (z + 1) * stride);
    a.set(tmp, z * stride);
  }
}

// Unsigned float of a 5-bit exponent (bias 15) and m mantissa bits (Vulkan's 11/10-bit floats)
function ufloat(v, m) {
  const e = v >> m, f = v & ((1 << m) - 1);
  if (e === 0) return f * 2 ** (-14 - m);
  if (e === 31) return f ? NaN : Infinity;
  return (1 + f / (1 << m)) * 2 ** (e - 15);
}

// n texels of KTX2Loader's level data (src: Uint32Array for 123 / 122, Uint16Array RGBA for 97)
// into out, RGBA float32 with alpha 1, per the Vulkan specification's formats:
//   123 E5B9G9R9: R, G, B 9-bit mantissas at bits 0, 9, 18, shared exponent at 27 (bias 15):
//       value = mantissa x 2^(exponent - 15 - 9)
//   122 B10G11R11: R 11 bits at 0, G 11 at 11, B 10 at 22 (5-bit exponent, 6/6/5-bit mantissa)
//    97 R16G16B16A16_SFLOAT: half floats
function decodeTexels(vkFormat, src, n, out) {
  for (let i = 0, o = 0; i < n; i++, o += 4) {
    if (vkFormat === 123) {
      const v = src[i], s = 2 ** ((v >>> 27) - 24);
      out[o] = (v & 511) * s; out[o + 1] = ((v >>> 9) & 511) * s; out[o + 2] = ((v >>> 18) & 511) * s;
    } else if (vkFormat === 122) {
      const v = src[i];
      out[o] = ufloat(v & 0x7ff, 6); out[o + 1] = ufloat((v >>> 11) & 0x7ff, 6); out[o + 2] = ufloat((v >>> 22) & 0x3ff, 5);
    } else {
      for (let k = 0; k < 3; k++) out[o + k] = THREE.DataUtils.fromHalfFloat(src[4 * i + k]);
    }
    out[o + 3] = 1;
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
    // (added to the material's other patches: an InstancedMesh's per-instance rectangle sets the
    // vLightMapUv this reads)
    addShaderPatch(m, 'lmbake-directional', (shader) => {
      shader.uniforms.lightDirectionMap = { value: tex };
      shader.fragmentShader = 'uniform sampler2D lightDirectionMap;\n' + shader.fragmentShader.replace(
        '#include <lights_fragment_maps>',
        THREE.ShaderChunk.lights_fragment_maps.replace('vec3 lightMapIrradiance = lightMapTexel.rgb * lightMapIntensity;', `
    vec3 lightMapIrradiance = lightMapTexel.rgb * lightMapIntensity;
    vec3 lmDir = (viewMatrix * vec4(texture2D(lightDirectionMap, vLightMapUv).rgb * 2.0 - 1.0, 0.0)).xyz;
    lightMapIrradiance *= max(0.0, 1.0 + 1.5 * dot(lmDir, normal)) / max(1e-3, 1.0 + 1.5 * dot(lmDir, nonPerturbedNormal));`));
    });
  }
  return materials.size;
}
