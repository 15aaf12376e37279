//! The kernel's Gauss–Legendre tables (`pdm-kernel/src/gauss_tables.rs`) against their generator
//! `pdm_host::gauss_gen`: the committed file must be byte-identical to the generator's output, the
//! multi-precision reference must itself be right, and every f64/f32 entry must be the correctly
//! rounded reference value.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use dashu_int::ops::{Abs, UnsignedAbs};
use dashu_int::{IBig, UBig};
use pdm_host::gauss_gen::{
    self, exact, exact_f32, exact_f64, from_fixed, hp_rule, hp_rule_with_bits, pow2, round_to_f32, round_to_f64,
    to_fixed, Float, ERROR_BOUND_BITS, MAX_ORDER, PRECISION, TABLE_LEN,
};

/// |x| < 10^−digits, for x = raw · 2^−bits.
fn below_ten_to_minus(raw: &IBig, bits: usize, digits: u32) -> bool {
    raw.clone().unsigned_abs() * UBig::from(10_u8).pow(digits as usize) < (UBig::ONE << bits)
}

#[test]
fn gauss_tables_are_bit_exact() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("pdm-kernel/src/gauss_tables.rs");
    let committed = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let generated = gauss_gen::render_tables().expect("table generation failed");
    if let Some((line, old, new)) = gauss_gen::first_difference(&committed, &generated) {
        panic!(
            "{} is not the generator's output; first difference at line {line}:\n  committed: {old}\n  \
             generated: {new}\nregenerate with `cargo run -p pdm-host --bin gen-gauss-tables`",
            path.display()
        );
    }
}

/// Sum of weights = 2 and ∫₋₁¹ x^(2k) dx = 2/(2k+1) for k = 0..n−1, to 1e−40 (in fact to ~1e−70).
/// With the exact mirror symmetry (odd moments vanish) this is exactness for every degree
/// ≤ 2n − 1, which characterises the n-point Gauss rule uniquely. Checked in fixed point with
/// [`PRECISION`] fractional bits (integer arithmetic, independent of the generator's floats).
#[test]
fn reference_rules_integrate_exactly() {
    for n in 1..=MAX_ORDER {
        let rule = hp_rule(n).unwrap();
        let bits = PRECISION;
        let nodes: Vec<IBig> = rule.nodes.iter().map(|x| to_fixed(x, bits)).collect();
        let weights: Vec<IBig> = rule.weights.iter().map(|w| to_fixed(w, bits)).collect();
        assert_eq!(nodes.len(), n);
        assert_eq!(weights.len(), n);
        let one = IBig::ONE << bits;
        for pair in nodes.windows(2) {
            assert!(pair[0] < pair[1], "order {n}: nodes not strictly ascending");
        }
        assert!(nodes.iter().all(|x| x.clone().unsigned_abs() < one.clone().unsigned_abs()));
        assert!(weights.iter().all(|w| *w > IBig::ZERO));

        let mut powers: Vec<IBig> = vec![one.clone(); n]; // x_i^(2k)
        for k in 0..n {
            let sum: IBig = weights.iter().zip(&powers).map(|(w, p)| (w * p) >> bits).sum();
            let exact = (IBig::from(2_u8) << bits) / IBig::from(2 * k + 1);
            let diff = &sum - &exact;
            assert!(below_ten_to_minus(&diff, bits, 40), "order {n}: moment x^{} off by more than 1e-40", 2 * k);
            assert!(below_ten_to_minus(&diff, bits, 70), "order {n}: moment x^{} off by > 1e-70", 2 * k);
            for (p, x) in powers.iter_mut().zip(&nodes) {
                *p = (&*p * x * x) >> (2 * bits);
            }
        }
    }
}

