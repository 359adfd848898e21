// lmbake-babylon: lmbake's lightmaps and light probes in Babylon.js, as a glTF loader extension
// (README.md beside this file; docs/output.md says what the files hold).
//   registerLmbakeLightmaps();                                  // once, before loading
//   const result = await SceneLoader.ImportMeshAsync('', '', 'level.gltf', scene);
// What it reads: MOZ_lightmap on materials ({index, texCoord, intensity}, KHR_texture_transform on
// it: the lightmap's rectangle) -> material.lightmapTexture (coordinatesIndex 1: TEXCOORD_1,
// uOffset / vOffset / uScale / vScale as Babylon's KHR_texture_transform sets them), with
// useLightmapAsShadowmap off. The texels: the KTX2 the lightmap texture's extras.lightmap.files.ktx2
// names when it is BC6H without supercompression and the GPU samples BC6H
// (EXT_texture_compression_bptc), else the Radiance .hdr of MOZ_texture_rgbe (read with Babylon's
// own RGBE reader, uploaded as half floats). Both hold irradiance E in lux (or E / pi with
// extras.lightmap.scale "radiance" and MOZ_lightmap.intensity pi).
// Babylon adds a lightmap to a PBR material's final colour as it is (radiance), where a
// diffuse surface under irradiance E shows albedo / pi x E: the texture's level is intensity / pi
// and a material plugin multiplies the lightmap by the surface's diffuse albedo.
// Light probes (asset.extras.lightmap.probes): read with the level, kept on the root mesh's
// metadata (lmbakeProbes(result.meshes[0])); lmbake-babylon-probes.js lights meshes by them.
// Light groups (extras.lightmap.groups on a lightmap texture; docs/light-groups.md): each group's
// lightmap is read too (its BC6H .ktx2 as the level's, else its .hdr), and a material plugin makes the lightmap sum_g w_g x intensity_g x group_g
// (intensity_g: RGB, from the glTF), with one weight per group the game sets at run time:
// lmbakeLightGroups(result.meshes[0]).setWeight('lamps', 0).
// Per-copy rectangles: a node with EXT_mesh_gpu_instancing whose attributes hold _LIGHTMAP_SCALE
// and _LIGHTMAP_OFFSET (VEC2, one per copy; docs/output.md) has its copies (Babylon's thin
// instances) read the atlas at TEXCOORD_1 x scale_k + offset_k: a thin-instance buffer
// lmbLightmapRect and a vertex plugin that recomputes the lightmap coordinates (WebGL's GLSL).
import { Texture } from '@babylonjs/core/Materials/Textures/texture.js';
import { RawTexture } from '@babylonjs/core/Materials/Textures/rawTexture.js';
import { MaterialPluginBase } from '@babylonjs/core/Materials/materialPluginBase.js';
import { RGBE_ReadHeader, RGBE_ReadPixels } from '@babylonjs/core/Misc/HighDynamicRange/hdr.js';
import { GLTFLoader, ArrayItem } from '@babylonjs/loaders/glTF/2.0/glTFLoader.js';
import { registerGLTFExtension, unregisterGLTFExtension } from '@babylonjs/loaders/glTF/2.0/glTFLoaderExtensionRegistry.js';
import { loadProbes } from './lmbake-babylon-probes.js';

const NAME = 'MOZ_lightmap';
const TEXTUREFORMAT_RGBA = 5, TEXTURETYPE_HALF_FLOAT = 2, BILINEAR = 2;
const COMPRESSED_RGB_BPTC_UNSIGNED_FLOAT_EXT = 0x8e8f;

// Multiplies a PBR material's lightmap by its diffuse albedo (surfaceAlbedo: base colour x
// (1 - metallic)), so the lightmap lights the surface as the bake's irradiance does.
class LightmapTimesAlbedo extends MaterialPluginBase {
  constructor(material) {
    super(material, 'LmbakeLightmapTimesAlbedo', 200, { LMBAKE_LIGHTMAP: false });
    this._enable(true);
  }

  prepareDefines(defines) { defines.LMBAKE_LIGHTMAP = true; }

  getClassName() { return 'LmbakeLightmapTimesAlbedo'; }

