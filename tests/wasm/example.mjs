// The minimal JavaScript use of pdm_wasm.wasm (README "Embedding"): the paper's sphere → floor
// form factor in f64. run.sh runs it: node tests/wasm/example.mjs [path/to/pdm_wasm.wasm]
import { readFile } from 'node:fs/promises';

const path = process.argv[2] ?? new URL('./target/wasm32-unknown-unknown/release/pdm_wasm.wasm', import.meta.url);
const { instance } = await WebAssembly.instantiate(await readFile(path), {}); // no imports needed
const pdm = instance.exports;

// Unit sphere at the origin; floor of the cube of side 6: origin, edge_t, edge_s (faces +z).
const pair = pdm.pdm_pair_new_f64(0, 0, 0, 1, -3, -3, -3, 6, 0, 0, 0, 6, 0);
if (pair < 0) throw new Error(`pdm_pair_new_f64 failed with code ${pair}`);
// Sphere in 4 × 8 patches, floor in 3 × 3, Gauss order 5.
const f = pdm.pdm_form_factor_f64(pair, 4, 8, 3, 3, 5);
pdm.pdm_pair_free(pair);
if (f < 0) throw new Error(`pdm_form_factor_f64 failed with code ${f}`);
console.log(`F(sphere -> floor) = ${f}`); // ≈ 1/6
