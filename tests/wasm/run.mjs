// Loads pdm_wasm.wasm in Node, computes a set of sphere/parallelogram form factors through its
// C-ABI exports in f64 and f32, runs the same cases through the same Rust code compiled natively
// (the pdm-wasm-native binary), and compares the results bit for bit.
//
//   node tests/wasm/run.mjs path/to/pdm_wasm.wasm path/to/pdm-wasm-native
//
// Exits 0 only if every case is bit-identical to native (f64 and f32), the API checks pass and
// the paper's scene gives its known values. Last line: "N passed, M failed".

import { readFileSync } from 'node:fs';
import { spawnSync } from 'node:child_process';

const [wasmPath, nativePath] = process.argv.slice(2);
if (!wasmPath || !nativePath) {
  console.error('usage: node run.mjs PDM_WASM.wasm PDM_WASM_NATIVE');
  process.exit(2);
}

const bytes = readFileSync(wasmPath);
const { module, instance } = await WebAssembly.instantiate(bytes, {});
const pdm = instance.exports;

let passed = 0;
let failed = 0;
const check = (ok, what) => {
  if (ok) passed++;
  else {
    failed++;
    console.log(`FAIL ${what}`);
  }
};

// ---- the cases ------------------------------------------------------------------------------
// A case: precision, sphere [cx, cy, cz, r], parallelogram [origin, edge_t, edge_s] (9 numbers),
// grids [sphere_m, sphere_n, plane_m, plane_n], order.
const cases = [];
const add = (prec, sphere, plane, grids, order, label) => {
  const round = prec === 'f32' ? Math.fround : (x) => x;
  cases.push({ prec, params: [...sphere, ...plane].map(round), grids, order, label });
};