/// The claimed error bound 2^(ERROR_BOUND_BITS − PRECISION) holds against a computation with 128
/// more bits (differences taken exactly).
#[test]
fn reference_error_bound_holds() {
    let bound = pow2(ERROR_BOUND_BITS as isize - PRECISION as isize);
    let mut worst = Float::ZERO;
    for n in 1..=MAX_ORDER {
        let lo = hp_rule(n).unwrap();
        let hi = hp_rule_with_bits(n, PRECISION + 128).unwrap();
        let pairs = lo.nodes.iter().zip(&hi.nodes).chain(lo.weights.iter().zip(&hi.weights));
        for (a, b) in pairs {
            let err = (exact(a) - exact(b)).abs();
            assert!(err < bound, "order {n}: reference error above 2^({ERROR_BOUND_BITS} - {PRECISION})");
            if err > worst {
                worst = err;
            }
        }
    }
    println!("largest reference discrepancy: {:e} (2^{:.1})", worst.to_f64().value(), worst.to_f64().value().log2());
}

#[test]
fn tables_are_exactly_symmetric() {
    let t = gauss_gen::tables().unwrap();
    assert_eq!(t.offsets.len(), MAX_ORDER + 2);
    assert_eq!((t.offsets[0], t.offsets[1]), (0, 0));
    for v in [t.nodes_f64.len(), t.weights_f64.len(), t.nodes_f32.len(), t.weights_f32.len()] {
        assert_eq!(v, TABLE_LEN);
    }
    for n in 1..=MAX_ORDER {
        let (a, b) = (t.offsets[n], t.offsets[n + 1]);
        assert_eq!(b - a, n);
        let (x64, w64, x32, w32) = (&t.nodes_f64[a..b], &t.weights_f64[a..b], &t.nodes_f32[a..b], &t.weights_f32[a..b]);
        for k in 0..n {
            let m = n - 1 - k;
            if k != m {
                assert_eq!(x64[k].to_bits(), (-x64[m]).to_bits(), "order {n} node {k} (f64)");
                assert_eq!(x32[k].to_bits(), (-x32[m]).to_bits(), "order {n} node {k} (f32)");
            }
            assert_eq!(w64[k].to_bits(), w64[m].to_bits(), "order {n} weight {k} (f64)");
            assert_eq!(w32[k].to_bits(), w32[m].to_bits(), "order {n} weight {k} (f32)");
        }
        if n % 2 == 1 {
            assert_eq!(x64[n / 2].to_bits(), 0, "order {n}: middle node must be +0.0");
            assert_eq!(x32[n / 2].to_bits(), 0, "order {n}: middle node must be +0.0");
        }
    }
}

/// The two representable neighbours of a nonzero finite f64 (below, above in magnitude).
fn neighbours_f64(v: f64) -> (f64, f64) {
    (f64::from_bits(v.to_bits() - 1), f64::from_bits(v.to_bits() + 1))
}

fn neighbours_f32(v: f32) -> (f32, f32) {
    (f32::from_bits(v.to_bits() - 1), f32::from_bits(v.to_bits() + 1))
}

/// Half an ulp of the normal float with biased exponent `exponent_bits` and `mant` stored
/// significand bits, exact.
fn half_ulp(exponent_bits: u64, bias: isize, mant: isize) -> Float {
    let e = isize::try_from(exponent_bits).unwrap() - bias; // v = 1.f · 2^e
    pow2(e - mant - 1)
}

