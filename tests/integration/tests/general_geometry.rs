//! Regression tests for the red-team findings on general geometry (F1–F13): values returned
//! wrong as `Ok`, refusals of well-posed pairs, and error estimates below the actual error.
//! Each case computes through the public API (`pair_exchange`, `adaptive_exchange`) and compares
//! with an exact reference written independently of the kernel: catalogue closed forms from
//! `pdm_host::reference::closed_form` (Howell C-11, C-14, C-41, the Van Oosterom–Strackee
//! polygon solid angle), configuration-factor algebra on them (superposition along a common
//! line, additivity), and sum rules in enclosures. Every test prints all its numbers before it
//! asserts.

use core::f64::consts::PI;
use pdm_host::reference::closed_form as exact;
use pdm_kernel::{
    adaptive_exchange, pair_exchange, vec3, Adaptive, AutoNormal, Cone, Cylinder, Disk, Frame, Occluder, PairSettings,
    Parallelogram, ParamRect, ParametricMap, Patch, PdmError, Real, Scalar, Side, Sphere, Surface, Vec3,
};

fn v<T: Real>(p: [f64; 3]) -> Vec3<T> {
    vec3(T::from_f64(p[0]), T::from_f64(p[1]), T::from_f64(p[2]))
}

/// Relative error of a result; infinite for a refusal (so that `< limit` fails).
fn rel(got: &Result<f64, PdmError>, reference: f64) -> f64 {
    got.as_ref().map_or(f64::INFINITY, |x| ((x - reference) / reference).abs())
}

/// A result for printing: the value to 16 digits, or the refusal.
fn show(got: &Result<f64, PdmError>) -> String {
    got.as_ref().map_or_else(|e| format!("Err({e})"), |x| format!("{x:.15e}"))
}

/// Gauss order `order` for separate pairs, 12 for touching pairs, visibility boundaries placed.
fn settings(order: usize) -> PairSettings {
    PairSettings { order, singular_order: 12, boundaries: true }
}

fn square<T: Real>(o: [f64; 3], et: [f64; 3], es: [f64; 3]) -> Parallelogram<T> {
    Parallelogram::new(v(o), v(et), v(es)).unwrap()
}

/// A_a·F_{a→b} by `pair_exchange`, as f64.
fn exchange<T: Real, SA: Surface<T>, SB: Surface<T>, O: Occluder<T>>(
    a: &Patch<'_, T, SA>,
    b: &Patch<'_, T, SB>,
    s: PairSettings,
    occluders: &O,
) -> Result<f64, PdmError> {
    pair_exchange::<T, _, _, _, 1024>(a, b, s, occluders).map(|e| e.value).map(Real::to_f64)
}

/// A_a·F_{a→b} and A_b·F_{b→a} of two whole surfaces, printed against `reference`.
fn both_orders<T: Real, SA: Surface<T>, SB: Surface<T>>(
    a: &SA,
    b: &SB,
    s: PairSettings,
    reference: f64,
) -> (Result<f64, PdmError>, Result<f64, PdmError>) {
    let (pa, pb) = (Patch::whole(a).unwrap(), Patch::whole(b).unwrap());
    let (ab, ba) = (exchange(&pa, &pb, s, &()), exchange(&pb, &pa, s, &()));
    println!("pair_exchange (order {}): {} / reversed {}, exact {reference:.15e}", s.order, show(&ab), show(&ba));
    println!("  relative errors {:.2e} / {:.2e}", rel(&ab, reference), rel(&ba, reference));
    (ab, ba)
}

/// Σ pair_exchange (a's cells → b's cells) over an m × n grid on a and a p × q grid on b; the
/// first refusal if any.
fn grid_sum<T: Real, SA: Surface<T>, SB: Surface<T>>(
    a: &SA,
    (m, n): (usize, usize),
    b: &SB,
    (p, q): (usize, usize),
    s: PairSettings,
) -> Result<f64, PdmError> {
    let mut sum = 0.0;
    for pa in Patch::whole(a).unwrap().grid(m, n).unwrap() {
        for pb in Patch::whole(b).unwrap().grid(p, q).unwrap() {
            sum += exchange(&pa, &pb, s, &())?;
        }
    }
    Ok(sum)
}

/// The tolerance mode (max order 12, max depth `depth`, `CAP` 256) on two whole surfaces,
/// printed against `reference`: (value, estimate, actual error), or the refusal.
fn adaptive_against<T: Real, SA: Surface<T>, SB: Surface<T>>(
    a: &SA,
    b: &SB,
    (tolerance, depth): (f64, u32),
    reference: f64,
) -> Result<(f64, f64, f64), PdmError> {
    let (pa, pb) = (Patch::whole(a).unwrap(), Patch::whole(b).unwrap());
    let settings = Adaptive { tolerance: T::from_f64(tolerance), max_order: 12, max_depth: depth, absolute: T::ZERO };
    let result = adaptive_exchange::<T, _, _, _, 256>(&pa, &pb, settings, &());
    match &result {
        Ok(e) => println!(
            "adaptive (tol {tolerance:e}, depth {depth}): {:.15e}: error {:.2e}, estimate {:.2e}, converged {}",
            e.value.to_f64(),
            (e.value.to_f64() - reference).abs(),
            e.error.unwrap().to_f64(),
            e.converged
        ),
        Err(e) => println!("adaptive (tol {tolerance:e}, depth {depth}): refused: {e}"),
    }
    result.map(|e| (e.value.to_f64(), e.error.unwrap().to_f64(), (e.value.to_f64() - reference).abs()))
}

/// The tolerance mode's result is `Ok` with an estimate that bounds the actual error.
fn assert_bounded(result: Result<(f64, f64, f64), PdmError>) {
    match result {
        Ok((_, error, actual)) => {
            assert!(actual <= error, "adaptive: error {actual:.2e} above the estimate {error:.2e}")
        }
        Err(e) => panic!("adaptive_exchange refused: {e}"),
    }
}

/// Howell C-14 superposition along the common line: floor x ∈ [0, a] × y ∈ [0, w] (z = 0,
/// facing +z) and wall x ∈ [0, b] × z ∈ [0, h] (y = 0, facing +y), a ≤ b, sharing x ∈ [0, a].
/// With E(L) = L·w·C-14(L, w, h) the exchange of the aligned pair of length L, and
/// X(I, J) = X(J, I) for intervals I, J of the common line (the kernel depends on x₁ − x₂ only
/// through an even function), E(b) = E(a) + E(b − a) + 2·X([0, a], [a, b]), so
/// X([0, a], [0, b]) = E(a) + X([0, a], [a, b]) = ½[E(a) + E(b) − E(b − a)].
fn floor_to_longer_wall(a: f64, b: f64, w: f64, h: f64) -> f64 {
    let e = |l: f64| if l > 0.0 { l * w * exact::perpendicular_rectangles(l, w, h) } else { 0.0 };
    0.5 * (e(a) + e(b) - e(b - a))
}

/// Howell C-11 algebra for parallel rectangles in the planes z = 0 (x ∈ ax, y ∈ ay) and z = c
/// (x ∈ bx, y ∈ by), any offsets: the kernel depends on x₁ − x₂ and y₁ − y₂ through even
/// functions, so A₁F₁₂ = ¼ Σᵢ Σⱼ cᵢ cⱼ f(|dxᵢ|, |dyⱼ|) with d = (a₁ − b₁, a₁ − b₀, a₀ − b₁,
/// a₀ − b₀), c = (+1, −1, −1, +1), and f(L, M) = L·M·C-11(L, M, c) the exchange of the
/// directly opposed L × M pair (Siegel & Howell, configuration-factor algebra).
fn parallel_offset(ax: [f64; 2], ay: [f64; 2], bx: [f64; 2], by: [f64; 2], c: f64) -> f64 {
    let diffs =
        |a: [f64; 2], b: [f64; 2]| [(a[1] - b[1], 1.0), (a[1] - b[0], -1.0), (a[0] - b[1], -1.0), (a[0] - b[0], 1.0)];
    let f = |l: f64, m: f64| if l == 0.0 || m == 0.0 { 0.0 } else { l * m * exact::parallel_rectangles(l, m, c) };
    let mut sum = 0.0;
    for (dx, cx) in diffs(ax, bx) {
        for (dy, cy) in diffs(ay, by) {
            sum += cx * cy * f(dx.abs(), dy.abs());
        }
    }
    0.25 * sum
}

