// lmbake preview page: loads the bake's glTF with the lightmap plugin and shows it in one of
// the view modes (lit, lightmap, checker, invalid, atlas, records). The URL query drives everything
// (mode, ev, tonemap, view (start: the default, start-view.js; front)|cam, atlas, layer, zoom, at, groups=w1,w2,...: light groups'
// weights (lmbake-groups.js), ui, directional=0 to shade without
// directional lightmaps, lightmap=ktx2 (the default: the KTX2 files the glTF names) or hdr, sphere=x,y,z: the probe-lit
// sphere there, probes=1: the probes as markers) and the page exposes hooks for tests: window.lmbReady, lmbInfo,
// lmbProject, lmbPick, lmbTexelToScreen, lmbAtlasData, lmbProbeSphere, lmbMoveProbeSphere, lmbSetView, lmbSet, lmbCamera;
// gen, kind and rev: the bake of `preview --watch` to show (page/watch.js sets them).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { lightmapPlugin, lightmapScaleOffset, applyDirectionalLightmaps, applyLightmapRectangles, patchInstanceRectangles, gltfNodeIndex, LIGHTMAP_SOURCES } from '/loaders/three/lmbake-three.js';
import { lightmapMaterial, invalidMaterial, checkerMaterial, checkerGeometry } from './materials.js';
import { AtlasView } from './atlas-view.js';
import { Fly } from './fly.js';
import { startView, frontViewPose } from './start-view.js';
import { loadRecords, recordsBaseMaterial, RECORD_RAMP } from './records-view.js';
import { loadProbes, ProbesView, shIrradiance, SPHERE_ALBEDO, probeLitCopies, probeLitMaterial } from './probes-view.js';
import { lightGroups, patchLightGroups } from '/loaders/three/lmbake-groups.js';

const MODES = ['lit', 'lightmap', 'checker', 'invalid', 'atlas', 'records'];
// "none" is three's LinearToneMapping: clamp(colour x 2^EV) (three applies no exposure at all
// with NoToneMapping). Default: AgX, which keeps a bright hotspot from clipping.
const TONEMAPS = { none: THREE.LinearToneMapping, agx: THREE.AgXToneMapping, aces: THREE.ACESFilmicToneMapping, neutral: THREE.NeutralToneMapping };
const FOV = 45; // degrees, vertical

const q = new URLSearchParams(location.search);
const state = {
  mode: q.get('mode') || 'lit', ev: q.get('ev') ?? 'auto', tonemap: q.get('tonemap') || 'agx',
  view: q.get('view') || 'start', cam: q.get('cam'), atlas: Number(q.get('atlas') ?? 0),
  layer: q.get('layer') || 'lightmap', zoom: q.get('zoom') ? Number(q.get('zoom')) : null,
  at: q.get('at') ? q.get('at').split(',').map(Number) : null, ui: q.get('ui') !== '0',
  directional: q.get('directional') !== '0', // directional lightmaps in the lit view, when the bake has them
  lightmap: q.get('lightmap') || 'ktx2', // the lightmap files read: ktx2 (when the glTF names them, else .hdr) or hdr
  sphere: q.get('sphere') ? q.get('sphere').split(',').map(Number) : null, // the probe-lit sphere's centre
  probes: q.get('probes') === '1', // the probes as markers
  groups: q.get('groups') ? q.get('groups').split(',').map(Number) : null, // light groups' weights (null: the bake's scales)
};
const info = (window.lmbInfo = { error: null });
window.lmbReady = false;
const $ = (id) => document.getElementById(id);

function fail(msg) {
  info.error = String(msg);
  $('error').textContent = 'lmbake preview: ' + msg;
  $('error').style.display = 'block';
  console.error('lmbake preview: ' + msg);
}
addEventListener('error', (e) => fail(e.message));
addEventListener('unhandledrejection', (e) => fail(e.reason && e.reason.stack ? e.reason.stack : e.reason));

if (!MODES.includes(state.mode)) throw new Error(`unknown mode '${state.mode}' (one of ${MODES.join(', ')})`);
if (!(state.tonemap in TONEMAPS)) throw new Error(`unknown tonemap '${state.tonemap}' (one of ${Object.keys(TONEMAPS).join(', ')})`);
if (state.ev !== 'auto' && !Number.isFinite((state.ev = Number(state.ev)))) throw new Error(`ev must be a number or auto`);
if (!LIGHTMAP_SOURCES.includes(state.lightmap)) throw new Error(`unknown lightmap '${state.lightmap}' (one of ${LIGHTMAP_SOURCES.join(', ')})`);

const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(devicePixelRatio);
renderer.setSize(innerWidth, innerHeight);
renderer.outputColorSpace = THREE.SRGBColorSpace;
renderer.debug.onShaderError = (gl, program, vs, fs) => fail('shader error: ' + (gl.getShaderInfoLog(fs) || gl.getShaderInfoLog(vs) || gl.getProgramInfoLog(program)));
document.body.prepend(renderer.domElement);