  getCustomCode(shaderType) {
    if (shaderType !== 'fragment') return null;
    return { CUSTOM_FRAGMENT_BEFORE_FINALCOLORCOMPOSITION: '#if defined(LIGHTMAP) && defined(LMBAKE_LIGHTMAP)\nlightmapColor.rgb *= surfaceAlbedo;\n#endif\n' };
  }
}

// Light groups: where the material read its lightmap it reads sum_g gain_g x group_g, gain_g =
// w_g x intensity_g (RGB), the groups' .hdr textures of its atlas sampled at the lightmap's own
// coordinates (the atlas is the same; a material's rectangle is in vLightmapUV). Runs before
// LightmapTimesAlbedo (priority 190 < 200), so the sum is what the albedo multiplies.
// lmbGroupsSum(uv) is the sum before the texture's level (tests read it).
class LightGroupsSum extends MaterialPluginBase {
  constructor(material, groups, textures) {
    super(material, 'LmbakeLightGroups', 190, { LMBAKE_GROUPS: 0 }, false); // added below: its code needs the textures
    this._groups = groups;
    this._textures = textures;
    this._pluginManager._addPlugin(this);
    this._enable(true);
  }

  prepareDefines(defines) { defines.LMBAKE_GROUPS = this._textures.length; }

  getClassName() { return 'LmbakeLightGroups'; }

  getSamplers(samplers) { this._textures.forEach((_, g) => samplers.push(`lmbGroup${g}`)); }

  getUniforms() {
    const n = this._textures.length;
    return {
      ubo: Array.from({ length: n }, (_, g) => ({ name: `lmbGroupGain${g}`, size: 3, type: 'vec3' })),
      fragment: Array.from({ length: n }, (_, g) => `uniform vec3 lmbGroupGain${g};`).join('\n'),
    };
  }

  bindForSubMesh(uniformBuffer) { // every frame: the weights change at run time
    this._textures.forEach((t, g) => {
      const w = this._groups.weights[g], k = this._groups.intensities[g];
      uniformBuffer.updateFloat3(`lmbGroupGain${g}`, w * k[0], w * k[1], w * k[2]);
      uniformBuffer.setTexture(`lmbGroup${g}`, t);
    });
  }

  hasTexture(texture) { return this._textures.includes(texture); }

  getActiveTextures(active) { active.push(...this._textures); }

  getCustomCode(shaderType) {
    if (shaderType !== 'fragment') return null;
    const n = this._textures.length;
    const sum = Array.from({ length: n }, (_, g) => `lmbGroupGain${g} * texture2D(lmbGroup${g}, uv).rgb`).join(' + ');
    return {
      CUSTOM_FRAGMENT_DEFINITIONS: `#if defined(LMBAKE_GROUPS) && LMBAKE_GROUPS > 0
${Array.from({ length: n }, (_, g) => `uniform sampler2D lmbGroup${g};`).join('\n')}
vec3 lmbGroupsSum(vec2 uv) { return ${sum}; }
#endif
`,
      CUSTOM_FRAGMENT_BEFORE_FINALCOLORCOMPOSITION: '#if defined(LIGHTMAP) && defined(LMBAKE_GROUPS) && LMBAKE_GROUPS > 0\nlightmapColor.rgb = lmbGroupsSum(vLightmapUV) * vLightmapInfos.y;\n#endif\n',
    };
  }
}

// The light groups of a bake loaded with registerLmbakeLightmaps (root: the load's first mesh), or
// null: {names, scales, intensities, weights, setWeight(group name or index, w)}; the weights
// start at the bake's scales and are read by every patched material at its next frame.
export function lmbakeLightGroups(root) {
  return (root && root.metadata && root.metadata.lmbake && root.metadata.lmbake.groups) || null;
}

// The per-copy rectangle attribute: (scale u, scale v, offset u, offset v) per thin instance.
export const INSTANCE_RECT = 'lmbLightmapRect';
const INSTANCE_RECT_SOURCES = ['_LIGHTMAP_SCALE', '_LIGHTMAP_OFFSET'];

const hasRects = (mesh) => !!(mesh && mesh._userThinInstanceBuffersStorage && mesh._userThinInstanceBuffersStorage.data[INSTANCE_RECT]);