/// F1: a whole disk r = 2 and a whole coaxial disk r = 0.5 at 0.05 facing it (the small disk
/// sees the large one at grazing distance; once `Err(InvalidResult)` from `pair_exchange` at
/// order 12 and from the tolerance mode, 6.3e-2 off at order 16, large disk outside).
/// Reference: C-41, A·F = π·2²·C-41(2, 0.5, 0.05). Both disks are flat: the contour form along
/// their edges takes the pair (2.4e-9 at order 10, 1e-14 at 16).
#[test]
fn f1_small_disk_close_over_a_large_disk() {
    let big = Disk::<f64>::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), 2.0).unwrap();
    let small = Disk::<f64>::new(v([0.0, 0.0, 0.05]), v([0.0, 0.0, -1.0]), 0.5).unwrap();
    let reference = PI * 4.0 * exact::coaxial_disks(2.0, 0.5, 0.05);
    assert!((reference - 0.7848749366776595).abs() < 1e-15, "{reference}");
    let (ab, ba) = both_orders(&big, &small, settings(16), reference);
    let adaptive = adaptive_against(&big, &small, (1e-10, 0), reference);
    assert!(rel(&ab, reference) < 1e-12 && rel(&ba, reference) < 1e-12, "{ab:?} / {ba:?} vs {reference}");
    assert_bounded(adaptive);
}

/// F2: equal whole disks r = 5 at a gap of 0.01 (once 1.0e-3 off in both argument orders at
/// orders 12 and 16, and `Err(Degenerate)` from the tolerance mode, later `converged = false`
/// after minutes). Reference: C-41, A·F = 25π·C-41(5, 5, 0.01). Both disks are flat: the
/// contour form along their edges takes the pair at every gap.
#[test]
fn f2_large_disks_at_a_small_gap() {
    let lower = Disk::<f64>::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), 5.0).unwrap();
    let upper = Disk::<f64>::new(v([0.0, 0.0, 0.01]), v([0.0, 0.0, -1.0]), 5.0).unwrap();
    let reference = 25.0 * PI * exact::coaxial_disks(5.0, 5.0, 0.01);
    let (ab, ba) = both_orders(&lower, &upper, settings(16), reference);
    assert!(rel(&ab, reference) < 1e-12 && rel(&ba, reference) < 1e-12, "{ab:?} / {ba:?} vs {reference}");
    for tolerance in [1e-3, 1e-8, 1e-12] {
        let adaptive = adaptive_against(&lower, &upper, (tolerance, 6), reference);
        assert!(adaptive.as_ref().is_ok_and(|&(value, error, _)| error <= tolerance * value), "{adaptive:?}");
        assert_bounded(adaptive);
    }
    // f32: the same pair to its precision.
    let lower = Disk::<f32>::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), 5.0).unwrap();
    let upper = Disk::<f32>::new(v([0.0, 0.0, 0.01]), v([0.0, 0.0, -1.0]), 5.0).unwrap();
    let (ab, ba) = both_orders(&lower, &upper, settings(12), reference);
    assert!(rel(&ab, reference) < 1e-4 && rel(&ba, reference) < 1e-4, "{ab:?} / {ba:?} vs {reference}");
}

/// Flat pairs with curved edges nearly coincident (the contour form along the edges): coaxial
/// disks of radii 1/1, 1/0.6 and 0.7/1.3 at gaps 2 … 1e-6 (C-41), and the annulus
/// r ∈ [0.3, r₁] against the same upper disk (C-41 algebra: the difference of two coaxial-disk
/// pairs). Both argument orders, f64 at order 16, and the tolerance mode at 1e-10.
#[test]
#[ignore = "slow (about 40 s alone): .ci/run runs it, `-- --ignored slow_`"]
fn slow_coaxial_flat_pairs_at_every_gap() {
    let mut worst: f64 = 0.0;
    for (r1, r2) in [(1.0, 1.0), (1.0, 0.6), (0.7, 1.3)] {
        for h in [2.0, 0.5, 0.1, 1e-2, 1e-4, 1e-6] {
            let lower = Disk::<f64>::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), r1).unwrap();
            let upper = Disk::<f64>::new(v([0.0, 0.0, h]), v([0.0, 0.0, -1.0]), r2).unwrap();
            let reference = PI * r1 * r1 * exact::coaxial_disks(r1, r2, h);
            let (ab, ba) = both_orders(&lower, &upper, settings(16), reference);
            worst = worst.max(rel(&ab, reference)).max(rel(&ba, reference));
            let adaptive = adaptive_against(&lower, &upper, (1e-10, 6), reference);
            assert!(adaptive.as_ref().is_ok_and(|&(value, error, _)| error <= 1e-10 * value), "{adaptive:?}");
            assert_bounded(adaptive);
            // The annulus r ∈ [0.3, r1] against the same disk: C-41 difference.
            let ring = Disk::<f64>::annulus(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), 0.3, r1).unwrap();
            let inner = PI * 0.09 * exact::coaxial_disks(0.3, r2, h);
            let (ab, ba) = both_orders(&ring, &upper, settings(16), reference - inner);
            worst = worst.max(rel(&ab, reference - inner)).max(rel(&ba, reference - inner));
        }
    }
    println!("worst relative error {worst:.2e}");
    assert!(worst < 1e-12, "{worst:.2e}");
}

/// Flat patches side by side, nearly in one plane: unit squares facing each other across a
/// lateral gap of ½ at heights 1e-2 … 1e-4, and unit disks 0.5 apart at the rims. The value is
/// small (down to 1e-9) while the contour form's terms are O(1): they cancel beyond half the
/// digits, so the pair falls to the 4-D paths, whose rules resolve it (once
/// `Err(Unresolvable)`). Squares: C-11 algebra ([`parallel_offset`]), whose own terms cancel
/// too — allowed 64 ε × Σ|terms| / value. Disks: both argument orders and orders 12 / 16 agree
/// to 1e-7 (the squares bound the method's accuracy in this configuration).
#[test]
fn flat_pairs_side_by_side_nearly_coplanar() {
    for h in [1e-2, 1e-3, 1e-4] {
        let lower = square::<f64>([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let upper = square::<f64>([1.5, 0.0, h], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]);
        let reference = parallel_offset([0.0, 1.0], [0.0, 1.0], [1.5, 2.5], [0.0, 1.0], h);
        // Σ|terms| of the algebra: the largest is L·M·C-11 ≤ L·M with L ≤ 2.5, M ≤ 1.
        let conditioning = 64.0 * f64::EPSILON * 16.0 * 2.5 / reference;
        let (ab, ba) = both_orders(&lower, &upper, settings(16), reference);
        let allowed = 1e-8 + conditioning;
        assert!(
            rel(&ab, reference) < allowed && rel(&ba, reference) < allowed,
            "h {h}: {ab:?} / {ba:?} vs {reference} (allowed {allowed:.1e})"
        );
        let lower = Disk::<f64>::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), 1.0).unwrap();
        let upper = Disk::<f64>::new(v([2.5, 0.0, h]), v([0.0, 0.0, -1.0]), 1.0).unwrap();
        let (pa, pb) = (Patch::whole(&lower).unwrap(), Patch::whole(&upper).unwrap());
        let value = exchange(&pa, &pb, settings(16), &()).unwrap();
        for (x, y, order) in [(&pa, &pb, 12), (&pb, &pa, 16)] {
            let other = exchange(x, y, settings(order), &()).unwrap();
            println!("disks 0.5 apart at {h:e}: {value:.12e}, order {order}: {:.1e}", (other - value).abs() / value);
            assert!(((other - value) / value).abs() < 1e-7, "h {h}: {other} vs {value}");
        }
    }
}