// the bake to show: the server's one, or under `preview --watch` the one the frame's gen and kind name
const sceneInfo = await (await fetch('/scene.json' + (q.has('gen') ? `?gen=${q.get('gen')}&kind=${q.get('kind')}${q.has('rev') ? `&rev=${q.get('rev')}` : ''}` : ''))).json();
document.title = `lmbake preview: ${sceneInfo.name}`;
$('title').textContent = sceneInfo.name;
const atlases = [];
// the renderer: KTX2 lightmaps load through three's KTX2Loader, which needs detectSupport(renderer)
const loader = new GLTFLoader().register(lightmapPlugin(atlases, { source: state.lightmap, renderer }));
const gltf = await loader.loadAsync(sceneInfo.gltf);
const root = gltf.scene;
// Rectangles the lightMap textures do not carry: an InstancedMesh's per-copy _LIGHTMAP_SCALE /
// _LIGHTMAP_OFFSET, a node's extras.lightmap.scaleOffset on a mesh nodes share (before the
// directional lightmaps, which patch the materials this clones)
const rectangles = applyLightmapRectangles(gltf);
const directionalMaterials = state.directional ? await applyDirectionalLightmaps(gltf) : 0;
const lights = [];
root.traverse((o) => { if (o.isLight) lights.push(o); });
for (const l of lights) l.removeFromParent(); // lit = lightmap only, no other lights
const scene = new THREE.Scene();
scene.add(root);
root.updateMatrixWorld(true);
// The irradiance cache's records (null: the bake has none)
const records = await loadRecords(gltf.parser.json, sceneInfo.gltf);
if (records) scene.add(records.points);

// ev=auto (the default): the median E/pi of the non-zero texels maps to 0.18 (middle grey),
// rounded to half an EV. Measured on every 7th texel of every atlas.
function autoEv() {
  const v = [];
  for (const a of atlases) if (a) for (let i = 0; i < a.data.length; i += 28) {
    const l = (0.2126 * a.data[i] + 0.7152 * a.data[i + 1] + 0.0722 * a.data[i + 2]) * a.toLux / Math.PI;
    if (l > 0) v.push(l);
  }
  v.sort((x, y) => x - y);
  return v.length ? Math.max(-12, Math.min(12, Math.round(2 * Math.log2(0.18 / v[v.length >> 1])) / 2)) : 0;
}
let evAuto = state.ev === 'auto';
if (evAuto) state.ev = autoEv();

// The glTF node index an object belongs to (a multi-primitive mesh's meshes are children of
// the node's group), or -1
const gltfNode = (o) => gltfNodeIndex(gltf.parser, o);

// The lightmap rectangle of an entry's copy k (an InstancedMesh with per-instance rectangles:
// uv1 x scale_k + offset_k, then the texture's own rectangle), else the entry's rectangle
function rectOf(e, k) {
  const [S, T, O, P] = e.scaleOffset;
  if (!e.instances || k === undefined || k === null) return e.scaleOffset;
  const i = e.instances, sx = i.scale[2 * k], sy = i.scale[2 * k + 1], ox = i.offset[2 * k], oy = i.offset[2 * k + 1];
  return [sx * S, sy * T, ox * S + O, oy * T + P];
}

// Light groups (lmbake-three's lmbake-groups.js): each group's lightmap, and weights the lit and lightmap views sum them at
// (lightGroups patches the glTF's own materials, the lit view's, as a game's; the lightmap view's
// materials, made below, get the same patch)
const groups = await lightGroups(gltf, sceneInfo.gltf, atlases);
const groupWeights = (w) => {
  if (!groups) { if (w) throw new Error('this bake has no light groups (output.light_groups)'); return; }
  const v = w || groups.scales;
  if (v.length !== groups.names.length || v.some((x) => !Number.isFinite(x) || x < 0)) throw new Error(`groups wants ${groups.names.length} weights >= 0 (${groups.names.join(', ')})`);
  v.forEach((x, g) => { groups.weights[g].value = x; });
};
groupWeights(state.groups);
const withGroups = (m, atlas) => (groups ? patchLightGroups(m, groups, atlas) : m);