// Makes a thin-instanced mesh's copies read the lightmap at their own rectangles: the lightmap
// coordinates (TEXCOORD_1, Babylon's uv2) x scale + offset, then the texture's matrix as Babylon
// applies it (LIGHTMAPDIRECTUV 0), or as the coordinates themselves (LIGHTMAPDIRECTUV 2: the
// lightmap reads vMainUV2, so other textures on TEXCOORD_1 of such a mesh move with it).
class InstanceRectangles extends MaterialPluginBase {
  constructor(material) {
    super(material, 'LmbakeInstanceRectangles', 210, { LMBAKE_INSTANCE_RECT: false });
    this._enable(true);
  }

  prepareDefines(defines, scene, mesh) { defines.LMBAKE_INSTANCE_RECT = hasRects(mesh); }

  getAttributes(attributes, scene, mesh) { if (hasRects(mesh)) attributes.push(INSTANCE_RECT); }

  getClassName() { return 'LmbakeInstanceRectangles'; }

  getCustomCode(shaderType) {
    if (shaderType !== 'vertex') return null;
    return {
      CUSTOM_VERTEX_DEFINITIONS: `#if defined(LMBAKE_INSTANCE_RECT) && defined(THIN_INSTANCES)\nattribute vec4 ${INSTANCE_RECT};\n#endif\n`,
      CUSTOM_VERTEX_MAIN_END: `#if defined(LMBAKE_INSTANCE_RECT) && defined(THIN_INSTANCES) && defined(LIGHTMAP) && defined(UV2)
#if LIGHTMAPDIRECTUV == 0
vLightmapUV = vec2(lightmapMatrix * vec4(uv2Updated * ${INSTANCE_RECT}.xy + ${INSTANCE_RECT}.zw, 1.0, 0.0));
#elif LIGHTMAPDIRECTUV == 2
vMainUV2 = uv2Updated * ${INSTANCE_RECT}.xy + ${INSTANCE_RECT}.zw;
#endif
#endif
`,
    };
  }
}

// float -> IEEE half bits (round to nearest), for the .hdr's upload
function toHalf(f) {
  const b = new DataView(new ArrayBuffer(4));
  b.setFloat32(0, f);
  const x = b.getUint32(0), sign = (x >>> 16) & 0x8000, e = ((x >>> 23) & 0xff) - 112, m = x & 0x7fffff;
  if (e <= 0) return e < -10 ? sign : sign | ((m | 0x800000) >> (1 - e + 13));
  if (e >= 31) return sign | 0x7bff;
  const h = sign | (e << 10) | (m >> 13);
  return (m & 0x1fff) > 0x1000 || ((m & 0x1fff) === 0x1000 && (h & 1)) ? h + 1 : h;
}

// The 2D level 0 of a KTX2 file: {vkFormat, width, height, supercompression, data} (header and
// level index: KTX 2.0 specification, section 3).
export function readKtx2Level0(buffer) {
  const v = new DataView(buffer), id = new Uint8Array(buffer, 0, 12);
  const magic = [0xab, 0x4b, 0x54, 0x58, 0x20, 0x32, 0x30, 0xbb, 0x0d, 0x0a, 0x1a, 0x0a];
  if (!magic.every((b, i) => id[i] === b)) throw new Error('not a KTX2 file');
  const vkFormat = v.getUint32(12, true), width = v.getUint32(20, true), height = v.getUint32(24, true);
  const supercompression = v.getUint32(44, true);
  const offset = Number(v.getBigUint64(80, true)), length = Number(v.getBigUint64(88, true));
  return { vkFormat, width, height, supercompression, data: new Uint8Array(buffer, offset, length) };
}

class MozLightmap {
  constructor(loader, options) {
    this.name = NAME;
    this.order = 200;
    this._loader = loader;
    this._options = options;
    this.enabled = loader.isExtensionUsed(NAME);
    this._textures = new Map(); // texture index -> Promise<{texture, source}>
    this._groupTextures = new Map(); // texture index -> Promise<[group textures]> (light groups)
    this._groups = null; // {names, scales, intensities, weights, setWeight}: the first atlas's groups
  }

  dispose() { this._loader = null; }