/// A square's edge clipping a shallow cap (depth 1e-3, 3e-4, 1e-4) off a unit disk's rim, 1e-6
/// above it (found by a red-team pass: the edge crosses the rim twice within one sample
/// spacing of the crossing search, which cut only one of them: 4.7e-3 and 5.7e-4 off by
/// argument order at order 16, and the tolerance mode's estimate below its error). Checks:
/// both argument orders at order 16 agree with order 24 to 1e-8, and the tolerance mode's
/// estimate at 1e-3 bounds its distance from the order-24 value.
#[test]
fn square_edge_clipping_a_shallow_cap_off_a_disk() {
    let half = core::f64::consts::FRAC_1_SQRT_2;
    let disk = Disk::<f64>::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), 1.0).unwrap();
    for depth in [1e-3, 3e-4, 1e-4] {
        let d = 1.0 - depth;
        let plate =
            square::<f64>([d * half + 0.5 * half, d * half - 0.5 * half, 1e-6], [-half, half, 0.0], [half, half, 0.0]);
        let (pa, pb) = (Patch::whole(&disk).unwrap(), Patch::whole(&plate).unwrap());
        let value = exchange(&pa, &pb, settings(24), &()).unwrap();
        for other in [exchange(&pa, &pb, settings(16), &()).unwrap(), exchange(&pb, &pa, settings(16), &()).unwrap()] {
            println!("cap depth {depth:e}: {value:.12e}, order 16: {:.1e}", (other - value).abs() / value);
            assert!(((other - value) / value).abs() < 1e-8, "depth {depth}: {other} vs {value}");
        }
        let e = adaptive_exchange::<f64, _, _, _, 256>(&pa, &pb, Adaptive::new(1e-3), &()).unwrap();
        assert!(e.error.unwrap() >= (e.value - value).abs(), "depth {depth}: {e:?} vs {value}");
    }
}

/// Disk sectors meeting at right angles along a shared radius: the half-disk y ≥ 0 of the
/// plane z = 0 (radiating +z) and the half-disk z ≥ 0 of the plane y = 0 (radiating +y), and
/// their quarters x ≥ 0. Both are flat: the contour form along their edges takes them,
/// exponentially, where the edge transform converges only algebraically at the common centre
/// (its side collapses there: the half-disks' value approaches the contour's from above, 1.9e-6
/// off at order 24). Checks: both argument orders at orders 12 and 16 agree with order 24 to
/// 1e-10 and 1e-13, and
/// the 4-D path (the same disks behind a wrapper without partial derivatives) at order 24 is
/// within its own algebraic error (≤ 4e-6) of the value.
#[test]
fn perpendicular_disk_sectors_sharing_a_radius() {
    /// A surface with point and normal only: the 4-D paths take every pair.
    struct Plain<S>(S);
    impl<S: Surface<f64>> Surface<f64> for Plain<S> {
        fn domain(&self) -> ParamRect<f64> {
            self.0.domain()
        }
        fn point(&self, t: f64, s: f64) -> Vec3<f64> {
            self.0.point(t, s)
        }
        fn normal(&self, t: f64, s: f64) -> Vec3<f64> {
            self.0.normal(t, s)
        }
    }
    let floor = Disk::<f64>::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), 1.0).unwrap();
    let wall = Disk::<f64>::new(v([0.0, 0.0, 0.0]), v([0.0, 1.0, 0.0]), 1.0).unwrap();
    for (a_rect, b_rect) in [((0.0, PI), (PI, 2.0 * PI)), ((0.0, 0.5 * PI), (1.5 * PI, 2.0 * PI))] {
        let ra = ParamRect::new(0.0, 1.0, a_rect.0, a_rect.1).unwrap();
        let rb = ParamRect::new(0.0, 1.0, b_rect.0, b_rect.1).unwrap();
        let (pa, pb) = (Patch::new(&floor, ra).unwrap(), Patch::new(&wall, rb).unwrap());
        let value = exchange(&pa, &pb, settings(24), &()).unwrap();
        for (order, allowed) in [(12, 1e-10), (16, 1e-13)] {
            for (x, y) in [(&pa, &pb), (&pb, &pa)] {
                let other = exchange(x, y, settings(order), &()).unwrap();
                assert!(((other - value) / value).abs() < allowed, "order {order}: {other} vs {value}");
            }
        }
        let (plain_floor, plain_wall) = (Plain(floor), Plain(wall));
        let (qa, qb) = (Patch::new(&plain_floor, ra).unwrap(), Patch::new(&plain_wall, rb).unwrap());
        let four_d = exchange(&qa, &qb, PairSettings { order: 24, singular_order: 24, boundaries: true }, &()).unwrap();
        println!("sectors {a_rect:?} / {b_rect:?}: contour {value:.15e}, 4-D {four_d:.15e}");
        assert!(((four_d - value) / value).abs() < 4e-6, "{four_d} vs {value}");
    }
}

/// F3: a floor 1/3 × 1/2 against a wall 1 × 0.35 whose bottom edge contains the floor's edge,
/// the two sharing one endpoint (a partial shared edge). Reference: C-14 superposition
/// ([`floor_to_longer_wall`]), 3.219835522191568e-2.
#[test]
fn f3_partial_shared_edge_with_a_common_endpoint() {
    let floor = square::<f64>([0.0, 0.0, 0.0], [1.0 / 3.0, 0.0, 0.0], [0.0, 0.5, 0.0]);
    let wall = square::<f64>([0.0, 0.0, 0.0], [0.0, 0.0, 0.35], [1.0, 0.0, 0.0]);
    let reference = floor_to_longer_wall(1.0 / 3.0, 1.0, 0.5, 0.35);
    println!("C-14 superposition: {reference:.16e}");
    assert!((reference / 3.219835522191568e-2 - 1.0).abs() < 1e-14, "{reference}");
    let (ab, ba) = both_orders(&floor, &wall, settings(16), reference);
    let adaptive = adaptive_against(&floor, &wall, (1e-8, 6), reference);
    assert!(rel(&ab, reference) < 1e-9 && rel(&ba, reference) < 1e-9, "{ab:?} / {ba:?} vs {reference}");
    assert_bounded(adaptive);
}

/// F5: a unit sphere whose poles point along (1, 1, 0), cut 4 × 8, over an off-centre plate
/// 0.01 below it (no occluder: the sphere is convex). Reference: sphere → polygon,
/// F = Ω/(4π) with Ω the plate's solid angle at the centre (Van Oosterom–Strackee), so
/// A·F = 4π·Ω/(4π) = Ω. Once 2.0e-4 off at order 16.
#[test]
fn f5_tilted_sphere_cells_over_an_off_centre_plate() {
    let frame = Frame::from_axis(v([1.0, 1.0, 0.0])).unwrap();
    let sphere = Sphere::<f64>::with_frame(v([0.0; 3]), 1.0, frame, Side::Outer).unwrap();
    let plate = square::<f64>([0.2, -0.7, -1.01], [2.3, 0.0, 0.0], [0.0, 2.6, 0.0]);
    let poly = [[0.2, -0.7, -1.01], [2.5, -0.7, -1.01], [2.5, 1.9, -1.01], [0.2, 1.9, -1.01]];
    let reference = 4.0 * PI * exact::sphere_to_polygon([0.0; 3], &poly);
    let got = grid_sum(&sphere, (4, 8), &plate, (1, 1), settings(16));
    println!("sphere 4x8 -> plate: {} vs {reference:.15e}: {:.2e}", show(&got), rel(&got, reference));
    assert!(rel(&got, reference) < 1e-6, "{got:?} vs {reference}: {:.2e}", rel(&got, reference));
}

