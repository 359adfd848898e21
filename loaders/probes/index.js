// lmbake-probes: lmbake's light probes without an engine (probe-field.js; README.md).
export { SH_Y, BAND_A, probeSet, probesOf, findTetrahedron, interpolateSH, shIrradiance, shQuadratic } from './probe-field.js';