// The paper's scene: unit sphere at the origin in a cube of side 6; the six faces facing inwards.
const faces = {
  floor: [-3, -3, -3, 6, 0, 0, 0, 6, 0],
  ceiling: [-3, -3, 3, 0, 6, 0, 6, 0, 0],
  west: [-3, -3, -3, 0, 6, 0, 0, 0, 6],
  east: [3, -3, -3, 0, 0, 6, 0, 6, 0],
  south: [-3, -3, -3, 0, 0, 6, 6, 0, 0],
  north: [-3, 3, -3, 6, 0, 0, 0, 0, 6],
};
const unit = [0, 0, 0, 1];
for (const prec of ['f64', 'f32']) {
  add(prec, unit, faces.floor, [4, 8, 3, 3], 5, 'paper floor, order 5');
  add(prec, unit, faces.floor, [8, 16, 4, 4], 8, 'paper floor, order 8');
  add(prec, unit, faces.floor, [2, 4, 1, 1], 3, 'paper floor, coarse');
  add(prec, unit, faces.floor, [2, 4, 1, 1], 16, 'paper floor, order 16');
  for (const [name, face] of Object.entries(faces)) add(prec, unit, face, [4, 8, 2, 2], 5, `paper ${name}`);
  add(prec, [0.3, -0.2, 0.5, 0.7], [-2, -1.5, -2.5, 0.2, 0, 3.5, 3, 0.5, 0], [4, 8, 3, 3], 6, 'tilted, off-centre');
  add(prec, [0, 0, 1.05, 1], [-0.5, -0.5, 0, 1, 0, 0, 0, 1, 0], [8, 16, 4, 4], 7, 'sphere almost touching');
  add(prec, [0, 0, 0, 1], faces.floor.map((x) => x * 1e3), [4, 8, 2, 2], 5, 'far plane');
  // Deterministic pseudo-random scenes (mulberry32).
  let seed = 12345;
  const rand = () => {
    seed = (seed + 0x6d2b79f5) | 0;
    let t = Math.imul(seed ^ (seed >>> 15), 1 | seed);
    t = (t + Math.imul(t ^ (t >>> 7), 61 | t)) ^ t;
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
  for (let k = 0; k < 12; k++) {
    const u = () => 4 * rand() - 2;
    const sphere = [u(), u(), u(), 0.2 + rand()];
    const plane = [u() - 3, u() - 3, -4 + u(), 3 + u(), u(), 0.3 * u(), u(), 3 + u(), 0.3 * u()];
    add(prec, sphere, plane, [1 + (k % 4), 2 + (k % 5), 1 + (k % 3), 1 + (k % 2)], 2 + (k % 9), `random ${k}`);
  }
  // Errors: the code must be the same too.
  add(prec, [0, 0, 0, -1], faces.floor, [4, 8, 3, 3], 5, 'negative radius (-4)');
  add(prec, [0, 0, 0, NaN], faces.floor, [4, 8, 3, 3], 5, 'NaN radius (-2)');
  add(prec, unit, [-3, -3, -3, 6, 0, 0, 12, 0, 0], [4, 8, 3, 3], 5, 'parallel edges (-4)');
  add(prec, unit, faces.floor, [4, 8, 3, 3], 0, 'order 0 (-1)');
  add(prec, unit, faces.floor, [4, 8, 3, 3], 17, 'order 17 (-1)');
  add(prec, unit, faces.floor, [0, 8, 3, 3], 5, 'empty grid (-3)');
  add(prec, unit, faces.floor, [4, -8, 3, 3], 5, 'negative grid (-23)');
}

// ---- WebAssembly -----------------------------------------------------------------------------
const view = new DataView(new ArrayBuffer(8));
const bitsOf = (prec, x) => {
  if (prec === 'f64') {
    view.setFloat64(0, x);
    return '0x' + view.getBigUint64(0).toString(16).padStart(16, '0');
  }
  view.setFloat32(0, x);
  return '0x' + view.getUint32(0).toString(16).padStart(8, '0');
};
const runWasm = (c) => {
  const h = (c.prec === 'f64' ? pdm.pdm_pair_new_f64 : pdm.pdm_pair_new_f32)(...c.params);
  const v = h >= 0 ? (c.prec === 'f64' ? pdm.pdm_form_factor_f64 : pdm.pdm_form_factor_f32)(h, ...c.grids, c.order) : h;
  pdm.pdm_pair_free(h);
  return { h, v, bits: bitsOf(c.prec, v) };
};
const wasmResults = cases.map(runWasm);

// ---- native ----------------------------------------------------------------------------------
const input = cases.map((c) => [c.prec, ...c.params.map(String), ...c.grids, c.order].join(' ')).join('\n') + '\n';
const native = spawnSync(nativePath, [], { input, encoding: 'utf8' });
if (native.status !== 0) {
  console.error(`native run failed (status ${native.status}):\n${native.stderr}`);
  process.exit(1);
}
const nativeLines = native.stdout.trim().split('\n');
check(nativeLines.length === cases.length, `native printed ${nativeLines.length} lines for ${cases.length} cases`);

// ---- comparison ------------------------------------------------------------------------------
const ulps = (prec, a, b) => {
  // Distance in units in the last place, for two results of the same sign.
  if (prec === 'f64') {
    view.setFloat64(0, a);
    const x = view.getBigInt64(0);
    view.setFloat64(0, b);
    const y = view.getBigInt64(0);
    return x > y ? x - y : y - x;
  }
  view.setFloat32(0, a);
  const x = view.getInt32(0);
  view.setFloat32(0, b);
  return Math.abs(x - view.getInt32(0));
};
let identical = { f64: 0, f32: 0 };
cases.forEach((c, i) => {
  const w = wasmResults[i];
  const [nh, nbits] = (nativeLines[i] ?? '').split(' ');
  const same = Number(nh) === w.h && nbits === w.bits;
  if (same) identical[c.prec]++;
  else {
    const nv = c.prec === 'f64'
      ? (view.setBigUint64(0, BigInt(nbits ?? '0x0')), view.getFloat64(0))
      : (view.setUint32(0, Number(nbits ?? 0)), view.getFloat32(0));
    console.log(`  ${c.prec} ${c.label}: wasm ${w.h} ${w.v} ${w.bits} vs native ${nh} ${nv} ${nbits} (${ulps(c.prec, w.v, nv)} ulp)`);
  }
  check(same, `${c.prec} ${c.label}: wasm and native differ`);
});
const count = { f64: cases.filter((c) => c.prec === 'f64').length, f32: cases.filter((c) => c.prec === 'f32').length };
console.log(`wasm vs native: f64 ${identical.f64}/${count.f64} bit-identical, f32 ${identical.f32}/${count.f32} bit-identical`);

// ---- known values ----------------------------------------------------------------------------
const value = (prec, label) => wasmResults[cases.findIndex((c) => c.prec === prec && c.label === label)].v;
for (const [prec, tol] of [['f64', 1e-4], ['f32', 1e-3]]) {
  const f = value(prec, 'paper floor, order 8');
  console.log(`${prec} sphere -> floor (8x16 / 4x4, order 8): ${f} (1/6 = ${1 / 6})`);
  check(Math.abs(f - 1 / 6) < tol, `${prec} paper floor ≈ 1/6`);
  const sum = Object.keys(faces).reduce((s, name) => s + value(prec, `paper ${name}`), 0);
  console.log(`${prec} sphere -> six faces, sum: ${sum}`);
  check(Math.abs(sum - 1) < 1e-2, `${prec} six faces sum to 1`);
}
for (const c of cases.filter((c) => c.label.includes('(-'))) {
  const want = Number(c.label.match(/\((-\d+)\)/)[1]);
  const got = wasmResults[cases.indexOf(c)].v;
  check(got === want, `${c.prec} ${c.label}: got ${got}`);
}

// ---- module ------------------------------------------------------------------------------------
const imports = WebAssembly.Module.imports(module);
check(imports.length === 0, `the module imports nothing (got ${JSON.stringify(imports)})`);
console.log(`module: ${bytes.length} bytes, exports ${WebAssembly.Module.exports(module).map((e) => e.name).join(', ')}`);

// ---- API ---------------------------------------------------------------------------------------
check(pdm.pdm_max_order() === 16, 'pdm_max_order() == 16');
const h64 = pdm.pdm_pair_new_f64(0, 0, 0, 1, ...faces.floor);
check(h64 >= 0, 'f64 pair created');
check(pdm.pdm_form_factor_f32(h64, 4, 8, 3, 3, 5) === -21, 'f32 call on an f64 pair: WRONG_PRECISION');
check(pdm.pdm_pair_free(h64) === 0, 'free');
check(pdm.pdm_pair_free(h64) === -20, 'double free: BAD_HANDLE');
check(pdm.pdm_form_factor_f64(h64, 4, 8, 3, 3, 5) === -20, 'freed handle: BAD_HANDLE');
check(pdm.pdm_form_factor_f64(999, 4, 8, 3, 3, 5) === -20, 'unknown handle: BAD_HANDLE');
const held = [];
for (let k = 0; k < pdm.pdm_max_pairs(); k++) held.push(pdm.pdm_pair_new_f32(0, 0, 0, 1, ...faces.floor));
check(held.every((h, k) => h === k), 'pdm_max_pairs() pairs at once');
check(pdm.pdm_pair_new_f32(0, 0, 0, 1, ...faces.floor) === -22, 'one more: NO_FREE_SLOT');
held.forEach((h) => pdm.pdm_pair_free(h));
check(pdm.pdm_pair_new_f64(0, 0, 0, 1, ...faces.floor) === 0, 'slots reusable after free');
pdm.pdm_pair_free(0);

console.log(`${passed} passed, ${failed} failed`);
process.exit(failed === 0 ? 0 : 1);
