// Readers for the preview e2e test, node only: PNG screenshots (8-bit RGB/RGBA), Radiance .hdr
// (decoded as three's HDRLoader does: c x 2^(e-128) / 255), OpenEXR (scanline, NONE/ZIPS/ZIP,
// HALF/FLOAT), and a glTF's TEXCOORD_1 triangles grouped by lightmap image.
import fs from 'node:fs';
import path from 'node:path';
import zlib from 'node:zlib';

export function decodePng(buf) {
  if (buf.readUInt32BE(0) !== 0x89504e47) throw new Error('not a PNG');
  let pos = 8, w = 0, h = 0, ct = 0; const idat = [];
  while (pos < buf.length) {
    const len = buf.readUInt32BE(pos), type = buf.toString('latin1', pos + 4, pos + 8), data = buf.subarray(pos + 8, pos + 8 + len);
    if (type === 'IHDR') {
      w = data.readUInt32BE(0); h = data.readUInt32BE(4); ct = data[9];
      if (data[8] !== 8 || (ct !== 2 && ct !== 6) || data[12] !== 0) throw new Error('PNG: only 8-bit RGB/RGBA, not interlaced');
    } else if (type === 'IDAT') idat.push(data);
    pos += 12 + len;
  }
  const bpp = ct === 6 ? 4 : 3, stride = w * bpp, raw = zlib.inflateSync(Buffer.concat(idat));
  const out = new Uint8Array(w * h * 3), line = new Uint8Array(stride), prev = new Uint8Array(stride);
  for (let y = 0; y < h; y++) {
    const f = raw[y * (stride + 1)], src = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let i = 0; i < stride; i++) {
      const a = i >= bpp ? line[i - bpp] : 0, b = prev[i], c = i >= bpp ? prev[i - bpp] : 0;
      let p = 0;
      if (f === 1) p = a; else if (f === 2) p = b; else if (f === 3) p = (a + b) >> 1;
      else if (f === 4) { const pa = Math.abs(b - c), pb = Math.abs(a - c), pc = Math.abs(a + b - 2 * c); p = pa <= pb && pa <= pc ? a : pb <= pc ? b : c; }
      line[i] = (src[i] + p) & 255;
    }
    for (let x = 0; x < w; x++) for (let k = 0; k < 3; k++) out[3 * (y * w + x) + k] = line[x * bpp + k];
    prev.set(line);
  }
  return { width: w, height: h, rgb: out, at: (x, y) => Array.from(out.subarray(3 * (y * w + x), 3 * (y * w + x) + 3)) };
}

export function readHdr(file) {
  const b = fs.readFileSync(file);
  let pos = 0; const line = () => { const e = b.indexOf(10, pos); const s = b.toString('latin1', pos, e); pos = e + 1; return s; };
  if (!line().startsWith('#?')) throw new Error(`${file}: not a Radiance file`);
  while (line() !== '');
  const m = /^-Y (\d+) \+X (\d+)$/.exec(line());
  if (!m) throw new Error(`${file}: only -Y H +X W orientation`);
  const h = +m[1], w = +m[2], rgbe = new Uint8Array(w * 4), data = new Float32Array(w * h * 3);
  for (let y = 0; y < h; y++) {
    if (b[pos] === 2 && b[pos + 1] === 2 && ((b[pos + 2] << 8) | b[pos + 3]) === w) { // new RLE
      pos += 4;
      for (let c = 0; c < 4; c++) for (let x = 0; x < w;) {
        let n = b[pos++];
        if (n > 128) { n -= 128; const v = b[pos++]; while (n--) rgbe[4 * x++ + c] = v; } else while (n--) rgbe[4 * x++ + c] = b[pos++];
      }
    } else { rgbe.set(b.subarray(pos, pos + 4 * w)); pos += 4 * w; }
    for (let x = 0; x < w; x++) {
      const s = Math.pow(2, rgbe[4 * x + 3] - 128) / 255, o = 3 * (y * w + x);
      for (let c = 0; c < 3; c++) data[o + c] = rgbe[4 * x + 3] ? rgbe[4 * x + c] * s : 0;
    }
  }
  return { width: w, height: h, data };
}

function halfToFloat(h) {
  const s = h & 0x8000 ? -1 : 1, e = (h >> 10) & 31, f = h & 1023;
  if (e === 0) return s * f * 2 ** -24;
  if (e === 31) return f ? NaN : s * Infinity;
  return s * (1 + f / 1024) * 2 ** (e - 15);
}

