// Compares a sadsplat model (3DGS PLY, RDF axes) with what independent readers decode from the
// files made of it, attribute by attribute, against each format's stated quantisation:
//   node compare_with_reference_readers.mjs MODEL.ply spz-loader FILE.spz
//   node compare_with_reference_readers.mjs MODEL.ply ply DECODED.ply   (e.g. splat-transform's)
// Prints one JSON line: the maximum error per attribute, the bound and pass/fail. Exit 1 on fail.
import { readFileSync } from 'node:fs';

const [modelPath, kind, otherPath] = process.argv.slice(2);

function readPly(path) {
  const bytes = readFileSync(path);
  const end = bytes.indexOf('end_header\n') + 11;
  const header = bytes.subarray(0, end).toString();
  const props = [...header.matchAll(/property (\w+) (\S+)/g)].map(m => ({ type: m[1], name: m[2] }));
  const size = { float: 4, double: 8, int: 4, uint: 4, uchar: 1 };
  const n = +header.match(/element vertex (\d+)/)[1];
  const stride = props.reduce((s, p) => s + size[p.type], 0);
  const view = new DataView(bytes.buffer, bytes.byteOffset + end, n * stride);
  const offsets = {};
  let o = 0;
  for (const p of props) { offsets[p.name] = [o, p.type]; o += size[p.type]; }
  const get = (i, name) => {
    const [off, type] = offsets[name];
    const at = i * stride + off;
    return type === 'double' ? view.getFloat64(at, true) : type === 'float' ? view.getFloat32(at, true)
      : view.getInt32(at, true);
  };
  const has = name => name in offsets;
  return { n, get, has };
}

const sigmoid = x => 1 / (1 + Math.exp(-x));
const model = readPly(modelPath);
let other;  // accessors in the model's conventions: RDF, rot w x y z, log-scales, f_dc, logits
if (kind === 'ply') {
  const p = readPly(otherPath);
  other = { n: p.n, get: p.get, has: p.has };
} else if (kind === 'spz-loader') {
  // The package is a browser build: told it runs in a renderer, it skips its Node branch (which
  // needs a createRequire the bundle lacks) and instantiates its embedded WASM.
  process.type = 'renderer';
  const { loadSpz } = await import('@spz-loader/core');
  // colorScaleFactor 1: its colours are f_dc + 0.5; scales come as exp(log-scale), alphas as
  // sigmoid(logit): both inverted below.
  const cloud = await loadSpz(readFileSync(otherPath),
    { colorScaleFactor: 1, unpackOptions: { coordinateSystem: 'RDF' } });
  const shDim = [0, 3, 8, 15][cloud.shDegree];
  other = {
    n: cloud.numPoints,
    has: name => !name.startsWith('f_rest_') || +name.slice(7) < 3 * shDim,
    get: (i, name) => {
      if (name === 'x' || name === 'y' || name === 'z') return cloud.positions[3 * i + 'xyz'.indexOf(name)];
      if (name.startsWith('scale_')) return Math.log(cloud.scales[3 * i + +name[6]]);
      if (name.startsWith('f_dc_')) return cloud.colors[3 * i + +name[5]] - 0.5;
      if (name === 'opacity') {
        const a = cloud.alphas[i];
        return Math.log(a / (1 - a));
      }
      if (name.startsWith('rot_')) {  // SPZ's library order is x y z w
        const k = +name[4];
        return cloud.rotations[4 * i + (k === 0 ? 3 : k - 1)];
      }
      // f_rest_k: channel-major in the PLY, coefficient-major with colour inner in SPZ.
      const k = +name.slice(7), c = Math.floor(k / shDim), j = k % shDim;
      return cloud.sh[(i * shDim + j) * 3 + c];
    },
  };
} else {
  console.error('kind: ply or spz-loader');
  process.exit(2);
}

if (other.n !== model.n) {
  console.log(JSON.stringify({ pass: false, reason: `count ${other.n} vs ${model.n}` }));
  process.exit(1);
}
const err = { position: 0, rotation: 0, log_scale: 0, f_dc: 0, alpha: 0, sh1: 0, sh23: 0 };
for (let i = 0; i < model.n; ++i) {
  for (const a of ['x', 'y', 'z']) err.position = Math.max(err.position, Math.abs(model.get(i, a) - other.get(i, a)));
  const q = [0, 1, 2, 3].map(k => model.get(i, `rot_${k}`));
  const r = [0, 1, 2, 3].map(k => other.get(i, `rot_${k}`));
  const nq = Math.hypot(...q), nr = Math.hypot(...r);
  const dot = Math.abs(q.reduce((s, v, k) => s + v * r[k], 0)) / (nq * nr);
  err.rotation = Math.max(err.rotation, Math.acos(Math.min(1, dot)) * 2);  // radians
  for (let k = 0; k < 3; ++k) {
    const s = model.get(i, `scale_${k}`);
    if (s > -10 && s < 5.9) err.log_scale = Math.max(err.log_scale, Math.abs(s - other.get(i, `scale_${k}`)));
    err.f_dc = Math.max(err.f_dc, Math.abs(model.get(i, `f_dc_${k}`) - other.get(i, `f_dc_${k}`)));
  }
  const o = other.get(i, 'opacity');
  err.alpha = Math.max(err.alpha, Math.abs(sigmoid(model.get(i, 'opacity')) - (Number.isFinite(o) ? sigmoid(o) : o > 0 ? 1 : 0)));
  for (let k = 0; k < 45; ++k) {
    if (!model.has(`f_rest_${k}`) || !other.has(`f_rest_${k}`)) continue;
    const v = model.get(i, `f_rest_${k}`);
    if (Math.abs(v) > 1) continue;  // SPZ clamps SH to [-1, 1]
    const j = k % 15, d = Math.abs(v - other.get(i, `f_rest_${k}`));
    if (j < 3) err.sh1 = Math.max(err.sh1, d); else err.sh23 = Math.max(err.sh23, d);
  }
}
// SPZ's quantisation (splat_formats.h), with float slack.
const bound = { position: 0.5 / 4096 + 1e-5, rotation: 0.02, log_scale: 1 / 32 + 1e-5, f_dc: 0.5 / (0.15 * 255) + 1e-5,
  alpha: 0.5 / 255 + 1e-5, sh1: 4.5 / 128, sh23: 8.5 / 128 };
const pass = Object.keys(err).every(k => err[k] <= bound[k]);
console.log(JSON.stringify({ pass, count: model.n, max_error: Object.fromEntries(Object.entries(err).map(([k, v]) => [k, +v.toPrecision(3)])) }));
process.exit(pass ? 0 : 1);