/// A tilted sphere R 0.3 cut 6 × 12 whose lowest point is 1e-2 or 1e-3 above a unit plate cut
/// 2 × 2, near the plate's corner (the sphere overhangs two of its edges), both argument orders.
/// Reference: sphere → polygon, F = Ω/(4π) with Ω the plate's solid angle at the centre
/// (Van Oosterom–Strackee), so A·F = R²·Ω.
#[test]
#[ignore = "slow (about 40 s alone): .ci/run runs it, `-- --ignored slow_`"]
fn slow_tilted_sphere_grid_close_above_a_plate_corner() {
    let radius = 0.3;
    for gap in [1e-2, 1e-3] {
        let centre = [0.95, 0.1, radius + gap];
        let frame = Frame::from_axis(v([0.3, -0.5, 1.0])).unwrap();
        let sphere = Sphere::<f64>::with_frame(v(centre), radius, frame, Side::Outer).unwrap();
        let plate = square::<f64>([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let poly = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let reference = 4.0 * PI * radius * radius * exact::sphere_to_polygon(centre, &poly);
        let ab = grid_sum(&sphere, (6, 12), &plate, (2, 2), settings(12));
        let ba = grid_sum(&plate, (2, 2), &sphere, (6, 12), settings(12));
        let (e_ab, e_ba) = (rel(&ab, reference), rel(&ba, reference));
        println!("gap {gap:.0e}: {} / reversed {} vs {reference:.15e}: {e_ab:.2e} / {e_ba:.2e}", show(&ab), show(&ba));
        assert!(e_ab < 1e-6 && e_ba < 1e-6, "gap {gap}: {e_ab:.2e} / {e_ba:.2e}");
    }
}

/// The inner wall of a frustum (r 1 → 0.5, h 1) cut 4 × 2 against the whole base disk it
/// stands on, both argument orders. From every wall point the base's rim touches the line where
/// the tangent plane meets the base plane, and the upper cells are within their own size of
/// the base: deciding whether such a pair is very near once refined every pair of parts along
/// the rim to the depth cap (one cell did not finish in 240 s). Reference: the enclosure sum
/// rule with C-41, A·F_base→wall = π(1 − F_base→top).
#[test]
fn frustum_wall_cells_to_the_base_they_stand_on() {
    let base = Disk::<f64>::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), 1.0).unwrap();
    let wall = Cone::<f64>::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), 1.0, 0.5, 1.0, Side::Inner).unwrap();
    let reference = PI * (1.0 - exact::coaxial_disks(1.0, 0.5, 1.0));
    let ab = grid_sum(&wall, (4, 2), &base, (1, 1), settings(12));
    let ba = grid_sum(&base, (1, 1), &wall, (4, 2), settings(12));
    let (e_ab, e_ba) = (rel(&ab, reference), rel(&ba, reference));
    println!("wall 4x2 -> base: {} / reversed {} vs {reference:.15e}: {e_ab:.2e} / {e_ba:.2e}", show(&ab), show(&ba));
    assert!(e_ab < 1e-9 && e_ba < 1e-9, "{e_ab:.2e} / {e_ba:.2e}");
}

/// F6: the base disk (cut 1 × 4) of a closed cylinder r = 1, h = 0.1 → its inner wall (cut
/// 4 × 2). Reference: the enclosure sum rule, F_base→wall = 1 − F_base→top with C-41:
/// A·F = π(1 − C-41(1, 1, 0.1)). Once 6.8e-6 off at order 16.
#[test]
fn f6_disk_cells_to_a_short_cylinder_wall() {
    let base = Disk::<f64>::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), 1.0).unwrap();
    let wall = Cylinder::<f64>::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), 1.0, 0.1, Side::Inner).unwrap();
    let reference = PI * (1.0 - exact::coaxial_disks(1.0, 1.0, 0.1));
    let got = grid_sum(&base, (1, 4), &wall, (4, 2), settings(16));
    println!("base 1x4 -> wall 4x2: {} vs {reference:.15e}: {:.2e}", show(&got), rel(&got, reference));
    assert!(rel(&got, reference) < 1e-8, "{got:?} vs {reference}: {:.2e}", rel(&got, reference));
}

/// F13 (f32): a unit square and a unit square 1e-6 above it, offset by (0.5, 0.25): the
/// exchange is about the overlap area 0.375. Once 1.3e-2 off as `Ok`. A refusal is
/// acceptable; a value must be right to 1e-4, and the tolerance mode's estimate must bound its
/// error. Reference: C-11 algebra in f64 ([`parallel_offset`]).
#[test]
fn f13_f32_offset_squares_almost_touching() {
    let gap = f64::from(1e-6f32);
    let lower = square::<f32>([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let upper = square::<f32>([0.5, 0.25, gap], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]);
    let reference = parallel_offset([0.0, 1.0], [0.0, 1.0], [0.5, 1.5], [0.25, 1.25], gap);
    println!("C-11 algebra: {reference:.15e} (overlap area 0.375)");
    assert!((reference - 0.375).abs() < 1e-5, "{reference}");
    let (ab, ba) = both_orders(&lower, &upper, settings(16), reference);
    let adaptive = adaptive_against(&lower, &upper, (1e-4, 6), reference);
    for (name, got) in [("lower -> upper", &ab), ("upper -> lower", &ba)] {
        assert!(got.is_err() || rel(got, reference) < 1e-4, "{name}: {got:?} vs {reference}");
    }
    if let Ok((_, error, actual)) = adaptive {
        assert!(actual <= error, "adaptive: error {actual:.2e} above the estimate {error:.2e}");
    }
}

/// F12: a whole disk r = 0.5 closing the inside of a cone r = 0.5, height 3 (apex over the
/// centre). The base is flat (F_base→base = 0), so the enclosure sum rule gives
/// F_base→cone = 1: A·F = π/4. The tolerance mode once refused it (`Err(InvalidResult)`).
#[test]
fn f12_disk_closing_a_tall_cone() {
    let base = Disk::<f64>::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), 0.5).unwrap();
    let cone = Cone::<f64>::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), 0.5, 0.0, 3.0, Side::Inner).unwrap();
    let reference = PI * 0.25;
    let (ab, ba) = both_orders(&base, &cone, settings(16), reference);
    let adaptive = adaptive_against(&base, &cone, (1e-6, 6), reference);
    assert!(rel(&ab, reference) < 1e-9 && rel(&ba, reference) < 1e-9, "{ab:?} / {ba:?} vs {reference}");
    assert_bounded(adaptive);
}

/// A whole surface against itself: `pair_exchange` at `order` in f64 and f32, and the tolerance
/// mode (f64, tolerance 1e-8, depth 2), printed against `reference`.
fn self_pair<S64: Surface<f64>, S32: Surface<f32>>(
    name: &str,
    s64: &S64,
    s32: &S32,
    order: usize,
    reference: f64,
) -> (f64, f64, Result<(f64, f64, f64), PdmError>) {
    let (p64, p32) = (Patch::whole(s64).unwrap(), Patch::whole(s32).unwrap());
    let r64 = exchange(&p64, &p64, settings(order), &());
    let r32 = exchange(&p32, &p32, settings(order), &());
    println!("{name}: pair_exchange (order {order}) f64 {} f32 {}, exact {reference:.15e}", show(&r64), show(&r32));
    println!("  relative errors {:.2e} / {:.2e}", rel(&r64, reference), rel(&r32, reference));
    let adaptive = adaptive_against(s64, s64, (1e-8, 2), reference);
    (rel(&r64, reference), rel(&r32, reference), adaptive)
}