  loadMaterialPropertiesAsync(context, material, babylonMaterial) {
    return GLTFLoader.LoadExtensionAsync(context, material, this.name, async (extContext, ext) => {
      await this._loader.loadMaterialPropertiesAsync(context, material, babylonMaterial);
      const base = await this._lightmap(extContext, ext.index);
      if (!base) return;
      // a texture of its own (its rectangle) on the shared GPU texture
      const internal = base.getInternalTexture();
      internal.incrementReferences();
      const tex = new Texture(null, this._loader.babylonScene, { noMipmap: true, invertY: false, samplingMode: BILINEAR, internalTexture: internal });
      tex.name = base.name;
      tex.wrapU = tex.wrapV = Texture.CLAMP_ADDRESSMODE;
      tex.anisotropicFilteringLevel = 1; // bilinear, as baked: Babylon's default 4 taps across charts at grazing views
      const tt = ext.extensions && ext.extensions.KHR_texture_transform;
      tex.coordinatesIndex = (tt && tt.texCoord) ?? ext.texCoord ?? 1;
      tex.uRotationCenter = 0;
      tex.vRotationCenter = 0;
      if (tt && tt.offset) { tex.uOffset = tt.offset[0]; tex.vOffset = tt.offset[1]; }
      if (tt && tt.scale) { tex.uScale = tt.scale[0]; tex.vScale = tt.scale[1]; }
      tex.level = (ext.intensity ?? 1) / Math.PI;
      babylonMaterial.lightmapTexture = tex;
      babylonMaterial.useLightmapAsShadowmap = false;
      const groupTextures = await this._lightGroups(extContext, ext.index);
      if (groupTextures && !(babylonMaterial.pluginManager && babylonMaterial.pluginManager.getPlugin('LmbakeLightGroups'))) new LightGroupsSum(babylonMaterial, this._groups, groupTextures);
      if (!babylonMaterial.pluginManager || !babylonMaterial.pluginManager.getPlugin('LmbakeLightmapTimesAlbedo')) new LightmapTimesAlbedo(babylonMaterial);
    });
  }

  // After every node is made (Babylon's EXT_mesh_gpu_instancing has set the copies' matrices),
  // before the load resolves: the light probes onto the root mesh's metadata, the per-copy
  // rectangles onto the thin-instanced meshes.
  async onReady() {
    const json = this._loader.gltf, root = this._loader.rootBabylonMesh;
    const probes = await loadProbes(this._loader);
    if (probes && root) {
      root.metadata = { ...(root.metadata || {}), lmbake: { ...((root.metadata || {}).lmbake || {}), probes } };
      console.log(`lmbake-babylon: ${probes.count} light probes (lmbakeProbes(root))`);
    }
    if (this._groups && root) {
      root.metadata = { ...(root.metadata || {}), lmbake: { ...((root.metadata || {}).lmbake || {}), groups: this._groups } };
      console.log(`lmbake-babylon: light groups ${this._groups.names.join(', ')} (lmbakeLightGroups(root))`);
    }
    for (const node of json.nodes || []) {
      const ext = node.extensions && node.extensions.EXT_mesh_gpu_instancing, attrs = ext && ext.attributes;
      if (!attrs || INSTANCE_RECT_SOURCES.every((k) => attrs[k] === undefined)) continue;
      const context = `/nodes/${node.index}/extensions/EXT_mesh_gpu_instancing/attributes`;
      if (INSTANCE_RECT_SOURCES.some((k) => attrs[k] === undefined)) throw new Error(`${context}: ${INSTANCE_RECT_SOURCES.join(' and ')} come together`);
      const [scale, offset] = await Promise.all(INSTANCE_RECT_SOURCES.map((k) => {
        const accessor = ArrayItem.Get(`${context}/${k}`, json.accessors, attrs[k]);
        if (accessor.type !== 'VEC2') throw new Error(`${context}/${k}: accessor ${attrs[k]} is ${accessor.type}, not VEC2`);
        return this._loader._loadFloatAccessorAsync(`/accessors/${accessor.index}`, accessor);
      }));
      const count = scale.length / 2;
      if (offset.length !== scale.length) throw new Error(`${context}: ${count} scales and ${offset.length / 2} offsets`);
      const rect = new Float32Array(4 * count);
      for (let i = 0; i < count; i++) rect.set([scale[2 * i], scale[2 * i + 1], offset[2 * i], offset[2 * i + 1]], 4 * i);
      for (const mesh of node._primitiveBabylonMeshes || []) {
        if (mesh.thinInstanceCount !== count) throw new Error(`${context}: ${count} rectangles for ${mesh.thinInstanceCount} copies of '${mesh.name}'`);
        mesh.thinInstanceSetBuffer(INSTANCE_RECT, rect, 4, true);
        const m = mesh.material;
        if (m && m.lightmapTexture && !(m.pluginManager && m.pluginManager.getPlugin('LmbakeInstanceRectangles'))) new InstanceRectangles(m);
      }
      console.log(`lmbake-babylon: node ${node.index}: ${count} copies at their own lightmap rectangles`);
    }
  }

