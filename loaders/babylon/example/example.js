// lmbake-babylon's example (index.html): the lines an engine project writes, then a camera that
// frames the level. ?probe=1 adds window.lmbProbe() for the loaders' test
// (tests/loaders/loader_pixels.mjs).
import { Engine } from '@babylonjs/core/Engines/engine.js';
import { Scene } from '@babylonjs/core/scene.js';
import { ImportMeshAsync } from '@babylonjs/core/Loading/sceneLoader.js';
import { UniversalCamera } from '@babylonjs/core/Cameras/universalCamera.js';
import { Vector3 } from '@babylonjs/core/Maths/math.vector.js';
import { Color4 } from '@babylonjs/core/Maths/math.color.js';
import { RenderTargetTexture } from '@babylonjs/core/Materials/Textures/renderTargetTexture.js';
import { MaterialPluginBase } from '@babylonjs/core/Materials/materialPluginBase.js';
import '@babylonjs/core/Materials/PBR/pbrMaterial.js';
import '@babylonjs/loaders/glTF/2.0/index.js';
import { registerLmbakeLightmaps } from 'lmbake-babylon';

const params = new URLSearchParams(location.search);
const canvas = document.getElementById('c');
const engine = new Engine(canvas, false, { preserveDrawingBuffer: true });
const scene = new Scene(engine);
scene.clearColor = new Color4(0, 0, 0, 1);

// -- what a project writes --
registerLmbakeLightmaps({ source: params.get('source') || 'ktx2' });
const gltfUrl = params.get('gltf');
const result = await ImportMeshAsync(gltfUrl, scene);
// --

// a camera looking at the level's bounds from the front, a little above (glTF's +z is Babylon's -z)
const { min, max } = result.meshes[0].getHierarchyBoundingVectors(true);
const centre = min.add(max).scale(0.5), size = max.subtract(min), diag = size.length();
const camera = new UniversalCamera('camera', new Vector3(centre.x, centre.y + 0.15 * size.y, centre.z - (0.5 * diag + 0.5 * size.z)), scene);
camera.setTarget(centre);
camera.fov = (50 * Math.PI) / 180;
camera.fovMode = 0; // vertical
camera.minZ = 0.01 * diag;
camera.maxZ = 10 * diag;
scene.activeCamera = camera;
await scene.whenReadyAsync();
scene.render();

// The loaders' test: each pixel's lightmap value (E in lux: the lightmap texel x its level x pi,
// the level being intensity / pi) and its lightmap coordinates (u, v, atlas 0) from the same
// camera into a float target, as lmbake-babylon set the materials up.
class Probe extends MaterialPluginBase {
  constructor(material) {
    super(material, 'LmbakeProbe', 300, { LMBAKE_PROBE_UV: false, LMBAKE_PROBE_VALUE: false });
    this.mode = 'off';
    this._enable(true);
  }

  prepareDefines(defines) {
    defines.LMBAKE_PROBE_UV = this.mode === 'uv';
    defines.LMBAKE_PROBE_VALUE = this.mode === 'value';
  }

  getClassName() { return 'LmbakeProbe'; }

  getCustomCode(shaderType) {
    if (shaderType !== 'fragment') return null;
    return {
      CUSTOM_FRAGMENT_BEFORE_FRAGCOLOR: `
#if defined(LIGHTMAP) && defined(LMBAKE_PROBE_VALUE)
finalColor = vec4(texture2D(lightmapSampler, vLightmapUV).rgb * vLightmapInfos.y * PI, 1.0);
#endif
#if defined(LIGHTMAP) && defined(LMBAKE_PROBE_UV)
finalColor = vec4(vLightmapUV, 0.0, 1.0);
#endif
#if !defined(LIGHTMAP) && (defined(LMBAKE_PROBE_VALUE) || defined(LMBAKE_PROBE_UV))
finalColor = vec4(0.0);
#endif
`,
    };
  }
}

window.lmbProbe = async () => {
  const w = 320, h = 240;
  const probes = [];
  for (const m of scene.materials) if (m.lightmapTexture !== undefined) probes.push(new Probe(m));
  const read = async (mode) => {
    for (const p of probes) { p.mode = mode; p.markAllDefinesAsDirty(); }
    const rtt = new RenderTargetTexture('probe', { width: w, height: h }, scene, false, true, 1 /* TEXTURETYPE_FLOAT */);
    rtt.renderList = scene.meshes.slice();
    rtt.clearColor = new Color4(0, 0, 0, 0);
    rtt.activeCamera = camera;
    await new Promise((resolve) => { const wait = () => (rtt.isReadyForRendering() ? resolve() : setTimeout(wait, 20)); wait(); });
    scene.executeWhenReady(() => {});
    rtt.render();
    const px = await rtt.readPixels();
    rtt.dispose();
    return Array.from(new Float32Array(px.buffer, px.byteOffset, px.byteLength / 4));
  };
  const value = await read('value');
  const uv = await read('uv');
  for (const p of probes) { p.mode = 'off'; p.markAllDefinesAsDirty(); }
  return { width: w, height: h, value, uv };
};
window.lmbReady = true;