/// F7: the inside of a thin tall tube (r = 0.2, h = 2), of a tall frustum (radii 0.5 and 0.1,
/// height 3) and of a tall cone (base radius 0.5, height 3) against themselves, each as one
/// whole patch (cut at the seam into four pieces: four self pairs and twelve touching or
/// separate pairs). The self rule of the two copies at interlaced orders was 1.6e-2 (tube) and
/// 1.7e-2 (cone) off at order 12, converging like p^−1.3; the identical-panel transform
/// converges exponentially. At the cone's apex the pieces' parameterisation collapses: the
/// opposite pieces, which touch only there, take the collapsed-side vertex sum (exponential),
/// but the self and edge pairs converge only algebraically there (open): the tolerance mode
/// must say so, with an estimate above the error. References from the enclosure sum rule on C-41: the wall sees
/// itself and its end disks, A_w·F_ww = A_w − Σ A_disk·(1 − F_disk→other disk).
#[test]
#[ignore = "slow (about 60 s alone): .ci/run runs it, `-- --ignored slow_`"]
fn slow_f7_tube_frustum_and_cone_walls_against_themselves() {
    let walls = |rb: f64, rt: f64, h: f64| {
        let wall = PI * (rb + rt) * ((rb - rt) * (rb - rt) + h * h).sqrt();
        let (ab, at) = (PI * rb * rb, PI * rt * rt);
        let to_top = exact::coaxial_disks(rb, rt, h);
        // A_t·F_tb = A_b·F_bt (reciprocity).
        wall - ab * (1.0 - to_top) - (at - ab * to_top)
    };
    let (r, h) = (0.2, 2.0);
    let tube64 = Cylinder::<f64>::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), r, h, Side::Inner).unwrap();
    let tube32 = Cylinder::<f32>::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), r as f32, h as f32, Side::Inner).unwrap();
    let (e64, e32, adaptive) = self_pair("tube r 0.2 h 2", &tube64, &tube32, 16, walls(r, r, h));
    assert!(e64 < 1e-8 && e32 < 1e-4, "tube: {e64:.2e} / {e32:.2e}");
    assert_bounded(adaptive);
    let cone = |rt: f64| {
        let c64 = Cone::<f64>::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), 0.5, rt, 3.0, Side::Inner).unwrap();
        let c32 = Cone::<f32>::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), 0.5, rt as f32, 3.0, Side::Inner).unwrap();
        (c64, c32)
    };
    let (f64_, f32_) = cone(0.1);
    let (e64, e32, adaptive) = self_pair("frustum r 0.5 -> 0.1 h 3", &f64_, &f32_, 16, walls(0.5, 0.1, 3.0));
    assert!(e64 < 1e-8 && e32 < 1e-4, "frustum: {e64:.2e} / {e32:.2e}");
    assert_bounded(adaptive);
    let (c64, c32) = cone(0.0);
    let (e64, e32, adaptive) = self_pair("cone r 0.5 h 3 (apex)", &c64, &c32, 16, walls(0.5, 0.0, 3.0));
    // Singular order 12: 2.0e-5 (6.6e-6 at 16), algebraic in the pieces' self and edge pairs
    // at the apex (7.5e-3 before the vertex pairs at the apex took the collapsed-side sum).
    assert!(e64 < 1e-4 && e32 < 1e-4, "cone: {e64:.2e} / {e32:.2e}");
    assert_bounded(adaptive);
}

/// The unit square [0, 1]² in z = 0 with a non-uniform parameterisation:
/// g(t, s) = (t + 0.3/(2π)·sin 2πt, ½s² + ½s, 0), both components increasing, normal +z.
struct WarpedSquare;

impl ParametricMap<f64> for WarpedSquare {
    fn domain(&self) -> ParamRect<f64> {
        ParamRect { t0: 0.0, t1: 1.0, s0: 0.0, s1: 1.0 }
    }
    fn map<S: Scalar<f64>>(&self, t: S, s: S) -> Vec3<S> {
        let k = S::constant(0.3 / (2.0 * PI));
        let x = t + k * (S::constant(2.0 * PI) * t).sin();
        let half = S::constant(0.5);
        let y = half * s * s + half * s;
        vec3(x, y, S::constant(0.0))
    }
}

