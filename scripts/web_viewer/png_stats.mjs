// node png_stats.mjs A.png [B.png]: the share of A's pixels that differ from its corner colour
// and A's number of distinct colours (a non-blank render has both well above zero); with B,
// also the mean absolute difference of A and B per channel (0..255).
import fs from 'node:fs';
import { PNG } from 'pngjs';
const a = PNG.sync.read(fs.readFileSync(process.argv[2]));
const bg = a.data.slice(0, 3);
let differ = 0;
const colours = new Set();
for (let i = 0; i < a.data.length; i += 4) {
  const d = Math.abs(a.data[i] - bg[0]) + Math.abs(a.data[i + 1] - bg[1]) +
            Math.abs(a.data[i + 2] - bg[2]);
  if (d > 30) differ++;
  colours.add((a.data[i] >> 3) << 10 | (a.data[i + 1] >> 3) << 5 | (a.data[i + 2] >> 3));
}
let line = `${(differ / (a.width * a.height)).toFixed(4)} ${colours.size}`;
if (process.argv[3]) {
  const b = PNG.sync.read(fs.readFileSync(process.argv[3]));
  let sum = 0, n = 0;
  for (let i = 0; i < a.data.length && i < b.data.length; i += 4) {
    for (let c = 0; c < 3; ++c) { sum += Math.abs(a.data[i + c] - b.data[i + c]); ++n; }
  }
  line += ` ${(sum / n).toFixed(2)}`;
}
console.log(line);
