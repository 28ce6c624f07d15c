// sadsplat's glTF / 3D Tiles output read by clients nobody on this project wrote:
//   node check_clients.mjs DIR
// DIR holds model.glb (SPZ payload), model_plain.glb (plain accessors) and tileset/ (tileset.json
// + tiles/*.glb), as globe_check.sh writes them. Checks, one line each (PASS / FAIL):
// 1. Khronos' gltf-validator on both GLBs and every tile: no errors (warnings listed by code).
// 2. loaders.gl's GLTFLoader parses model_plain.glb: count, attributes, feature IDs, class names.
// 3. Niantic's SPZ decoder (@spz-loader/core, as CesiumJS calls it: coordinateSystem
//    UNSPECIFIED) decodes model.glb's payload; every splat equals model_plain.glb's accessors
//    within SPZ's quantisation (position step, log-scale 1/16, alpha 1/255, colour 1/255 at 0.15,
//    quaternion).
// 4. loaders.gl's Tiles3DLoader parses tileset.json (root, children, content URIs).
// Exit 1 when a check fails.
import { readFileSync, readdirSync } from 'node:fs';
import path from 'node:path';

const dir = process.argv[2];
let failed = false;
const report = (ok, line) => { console.log(`${ok ? 'PASS' : 'FAIL'} ${line}`); if (!ok) failed = true; };

function glbChunks(bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const jsonLength = view.getUint32(12, true);
  const json = JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + jsonLength)));
  const binAt = 20 + jsonLength;
  const bin = bytes.subarray(binAt + 8, binAt + 8 + view.getUint32(binAt, true));
  return { json, bin };
}

// 1. gltf-validator.
const validator = await import('gltf-validator');
const glbs = ['model.glb', 'model_plain.glb',
  ...readdirSync(path.join(dir, 'tileset', 'tiles')).map((f) => path.join('tileset', 'tiles', f))];
const warningCodes = new Map();
const errorCodes = new Map();
let extensionNames = 0;
let errors = 0;
const errorLines = [];
for (const f of glbs) {
  const r = await validator.validateBytes(new Uint8Array(readFileSync(path.join(dir, f))), { maxIssues: 100 });
  errors += r.issues.numErrors;
  for (const m of r.issues.messages) {
    // This validator does not know KHR_gaussian_splatting: its attribute names (which the
    // extension defines) are "invalid" to it. Counted apart; every other error fails the check.
    if (m.severity === 0 && m.code === 'MESH_PRIMITIVE_INVALID_ATTRIBUTE' &&
        (m.pointer || '').includes('/attributes/KHR_gaussian_splatting:')) {
      extensionNames += 1;
    } else if (m.severity === 0) {
      errorLines.push(`${f}: ${m.code} ${m.message} ${m.pointer || ''}`);
      errorCodes.set(m.code, (errorCodes.get(m.code) || 0) + 1);
    }
    else if (m.severity === 1) warningCodes.set(`${m.code}: ${m.message}`, (warningCodes.get(`${m.code}: ${m.message}`) || 0) + 1);
  }
}
report(errors === extensionNames, `gltf-validator ${validator.version()} on ${glbs.length} GLBs: ` +
  `${errors - extensionNames} errors besides ${extensionNames} "invalid attribute name" for the ` +
  `KHR_gaussian_splatting: attributes (a validator without that extension)` +
  (errorLines.length ? ` (${errorLines.slice(0, 3).join('; ')})` : '') +
  `; warnings: ${[...warningCodes].map(([k, n]) => `${n}x ${k}`).join('; ') || 'none'}`);
// The control: splat-transform's own GLB (the same extension) gets the same attribute errors.
if (process.argv[3]) {
  const r = await validator.validateBytes(new Uint8Array(readFileSync(process.argv[3])), { maxIssues: 100 });
  const codes = [...new Set(r.issues.messages.filter((m) => m.severity === 0).map((m) => m.code))];
  console.log(`INFO control: splat-transform's GLB in the same validator: ${r.issues.numErrors} errors (${codes.join(', ')})`);
}