export function readExr(file) {
  const b = fs.readFileSync(file);
  if (b.readUInt32LE(0) !== 20000630) throw new Error(`${file}: not an OpenEXR file`);
  let pos = 8; const attrs = {};
  for (;;) {
    const n0 = b.indexOf(0, pos), name = b.toString('latin1', pos, n0); pos = n0 + 1;
    if (!name) break;
    const t0 = b.indexOf(0, pos), type = b.toString('latin1', pos, t0); pos = t0 + 1;
    const size = b.readInt32LE(pos); pos += 4;
    attrs[name] = { type, v: b.subarray(pos, pos + size) }; pos += size;
  }
  const ch = [], cl = attrs.channels.v;
  for (let p = 0; cl[p];) { const e = cl.indexOf(0, p); ch.push({ name: cl.toString('latin1', p, e), type: cl.readInt32LE(e + 1) }); p = e + 17; }
  const comp = attrs.compression.v[0], dw = attrs.dataWindow.v;
  const x0 = dw.readInt32LE(0), y0 = dw.readInt32LE(4), w = dw.readInt32LE(8) - x0 + 1, h = dw.readInt32LE(12) - y0 + 1;
  const lines = { 0: 1, 2: 1, 3: 16 }[comp];
  if (!lines) throw new Error(`${file}: compression ${comp} not supported (NONE, ZIPS, ZIP only)`);
  const nChunks = Math.ceil(h / lines), data = new Float32Array(w * h * 3);
  const idx = { R: 0, G: 1, B: 2 };
  for (let c = 0; c < nChunks; c++) {
    let p = Number(b.readBigUInt64LE(pos + 8 * c));
    const y = b.readInt32LE(p) - y0, size = b.readInt32LE(p + 4); p += 8;
    let raw = b.subarray(p, p + size);
    const n = Math.min(lines, h - y), expect = n * w * ch.reduce((s, k) => s + (k.type === 1 ? 2 : 4), 0);
    if (comp !== 0 && size < expect) {
      const t = zlib.inflateSync(raw);
      for (let i = 1; i < t.length; i++) t[i] = (t[i - 1] + t[i] - 128) & 255;
      raw = Buffer.alloc(t.length); const half = (t.length + 1) >> 1;
      for (let i = 0; i < t.length; i++) raw[i] = i & 1 ? t[half + (i >> 1)] : t[i >> 1];
    }
    let q = 0;
    for (let l = 0; l < n; l++) for (const k of ch) for (let x = 0; x < w; x++) {
      const v = k.type === 1 ? halfToFloat(raw.readUInt16LE(q)) : k.type === 2 ? raw.readFloatLE(q) : raw.readUInt32LE(q);
      q += k.type === 1 ? 2 : 4;
      if (k.name in idx) data[3 * ((y + l) * w + x) + idx[k.name]] = v;
    }
  }
  return { width: w, height: h, data };
}

export function readImage(file) { return file.toLowerCase().endsWith('.exr') ? readExr(file) : readHdr(file); }