// Each mesh and its materials per mode
const GREY = new THREE.MeshBasicMaterial({ color: 0x404040, toneMapped: false });
const entries = [];
const cache = new Map();
const cached = (k, make) => (cache.has(k) ? cache.get(k) : cache.set(k, make()).get(k));
let charts = 0;
root.traverse((o) => {
  if (!o.isMesh) return;
  const lit = o.material, lm = lit.lightMap;
  // scaleOffset: the mesh's rectangle in its atlas (uv1 x scale + offset), from the lightMap's offset / repeat
  const e = { mesh: o, lit, geometry: o.geometry, atlas: lm && lm.userData.atlas !== undefined ? lm.userData.atlas : -1, scaleOffset: lightmapScaleOffset(lm), node: gltfNode(o) };
  // an InstancedMesh with per-instance rectangles: {count, scale, offset} (lmbake-three.js)
  e.instances = (lm && o.isInstancedMesh && o.userData.lightmapInstances) || null;
  const inst = e.instances ? 'inst' : '';
  if (lm) e.lightmap = cached(`lm:${lm.uuid}:${lit.lightMapIntensity}:${lit.side}:${inst}`, () => {
    const m = Object.assign(lightmapMaterial(lm, lit.lightMapIntensity), { side: lit.side });
    return withGroups(e.instances ? patchInstanceRectangles(m) : m, e.atlas);
  });
  if (e.atlas >= 0 && o.geometry.attributes.uv1) {
    const a = atlases[e.atlas], so = e.scaleOffset, instanced = !!e.instances;
    e.invalid = cached(`inv:${e.atlas}:${so}:${lit.lightMapIntensity}:${lit.side}:${inst}`, () => Object.assign(invalidMaterial(a, lit.lightMapIntensity, { scaleOffset: so, instanced }), { side: lit.side }));
    e.checker = cached(`chk:${e.atlas}:${so}:${lit.side}:${inst}`, () => Object.assign(checkerMaterial(a, so, { instanced }), { side: lit.side }));
    e.checkerGeometry = checkerGeometry(o.geometry, charts);
    charts += e.checkerGeometry.userData.charts;
  }
  entries.push(e);
});
const chartMeshes = entries.filter((e) => e.checkerGeometry).map((e) => ({
  atlas: e.atlas, checkerGeometry: e.checkerGeometry, scaleOffset: e.scaleOffset,
  rects: e.instances ? Array.from({ length: e.instances.count }, (_, k) => rectOf(e, k)) : null,
}));
const atlasView = new AtlasView(atlases, chartMeshes);
// atlases[i] is undefined for a lightmap without its .hdr or KTX2 (PNG only): no data to show
if (state.mode === 'atlas' && !atlases[state.atlas]) throw new Error(`atlas ${state.atlas} does not exist or has no .hdr (MOZ_texture_rgbe) or KTX2 file (${atlases.filter(Boolean).length} atlases)`);
if (!['lightmap', 'invalid', 'checker'].includes(state.layer)) throw new Error(`unknown layer '${state.layer}'`);

// Camera: "front" looks along -Z at the centre of the scene's bounding box, from where the
// box's +Z face fills 1/1.1 of the view height (or width, if narrower); fov 45 degrees.
const box = new THREE.Box3().setFromObject(root);
const size = box.getSize(new THREE.Vector3()), centre = box.getCenter(new THREE.Vector3());
const extent = Math.max(size.length(), 1e-3);
const camera = new THREE.PerspectiveCamera(FOV, innerWidth / innerHeight, extent * 1e-3, extent * 100);
const controls = new OrbitControls(camera, renderer.domElement);
// Light probes (probes-view.js): the moving sphere (sphere=x,y,z, or P at the orbit target;
// I/K, J/L, U/O move it) and the probes as markers (probes=1, or G)
const probes = await loadProbes(gltf.parser);
const probesView = probes ? new ProbesView(probes, 0.35 * (probes.spacing || extent * 0.1)) : null;
if (probesView) {
  scene.add(probesView.sphere, probesView.markers);
  probesView.markers.visible = state.probes;
  if (state.sphere) {
    if (state.sphere.length !== 3 || state.sphere.some((v) => !Number.isFinite(v))) throw new Error('sphere wants x,y,z');
    probesView.moveTo(state.sphere);
  }
} else if (state.sphere || state.probes) throw new Error('this bake has no light probes (probes.auto: false and no probes.volumes)');
// Meshes without a lightmap (props the bake lit by its probes, meshes the config excluded): lit by
// the probes at each copy's centre in the lit view (their material's colour) and the lightmap view
// (white), as an engine lights them (probes-view.js)
if (probes) for (const e of entries) {
  if (e.lit.lightMap) continue;
  e.probeLit = probeLitCopies(probes, e.mesh);
  e.probeLitAlbedo = e.lit.color ? e.lit.color.clone() : new THREE.Color(1, 1, 1);
  const normals = !!e.geometry.attributes.normal;
  e.probeLitLit = probeLitMaterial(e.probeLit, e.probeLitAlbedo, normals);
  e.probeLitWhite = probeLitMaterial(e.probeLit, new THREE.Color(1, 1, 1), normals);
}
const fly = new Fly(camera, renderer.domElement, extent * 0.3);