  // The light groups a lightmap texture names (extras.lightmap.groups): each group's .hdr as a
  // texture (as the level's .hdr is read), in the groups' order; null without groups. Every atlas
  // must name the same groups (the first one's are the weights' groups).
  _lightGroups(context, index) {
    if (!this._groupTextures.has(index)) this._groupTextures.set(index, this._loadLightGroups(context, index));
    return this._groupTextures.get(index);
  }

  async _loadLightGroups(context, index) {
    const def = this._loader.gltf.textures[index];
    const groups = def && def.extras && def.extras.lightmap && def.extras.lightmap.groups;
    if (!Array.isArray(groups) || !groups.length) return null;
    const names = groups.map((g) => String(g.name));
    if (!this._groups) {
      const state = {
        names,
        scales: groups.map((g) => Number(g.scale)),
        intensities: groups.map((g) => (Array.isArray(g.intensity) && g.intensity.length === 3 ? g.intensity.map(Number) : [1, 1, 1])),
      };
      state.weights = state.scales.slice();
      state.setWeight = (g, w) => {
        const k = typeof g === 'number' ? g : state.names.indexOf(g);
        if (!(k >= 0 && k < state.names.length)) throw new Error(`no light group ${g} (${state.names.join(', ')})`);
        state.weights[k] = Number(w);
      };
      this._groups = state;
    } else if (names.join('\n') !== this._groups.names.join('\n')) {
      throw new Error(`${context}: texture ${index} names light groups ${names} where another names ${this._groups.names}`);
    }
    // each group's BC6H .ktx2 where the glTF names one and the loader reads KTX2 here (as the
    // level's: BC6H without supercompression, a GPU that samples it), else its .hdr
    const read = await Promise.all(groups.map(async (g) => {
      let texture = null;
      if (g.files.ktx2 && this._options.source !== 'hdr') {
        const k = readKtx2Level0(await this._fetch(context, def, g.files.ktx2));
        const why = this._bc6hRefused(k);
        if (!why) texture = this._bc6hTexture(k, g.files.ktx2);
        else console.log(`lmbake-babylon: light group ${g.name}: ${g.files.ktx2}: ${why}; the .hdr instead`);
      }
      const source = texture ? 'ktx2' : 'hdr';
      if (!texture) texture = this._hdrTexture(new Uint8Array(await this._fetch(context, def, g.files.hdr)), g.files.hdr);
      texture.wrapU = texture.wrapV = Texture.CLAMP_ADDRESSMODE;
      texture.anisotropicFilteringLevel = 1;
      return { texture, source };
    }));
    console.log(`lmbake-babylon: texture ${index}: light groups from ${read.map((r, g) => `${names[g]} ${r.source}`).join(', ')}`);
    return read.map((r) => r.texture);
  }

  // Why a KTX2 level 0 is not read as BC6H here, or '' when it is
  _bc6hRefused(k) {
    if (k.vkFormat !== 143) return `vkFormat ${k.vkFormat} (this loader reads BC6H, 143)`;
    if (k.supercompression !== 0) return 'supercompressed (write it with output.ktx2_supercompression: none)';
    if (!this._loader.babylonScene.getEngine().getCaps().bptc) return 'this GPU cannot sample BC6H';
    return '';
  }