/// F4: the warped user-map unit square → the perpendicular unit square sharing its edge y = 0.
/// Reference: C-14 for unit squares. Once 1.1e-5 off at order 16 with the user map outside,
/// and the tolerance mode's estimate below its error.
#[test]
fn f4_user_map_square_sharing_an_edge() {
    let warped = AutoNormal(WarpedSquare);
    let wall = square::<f64>([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
    let reference = exact::perpendicular_rectangles(1.0, 1.0, 1.0);
    let (ab, ba) = both_orders(&warped, &wall, settings(16), reference);
    let adaptive = adaptive_against(&warped, &wall, (1e-8, 6), reference);
    assert!(rel(&ab, reference) < 1e-8 && rel(&ba, reference) < 1e-8, "{ab:?} / {ba:?} vs {reference}");
    assert_bounded(adaptive);
}

/// F10: a box [0, 2] × [0, 1.5] × [0, 1] (faces radiating inward) with a sphere R = 0.3 at
/// (0.7, 0.6, 0.45) as occluder: the floor → the five other faces. Reference: the floor's row
/// sum, Σⱼ A_f·F_f→j = A_f − A_f·F_f→sphere (F_f→f = 0, A_f = 3), and by reciprocity
/// A_f·F_f→sphere = A_s·F_sphere→f = 4πR²·Ω_f/(4π) = R²·Ω_f with Ω_f the floor's solid angle
/// at the sphere's centre (Van Oosterom–Strackee; nothing stands between the sphere and the
/// floor). A Monte Carlo check of F_floor→sphere (4e8 cosine-weighted rays from the floor)
/// gave 0.1036118 ± 1.5e-5 against 0.1036194 from this formula. Once 4.1e-4 off at order 16:
/// the floor shares an edge with each wall, and the touching transforms sampled the sphere's
/// shadow across the pair; such pairs are now split until the cells along the contact are
/// clear of the sphere (1.2e-6 at order 16, the rest the outer rule's algebraic error across
/// the shadow).
#[test]
fn f10_box_floor_row_with_a_sphere_inside() {
    box_floor_row([0.7, 0.6, 0.45], 0.3, 16, false);
}

/// F10 with another sphere (R = 0.22 at (1.45, 1.05, 0.4): nearer the corner x = 2, y = 1.5)
/// at order 12, each face integrated outside (the other argument order).
#[test]
fn f10_box_floor_row_other_sphere_reversed() {
    box_floor_row([1.45, 1.05, 0.4], 0.22, 12, true);
}

/// The floor's row of the F10 box with a sphere (`centre`, `radius`) inside as occluder, by
/// `pair_exchange` at `order` (floor outside, or each face outside if `reversed`), against
/// the row-sum reference of [`f10_box_floor_row_with_a_sphere_inside`] to 1e-5.
fn box_floor_row(centre: [f64; 3], radius: f64, order: usize, reversed: bool) {
    let sphere = Sphere::<f64>::outer(v(centre), radius).unwrap();
    let floor = square::<f64>([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.5, 0.0]);
    let others = [
        ("ceiling", square::<f64>([0.0, 0.0, 1.0], [0.0, 1.5, 0.0], [2.0, 0.0, 0.0])),
        ("x = 0", square::<f64>([0.0, 0.0, 0.0], [0.0, 1.5, 0.0], [0.0, 0.0, 1.0])),
        ("x = 2", square::<f64>([2.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.5, 0.0])),
        ("y = 0", square::<f64>([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [2.0, 0.0, 0.0])),
        ("y = 1.5", square::<f64>([0.0, 1.5, 0.0], [2.0, 0.0, 0.0], [0.0, 0.0, 1.0])),
    ];
    let floor_poly = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 1.5, 0.0], [0.0, 1.5, 0.0]];
    let to_sphere = radius * radius * exact::polygon_solid_angle(centre, &floor_poly);
    let reference = 3.0 - to_sphere;
    let pf = Patch::whole(&floor).unwrap();
    let mut total = Ok(0.0);
    for (name, face) in &others {
        let pface = Patch::whole(face).unwrap();
        let x = if reversed {
            exchange(&pface, &pf, settings(order), &sphere)
        } else {
            exchange(&pf, &pface, settings(order), &sphere)
        };
        println!("floor -> {name}: {}", show(&x));
        total = total.and_then(|t| x.map(|x| t + x));
    }
    println!(
        "row sum {} vs {reference:.15e} (floor -> sphere {to_sphere:.15e}): {:.2e}",
        show(&total),
        rel(&total, reference)
    );
    assert!(rel(&total, reference) < 1e-5, "{total:?} vs {reference}: {:.2e}", rel(&total, reference));
}

/// Flat patches one of which lies wholly behind the other's plane — back-to-back facets sharing
/// an edge or a corner, folded at any angle, and separate ones — never see each other: exactly
/// 0 in both modes and both argument orders, without integrating (they took the touching
/// transforms before, 400 µs per shared-corner pair for the same 0). A pair folded the other
/// way (each in front of the other) stays positive, and a facet that straddles the other's
/// plane is not taken for hidden.
#[test]
fn flat_patches_behind_each_other_are_zero_without_work() {
    let floor = square::<f64>([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let pf = Patch::whole(&floor).unwrap();
    for degrees in [5.0f64, 60.0, 90.0, 150.0, 179.0] {
        let (c, s) = (degrees.to_radians().cos(), degrees.to_radians().sin());
        // A flap hinged on the floor's edge x = 1 (or only at its corner (1, 1, 0)), rising at
        // `degrees` from the floor's plane, radiating to the side away from the floor.
        let edge = square::<f64>([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [c, 0.0, s]);
        let corner = square::<f64>([1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [c, 0.0, s]);
        let apart = square::<f64>([1.5, 0.0, 0.0], [0.0, 1.0, 0.0], [c, 0.0, s]);
        for flap in [&edge, &corner, &apart] {
            let pb = Patch::whole(flap).unwrap();
            // The flap's normal (0, 1, 0) × (c, 0, s) = (s, 0, −c) points away from the floor
            // (below its plane for c < 0, behind its far side otherwise): the floor is behind it
            // or it is behind the floor.
            for (x, y) in [(&pf, &pb), (&pb, &pf)] {
                let fixed = pair_exchange::<f64, _, _, _, 256>(x, y, settings(8), &()).unwrap();
                let tol = adaptive_exchange::<f64, _, _, _, 256>(x, y, Adaptive::new(1e-9), &()).unwrap();
                assert_eq!((fixed.value, fixed.evaluations), (0.0, 0), "{degrees}°");
                assert_eq!(
                    (tol.value, tol.error, tol.converged, tol.evaluations),
                    (0.0, Some(0.0), true, 0),
                    "{degrees}°"
                );
            }
        }
        // Folded the other way (radiating towards the floor): C-14's family, positive.
        let facing = square::<f64>([1.0, 0.0, 0.0], [c, 0.0, s], [0.0, 1.0, 0.0]);
        let value =
            pair_exchange::<f64, _, _, _, 256>(&pf, &Patch::whole(&facing).unwrap(), settings(8), &()).unwrap().value;
        assert!(value > 0.0, "{degrees}°: {value}");
    }
    // A facet standing across the floor's plane sees the floor from its upper half.
    let across = square::<f64>([2.0, 0.0, -0.5], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]);
    let value =
        pair_exchange::<f64, _, _, _, 256>(&pf, &Patch::whole(&across).unwrap(), settings(12), &()).unwrap().value;
    assert!(value > 0.0, "straddling: {value}");
}

/// A_a·F_{a→b} summed over the cells of two grids, and the evaluations, by both modes: the
/// fixed orders (`settings(12)`) and the tolerance mode (1e-9, depth 4).
fn grid_sums<SA: Surface<f64>, SB: Surface<f64>>(
    a: &Patch<'_, f64, SA>,
    (m, n): (usize, usize),
    b: &Patch<'_, f64, SB>,
    (p, q): (usize, usize),
) -> [(f64, f64, u64); 2] {
    let mut out = [(0.0, 0.0, 0u64); 2];
    let adaptive = Adaptive { tolerance: 1e-9, max_order: 12, max_depth: 4, absolute: 0.0 };
    for pa in a.grid(m, n).unwrap() {
        for pb in b.grid(p, q).unwrap() {
            let fixed = pair_exchange::<f64, _, _, _, 1024>(&pa, &pb, settings(12), &()).unwrap();
            let tol = adaptive_exchange::<f64, _, _, _, 1024>(&pa, &pb, adaptive, &()).unwrap();
            for (slot, e) in out.iter_mut().zip([fixed, tol]) {
                slot.0 += e.value;
                slot.1 += e.error.unwrap_or(0.0);
                slot.2 += e.evaluations;
            }
        }
    }
    out
}

/// Prints and checks both modes' sums against `reference`: within `limit` relative (absolute
/// for a zero), the tolerance mode within its estimate, and each mode's work at most `factor`
/// × that of the same surfaces on grids whose edges match (`matched`). Integrated as separate, with
/// the contact inside, one such pair took 1e7–1e8 evaluations (tens of seconds) or did not
/// finish; cut at the contact, about what the matched grid takes.
fn check_contact_sums(
    what: &str,
    sums: [(f64, f64, u64); 2],
    matched: [(f64, f64, u64); 2],
    reference: f64,
    factor: u64,
) {
    let limit = 1e-11;
    let modes = ["fixed order 12", "tolerance 1e-9"];
    for (((value, estimate, evaluations), (_, _, work)), mode) in sums.into_iter().zip(matched).zip(modes) {
        let actual = (value - reference).abs();
        println!(
            "{what}, {mode}: {value:.15e} vs {reference:.15e}: {actual:.2e} (estimate {estimate:.2e}), \
             {evaluations} evaluations (matched grids: {work})"
        );
        assert!(actual <= limit * reference.abs().max(1.0), "{what}, {mode}: {actual:.2e} off");
        assert!(evaluations <= factor * work, "{what}, {mode}: {evaluations} evaluations, matched {work}");
        if mode.starts_with("tolerance") {
            let allowance = 8.0 * f64::EPSILON * reference.abs();
            assert!(actual <= estimate + allowance, "{what}: {actual:.2e} above the estimate {estimate:.2e}");
        }
    }
}

/// T-junctions: a disk in 4 sectors closing a cylinder wall cut into 3 cells around (the
/// wall's bottom edges span 120°, the sectors' rims 90°: corners of each lie inside the
/// other's edges), and the top disk in 5 sectors against 3 cells. Reference: C-41 and the sum
/// rule, A_disk·F(disk → wall) = π·(1 − C-41(1, 1, H)). Matched: 4 and 5 wall cells around.
#[test]
fn t_junctions_disk_sectors_against_wall_cells_of_other_angles() {
    let h = 0.6;
    let wall = Cylinder::<f64>::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), 1.0, h, Side::Inner).unwrap();
    let bottom = Disk::<f64>::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), 1.0).unwrap();
    let top = Disk::<f64>::new(v([0.0, 0.0, h]), v([0.0, 0.0, -1.0]), 1.0).unwrap();
    let reference = PI * (1.0 - exact::coaxial_disks(1.0, 1.0, h));
    let (w, b, t) = (Patch::whole(&wall).unwrap(), Patch::whole(&bottom).unwrap(), Patch::whole(&top).unwrap());
    let matched = grid_sums(&b, (1, 4), &w, (4, 2));
    check_contact_sums("bottom 1x4 -> wall 3x2", grid_sums(&b, (1, 4), &w, (3, 2)), matched, reference, 4);
    let matched = grid_sums(&t, (2, 5), &w, (5, 1));
    check_contact_sums("top 2x5 -> wall 3x1", grid_sums(&t, (2, 5), &w, (3, 1)), matched, reference, 4);
}