function frontView() {
  const pose = frontViewPose(box, camera.aspect, FOV);
  camera.position.copy(pose.position);
  controls.target.copy(pose.target);
  camera.lookAt(pose.target);
}
// The camera for view (start, front) or cam (px,py,pz,tx,ty,tz, which wins): at load and lmbSet
function placeCamera(view, cam) {
  if (cam) {
    const c = cam.split(',').map(Number);
    if (c.length !== 6 || c.some((v) => !Number.isFinite(v))) throw new Error(`cam wants px,py,pz,tx,ty,tz`);
    camera.position.set(c[0], c[1], c[2]); controls.target.set(c[3], c[4], c[5]); camera.lookAt(controls.target);
  } else if (view === 'front') frontView();
  else if (view === 'start') {
    const start = startView(gltf, root, box, camera.aspect, FOV);
    if (start) {
      camera.position.copy(start.position); controls.target.copy(start.target); camera.lookAt(start.target);
    } else frontView();
    info.startView = start ? start.from : 'front';
    info.startProbe = startView.last || null; // the candidates: eye, blocked, walls met of 16, median distance
    info.startScores = startView.scores || null; // inside against front: what each view shows (viewScore)
  } else throw new Error(`unknown view '${view}' (start, front, or cam=px,py,pz,tx,ty,tz)`);
  controls.update();
}
placeCamera(state.view, state.cam);

// Applying the state
let dirty = true;
const requestRender = () => { dirty = true; };
controls.addEventListener('change', requestRender);

function apply() {
  const m = state.mode;
  for (const e of entries) {
    let mat = e.probeLitLit || e.lit, geom = e.geometry;
    if (m === 'lightmap') mat = e.lightmap || e.probeLitWhite || GREY;
    else if (m === 'records') mat = e.lightmap ? (e.recordsBase ||= recordsBaseMaterial(e.lightmap)) : GREY;
    else if (m === 'invalid') mat = e.invalid || GREY;
    else if (m === 'checker') { mat = e.checker || GREY; geom = e.checkerGeometry || e.geometry; }
    e.mesh.material = mat; e.mesh.geometry = geom;
  }
  if (records) records.points.visible = m === 'records';
  $('noRecords').classList.toggle('hidden', m !== 'records' || !!records);
  renderer.toneMapping = TONEMAPS[state.tonemap];
  renderer.toneMappingExposure = Math.pow(2, state.ev);
  atlasView.atlas = state.atlas; atlasView.layer = state.layer;
  if (m === 'atlas') atlasView.layout(innerWidth, innerHeight, state.zoom, state.at);
  controls.enabled = m !== 'atlas' && !fly.enabled;
  updateInfo();
  requestRender();
}

const isInstancePatched = (m) => m.customProgramCacheKey().includes('lmbake-instance-rect');
function updateInfo() {
  Object.assign(info, {
    gltf: sceneInfo.name, mode: state.mode, ev: state.ev, evAuto, tonemap: state.tonemap, view: state.cam ? 'cam' : state.view,
    groups: groups ? { names: groups.names, scales: groups.scales, weights: groups.weights.map((w) => w.value), sources: groups.sources } : null,
    camera: { position: camera.position.toArray(), target: controls.target.toArray(), fov: FOV },
    bounds: { min: box.min.toArray(), max: box.max.toArray() },
    canvas: { width: innerWidth, height: innerHeight, pixelRatio: devicePixelRatio },
    // uri: the file read (source ktx2 or hdr; format: its texel format; loader: KTX2Loader or
    // HDRLoader; gpu: the texture the views sample); hdr: the .hdr's uri either way
    atlases: atlases.filter(Boolean).map((a) => ({ index: a.index, uri: a.uri, source: a.source, format: a.format, loader: a.loader, gpu: a.gpu, hdr: a.hdr, fallback: a.fallback, scale: a.scale, width: a.width, height: a.height, zeroTexels: a.zeroTexels })),
    lightmap: state.lightmap,
    meshes: entries.length, lightmapped: entries.filter((e) => e.atlas >= 0).length,
    // InstancedMeshes: copies, their per-instance attributes (geometry.attributes, InstancedBufferAttribute),
    // whether each copy reads its own rectangle (_LIGHTMAP_SCALE / _LIGHTMAP_OFFSET)
    instancedMeshes: entries.filter((e) => e.mesh.isInstancedMesh).map((e) => ({
      object: e.mesh.name, node: e.node, count: e.mesh.count, atlas: e.atlas, rectangles: !!e.instances,
      instanceAttributes: Object.entries(e.geometry.attributes).filter(([, a]) => a.isInstancedBufferAttribute).map(([k, a]) => ({ name: k, itemSize: a.itemSize, count: a.count })),
      litPatched: isInstancePatched(e.lit), sharesMaterial: entries.some((x) => x !== e && x.lit === e.lit),
    })),
    patchedOthers: entries.filter((e) => !e.mesh.isInstancedMesh && isInstancePatched(e.lit)).length, // 0: the patch stays on InstancedMeshes' own materials
    // meshes given their node's extras.lightmap.scaleOffset (one mesh shared by several nodes)
    perNodeRectangles: rectangles.perNode.map((r) => ({ object: r.object.name, node: r.node, scaleOffset: r.scaleOffset })),
    charts: chartMeshes.reduce((s, c) => s + c.checkerGeometry.userData.charts, 0),
    directionalMaterials,
    records: records ? { count: records.count, reachMin: records.reachMin, reachMax: records.reachMax, uri: records.uri } : { count: 0 },
    atlasView: { atlas: atlasView.atlas, layer: atlasView.layer, zoom: atlasView.zoom, originX: atlasView.originX, originY: atlasView.originY },
    // meshes without a lightmap lit by the probes: copies, and how each copy's SH was interpolated
    probeLit: entries.filter((e) => e.probeLit).map((e) => ({ object: e.mesh.name, node: e.node, copies: e.probeLit.copies, interpolation: e.probeLit.how })),
    probes: probesView ? { count: probes.count, spacing: probes.spacing, markers: probesView.markers.visible,
      sphere: probesView.sphere.visible ? { at: probesView.at, radius: probesView.sphere.geometry.parameters.radius, probes: probesView.used } : null } : { count: 0 },
  });
}