  // A BC6H level 0 as a texture. Babylon's raw textures take compressed formats from S3TC only:
  // the texture is made empty, then its level 0 given the blocks (the engine's own compressed upload)
  _bc6hTexture(k, name) {
    const scene = this._loader.babylonScene, engine = scene.getEngine();
    const internal = engine.createRawTexture(null, k.width, k.height, TEXTUREFORMAT_RGBA, false, false, BILINEAR, null, 0);
    engine._bindTextureDirectly(engine._gl.TEXTURE_2D, internal, true);
    engine._uploadCompressedDataToTextureDirectly(internal, COMPRESSED_RGB_BPTC_UNSIGNED_FLOAT_EXT, k.width, k.height, k.data, 0, 0);
    engine._bindTextureDirectly(engine._gl.TEXTURE_2D, null);
    internal.isReady = true;
    const texture = new Texture(null, scene, { noMipmap: true, invertY: false, samplingMode: BILINEAR, internalTexture: internal });
    texture.name = name;
    return texture;
  }

  // A Radiance .hdr as a half-float RGBA texture (Babylon's own RGBE reader)
  _hdrTexture(bytes, name) {
    const info = RGBE_ReadHeader(bytes), rgb = RGBE_ReadPixels(bytes, info), n = info.width * info.height;
    const half = new Uint16Array(4 * n);
    for (let i = 0; i < n; i++) {
      for (let c = 0; c < 3; c++) half[4 * i + c] = toHalf(rgb[3 * i + c]);
      half[4 * i + 3] = 0x3c00;
    }
    const texture = new RawTexture(half, info.width, info.height, TEXTUREFORMAT_RGBA, this._loader.babylonScene, false, false, BILINEAR, TEXTURETYPE_HALF_FLOAT);
    texture.name = name;
    return texture;
  }

  _lightmap(context, index) {
    if (!this._textures.has(index)) this._textures.set(index, this._loadLightmap(context, index));
    return this._textures.get(index);
  }

  // A file beside the glTF, through the loader (its root URL, its request hooks)
  async _fetch(context, property, uri) {
    const view = await this._loader.loadUriAsync(context, property, uri);
    return view.buffer.slice(view.byteOffset, view.byteOffset + view.byteLength);
  }

  async _loadLightmap(context, index) {
    const json = this._loader.gltf;
    const def = json.textures && json.textures[index];
    if (!def) throw new Error(`${context}: texture ${index} does not exist`);
    const extras = (def.extras && def.extras.lightmap) || {}, files = extras.files || {};
    const rgbe = def.extensions && def.extensions.MOZ_texture_rgbe;
    let texture = null, why = '';
    if (files.ktx2 && this._options.source !== 'hdr') {
      const k = readKtx2Level0(await this._fetch(context, def, files.ktx2));
      why = this._bc6hRefused(k);
      if (!why) {
        texture = this._bc6hTexture(k, files.ktx2);
        console.log(`lmbake-babylon: atlas from ${files.ktx2} (BC6H_UFLOAT_BLOCK)`);
      }
      if (why) console.log(`lmbake-babylon: ${files.ktx2}: ${why}; the .hdr instead`);
    }
    if (!texture && rgbe) {
      const img = json.images[rgbe.source];
      texture = this._hdrTexture(new Uint8Array(await this._fetch(context, img, img.uri)), img.uri);
      console.log(`lmbake-babylon: atlas from ${img.uri} (RGBE as half floats)`);
    }
    if (!texture) throw new Error(`${context}: lightmap texture ${index} has neither a BC6H KTX2 this GPU reads nor a .hdr`);
    texture.wrapU = texture.wrapV = Texture.CLAMP_ADDRESSMODE;
    texture.anisotropicFilteringLevel = 1;
    return texture;
  }
}

// Registers the extension with Babylon's glTF loader (once; again replaces it). source: 'ktx2'
// (the default: a BC6H KTX2 when the GPU samples it, else the .hdr) or 'hdr'.
export function registerLmbakeLightmaps({ source = 'ktx2' } = {}) {
  unregisterGLTFExtension(NAME);
  registerGLTFExtension(NAME, true, (loader) => new MozLightmap(loader, { source }));
}
