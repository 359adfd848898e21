// The preview's HTTP server (node's http module only): binds 127.0.0.1, serves the page,
// three.js from the project's node_modules, lmbake's loaders (loaders/) and the bake's folder,
// read-only, GET/HEAD only, no directory listing, nothing outside those roots. Shared by
// serve.mjs and render.mjs.
import fs from 'node:fs';
import http from 'node:http';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

export const projectRoot = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');

export const TYPES = {
  '.html': 'text/html; charset=utf-8', '.js': 'text/javascript; charset=utf-8',
  '.mjs': 'text/javascript; charset=utf-8', '.json': 'application/json', '.css': 'text/css',
  '.gltf': 'model/gltf+json', '.glb': 'model/gltf-binary', '.bin': 'application/octet-stream',
  '.png': 'image/png', '.jpg': 'image/jpeg', '.jpeg': 'image/jpeg', '.webp': 'image/webp',
  '.ktx2': 'image/ktx2', '.hdr': 'image/vnd.radiance', '.exr': 'image/x-exr',
};

export class InputError extends Error {}

// Checks that the glTF exists, is a readable file and parses (a .glb: starts with its magic).
export function checkGltf(file) {
  const abs = path.resolve(file);
  let bytes;
  try {
    if (!fs.statSync(abs).isFile()) throw new Error('not a regular file');
    bytes = fs.readFileSync(abs);
  } catch (e) {
    throw new InputError(`cannot read glTF '${file}': ${e.code || e.message}`);
  }
  if (abs.toLowerCase().endsWith('.glb')) {
    if (bytes.length < 12 || bytes.toString('latin1', 0, 4) !== 'glTF') throw new InputError(`'${file}' is not a .glb file`);
  } else {
    try { JSON.parse(bytes.toString('utf8')); } catch (e) { throw new InputError(`'${file}' is not JSON: ${e.message.replace(/\s+/g, ' ')}`); }
  }
  return abs;
}

// Maps a URL path to a file under one of the roots, or null. realpath defeats symlinks out.
export function resolveFile(roots, urlPath) {
  let p;
  try { p = decodeURIComponent(urlPath); } catch { return null; }
  if (p.includes('\0')) return null;
  for (const [prefix, root] of roots) {
    if (!p.startsWith(prefix)) continue;
    const rel = p.slice(prefix.length);
    const abs = path.resolve(root, '.' + path.posix.normalize('/' + rel));
    try {
      const real = fs.realpathSync(abs);
      const realRoot = fs.realpathSync(root);
      if (real !== realRoot && !real.startsWith(realRoot + path.sep)) return null;
      if (!fs.statSync(real).isFile()) return null; // no directory listing
      return real;
    } catch { return null; }
  }
  return null;
}

// Starts the server for one bake; resolves to {server, port, url, close()}. bakeRoot: the folder
// served at /bake/ (default: the glTF's; the loaders' test serves several bakes under one);
// cacheModules: three.js, Babylon.js and lmbake's loaders may be cached by the browser (one
// browser loading many pages fetches them once), everything else is sent no-store.
export function startServer(gltfFile, { port = 0, log = () => {}, bakeRoot = null, cacheModules = false } = {}) {
  const gltf = checkGltf(gltfFile);
  const bakeDir = bakeRoot ? path.resolve(bakeRoot) : path.dirname(gltf);
  const three = path.join(projectRoot, 'node_modules', 'three');
  if (!fs.existsSync(path.join(three, 'build', 'three.module.js'))) {
    throw new Error(`three.js is not installed (${three}): run npm install in ${projectRoot}`);
  }
  const roots = [
    ['/page/', path.join(projectRoot, 'tools', 'preview', 'page')],
    ['/loaders/', path.join(projectRoot, 'loaders')],
    ['/babylon/core/', path.join(projectRoot, 'node_modules', '@babylonjs', 'core')],
    ['/babylon/loaders/', path.join(projectRoot, 'node_modules', '@babylonjs', 'loaders')],
    ['/three/build/', path.join(three, 'build')],
    ['/three/examples/jsm/', path.join(three, 'examples', 'jsm')],
    ['/bake/', bakeDir],
  ];
  const sceneJson = JSON.stringify({ gltf: '/bake/' + encodeURIComponent(path.basename(gltf)), name: path.basename(gltf) });

  const server = http.createServer((req, res) => {
    const send = (code, type, body) => {
      const cache = cacheModules && code === 200 && /^\/(three|babylon|loaders)\//.test(req.url) ? 'max-age=3600' : 'no-store';
      res.writeHead(code, { 'Content-Type': type, 'Cache-Control': cache, 'X-Content-Type-Options': 'nosniff' });
      res.end(req.method === 'HEAD' ? undefined : body);
    };
    if (req.method !== 'GET' && req.method !== 'HEAD') { res.setHeader('Allow', 'GET, HEAD'); return send(405, 'text/plain', 'read-only\n'); }
    const urlPath = new URL(req.url, 'http://127.0.0.1').pathname;
    if (urlPath === '/' || urlPath === '/index.html') urlPathServe(path.join(roots[0][1], 'index.html'));
    else if (urlPath === '/scene.json') send(200, 'application/json', sceneJson);
    else {
      const file = resolveFile(roots, urlPath);
      if (!file) { log(`404 ${urlPath}`); return send(404, 'text/plain', 'not found\n'); }
      urlPathServe(file);
    }
    function urlPathServe(file) {
      fs.readFile(file, (err, data) => {
        if (err) return send(404, 'text/plain', 'not found\n');
        send(200, TYPES[path.extname(file).toLowerCase()] || 'application/octet-stream', data);
      });
    }
  });

  return new Promise((resolve, reject) => {
    server.once('error', reject);
    server.listen(port, '127.0.0.1', () => {
      const actual = server.address().port;
      resolve({
        server, port: actual, url: `http://127.0.0.1:${actual}/`, gltf,
        close: () => new Promise((r) => { server.closeAllConnections(); server.close(() => r()); }),
      });
    });
  });
}