function render() {
  if (state.mode === 'atlas') atlasView.render(renderer);
  else renderer.render(scene, camera);
}

// UI
$('panel').classList.toggle('hidden', !state.ui);
$('hover').classList.toggle('hidden', !state.ui);
$('help').textContent = 'drag: orbit/look, wheel: zoom, F: fly (WASD, Q/E, Shift), R: front view, 1-6: views' +
  (probesView ? ', P: probe-lit sphere (I/K J/L U/O move it), G: probes' : '');
$('atlas').innerHTML = atlases.filter(Boolean).map((a) => `<option value="${a.index}">${a.index}: ${a.uri} (${a.width}x${a.height})</option>`).join('');
// one slider per light group (lmbake-groups.js): its weight in the lit and lightmap views
if (groups) {
  $('groups').innerHTML = groups.names.map((n, g) => `<label>${n} <input id="group${g}" type="range" min="0" max="${Math.max(4, 2 * groups.scales[g])}" step="0.05"> <span id="groupText${g}"></span></label>`).join('');
  groups.names.forEach((_, g) => $(`group${g}`).addEventListener('input', (e) => { groups.weights[g].value = Number(e.target.value); sync(); updateInfo(); requestRender(); }));
}
const sync = () => {
  for (let g = 0; groups && g < groups.names.length; g++) {
    $(`group${g}`).value = groups.weights[g].value;
    $(`groupText${g}`).textContent = `x ${groups.weights[g].value.toFixed(2)}`;
  }
  $('mode').value = state.mode; $('ev').value = state.ev; $('evText').textContent = state.ev.toFixed(1);
  $('tonemap').value = state.tonemap; $('atlas').value = state.atlas; $('layer').value = state.layer;
  $('atlasControls').classList.toggle('hidden', state.mode !== 'atlas');
  $('fly').checked = fly.enabled;
  const u = new URL(location.href);
  for (const k of ['mode', 'ev', 'tonemap', 'atlas', 'layer']) u.searchParams.set(k, state[k]);
  if (groups) u.searchParams.set('groups', groups.weights.map((w) => w.value).join(','));
  history.replaceState(null, '', u);
};
const onInput = (id, f) => $(id).addEventListener('input', (e) => { f(e.target.value); sync(); apply(); });
onInput('mode', (v) => { state.mode = v; });
onInput('ev', (v) => { state.ev = Number(v); });
onInput('tonemap', (v) => { state.tonemap = v; });
onInput('atlas', (v) => { state.atlas = Number(v); state.zoom = null; state.at = null; });
onInput('layer', (v) => { state.layer = v; });
const setFly = (on) => {
  if (!on && fly.enabled) { // orbit around the point in front of the camera
    const d = camera.position.distanceTo(controls.target);
    controls.target.copy(camera.position).add(new THREE.Vector3(0, 0, -d).applyQuaternion(camera.quaternion));
  }
  fly.enabled = on; sync(); apply();
};
$('fly').addEventListener('change', (e) => setFly(e.target.checked));
$('reset').addEventListener('click', () => { setFly(false); frontView(); controls.update(); requestRender(); });
addEventListener('keydown', (e) => {
  if (['INPUT', 'SELECT'].includes(e.target.tagName)) return;
  if (e.code === 'KeyF') setFly(!fly.enabled);
  else if (e.code === 'KeyR') $('reset').click();
  else if (/^Digit[1-6]$/.test(e.code)) { state.mode = MODES[Number(e.code[5]) - 1]; sync(); apply(); }
  else if (probesView) moveSphereByKey(e.code);
});
// P: the sphere at the orbit target (or hidden again); I/K, J/L, U/O: -z/+z, -x/+x, +y/-y by half
// the probe spacing; G: the probes' markers
function moveSphereByKey(code) {
  const step = 0.5 * (probes.spacing || extent * 0.05);
  const moves = { KeyI: [0, 0, -step], KeyK: [0, 0, step], KeyJ: [-step, 0, 0], KeyL: [step, 0, 0], KeyU: [0, step, 0], KeyO: [0, -step, 0] };
  if (code === 'KeyP') {
    if (probesView.sphere.visible) probesView.sphere.visible = false;
    else probesView.moveTo(controls.target.toArray());
  } else if (code === 'KeyG') probesView.markers.visible = !probesView.markers.visible;
  else if (moves[code] && probesView.sphere.visible) probesView.moveTo(probesView.at.map((v, k) => v + moves[code][k]));
  else return;
  updateInfo(); requestRender();
}
addEventListener('resize', () => {
  renderer.setSize(innerWidth, innerHeight);
  camera.aspect = innerWidth / innerHeight; camera.updateProjectionMatrix();
  if (state.mode === 'atlas') atlasView.updateCamera(innerWidth, innerHeight);
  updateInfo(); requestRender();
});

