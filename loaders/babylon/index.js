// lmbake-babylon: lmbake's lightmaps (lmbake-babylon.js) and light probes
// (lmbake-babylon-probes.js) in Babylon.js. README.md says how to load a bake.
export { registerLmbakeLightmaps, lmbakeLightGroups, readKtx2Level0, INSTANCE_RECT } from './lmbake-babylon.js';
export { lmbakeProbes, loadProbes, sphericalPolynomialAt, probeLightTexture, applyProbeLight } from './lmbake-babylon-probes.js';
