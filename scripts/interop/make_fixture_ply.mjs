// Writes a small 3DGS PLY (300 Gaussians, SH degree 3, seeded values in the ranges real models
// have, a quarter of them nearly opaque) for the interop fixtures:
//   node make_fixture_ply.mjs OUT.ply
import { writeFileSync } from 'node:fs';

const n = 300;
const names = ['x', 'y', 'z', 'nx', 'ny', 'nz', 'f_dc_0', 'f_dc_1', 'f_dc_2'];
for (let i = 0; i < 45; ++i) names.push(`f_rest_${i}`);
names.push('opacity', 'scale_0', 'scale_1', 'scale_2', 'rot_0', 'rot_1', 'rot_2', 'rot_3');
let state = 7n;
const uniform = (lo, hi) => {
  state = (state * 6364136223846793005n + 1442695040888963407n) & ((1n << 64n) - 1n);
  return lo + (hi - lo) * Number(state >> 40n) / 16777216;
};
const data = new Float32Array(n * names.length);
for (let i = 0; i < n; ++i) {
  const r = data.subarray(i * names.length, (i + 1) * names.length);
  r[0] = uniform(-40, 40); r[1] = uniform(-30, 5); r[2] = uniform(-20, 60);
  for (let k = 6; k < 9; ++k) r[k] = uniform(-1.5, 1.5);
  for (let k = 9; k < 54; ++k) r[k] = uniform(-0.8, 0.8);
  r[54] = i % 4 === 0 ? uniform(6, 9) : uniform(-4, 4);  // opacity logit
  for (let k = 55; k < 58; ++k) r[k] = uniform(-6, 0.5);
  const q = [uniform(-1, 1), uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)];
  const l = Math.hypot(...q);
  for (let k = 0; k < 4; ++k) r[58 + k] = q[k] / l;
}
const header = 'ply\nformat binary_little_endian 1.0\n' +
  'comment interop fixture: 300 seeded Gaussians, SH degree 3\n' +
  `element vertex ${n}\n` + names.map(x => `property float ${x}\n`).join('') + 'end_header\n';
writeFileSync(process.argv[2], Buffer.concat([Buffer.from(header), Buffer.from(data.buffer)]));
