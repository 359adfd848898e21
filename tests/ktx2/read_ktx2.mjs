#!/usr/bin/env node
// An independent KTX2 reader for the tests: the container through ktx-parse (npm), the level
// through three.js's Zstandard decoder when supercompressed, the texels decoded here from the
// Vulkan specification's formats (not lmbake's code). Prints the header, the DFD and the
// key/value data as JSON and writes the texels as float32 RGB (rows as stored) to OUT; for the
// block formats (BC6H, ASTC) it writes level 0's blocks as stored, and the caller decodes them.
//   usage: node tests/ktx2/read_ktx2.mjs FILE.ktx2 OUT.f32
import fs from 'node:fs';
import { read } from 'ktx-parse';
import { ZSTDDecoder } from 'three/examples/jsm/libs/zstddec.module.js';

const [file, out] = process.argv.slice(2);
if (!out) { console.error('usage: node tests/ktx2/read_ktx2.mjs FILE.ktx2 OUT.f32'); process.exit(1); }
const bytes = new Uint8Array(fs.readFileSync(file));
const c = read(bytes);
const level = c.levels[0];
const z = new ZSTDDecoder();
if (c.supercompressionScheme === 2) await z.init();
const unpack = (l) => (c.supercompressionScheme === 2 ? z.decode(l.levelData, l.uncompressedByteLength) : l.levelData);
const data = unpack(level);
const block = c.vkFormat === 143 || c.vkFormat === 1000066000;
const w = c.pixelWidth, h = c.pixelHeight, n = w * h * Math.max(1, c.pixelDepth); // 3D: slices one after the other
const rgb = new Float32Array(3 * n);
const view = new DataView(data.buffer, data.byteOffset, data.byteLength);
// unsigned float of e exponent bits (bias 15) and m mantissa bits
const ufloat = (v, m) => {
  const e = v >> m, f = v & ((1 << m) - 1);
  if (e === 0) return f * 2 ** (-14 - m);
  if (e === 31) return f ? NaN : Infinity;
  return (1 + f / (1 << m)) * 2 ** (e - 15);
};
const half = (v) => (v & 0x8000 ? -1 : 1) * ufloat(v & 0x7fff, 10);
for (let i = 0; i < n && !block; i++) {
  if (c.vkFormat === 123) { // E5B9G9R9: value = mantissa x 2^(exponent - 15 - 9)
    const v = view.getUint32(4 * i, true), s = 2 ** ((v >>> 27) - 15 - 9);
    rgb[3 * i] = (v & 511) * s; rgb[3 * i + 1] = ((v >>> 9) & 511) * s; rgb[3 * i + 2] = ((v >>> 18) & 511) * s;
  } else if (c.vkFormat === 122) { // B10G11R11: R 11 bits at 0, G 11 at 11, B 10 at 22
    const v = view.getUint32(4 * i, true);
    rgb[3 * i] = ufloat(v & 0x7ff, 6); rgb[3 * i + 1] = ufloat((v >>> 11) & 0x7ff, 6); rgb[3 * i + 2] = ufloat((v >>> 22) & 0x3ff, 5);
  } else if (c.vkFormat === 97) { // R16G16B16A16_SFLOAT
    for (let k = 0; k < 3; k++) rgb[3 * i + k] = half(view.getUint16(8 * i + 2 * k, true));
  } else { console.error(`unexpected vkFormat ${c.vkFormat}`); process.exit(2); }
}
fs.writeFileSync(out, block ? Buffer.from(data.buffer, data.byteOffset, data.byteLength) : Buffer.from(rgb.buffer));
const kv = {};
for (const [k, v] of Object.entries(c.keyValue)) kv[k] = typeof v === 'string' ? v : new TextDecoder().decode(v).replace(/\0$/, '');
const d = c.dataFormatDescriptor[0];
console.log(JSON.stringify({
  vkFormat: c.vkFormat, typeSize: c.typeSize, pixelWidth: w, pixelHeight: h, pixelDepth: c.pixelDepth,
  layerCount: c.layerCount, faceCount: c.faceCount, levelCount: c.levels.length,
  supercompressionScheme: c.supercompressionScheme, levelBytes: level.levelData.byteLength,
  uncompressedByteLength: level.uncompressedByteLength, keyValue: kv,
  levels: c.levels.map((l) => ({ bytes: l.levelData.byteLength, uncompressed: l.uncompressedByteLength,
    unpacked: unpack(l).byteLength })),
  dfd: { vendorId: d.vendorId, descriptorType: d.descriptorType, versionNumber: d.versionNumber,
    colorModel: d.colorModel, colorPrimaries: d.colorPrimaries, transferFunction: d.transferFunction,
    flags: d.flags, texelBlockDimension: d.texelBlockDimension, bytesPlane: d.bytesPlane,
    samples: d.samples.map((s) => ({ bitOffset: s.bitOffset, bitLength: s.bitLength, channelType: s.channelType,
      samplePosition: s.samplePosition, sampleLower: s.sampleLower, sampleUpper: s.sampleUpper })) },
}));