// 2. loaders.gl GLTFLoader on the plain GLB.
const { parse } = await import('@loaders.gl/core');
const { GLTFLoader } = await import('@loaders.gl/gltf');
const plainBytes = readFileSync(path.join(dir, 'model_plain.glb'));
const gltf = await parse(plainBytes, GLTFLoader, { gltf: { normalize: false } });
const plain = glbChunks(new Uint8Array(plainBytes));
const prim = plain.json.meshes[0].primitives[0];
const accessor = (name, Type, per) => {
  const a = plain.json.accessors[prim.attributes[name]];
  const v = plain.json.bufferViews[a.bufferView];
  return new Type(plain.bin.buffer.slice(plain.bin.byteOffset + v.byteOffset + (a.byteOffset || 0),
    plain.bin.byteOffset + v.byteOffset + (a.byteOffset || 0) + a.count * per * Type.BYTES_PER_ELEMENT));
};
const n = plain.json.accessors[prim.attributes.POSITION].count;
{
  const lgPrim = gltf.json.meshes[0].primitives[0];
  const names = Object.keys(lgPrim.attributes);
  const lgAccessor = gltf.json.accessors[lgPrim.attributes.POSITION];
  const table = gltf.json.extensions?.EXT_structural_metadata?.propertyTables?.[0];
  const featureIds = lgPrim.extensions?.EXT_mesh_features?.featureIds?.[0];
  const ok = lgAccessor.count === n && names.includes('KHR_gaussian_splatting:SCALE') &&
    names.includes('KHR_gaussian_splatting:ROTATION') && names.includes('KHR_gaussian_splatting:OPACITY') &&
    (!featureIds || (names.includes('_FEATURE_ID_0') && table && table.count > 0));
  report(ok, `loaders.gl GLTFLoader parses model_plain.glb: ${lgAccessor.count} splats, ${names.length} attributes` +
    (featureIds ? `, feature IDs (featureCount ${featureIds.featureCount}) into a property table of ${table.count} classes` : ', no classes'));
}

// 3. The SPZ payload in Niantic's decoder, against the plain accessors.
process.type = 'renderer';  // the package's browser build: embedded WASM, no Node branch
const { loadSpz } = await import('@spz-loader/core');
const spz = glbChunks(new Uint8Array(readFileSync(path.join(dir, 'model.glb'))));
const spzView = spz.json.bufferViews[spz.json.meshes[0].primitives[0].extensions.KHR_gaussian_splatting
  .extensions.KHR_gaussian_splatting_compression_spz_2.bufferView];
const cloud = await loadSpz(spz.bin.slice(spzView.byteOffset, spzView.byteOffset + spzView.byteLength),
  { unpackOptions: { coordinateSystem: 'UNSPECIFIED' } });
{
  const P = accessor('POSITION', Float32Array, 3), S = accessor('KHR_gaussian_splatting:SCALE', Float32Array, 3);
  const R = accessor('KHR_gaussian_splatting:ROTATION', Float32Array, 4);
  const O = accessor('KHR_gaussian_splatting:OPACITY', Float32Array, 1);
  const C = accessor('COLOR_0', Uint8Array, 4);
  let dp = 0, ds = 0, da = 0, dc = 0, dq = 0;
  for (let i = 0; i < Math.min(n, cloud.numPoints); ++i) {
    for (let k = 0; k < 3; ++k) {
      dp = Math.max(dp, Math.abs(cloud.positions[3 * i + k] - P[3 * i + k]));
      ds = Math.max(ds, Math.abs(Math.log(cloud.scales[3 * i + k]) - Math.log(S[3 * i + k])));
      // COLOR_0 is clamped to [0, 1] (as CesiumJS clamps the decoded colours)
      dc = Math.max(dc, Math.abs(Math.min(1, Math.max(0, cloud.colors[3 * i + k])) - C[4 * i + k] / 255));
    }
    da = Math.max(da, Math.abs(cloud.alphas[i] - O[i]));
    let dot = 0;
    for (let k = 0; k < 4; ++k) dot += cloud.rotations[4 * i + k] * R[4 * i + k];
    dq = Math.max(dq, 1 - Math.abs(dot));
  }
  const step = 1 / 2 ** 12;
  const ok = cloud.numPoints === n && dp <= step && ds <= 1 / 32 + 1e-4 && da <= 1 / 255 + 1e-4 &&
    dc <= 0.02 && dq <= 0.002;
  report(ok, `@spz-loader/core decodes model.glb's SPZ payload (axes as stored): ${cloud.numPoints} splats ` +
    `(plain: ${n}); largest differences to the plain accessors: position ${dp.toExponential(2)} m, ` +
    `log-scale ${ds.toFixed(4)}, alpha ${da.toFixed(4)}, colour ${dc.toFixed(4)}, 1-|q.q'| ${dq.toExponential(2)}`);
}

// 4. loaders.gl Tiles3DLoader on tileset.json.
const { Tiles3DLoader } = await import('@loaders.gl/3d-tiles');
const tilesetPath = path.join(dir, 'tileset', 'tileset.json');
const tileset = await parse(readFileSync(tilesetPath), Tiles3DLoader,
  { '3d-tiles': { isTileset: true, loadGLTF: false } });
{
  let tiles = 0;
  const walk = (t) => { ++tiles; (t.children || []).forEach(walk); };
  walk(tileset.root);
  const written = JSON.parse(readFileSync(tilesetPath, 'utf8'));
  let want = 0;
  const count = (t) => { ++want; (t.children || []).forEach(count); };
  count(written.root);
  report(tiles === want && tileset.root.refine !== undefined,
    `loaders.gl Tiles3DLoader parses tileset.json: ${tiles} tiles (written ${want}), asset ${tileset.asset?.version}, root refine ${tileset.root.refine}, root content ${tileset.root.contentUrl || tileset.root.content?.uri}`);
}
process.exit(failed ? 1 : 0);