// Atlas view: drag pans, wheel zooms about the cursor
let pan = null;
renderer.domElement.addEventListener('pointerdown', (e) => { if (state.mode === 'atlas') pan = [e.clientX, e.clientY]; });
addEventListener('pointerup', () => { pan = null; });
renderer.domElement.addEventListener('wheel', (e) => {
  if (state.mode !== 'atlas') return;
  atlasView.zoomAt(e.deltaY < 0 ? 1.25 : 0.8, e.offsetX, e.offsetY, innerWidth, innerHeight);
  updateInfo(); requestRender();
}, { passive: true });

// Hover: texel coordinates and the stored irradiance (from the .hdr or KTX2 data, x toLux: E in lux)
const raycaster = new THREE.Raycaster();
function pick(px, py) {
  const ndc = new THREE.Vector2((px / innerWidth) * 2 - 1, -(py / innerHeight) * 2 + 1);
  raycaster.setFromCamera(ndc, camera);
  const hit = raycaster.intersectObject(root, true)[0];
  if (!hit) return null;
  const e = entries.find((x) => x.mesh === hit.object);
  const r = { object: hit.object.name, point: hit.point.toArray(), distance: hit.distance, atlas: e ? e.atlas : -1 };
  if (e) r.node = e.node;
  if (hit.instanceId !== undefined) r.instance = hit.instanceId; // an InstancedMesh's copy
  if (hit.face) { // the triangle's normal in world space (through the copy's matrix too)
    const m = hit.object.matrixWorld.clone();
    if (hit.instanceId !== undefined) m.multiply(hit.object.getMatrixAt(hit.instanceId, new THREE.Matrix4()));
    r.faceNormal = hit.face.normal.clone().applyMatrix3(new THREE.Matrix3().getNormalMatrix(m)).normalize().toArray();
  }
  if (hit.uv1) {
    // uv1: the mesh's TEXCOORD_1; lightmapUv: where the atlas is read, uv1 x scale + offset
    // (an InstancedMesh's copy: its own rectangle, scaleOffset)
    r.uv1 = [hit.uv1.x, hit.uv1.y];
    const so = e ? rectOf(e, hit.instanceId) : [1, 1, 0, 0];
    r.scaleOffset = so;
    r.lightmapUv = [hit.uv1.x * so[0] + so[2], hit.uv1.y * so[1] + so[3]];
    const a = atlases[r.atlas];
    const clamp = (t, n) => Math.max(0, Math.min(n - 1, Math.floor(t * n)));
    if (a) r.texel = [clamp(r.lightmapUv[0], a.width), clamp(r.lightmapUv[1], a.height)];
  }
  return r;
}
addEventListener('pointermove', (e) => {
  if (e.target !== renderer.domElement) return;
  if (pan && state.mode === 'atlas') {
    atlasView.pan(e.clientX - pan[0], e.clientY - pan[1], innerWidth, innerHeight); pan = [e.clientX, e.clientY];
    updateInfo(); requestRender();
  }
  let t = null;
  if (state.mode === 'atlas') t = atlasView.texelAt(e.offsetX, e.offsetY);
  else { const h = pick(e.offsetX, e.offsetY); if (h && h.texel) t = { atlas: h.atlas, x: h.texel[0], y: h.texel[1], object: h.instance !== undefined ? `${h.object} #${h.instance}` : h.object }; }
  if (t && !t.rgb) { const a = atlases[t.atlas], i = 4 * (t.y * a.width + t.x); t.rgb = Array.from(a.data.subarray(i, i + 3), (v) => v * a.toLux); }
  const f = (v) => v.toPrecision(4);
  $('hover').textContent = t ? `atlas ${t.atlas} texel (${t.x}, ${t.y})${t.object ? '  ' + t.object : ''}\nE = ${t.rgb.map(f).join(' ')} lux   E/pi = ${t.rgb.map((v) => f(v / Math.PI)).join(' ')}` : '';
});