/// Patches that overlap: each cell of a sphere's inside against the whole sphere (as one
/// patch, which the kernel cuts into pieces at its seam and poles that the cells overlap
/// partly, and across the seam only along part of an edge). Every point of a sphere's inside
/// sees all of it: A_cell·F(cell → sphere) = A_cell. The outside sees none of itself: 0,
/// without work (two patches of one convex ball).
/// Matched: the cell against every cell of the same grid. The whole sphere's pieces (2 × 4)
/// overlaid on a 3 × 3 grid leave more, smaller contact pairs: up to 16 × the matched work
/// (integrated as separate, the partial overlaps took 70–150 ×).
#[test]
fn cells_of_a_sphere_against_the_whole_sphere() {
    for side in [Side::Inner, Side::Outer] {
        let sphere = Sphere::<f64>::new(v([0.2, -0.1, 0.3]), 1.3, side).unwrap();
        let whole = Patch::whole(&sphere).unwrap();
        for cell in whole.grid(3, 3).unwrap() {
            let reference = if side == Side::Inner { cell.area(24).unwrap() } else { 0.0 };
            let matched = grid_sums(&cell, (1, 1), &whole, (3, 3));
            let what = format!("{side:?} cell {:?} -> whole sphere", cell.rect());
            let sums = grid_sums(&cell, (1, 1), &whole, (1, 1));
            check_contact_sums(&what, sums, matched, reference, 16);
            if side == Side::Outer {
                assert!(sums.iter().all(|s| s.2 == 0), "{what}: {sums:?}");
            }
        }
    }
}

/// A parallelogram inside a sphere's inside, across a smaller sphere with the same centre: the
/// sphere cell is the outer patch, and its outer events are circles of its sphere (the
/// occluder's tangent cones through the parallelogram's corners and the planes through its
/// edges tangent to the occluder, `boundary/concentric.rs`). Red-team cases of the thirty-fifth
/// session (FUZZING.md), as (a's origin, edges, rect; b's radius, frame (u, w, axis), rect;
/// occluder radius; reference). Each reference is the helper's independent computation (its own
/// geometry, segment–sphere test and adaptive Gauss–Kronrod, no pdm code) at tolerance 1e-9
/// with 9 initial pieces per level, uncertainty 1e-8 relative (its floor). Before the events,
/// the fixed orders 8 / 16 / 20 were up to 2e-3 / 4e-4 / 3.4e-4 off, not monotone.
#[test]
fn parallelograms_inside_a_shell_around_a_concentric_sphere() {
    type Case = ([[f64; 3]; 3], [f64; 4], f64, [[f64; 3]; 3], [f64; 4], f64, f64);
    let cases: [(&str, Case); 2] = [
        (
            "1009",
            (
                [
                    [0.6647921387363426, 0.35513971611874817, 0.8659044802034667],
                    [-0.3480615837009827, 0.18002450062927539, -0.11002180044502936],
                    [-0.02801803313928252, 0.11200959943162943, 0.2719140485703725],
                ],
                [0.5478021499860282, 0.9904346907422505, 0.0929405502473882, 0.8048356190332533],
                1.5859558347341183,
                [
                    [0.9466435043807694, 0.09451193802706966, 0.30811291628892107],
                    [0.17234508827399397, 0.6593934692383877, -0.7317768944655144],
                    [-0.272329297288275, 0.7458335915578826, 0.6079218761833987],
                ],
                [1.12066044404378, 1.4454802496775114, 2.067195423598212, 4.2270023051631895],
                0.5774062872214444,
                7.961658289601073e-5,
            ),
        ),
        (
            "1010",
            (
                [
                    [1.1341770162822575, 0.7689552444841707, -0.3117246479034596],
                    [0.05681239183981273, -0.12132221875665537, 0.031485224876152455],
                    [0.0030436948573270323, -0.04170917807490758, -0.14730268448102668],
                ],
                [0.0, 1.0, 0.0, 1.0],
                1.661997962023971,
                [
                    [0.00829456310224151, 0.8441200297919634, 0.5360900815413],
                    [0.5990901857673819, -0.4334388206870291, 0.6732174522683152],
                    [0.8006385885904743, 0.3155822618992586, -0.509299211107185],
                ],
                [0.8631332917053611, 1.9138676576153748, 1.0783809493764902, 2.5818486729217396],
                1.0962709742390524,
                1.124676808549949e-5,
            ),
        ),
    ];
    let rect = |r: [f64; 4]| ParamRect::new(r[0], r[1], r[2], r[3]).unwrap();
    for (name, (a, ra, radius, frame, rb, rho, reference)) in cases {
        let flat = square::<f64>(a[0], a[1], a[2]);
        let frame = Frame { u: v(frame[0]), w: v(frame[1]), axis: v(frame[2]) };
        let shell = Sphere::<f64>::with_frame(v([0.0; 3]), radius, frame, Side::Inner).unwrap();
        let occluder = [Sphere::<f64>::outer(v([0.0; 3]), rho).unwrap()];
        let (pa, pb) = (Patch::new(&flat, rect(ra)).unwrap(), Patch::new(&shell, rect(rb)).unwrap());
        let at = |order: usize| exchange(&pa, &pb, settings(order), &occluder).unwrap();
        let (e8, e16) = (at(8), at(16));
        let adaptive = Adaptive { tolerance: 1e-9, max_order: 16, max_depth: 4, absolute: 0.0 };
        let tol = adaptive_exchange::<f64, _, _, _, 1024>(&pa, &pb, adaptive, &occluder).unwrap();
        let estimate = tol.error.unwrap();
        println!(
            "case {name}: order 8 {e8:.15e}, 16 {e16:.15e} ({:.1e} apart); tolerance 1e-9 {:.15e} (estimate {estimate:.1e}, \
             converged {}); reference {reference:.15e}: {:.1e} off",
            (e8 / e16 - 1.0).abs(),
            tol.value,
            tol.converged,
            (e16 / reference - 1.0).abs()
        );
        assert!((e8 / e16 - 1.0).abs() < 1e-11, "case {name}: orders 8 and 16 {e8} / {e16}");
        assert!((e16 / reference - 1.0).abs() < 3e-8, "case {name}: {e16} vs the reference {reference}");
        assert!(tol.converged && (tol.value - e16).abs() <= estimate + 1e-14 * e16, "case {name}: {tol:?}");
    }
}

