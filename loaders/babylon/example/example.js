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
import { CreateSphere } from '@babylonjs/core/Meshes/Builders/sphereBuilder.js';
import { PBRMaterial } from '@babylonjs/core/Materials/PBR/pbrMaterial.js';
import { registerLmbakeLightmaps, lmbakeProbes, applyProbeLight, lmbakeLightGroups } from 'lmbake-babylon';
import { interpolateSH, shIrradiance } from 'lmbake-probes';

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
// ?groups=w1,w2,...: the light groups' weights (a bake with output.light_groups)
if (params.get('groups')) {
  const groups = lmbakeLightGroups(result.meshes[0]);
  if (!groups) throw new Error('groups= given, but the bake has no light groups');
  params.get('groups').split(',').map(Number).forEach((w, g) => groups.setWeight(g, w));
  console.log(`light groups ${groups.names.join(', ')} at weights ${groups.weights.join(', ')}`);
}

// a camera looking at the level's bounds from the front (glTF's +z side), a little above: the
// view of lmbake-three's example (Babylon's glTF root maps glTF's (x, y, z) to (-x, y, z), and
// its left-handed camera looking down -z has +x of glTF to its right)
const { min, max } = result.meshes[0].getHierarchyBoundingVectors(true);
const centre = min.add(max).scale(0.5), size = max.subtract(min), diag = size.length();
const camera = new UniversalCamera('camera', new Vector3(centre.x, centre.y + 0.15 * size.y, centre.z + (0.5 * diag + 0.5 * size.z)), scene);
camera.setTarget(centre);
camera.fov = (50 * Math.PI) / 180;
camera.fovMode = 0; // vertical
camera.minZ = 0.01 * diag;
camera.maxZ = 10 * diag;
scene.activeCamera = camera;
// the picture (with ?probe=1, the loaders' test, only the probes' float targets are rendered:
// the picture costs a software GPU seconds)
if (!params.get('probe')) {
  await scene.whenReadyAsync();
  scene.render();
}

// The loaders' test: each pixel's lightmap value (E in lux: the lightmap texel x its level x pi,
// the level being intensity / pi; with light groups, their sum at the weights) and its lightmap coordinates (u, v, atlas 0) from the same
// camera into a float target, as lmbake-babylon set the materials up.
class Probe extends MaterialPluginBase {
  constructor(material) {
    super(material, 'LmbakeProbe', 300, { LMBAKE_PROBE_UV: false, LMBAKE_PROBE_VALUE: false, LMBAKE_PROBE_IRRADIANCE: false, LMBAKE_PROBE_NORMAL: false });
    this.mode = 'off';
    this._enable(true);
  }

  prepareDefines(defines) {
    defines.LMBAKE_PROBE_UV = this.mode === 'uv';
    defines.LMBAKE_PROBE_VALUE = this.mode === 'value';
    defines.LMBAKE_PROBE_IRRADIANCE = this.mode === 'irradiance';
    defines.LMBAKE_PROBE_NORMAL = this.mode === 'normal';
  }

  getClassName() { return 'LmbakeProbe'; }

  // the atlas the material's lightmap is (its file's -lightmap-N), written beside the coordinates
  getUniforms() { return { ubo: [{ name: 'lmbAtlas', size: 1, type: 'float' }], fragment: 'uniform float lmbAtlas;\n' }; }

  bindForSubMesh(uniformBuffer) {
    const t = this._material.lightmapTexture, m = t && /-lightmap-(\d+)/.exec(t.name || '');
    uniformBuffer.updateFloat('lmbAtlas', m ? Number(m[1]) : 0);
  }

  getCustomCode(shaderType) {
    if (shaderType !== 'fragment') return null;
    return {
      CUSTOM_FRAGMENT_BEFORE_FRAGCOLOR: `
#if defined(LIGHTMAP) && defined(LMBAKE_PROBE_VALUE) && defined(LMBAKE_GROUPS) && LMBAKE_GROUPS > 0
finalColor = vec4(lmbGroupsSum(vLightmapUV) * vLightmapInfos.y * PI, 1.0);
#elif defined(LIGHTMAP) && defined(LMBAKE_PROBE_VALUE)
finalColor = vec4(texture2D(lightmapSampler, vLightmapUV).rgb * vLightmapInfos.y * PI, 1.0);
#endif
#if defined(LIGHTMAP) && defined(LMBAKE_PROBE_UV)
finalColor = vec4(vLightmapUV, lmbAtlas, 1.0);
#endif
#if !defined(LIGHTMAP) && (defined(LMBAKE_PROBE_VALUE) || defined(LMBAKE_PROBE_UV))
finalColor = vec4(0.0);
#endif
#if defined(REFLECTION) && defined(LMBAKE_PROBE_IRRADIANCE)
finalColor = vec4(reflectionOut.environmentIrradiance * PI, 1.0);
#endif
#if defined(LMBAKE_PROBE_NORMAL)
finalColor = vec4(normalW, 1.0);
#endif
`,
    };
  }
}

