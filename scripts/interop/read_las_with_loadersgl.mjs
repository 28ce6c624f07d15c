// Reads a LAS file with loaders.gl's LAS loader (laz-rs, which reads LAS 1.4 point formats 6-10)
// and prints what a user checks: version, point format, point count, CRS WKT presence, bounds,
// the classification histogram and the first point's colour, as one JSON line.
//   node read_las_with_loadersgl.mjs FILE.las
import {readFileSync} from 'node:fs';
import {parse} from '@loaders.gl/core';
import {LAZRsLoader} from '@loaders.gl/las';
import {join} from 'node:path';

// The loader fetches its WebAssembly by URL, which Node's fetch cannot do for file: URLs:
// initialise the same module from the file's bytes first (its later init call is then a no-op).
const lasDir = join(process.cwd(), 'node_modules/@loaders.gl/las/dist/libs/laz-rs-wasm');
const wasmModule = await import(join(lasDir, 'laz_rs_wasm.js'));
wasmModule.initSync({module: readFileSync(join(lasDir, 'laz_rs_wasm_bg.wasm'))});

const file = process.argv[2];
const bytes = readFileSync(file);
const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
const data = await parse(buffer, LAZRsLoader, {las: {shape: 'mesh', skip: 1, colorDepth: 16}, worker: false});
const meta = data.loaderData || {};
const n = data.header.vertexCount;
const cls = data.attributes.classification.value;
const histogram = {};
for (let i = 0; i < n; ++i) histogram[cls[i]] = (histogram[cls[i]] || 0) + 1;
const pos = data.attributes.POSITION.value;
const colors = data.attributes.COLOR_0 ? data.attributes.COLOR_0.value : null;
console.log(JSON.stringify({
  version: meta.versionAsString, pointsFormatId: meta.pointsFormatId, points: n,
  bounds: data.header.boundingBox, histogram,
  first: [pos[0], pos[1], pos[2]], firstColor: colors ? Array.from(colors.slice(0, 4)) : null,
}));