/// Every f64 and f32 entry is the nearest float to the reference value (f32 rounded directly, not
/// through f64); where `(f64 as f32)` disagrees, the f64 value must sit exactly on an f32 midpoint
/// (the only way double rounding can bite). Distances are exact.
#[test]
fn entries_are_correctly_rounded() {
    let t = gauss_gen::tables().unwrap();
    let mut double_rounding_cases = 0;
    let mut checked = 0;
    for n in 1..=MAX_ORDER {
        let rule = hp_rule(n).unwrap();
        let a = t.offsets[n];
        let values = rule.nodes.iter().enumerate().map(|(i, x)| (x, t.nodes_f64[a + i], t.nodes_f32[a + i]));
        let weights = rule.weights.iter().enumerate().map(|(i, w)| (w, t.weights_f64[a + i], t.weights_f32[a + i]));
        for (hp, v64, v32) in values.chain(weights) {
            checked += 1;
            let hp = exact(hp);
            if hp == Float::ZERO {
                assert_eq!((v64.to_bits(), v32.to_bits()), (0, 0));
                continue;
            }
            let dist = |f: Float| (&hp - f).abs();

            let d64 = dist(exact_f64(v64).unwrap());
            let h64 = half_ulp((v64.to_bits() >> 52) & 0x7ff, 1023, 52);
            assert!(d64 <= h64, "order {n}: f64 {v64:e} more than half an ulp from the reference");
            let (lo, up) = neighbours_f64(v64);
            assert!(d64 < dist(exact_f64(lo).unwrap()));
            assert!(d64 < dist(exact_f64(up).unwrap()));

            let d32 = dist(exact_f32(v32).unwrap());
            let h32 = half_ulp(u64::from((v32.to_bits() >> 23) & 0xff), 127, 23);
            assert!(d32 <= h32, "order {n}: f32 {v32:e} more than half an ulp from the reference");
            let (lo, up) = neighbours_f32(v32);
            assert!(d32 < dist(exact_f32(lo).unwrap()));
            assert!(d32 < dist(exact_f32(up).unwrap()));

            #[allow(clippy::cast_possible_truncation)]
            let via_f64 = v64 as f32;
            if via_f64.to_bits() != v32.to_bits() {
                double_rounding_cases += 1;
                let (lo, up) = neighbours_f32(v32);
                let other = if via_f64 == lo { lo } else { up };
                assert_eq!(via_f64.to_bits(), other.to_bits(), "order {n}: f64→f32 off by > 1 ulp");
                let mid = (exact_f32(v32).unwrap() + exact_f32(other).unwrap()) * pow2(-1);
                assert_eq!(exact_f64(v64).unwrap(), mid, "order {n}: not a double-rounding case");
            }
        }
    }
    assert_eq!(checked, 2 * TABLE_LEN);
    println!("{checked} entries correctly rounded; {double_rounding_cases} where (f64 as f32) double-rounds");
}

/// The rounding primitives on hand-made values, including a genuine double-rounding trap.
#[test]
fn rounding_primitives() {
    let bits = PRECISION;
    let fx = |raw: IBig| from_fixed(raw, bits);
    let third = fx((IBig::ONE << bits) / IBig::from(3_u8));
    assert_eq!(round_to_f64(&third, bits), Some(1.0_f64 / 3.0));
    assert_eq!(round_to_f32(&third, bits), Some(1.0_f32 / 3.0));
    assert_eq!(round_to_f64(&-third.clone(), bits), Some(-1.0_f64 / 3.0));
    assert_eq!(round_to_f64(&Float::ZERO, bits).map(f64::to_bits), Some(0));

    // x = 1 + 2^−24 + 2^−60: just above the f32 midpoint between 1 and 1 + 2^−23. Rounding to f64
    // first lands exactly on that midpoint, and ties-to-even then gives 1.0 — wrong.
    let x = fx((IBig::ONE << bits) + (IBig::ONE << (bits - 24)) + (IBig::ONE << (bits - 60)));
    let x64 = round_to_f64(&x, bits).unwrap();
    assert_eq!(x64, 1.0 + 2.0_f64.powi(-24));
    #[allow(clippy::cast_possible_truncation)]
    let naive = x64 as f32;
    assert_eq!(naive, 1.0);
    assert_eq!(round_to_f32(&x, bits), Some(1.0 + 2.0_f32.powi(-23)));

    // Values within the error bound of 1 (just below and above) still round to 1 exactly.
    let near = UBig::ONE << 20;
    let one = IBig::ONE << bits;
    assert_eq!(round_to_f64(&fx(&one - IBig::from(near.clone())), bits), Some(1.0));
    assert_eq!(round_to_f32(&fx(&one + IBig::from(near)), bits), Some(1.0));

    // Exactly on (or within the error bound of) a midpoint: refused rather than guessed.
    let mid = (IBig::ONE << bits) + (IBig::ONE << (bits - 24));
    assert_eq!(round_to_f32(&fx(mid.clone()), bits), None);
    assert_eq!(round_to_f32(&fx(&mid + IBig::from(7_u8)), bits), None);
    // A value within the error bound of 0 cannot be rounded either.
    assert_eq!(round_to_f64(&fx(IBig::ONE << 20), bits), None);
}