// TEXCOORD_1 triangles ([u0,v0,u1,v1,u2,v2] per triangle, with object-space positions for the
// chart-border weld and the node's translation) of every primitive whose material's MOZ_lightmap texture has the .hdr
// image `hdrName` (basename). Float or normalized unsigned accessors.
export function lightmapTriangles(gltfFile, hdrName) {
  const g = JSON.parse(fs.readFileSync(gltfFile, 'utf8')), dir = path.dirname(gltfFile);
  const bufs = g.buffers.map((bf) => fs.readFileSync(path.join(dir, decodeURIComponent(bf.uri))));
  const read = (ai) => {
    const a = g.accessors[ai], bv = g.bufferViews[a.bufferView], n = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 }[a.type];
    const cs = { 5121: 1, 5123: 2, 5125: 4, 5126: 4 }[a.componentType], stride = bv.byteStride || cs * n;
    const buf = bufs[bv.buffer], base = (bv.byteOffset || 0) + (a.byteOffset || 0), out = [];
    for (let i = 0; i < a.count; i++) for (let k = 0; k < n; k++) {
      const o = base + i * stride + k * cs;
      let v = a.componentType === 5126 ? buf.readFloatLE(o) : a.componentType === 5125 ? buf.readUInt32LE(o) : a.componentType === 5123 ? buf.readUInt16LE(o) : buf[o];
      if (a.normalized) v /= a.componentType === 5123 ? 65535 : 255;
      out.push(v);
    }
    return out;
  };
  const tris = [];
  for (const node of g.nodes || []) {
    if (node.mesh === undefined) continue;
    for (const prim of g.meshes[node.mesh].primitives) {
      const mat = prim.material !== undefined ? g.materials[prim.material] : null;
      const lm = mat && mat.extensions && mat.extensions.MOZ_lightmap;
      if (!lm || (prim.mode !== undefined && prim.mode !== 4)) continue;
      const tex = g.textures[lm.index], rgbe = tex.extensions && tex.extensions.MOZ_texture_rgbe;
      if (!rgbe || path.basename(decodeURIComponent(g.images[rgbe.source].uri || '')) !== hdrName) continue;
      const uv = read(prim.attributes[`TEXCOORD_${lm.texCoord ?? 1}`]), pos = read(prim.attributes.POSITION);
      const ind = prim.indices !== undefined ? read(prim.indices) : uv.map((_, i) => i).slice(0, uv.length / 2);
      for (let t = 0; t < ind.length; t += 3) {
        const v = [ind[t], ind[t + 1], ind[t + 2]];
        tris.push({ node: node.name, translation: node.translation || [0, 0, 0], uv: v.flatMap((i) => [uv[2 * i], uv[2 * i + 1]]), pos: v.flatMap((i) => [pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]]) });
      }
    }
  }
  return tris;
}

export const srgb = (x) => { x = Math.min(1, Math.max(0, x)); return 255 * (x <= 0.0031308 ? 12.92 * x : 1.055 * x ** (1 / 2.4) - 0.055); };
export const luma = (p) => 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];

// A glTF's JSON and its accessors: {json, dir, read(accessorIndex)} where read gives the
// accessor's values as a flat array of numbers (float, normalized or integer components, byte
// strides honoured) and its number of components per element (itemSize).
export function gltfAccessors(gltfFile) {
  const json = JSON.parse(fs.readFileSync(gltfFile, 'utf8')), dir = path.dirname(gltfFile);
  const bufs = json.buffers.map((bf) => fs.readFileSync(path.join(dir, decodeURIComponent(bf.uri))));
  const read = (ai) => {
    const a = json.accessors[ai], bv = json.bufferViews[a.bufferView], n = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 }[a.type];
    const cs = { 5121: 1, 5123: 2, 5125: 4, 5126: 4 }[a.componentType], stride = bv.byteStride || cs * n;
    const buf = bufs[bv.buffer], base = (bv.byteOffset || 0) + (a.byteOffset || 0), out = [];
    for (let i = 0; i < a.count; i++) for (let k = 0; k < n; k++) {
      const o = base + i * stride + k * cs;
      let v = a.componentType === 5126 ? buf.readFloatLE(o) : a.componentType === 5125 ? buf.readUInt32LE(o) : a.componentType === 5123 ? buf.readUInt16LE(o) : buf[o];
      if (a.normalized) v /= a.componentType === 5123 ? 65535 : 255;
      out.push(v);
    }
    out.itemSize = n;
    return out;
  };
  return { json, dir, read };
}

// A bake's light probes from its glTF (asset.extras.lightmap.probes), read from the buffers here,
// not by the page's code: {count, spacing, positions (Float32Array xyz), sh (27 per probe, E in
// lux), tetrahedra (Uint32Array, 4 per tetrahedron) or null}.
export function readProbes(file) {
  const doc = JSON.parse(fs.readFileSync(file, 'utf8'));
  const p = doc.asset.extras.lightmap.probes;
  const bytes = (viewIndex, length) => {
    const v = doc.bufferViews[viewIndex], b = fs.readFileSync(path.join(path.dirname(file), doc.buffers[v.buffer].uri));
    const start = b.byteOffset + (v.byteOffset || 0);
    return b.buffer.slice(start, start + (length ?? v.byteLength));
  };
  const scale = p.scale === 'radiance' ? Math.PI : 1;
  const tetrahedra = p.tetrahedra !== undefined
    ? new Uint32Array(bytes(doc.accessors[p.tetrahedra].bufferView, 4 * doc.accessors[p.tetrahedra].count)) : null;
  return { count: p.count, spacing: p.spacing, positions: new Float32Array(bytes(doc.accessors[p.positions].bufferView)),
    sh: new Float32Array(bytes(p.sh)).map((v) => v * scale), tetrahedra };
}