// Hooks for tests (pixel coordinates: CSS pixels from the canvas's top-left)
// Record i: its world position, reach and the ramp colour (sRGB 8-bit) it is drawn in.
window.lmbRecord = (i) => records && i < records.count ? {
  point: Array.from(records.records.subarray(4 * i, 4 * i + 3)), reach: records.records[4 * i + 3], colour: RECORD_RAMP[records.rampIndex(i)],
} : null;
// The probe-lit sphere: where it is, the irradiance SH lighting it (E, lux), the E and the linear
// colour (albedo / pi x E) it shows for normal n; and moving it.
window.lmbProbeSphere = (n) => probesView && probesView.sphere.visible ? {
  at: probesView.at, sh: Array.from(probesView.sh), probes: probesView.used, interpolation: probesView.how, albedo: SPHERE_ALBEDO,
  irradiance: n ? shIrradiance(probesView.sh, n) : null,
  linear: n ? shIrradiance(probesView.sh, n).map((e) => Math.max(0, e) * SPHERE_ALBEDO / Math.PI) : null,
} : null;
// A mesh without a lightmap lit by the probes (object: its name): copy k's centre, SH, albedo,
// and for normal n the E and the linear colour (albedo / pi x E) the lit view shows.
window.lmbProbeLit = (object, k, n) => {
  const e = entries.find((x) => x.probeLit && x.mesh.name === object);
  if (!e || !(k >= 0 && k < e.probeLit.copies)) return null;
  const sh = e.probeLit.sh.subarray(27 * k, 27 * k + 27), albedo = e.probeLitAlbedo.toArray();
  const E = n ? shIrradiance(sh, n) : null;
  return { centre: e.probeLit.centres[k], sh: Array.from(sh), albedo, irradiance: E,
    linear: E ? E.map((x, c) => Math.max(0, x) * albedo[c] / Math.PI) : null };
};
// The camera (px,py,pz,tx,ty,tz as the cam parameter) and the exposure, without a reload.
window.lmbSetView = (cam, ev) => {
  const c = cam.split(',').map(Number);
  camera.position.set(c[0], c[1], c[2]); controls.target.set(c[3], c[4], c[5]); camera.lookAt(controls.target);
  controls.update();
  if (ev !== undefined) state.ev = ev;
  apply();
};
// The view parameters of the URL (mode, ev, tonemap, view|cam, atlas, layer, zoom, at, groups) without a
// reload, each missing one at its default as in a fresh page; those read at load only (lightmap,
// directional, sphere, probes, ui) cannot change. A test's shots of one bake share a page this way
// (a page takes ~2 s to open in SwiftShader, a switch ~0.3 s). Returns lmbInfo after the frame.
window.lmbSet = (p) => {
  for (const k of Object.keys(p)) if (!['mode', 'ev', 'tonemap', 'view', 'cam', 'atlas', 'layer', 'zoom', 'at', 'groups'].includes(k)) throw new Error(`lmbSet: '${k}' is read at load only`);
  groupWeights(p.groups !== undefined ? String(p.groups).split(',').map(Number) : null);
  const mode = p.mode ?? 'lit', tonemap = p.tonemap ?? 'agx', layer = p.layer ?? 'lightmap', atlas = Number(p.atlas ?? 0);
  const ev = p.ev === undefined || p.ev === 'auto' ? 'auto' : Number(p.ev);
  if (!MODES.includes(mode)) throw new Error(`unknown mode '${mode}' (one of ${MODES.join(', ')})`);
  if (!(tonemap in TONEMAPS)) throw new Error(`unknown tonemap '${tonemap}' (one of ${Object.keys(TONEMAPS).join(', ')})`);
  if (ev !== 'auto' && !Number.isFinite(ev)) throw new Error('ev must be a number or auto');
  if (!['lightmap', 'invalid', 'checker'].includes(layer)) throw new Error(`unknown layer '${layer}'`);
  if (mode === 'atlas' && !atlases[atlas]) throw new Error(`atlas ${atlas} does not exist or has no .hdr or KTX2 file`);
  placeCamera(p.view ?? 'start', p.cam ?? null);
  Object.assign(state, { mode, tonemap, layer, atlas, view: p.view ?? 'start', cam: p.cam ?? null,
    zoom: p.zoom !== undefined ? Number(p.zoom) : null, at: p.at !== undefined ? String(p.at).split(',').map(Number) : null,
    ev: ev === 'auto' ? autoEv() : ev });
  evAuto = ev === 'auto';
  sync(); apply();
  render(); dirty = false;
  return JSON.parse(JSON.stringify(info));
};
// The camera now (the watch page carries it over to the next bake's frame).
window.lmbCamera = () => ({ position: camera.position.toArray(), target: controls.target.toArray() });
window.lmbMoveProbeSphere = (x, y, z) => { if (!probesView) return false; probesView.moveTo([x, y, z]); updateInfo(); requestRender(); return true; };
window.lmbProject = (x, y, z) => {
  const v = new THREE.Vector3(x, y, z).project(camera);
  return { x: (v.x + 1) / 2 * innerWidth, y: (1 - v.y) / 2 * innerHeight, inFront: v.z < 1 };
};
// What the centre of pixel (px, py) sees: object, glTF node, instance (an InstancedMesh's copy),
// world point, uv1, scaleOffset and lightmapUv (the atlas uv: uv1 through the mesh's or the
// copy's lightmap rectangle), atlas and texel.
window.lmbPick = (px, py) => pick(px + 0.5, py + 0.5);
// Where the centre of texel (x, y) of an atlas is drawn: in the atlas view, the pixel; in
// the 3D views, the projection of the surface point with that UV1 (visible: a pick there
// sees the same atlas within a texel). Triangles are matched in atlas uv (uv1 x scale + offset,
// an InstancedMesh's copies each at its own rectangle; instance: the copy's index).
window.lmbTexelToScreen = (atlasIndex, x, y) => {
  if (state.mode === 'atlas') return { ...atlasView.texelToScreen(x, y), visible: atlasIndex === atlasView.atlas };
  const a = atlases[atlasIndex];
  const p = new THREE.Vector3((x + 0.5) / a.width, (y + 0.5) / a.height, 0);
  const A = new THREE.Vector3(), B = new THREE.Vector3(), C = new THREE.Vector3(), bc = new THREE.Vector3(), im = new THREE.Matrix4();
  for (const e of entries) {
    if (e.atlas !== atlasIndex) continue;
    const g = e.geometry, uv = g.attributes.uv1, pos = g.attributes.position;
    if (!uv) continue;
    const idx = g.index ? g.index.array : null, n = idx ? idx.length : pos.count;
    // the uv1 bounds: a copy whose rectangle does not hold p is skipped
    let u0 = Infinity, v0 = Infinity, u1 = -Infinity, v1 = -Infinity;
    for (let i = 0; i < uv.count; i++) { u0 = Math.min(u0, uv.getX(i)); u1 = Math.max(u1, uv.getX(i)); v0 = Math.min(v0, uv.getY(i)); v1 = Math.max(v1, uv.getY(i)); }
    for (let k = 0; k < (e.instances ? e.instances.count : 1); k++) {
      const [su, sv, ou, ov] = rectOf(e, e.instances ? k : null);
      if (p.x < u0 * su + ou || p.x > u1 * su + ou || p.y < v0 * sv + ov || p.y > v1 * sv + ov) continue;
      const toAtlas = (v, i) => v.set(uv.getX(i) * su + ou, uv.getY(i) * sv + ov, 0);
      for (let t = 0; t < n; t += 3) {
        const i0 = idx ? idx[t] : t, i1 = idx ? idx[t + 1] : t + 1, i2 = idx ? idx[t + 2] : t + 2;
        toAtlas(A, i0); toAtlas(B, i1); toAtlas(C, i2);
        // inside, or on an edge within rounding (a texel centre on the diagonal two triangles share)
        if (THREE.Triangle.getBarycoord(p, A, B, C, bc) === null || Math.min(bc.x, bc.y, bc.z) < -1e-6) continue;
        const w = new THREE.Vector3().fromBufferAttribute(pos, i0).multiplyScalar(bc.x)
          .add(new THREE.Vector3().fromBufferAttribute(pos, i1).multiplyScalar(bc.y))
          .add(new THREE.Vector3().fromBufferAttribute(pos, i2).multiplyScalar(bc.z));
        if (e.mesh.isInstancedMesh) w.applyMatrix4(e.mesh.getMatrixAt(k, im));
        w.applyMatrix4(e.mesh.matrixWorld);
        const s = window.lmbProject(w.x, w.y, w.z);
        const h = pick(s.x, s.y);
        const visible = s.inFront && s.x >= 0 && s.y >= 0 && s.x < innerWidth && s.y < innerHeight && !!h && h.atlas === atlasIndex &&
          !!h.texel && Math.abs(h.texel[0] - x) <= 1 && Math.abs(h.texel[1] - y) <= 1;
        const r = { x: s.x, y: s.y, visible, object: e.mesh.name, point: w.toArray() };
        if (e.mesh.isInstancedMesh) r.instance = k;
        return r;
      }
    }
  }
  return null;
};

// An atlas's float data as stored in the file read (RGBA float32, row 0 = the top; before
// toLux) for tests: {width, height, source, uri, base64} (the bytes, little-endian), or null.
window.lmbAtlasData = (i) => {
  const a = atlases[i];
  if (!a) return null;
  const bytes = new Uint8Array(a.data.buffer, a.data.byteOffset, a.data.byteLength);
  let bin = '';
  for (let k = 0; k < bytes.length; k += 0x8000) bin += String.fromCharCode.apply(null, bytes.subarray(k, k + 0x8000));
  return { width: a.width, height: a.height, source: a.source, uri: a.uri, base64: btoa(bin) };
};

// Render loop: only when something changed (SwiftShader is slow); ready after the first frame
sync();
apply();
let last = performance.now();
function frame(now) {
  if (fly.update((now - last) / 1000)) { dirty = true; updateInfo(); }
  last = now;
  if (dirty) { dirty = false; render(); }
  requestAnimationFrame(frame);
}
render(); dirty = false;
requestAnimationFrame((t) => { last = t; if (!info.error) window.lmbReady = true; requestAnimationFrame(frame); });
