// lmbake-three: lmbake's lightmaps (lmbake-three.js), light groups (lmbake-groups.js) and light probes (lmbake-probes.js) in
// three.js. README.md says how to load a bake.
export { lmbakeLightmaps, applyLightmapRectangles, applyDirectionalLightmaps, gpuSamples } from './lmbake-three.js';
export { lightGroups, loadLightGroups, patchLightGroups } from './lmbake-groups.js';
export { loadProbes, findTetrahedron, interpolateSH, lightProbeAt, shIrradiance } from './lmbake-probes.js';
