// lmbake-three's example (index.html): the five lines an engine project writes, then a camera
// that frames the level. ?probe=1 adds window.lmbProbe() for the loaders' test
// (tests/preview/loader_pixels.mjs).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { lmbakeLightmaps } from 'lmbake-three';

const params = new URLSearchParams(location.search);
const renderer = new THREE.WebGLRenderer({ antialias: false });
renderer.setSize(640, 480);
document.body.appendChild(renderer.domElement);
const scene = new THREE.Scene();

// -- what a project writes --
const loader = new GLTFLoader().register(lmbakeLightmaps({ renderer, source: params.get('source') || 'ktx2' }));
const gltf = await loader.loadAsync(params.get('gltf'));
scene.add(gltf.scene);
// --

// a camera looking at the level's bounds from the front, a little above
const box = new THREE.Box3().setFromObject(gltf.scene), size = box.getSize(new THREE.Vector3()), centre = box.getCenter(new THREE.Vector3());
const camera = new THREE.PerspectiveCamera(50, 640 / 480, 0.01 * size.length(), 10 * size.length());
camera.position.copy(centre).add(new THREE.Vector3(0, 0.15 * size.y, 0.5 * size.length() + 0.5 * size.z));
camera.lookAt(centre);
if (!params.get('probe')) renderer.render(scene, camera); // with ?probe=1 (the loaders' test) only its float targets

// The loaders' test: each pixel's lightmap value (E in lux: the lightmap times its intensity,
// three's lightMap as a MeshBasicMaterial shows it, x pi) and its lightmap coordinates (u, v,
// atlas) from the same camera, into float targets, as the materials lmbake-three made them
// (their lightMap, intensity, rectangles and per-copy patches).
window.lmbProbe = () => {
  const w = 160, h = 120, target = new THREE.WebGLRenderTarget(w, h, { type: THREE.FloatType });
  const read = (make) => {
    const saved = new Map();
    gltf.scene.traverse((o) => { if (o.isMesh) { saved.set(o, o.material); o.material = make(o.material); } });
    renderer.setRenderTarget(target);
    renderer.setClearColor(0x000000, 0);
    renderer.clear();
    renderer.render(scene, camera);
    const px = new Float32Array(4 * w * h);
    renderer.readRenderTargetPixels(target, 0, 0, w, h, px);
    renderer.setRenderTarget(null);
    for (const [o, m] of saved) o.material = m;
    return Array.from(px);
  };
  const patched = (m, key, patch) => {
    const c = m.clone(); // keeps onBeforeCompile (a per-copy rectangle patch) as an own property
    if (Object.prototype.hasOwnProperty.call(m, 'onBeforeCompile')) c.onBeforeCompile = m.onBeforeCompile;
    const prev = c.onBeforeCompile, prevKey = m.customProgramCacheKey();
    c.onBeforeCompile = (shader, r) => { prev.call(c, shader, r); patch(shader); };
    c.customProgramCacheKey = () => `${prevKey}|${key}`;
    return c;
  };
  const out = (m, glsl) => !m.lightMap ? new THREE.MeshBasicMaterial({ color: 0, transparent: true, opacity: 0 })
    : patched(m, glsl, (shader) => {
      shader.fragmentShader = shader.fragmentShader.replace('#include <dithering_fragment>', `#include <dithering_fragment>\n${glsl}`);
    });
  const value = read((m) => out(m, 'gl_FragColor = vec4(texture2D(lightMap, vLightMapUv).rgb * lightMapIntensity, 1.0);'));
  const uv = read((m) => out(m, `gl_FragColor = vec4(vLightMapUv, ${(m.lightMap && m.lightMap.userData.atlas) || 0}.0, 1.0);`));
  return { width: w, height: h, value, uv };
};
window.lmbReady = true;
