// lmbake-babylon: lmbake's lightmaps (lmbake-babylon.js) and light probes (lmbake-probes.js) in
// Babylon.js. README.md says how to load a bake.
export { registerLmbakeLightmaps, readKtx2Level0 } from './lmbake-babylon.js';
