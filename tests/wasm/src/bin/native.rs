//! The same exports, called natively on the build machine: reads cases from standard input,
//! one per line, and prints the handle and the result's bit pattern for each, so that the Node
//! script (run.mjs) can compare the WebAssembly module with native code bit for bit.
//!
//! Input line:  `f64|f32 cx cy cz r ox oy oz tx ty tz sx sy sz sphere_m sphere_n plane_m plane_n order`
//! Output line: `<handle or code> 0x<bits>` (16 hex digits for f64, 8 for f32; the value is the
//! form factor, or the error code as a float when the pair could not be created or computed).
//! Numbers are decimal text as JavaScript prints them (shortest round-trip form); f32 inputs
//! are parsed as f64 and rounded to f32 (round-to-nearest-even, as WebAssembly's f32 parameters).

use std::io::{BufRead, Write};

use pdm_wasm::{
    pdm_form_factor_f32, pdm_form_factor_f64, pdm_pair_free, pdm_pair_new_f32, pdm_pair_new_f64,
};

fn main() {
    let stdin = std::io::stdin();
    let mut out = std::io::stdout().lock();
    for line in stdin.lock().lines() {
        let line = line.expect("read stdin");
        let mut words = line.split_whitespace();
        let Some(precision) = words.next() else {
            continue;
        };
        let nums: Vec<f64> = words
            .map(|w| {
                w.parse::<f64>()
                    .unwrap_or_else(|_| panic!("bad number {w:?}"))
            })
            .collect();
        assert_eq!(
            nums.len(),
            18,
            "expected 13 parameters and 5 integers: {line}"
        );
        let ints: Vec<i32> = nums[13..].iter().map(|&x| x as i32).collect();
        let [sm, sn, pm, pn, order] = ints[..] else {
            unreachable!()
        };
        match precision {
            "f64" => {
                let p = &nums[..13];
                let h = pdm_pair_new_f64(
                    p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9], p[10], p[11], p[12],
                );
                let v = if h >= 0 {
                    pdm_form_factor_f64(h, sm, sn, pm, pn, order)
                } else {
                    f64::from(h)
                };
                pdm_pair_free(h);
                writeln!(out, "{h} 0x{:016x}", v.to_bits()).unwrap();
            }
            "f32" => {
                let p: Vec<f32> = nums[..13].iter().map(|&x| x as f32).collect();
                let h = pdm_pair_new_f32(
                    p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9], p[10], p[11], p[12],
                );
                let v = if h >= 0 {
                    pdm_form_factor_f32(h, sm, sn, pm, pn, order)
                } else {
                    h as f32
                };
                pdm_pair_free(h);
                writeln!(out, "{h} 0x{:08x}", v.to_bits()).unwrap();
            }
            other => panic!("unknown precision {other:?}"),
        }
    }
}