/// A sphere's cell against a parallelogram in front of all its tangent planes, across a sphere
/// occluder off every centre, from the sphere's outside (a plate above a cell, three
/// occluders) and inside (a plate inside a shell). The outer events are the occluder's
/// tangent planes through b's edges (circles of the cell's sphere) and, per corner of b, the
/// cone from that corner tangent to the occluder, cut by the sphere (a quartic curve along
/// each meridian): with them placed, orders 12 and 20 agree to 1e-11, where they were 1e-8 to
/// 4e-7 apart (algebraic); both argument orders agree; the tolerance mode at 1e-9 converges
/// with an estimate that covers its distance from order 24. The cells outside against an
/// independent reference (a helper's scipy program sharing no code with the kernel: the
/// point-to-polygon closed form less the shadow ellipse integrated in its own parameter, the
/// outer integral by nested adaptive quadrature and by a rule split at the kinks it finds
/// itself; the methods agree to 5e-16 / 2.6e-15 absolute, ±1e-15 / ±3e-15 stated).
#[test]
fn sphere_cells_against_parallelograms_across_a_sphere_anywhere() {
    let outside = Sphere::<f64>::outer(v([0.0; 3]), 1.0).unwrap();
    let above = square::<f64>([-1.0, -1.0, 4.0], [0.0, 2.0, 0.0], [2.0, 0.0, 0.0]);
    let shell = Sphere::<f64>::inner(v([0.0; 3]), 3.0).unwrap();
    let within = square::<f64>([-0.7, -0.5, 1.0], [0.2, 1.1, 0.3], [1.2, 0.1, 0.0]);
    let cell_out = Patch::new(&outside, ParamRect::new(0.3, 0.8, 0.2, 1.2).unwrap()).unwrap();
    let cell_in = Patch::new(&shell, ParamRect::new(2.3, 2.9, 0.5, 2.0).unwrap()).unwrap();
    let (plate_above, plate_within) = (Patch::whole(&above).unwrap(), Patch::whole(&within).unwrap());
    let cases = [
        ("outside, occluder over a corner", &cell_out, &plate_above, [0.5, 0.5, 2.2], 0.3, Some(0.014949916734122)),
        ("outside, occluder over the middle", &cell_out, &plate_above, [0.1, -0.3, 2.5], 0.5, Some(0.0134401246499504)),
        ("inside, occluder under the plate", &cell_in, &plate_within, [0.3, 0.2, -0.8], 0.4, None),
        ("inside, larger occluder", &cell_in, &plate_within, [-0.2, 0.4, -1.4], 0.6, None),
    ];
    for (name, cell, plate, centre, radius, reference) in cases {
        let occluder = [Sphere::<f64>::outer(v(centre), radius).unwrap()];
        let at = |order: usize| exchange(cell, plate, settings(order), &occluder).unwrap();
        let (e12, e20, e24) = (at(12), at(20), at(24));
        let reversed = exchange(plate, cell, settings(20), &occluder).unwrap();
        let adaptive = Adaptive { tolerance: 1e-9, max_order: 16, max_depth: 4, absolute: 0.0 };
        let tol = adaptive_exchange::<f64, _, _, _, 1024>(cell, plate, adaptive, &occluder).unwrap();
        let estimate = tol.error.unwrap();
        println!(
            "{name}: order 12 {e12:.15e}, 20 {e20:.15e}, 24 {e24:.15e} ({:.1e} / {:.1e} apart); reversed {:.1e}; \
             tolerance 1e-9 {:.15e}, estimate {estimate:.1e}, {:.1e} from order 24, converged {}, {} evaluations",
            (e12 / e24 - 1.0).abs(),
            (e20 / e24 - 1.0).abs(),
            (reversed / e20 - 1.0).abs(),
            tol.value,
            (tol.value - e24).abs(),
            tol.converged,
            tol.evaluations
        );
        assert!(e24 > 0.0);
        if let Some(reference) = reference {
            println!("{name}: order 24 {:.1e} from the reference", (e24 / reference - 1.0).abs());
            assert!((e24 / reference - 1.0).abs() < 1e-12, "{name}: {e24} vs the reference {reference}");
        }
        assert!((e12 / e24 - 1.0).abs() < 1e-11 && (e20 / e24 - 1.0).abs() < 1e-12, "{name}: {e12} {e20} {e24}");
        assert!((reversed / e20 - 1.0).abs() < 1e-13, "{name}: reversed {reversed} vs {e20}");
        assert!(tol.converged && (tol.value - e24).abs() <= estimate, "{name}: {tol:?} vs {e24}");
    }
    // The same events in f32: the first case within 1e-5 of f64's value.
    let sphere = Sphere::<f32>::outer(v([0.0; 3]), 1.0).unwrap();
    let plate = square::<f32>([-1.0, -1.0, 4.0], [0.0, 2.0, 0.0], [2.0, 0.0, 0.0]);
    let cell = Patch::new(&sphere, ParamRect::new(0.3, 0.8, 0.2, 1.2).unwrap()).unwrap();
    let occluder = [Sphere::<f32>::outer(v([0.5, 0.5, 2.2]), 0.3).unwrap()];
    let single = exchange(&cell, &Patch::whole(&plate).unwrap(), settings(12), &occluder).unwrap();
    let double =
        exchange(&cell_out, &plate_above, settings(24), &[Sphere::<f64>::outer(v([0.5, 0.5, 2.2]), 0.3).unwrap()])
            .unwrap();
    println!("f32 at order 12: {single:.7e}, {:.1e} from f64", (single / double - 1.0).abs());
    assert!((single / double - 1.0).abs() < 1e-5, "f32 {single} vs f64 {double}");
}

/// A cell of a small sphere inside a shell, against a cell of the shell's inside across a
/// sphere with the shell's centre (not the small sphere's): each boundary on b is a circle
/// about p's direction from the common centre, of angle ψ(|p − c|), and the curves on a where
/// it passes b's corners or touches b's edges are quadric sections of a's sphere
/// (`concentric::offcentre_events`). Orders 12, 20 and 24 agree to 1e-12 (they were up to 1.4e-9
/// apart), both argument orders agree, the tolerance mode converges at 1e-9 with an estimate
/// that covers its distance from order 24; order 24 lies within 1e-12 of an independent
/// reference (a helper's scipy program sharing no code with the kernel: rows of b split
/// exactly at the cap ω = ψ, checked against an explicit segment test, the outer integral by
/// nested adaptive quadrature in both orders; ±1e-17 and ±2e-19 absolute stated).
#[test]
fn an_offcentre_sphere_cell_around_a_concentric_occluder() {
    let shell = Sphere::<f64>::inner(v([0.0; 3]), 2.0).unwrap();
    let cases = [
        ("ρ 0.6", [1.0, -0.2, 0.3], 0.2, [1.2, 1.9, 2.9, 3.4], [1.1, 1.7, 3.3, 3.9], 0.6, 1.4581536976131e-4),
        ("ρ 0.5", [1.2, 0.0, 0.0], 0.1, [1.35, 1.8, 2.89, 3.39], [1.35, 1.8, 3.44, 4.04], 0.5, 2.31310894063328e-5),
    ];
    let rect = |r: [f64; 4]| ParamRect::new(r[0], r[1], r[2], r[3]).unwrap();
    for (name, centre, radius, ra, rb, rho, reference) in cases {
        let small = Sphere::<f64>::outer(v(centre), radius).unwrap();
        let occluder = [Sphere::<f64>::outer(v([0.0; 3]), rho).unwrap()];
        let (a, b) = (Patch::new(&small, rect(ra)).unwrap(), Patch::new(&shell, rect(rb)).unwrap());
        let at = |order: usize| exchange(&a, &b, settings(order), &occluder).unwrap();
        let (e12, e20, e24) = (at(12), at(20), at(24));
        let reversed = exchange(&b, &a, settings(20), &occluder).unwrap();
        let adaptive = Adaptive { tolerance: 1e-9, max_order: 16, max_depth: 4, absolute: 0.0 };
        let tol = adaptive_exchange::<f64, _, _, _, 1024>(&a, &b, adaptive, &occluder).unwrap();
        let estimate = tol.error.unwrap();
        println!(
            "{name}: order 12 {e12:.15e}, 20 {e20:.15e}, 24 {e24:.15e} ({:.1e} / {:.1e} apart); reversed {:.1e}; \
             tolerance 1e-9 {:.15e}, estimate {estimate:.1e}, {:.1e} from order 24, converged {}",
            (e12 / e24 - 1.0).abs(),
            (e20 / e24 - 1.0).abs(),
            (reversed / e20 - 1.0).abs(),
            tol.value,
            (tol.value - e24).abs(),
            tol.converged
        );
        assert!((e24 / reference - 1.0).abs() < 1e-12, "{name}: {e24} vs the reference {reference}");
        assert!((e12 / e24 - 1.0).abs() < 1e-12 && (e20 / e24 - 1.0).abs() < 1e-12, "{name}: {e12} {e20} {e24}");
        assert!((reversed / e20 - 1.0).abs() < 1e-13, "{name}: reversed {reversed} vs {e20}");
        assert!(tol.converged && (tol.value - e24).abs() <= estimate, "{name}: {tol:?} vs {e24}");
    }
}
