#!/usr/bin/env node
// lmbake preview server: `node tools/preview/serve.mjs OUT.gltf [--port N] [--lightmap ktx2|hdr]`
// serves the artist-facing preview of a bake on http://127.0.0.1:PORT/ until Ctrl-C (exit 0);
// --lightmap hdr prints the address with ?lightmap=hdr (the page reads the .hdr files, not the KTX2).
// Exit 1: usage error; 2: the glTF is missing or unreadable; 3: the server could not start.
import { startServer, InputError } from './server.mjs';

const usage = 'usage: node tools/preview/serve.mjs OUT.gltf [--port N] [--lightmap ktx2|hdr]';
const args = process.argv.slice(2);
let gltf = null, port = 0, lightmap = null;
for (let i = 0; i < args.length; i++) {
  const a = args[i];
  if (a === '-h' || a === '--help') { console.log(usage); process.exit(0); }
  else if (a === '--port' || a.startsWith('--port=')) {
    const v = a.includes('=') ? a.slice(7) : args[++i];
    port = Number(v);
    if (v === undefined || !Number.isInteger(port) || port < 0 || port > 65535) {
      console.error(`preview: --port wants an integer 0..65535, got '${v}'\n${usage}`); process.exit(1);
    }
  } else if (a === '--lightmap' || a.startsWith('--lightmap=')) {
    lightmap = a.includes('=') ? a.slice(11) : args[++i];
    if (!['ktx2', 'hdr'].includes(lightmap)) { console.error(`preview: --lightmap wants ktx2 or hdr, got '${lightmap}'\n${usage}`); process.exit(1); }
  } else if (a.startsWith('-')) { console.error(`preview: unknown option '${a}'\n${usage}`); process.exit(1); }
  else if (gltf === null) gltf = a;
  else { console.error(`preview: one glTF only ('${a}')\n${usage}`); process.exit(1); }
}
if (gltf === null) { console.error(usage); process.exit(1); }

let srv;
try {
  srv = await startServer(gltf, { log: (m) => process.env.LMB_PREVIEW_VERBOSE && console.error(m) });
} catch (e) {
  console.error(`preview: error: ${e.message}`);
  process.exit(e instanceof InputError ? 2 : 3);
}
console.log(`preview: http://127.0.0.1:${srv.port}/${lightmap ? '?lightmap=' + lightmap : ''}`);
const stop = async () => { await srv.close(); process.exit(0); };
process.on('SIGINT', stop);
process.on('SIGTERM', stop);