window.lmbProbe = async () => {
  const w = 160, h = 120; // as lmbake-three's example: the two pages' pixels correspond
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
// The loaders' probe test: a white sphere at a point of the level (glTF's frame) lit by
// lmbake-babylon's applyProbeLight, rendered as each pixel's environment irradiance (Babylon's
// E / pi, times pi) and world normal, against lmbake-probes' E at that normal taken to glTF's frame
// as Babylon's glTF loader maps it (its root turns by pi about y and mirrors z: x -> -x).
// which: 0 the probes' centroid, 1 halfway from it to the farthest probe, 2 a probe itself.
window.lmbProbeLight = async (which) => {
  const root = result.meshes[0], probes = lmbakeProbes(root);
  if (!probes) throw new Error('no light probes in the bake');
  const P = probes.positions, c = [0, 0, 0];
  for (let i = 0; i < probes.count; i++) for (let k = 0; k < 3; k++) c[k] += P[3 * i + k] / probes.count;
  let far = 0, farD = -1;
  for (let i = 0; i < probes.count; i++) {
    const d = Math.hypot(P[3 * i] - c[0], P[3 * i + 1] - c[1], P[3 * i + 2] - c[2]);
    if (d > farD) { farD = d; far = i; }
  }
  const probeAt = [P[3 * far], P[3 * far + 1], P[3 * far + 2]];
  const point = which === 0 ? c : which === 1 ? c.map((v, k) => 0.5 * (v + probeAt[k])) : probeAt;
  const at = new Vector3(-point[0], point[1], point[2]);
  const sphere = CreateSphere('lmbake probe test', { diameter: 0.2 * diag, segments: 32 }, scene);
  sphere.position = at;
  const mat = new PBRMaterial('white', scene);
  mat.albedoColor.set(1, 1, 1);
  mat.metallic = 0;
  mat.roughness = 1;
  sphere.material = mat;
  sphere.computeWorldMatrix(true);
  applyProbeLight(sphere, probes, root);
  const probe = new Probe(sphere.material);
  const eye = at.add(new Vector3(0, 0.1 * diag, -0.35 * diag));
  const cam = new UniversalCamera('probe camera', eye, scene);
  cam.setTarget(at);
  cam.fov = (40 * Math.PI) / 180;
  cam.minZ = 0.001 * diag;
  const w = 160, h = 120;
  const read = async (mode) => {
    probe.mode = mode;
    probe.markAllDefinesAsDirty();
    const rtt = new RenderTargetTexture('probe light', { width: w, height: h }, scene, false, true, 1 /* TEXTURETYPE_FLOAT */);
    rtt.renderList = [sphere];
    rtt.clearColor = new Color4(0, 0, 0, 0);
    rtt.activeCamera = cam;
    await new Promise((resolve) => { const wait = () => (rtt.isReadyForRendering() ? resolve() : setTimeout(wait, 20)); wait(); });
    rtt.render();
    const px = await rtt.readPixels();
    rtt.dispose();
    return new Float32Array(px.buffer, px.byteOffset, px.byteLength / 4);
  };
  const irradiance = await read('irradiance'), normal = await read('normal');
  const { sh } = interpolateSH(probes, point);
  let n = 0, worst = 0, sum = 0;
  for (let i = 0; i < w * h; i++) {
    if (normal[4 * i + 3] < 0.5) continue;
    const nb = [normal[4 * i], normal[4 * i + 1], normal[4 * i + 2]], len = Math.hypot(...nb);
    const want = shIrradiance(sh, [-nb[0] / len, nb[1] / len, nb[2] / len]);
    const got = [irradiance[4 * i], irradiance[4 * i + 1], irradiance[4 * i + 2]];
    const err = Math.abs(got[0] - want[0]) + Math.abs(got[1] - want[1]) + Math.abs(got[2] - want[2]);
    const rel = err / Math.max(1e-9, want[0] + want[1] + want[2]);
    worst = Math.max(worst, rel);
    sum += rel;
    n++;
  }
  sphere.dispose();
  cam.dispose();
  return { point, pixels: n, worst, mean: n ? sum / n : 0 };
};
window.lmbReady = true;
