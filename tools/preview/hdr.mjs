// Radiance .hdr files as the preview page reads them and the composer writes them: readHdr decodes
// with three's HDRLoader (what the page runs), encodeHdr writes RGBE whose bytes HDRLoader reads
// back to the same floats.
import fs from 'node:fs';
import { HDRLoader } from 'three/examples/jsm/loaders/HDRLoader.js';

const FLOAT_TYPE = 1015; // three's FloatType: HDRLoader decodes to float32 RGBA

// A Radiance .hdr as three's HDRLoader reads it for the page: {width, height, data (RGBA float32)}.
export function readHdr(file) {
  const bytes = fs.readFileSync(file);
  const loader = new HDRLoader();
  loader.setDataType(FLOAT_TYPE);
  return loader.parse(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.length));
}

// A Radiance .hdr (RGBE, each scanline run-length framed with literal runs only: what three's
// HDRLoader and OIIO read). Mantissas are rounded for three's decoding, byte x 2^(e-128) / 255
// (the page's reader), so an .hdr read by HDRLoader and written again keeps its bytes.
const POW2 = Float64Array.from({ length: 256 }, (_, k) => 2 ** (k - 128)); // 2^e at e + 128
const f64 = new Float64Array(1), u32 = new Uint32Array(f64.buffer); // a double's bits (little-endian)
export function encodeHdr(width, height, rgba) {
  const head = Buffer.from(`#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y ${height} +X ${width}\n`, 'ascii');
  const rle = width >= 8 && width < 32768;
  const perLine = rle ? 4 + 4 * (width + Math.ceil(width / 128)) : 4 * width;
  const out = Buffer.alloc(head.length + height * perLine);
  head.copy(out);
  let o = head.length;
  const line = new Uint8Array(4 * width);
  for (let y = 0; y < height; y++) {
    for (let x = 0; x < width; x++) {
      const i = (y * width + x) * 4;
      const r = Math.max(rgba[i], 0), g = Math.max(rgba[i + 1], 0), b = Math.max(rgba[i + 2], 0);
      const m = Math.max(r, g, b);
      if (!(m > 1e-32) || !Number.isFinite(m)) { line.fill(0, 4 * x, 4 * x + 4); continue; }
      // the smallest e with m <= 2^e, from the double's exponent: m = f 2^x, f in [0.5, 1)
      f64[0] = m;
      const hi = u32[1];
      let e = ((hi >>> 20) & 0x7ff) - 1022;
      if ((hi & 0xfffff) === 0 && u32[0] === 0) e--; // m is 2^(x - 1) exactly
      if (e > 127) e = 127;
      if (e < -127) e = -127;
      const scale = 255 / POW2[e + 128];
      line[4 * x] = Math.min(Math.round(r * scale), 255);
      line[4 * x + 1] = Math.min(Math.round(g * scale), 255);
      line[4 * x + 2] = Math.min(Math.round(b * scale), 255);
      line[4 * x + 3] = e + 128;
    }
    if (!rle) { out.set(line, o); o += 4 * width; continue; }
    out[o++] = 2; out[o++] = 2; out[o++] = width >> 8; out[o++] = width & 255;
    for (let c = 0; c < 4; c++) {
      for (let x = 0; x < width; x += 128) {
        const n = Math.min(128, width - x);
        out[o++] = n;
        for (let k = 0; k < n; k++) out[o++] = line[4 * (x + k) + c];
      }
    }
  }
  return out.subarray(0, o);
}
