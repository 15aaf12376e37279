//! Properties of the kernel that need no external reference: invariance under scaling, reciprocity
//! on curved pairs, errors (not panics, not NaN) for bad input, and the sphere's poles.

use pdm_kernel::{
    exchange, form_factor, form_factor_between, surface_form_factor, vec3, AutoNormal, BezierPatch, Cone, Cylinder,
    Disk, Parallelogram, ParamRect, ParametricMap, Patch, PatchGrid, PatchSamples, PdmError, Quadrature, Real, Scalar,
    Side, Sphere, Vec3, MAX_ORDER,
};

/// A scene scaled by `k`: sphere → square with a second sphere partly shadowing, plus a curved pair.
fn scaled_scene<T: Real>(k: f64) -> Result<[T; 3], PdmError> {
    let v = |x: f64, y: f64, z: f64| vec3(T::from_f64(x * k), T::from_f64(y * k), T::from_f64(z * k));
    let r = |x: f64| T::from_f64(x * k);
    let sphere = Sphere::outer(v(0.0, 0.0, 0.0), r(1.0))?;
    let blocker = Sphere::outer(v(0.6, 0.4, -2.0), r(0.5))?;
    let square = Parallelogram::new(v(-1.5, -1.5, -3.0), v(3.0, 0.0, 0.0), v(0.0, 3.0, 0.0))?;
    let f1 = surface_form_factor::<T, _, _, _, 36>(
        PatchGrid::new(&sphere, 4, 4)?,
        PatchGrid::new(&square, 2, 2)?,
        Quadrature::uniform(6),
        &blocker,
    )?;
    let a = Parallelogram::new(v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0))?;
    let b = Parallelogram::new(v(0.0, 0.0, 1.0), v(0.0, 1.0, 0.0), v(1.0, 0.0, 0.0))?;
    let f2 =
        form_factor_between::<T, _, _, _, 64>(&Patch::whole(&a)?, &Patch::whole(&b)?, Quadrature::uniform(8), &())?;
    let tube = Cylinder::new(v(0.0, 0.0, 0.0), v(0.0, 0.0, 1.0), r(1.0), r(2.0), Side::Inner)?;
    let cell_a = PatchGrid::new(&tube, 4, 2)?.cell(0, 0).ok_or(PdmError::Degenerate)?;
    let cell_b = PatchGrid::new(&tube, 4, 2)?.cell(2, 1).ok_or(PdmError::Degenerate)?;
    let f3 = form_factor_between::<T, _, _, _, 64>(&cell_a, &cell_b, Quadrature::uniform(8), &tube)?;
    Ok([f1, f2, f3])
}

#[test]
fn scale_invariance_f64_from_1e_minus_12_to_1e12() {
    let base = scaled_scene::<f64>(1.0).unwrap();
    assert!(base.iter().all(|f| *f > 0.01), "{base:?}");
    for e in -12..=12 {
        let k = 10f64.powi(e);
        let got = scaled_scene::<f64>(k).unwrap();
        for (g, b) in got.iter().zip(&base) {
            let rel = (g - b).abs() / b;
            assert!(rel < 1e-13, "scale 1e{e}: {g} vs {b} (rel {rel:e})");
        }
    }
}

#[test]
fn scale_invariance_f32_from_1e_minus_4_to_1e4() {
    let base = scaled_scene::<f32>(1.0).unwrap();
    for e in -4..=4 {
        let k = 10f64.powi(e);
        let got = scaled_scene::<f32>(k).unwrap();
        for (g, b) in got.iter().zip(&base) {
            let rel = ((g - b) / b).abs();
            assert!(rel < 2e-5, "scale 1e{e}: {g} vs {b} (rel {rel:e})");
        }
    }
}

/// A_a F_ab = A_b F_ba: exact for the discrete sum when both patches use the same order
/// (the sum is symmetric), so this checks the implementation's symmetry (sign conventions,
/// visibility tests) on curved pairs, including with an occluder.
#[test]
fn reciprocity_on_curved_pairs() {
    let sphere = Sphere::outer(vec3(0.0, 0.0, 0.0), 1.0).unwrap();
    let tube = Cylinder::new(vec3(2.5, 0.0, -1.0), vec3(0.0, 0.0, 1.0), 0.7, 2.0, Side::Outer).unwrap();
    let cone = Cone::new(vec3(-2.0, 1.0, -1.0), vec3(0.2, 0.0, 1.0), 0.8, 0.1, 1.5, Side::Outer).unwrap();
    let mut net = [[vec3(0.0, 0.0, 0.0); 4]; 4];
    for (i, row) in net.iter_mut().enumerate() {
        for (j, p) in row.iter_mut().enumerate() {
            *p = vec3(-1.5 + i as f64, -1.5 + j as f64, 2.0 + 0.3 * ((i * j) % 3) as f64);
        }
    }
    let bezier = pdm_kernel::Flipped(BezierPatch::new(net).unwrap()); // facing down at the sphere
    let blocker = Sphere::outer(vec3(1.3, 0.1, 0.2), 0.3).unwrap();
    for order in [3, 7] {
        let s =
            PatchSamples::<f64, 64>::new(&PatchGrid::new(&sphere, 2, 4).unwrap().cell(0, 0).unwrap(), order).unwrap();
        let t = PatchSamples::<f64, 64>::new(&PatchGrid::new(&tube, 4, 1).unwrap().cell(2, 0).unwrap(), order).unwrap();
        let c = PatchSamples::<f64, 64>::new(&Patch::whole(&cone).unwrap(), order).unwrap();
        let b = PatchSamples::<f64, 64>::new(&Patch::whole(&bezier).unwrap(), order).unwrap();
        let all = [&s, &t, &c, &b];
        for x in all {
            for y in all {
                if core::ptr::eq(x, y) {
                    continue;
                }
                let fxy = form_factor(x, y, &blocker).unwrap();
                let fyx = form_factor(y, x, &blocker).unwrap();
                let (lhs, rhs) = (x.area() * fxy, y.area() * fyx);
                assert!((lhs - rhs).abs() <= 1e-14 * lhs.abs().max(1e-300), "order {order}: {lhs} vs {rhs}");
                let e = exchange(x, y, &blocker).unwrap();
                assert!((e - lhs).abs() <= 1e-14 * lhs.abs().max(1e-300));
            }
        }
        // At least one pair must be non-trivial, else the test proves nothing.
        assert!(form_factor(&s, &t, &blocker).unwrap() > 1e-3);
        assert!(form_factor(&s, &b, &()).unwrap() > 1e-3);
    }
}

#[test]
fn bad_input_is_an_error_never_a_panic_or_nan() {
    let nan = f64::NAN;
    let inf = f64::INFINITY;
    let o = vec3(0.0, 0.0, 0.0);
    let z = vec3(0.0, 0.0, 1.0);
    assert_eq!(Sphere::outer(vec3(nan, 0.0, 0.0), 1.0), Err(PdmError::NonFinite));
    assert_eq!(Sphere::outer(o, inf), Err(PdmError::NonFinite));
    assert_eq!(Disk::new(o, z, -1.0), Err(PdmError::Degenerate));
    assert_eq!(Parallelogram::new(o, z, z), Err(PdmError::Degenerate));
    let sq = Parallelogram::new(o, vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0)).unwrap();
    let whole = Patch::whole(&sq).unwrap();
    for bad in [0, MAX_ORDER + 1, usize::MAX] {
        assert_eq!(
            form_factor_between::<f64, _, _, _, 64>(&whole, &whole, Quadrature::uniform(bad), &()),
            Err(PdmError::UnsupportedOrder { order: bad })
        );
    }
    assert_eq!(
        PatchSamples::<f64, 16>::new(&whole, 5).err(),
        Some(PdmError::CapacityExceeded { needed: 25, capacity: 16 })
    );
    assert_eq!(
        Patch::new(&sq, ParamRect { t0: 0.5, t1: 0.5, s0: 0.0, s1: 1.0 }).err(),
        Some(PdmError::EmptyParameterRange)
    );
    assert_eq!(Patch::new(&sq, ParamRect { t0: 0.0, t1: nan, s0: 0.0, s1: 1.0 }).err(), Some(PdmError::NonFinite));
    assert_eq!(Patch::new(&sq, ParamRect { t0: 0.0, t1: 2.0, s0: 0.0, s1: 1.0 }).err(), Some(PdmError::OutsideDomain));

    // A user surface that evaluates to NaN, and one that is collapsed to a curve (zero area).
    struct Broken(f64);
    impl ParametricMap<f64> for Broken {
        fn domain(&self) -> ParamRect<f64> {
            ParamRect { t0: 0.0, t1: 1.0, s0: 0.0, s1: 1.0 }
        }
        fn map<S: Scalar<f64>>(&self, t: S, s: S) -> Vec3<S> {
            let k = S::constant(self.0);
            vec3(t, s * k, (t * k).sqrt())
        }
    }
    let nan_surface = AutoNormal(Broken(-1.0)); // sqrt of a negative number
    assert_eq!(PatchSamples::<f64, 25>::new(&Patch::whole(&nan_surface).unwrap(), 5).err(), Some(PdmError::NonFinite));
    struct Curve;
    impl ParametricMap<f64> for Curve {
        fn domain(&self) -> ParamRect<f64> {
            ParamRect { t0: 0.0, t1: 1.0, s0: 0.0, s1: 1.0 }
        }
        fn map<S: Scalar<f64>>(&self, t: S, s: S) -> Vec3<S> {
            vec3(t + s, t + s, t + s)
        }
    }
    let curve = AutoNormal(Curve);
    assert_eq!(PatchSamples::<f64, 25>::new(&Patch::whole(&curve).unwrap(), 5).err(), Some(PdmError::Degenerate));
    assert_eq!(Patch::whole(&curve).unwrap().area(5).err(), Some(PdmError::Degenerate));
    // A Bézier net collapsed to one point.
    let point_net = BezierPatch::new([[vec3(1.0, 2.0, 3.0); 4]; 4]).unwrap();
    assert_eq!(PatchSamples::<f64, 25>::new(&Patch::whole(&point_net).unwrap(), 5).err(), Some(PdmError::Degenerate));
}

#[test]
fn poles_are_handled_not_divided_by() {
    // Patches touching the poles, at every order: finite, positive, and the pole cells' areas exact.
    let s = Sphere::outer(vec3(0.0, 0.0, 0.0), 1.0).unwrap();
    let floor = Parallelogram::new(vec3(-3.0, -3.0, -3.0), vec3(6.0, 0.0, 0.0), vec3(0.0, 6.0, 0.0)).unwrap();
    let cap = PatchGrid::new(&s, 4, 1).unwrap().cell(3, 0).unwrap(); // touches φ = π (south pole)
    let fp = Patch::whole(&floor).unwrap();
    let converged = {
        let a = PatchSamples::<f64, 1024>::new(&cap, MAX_ORDER).unwrap();
        let b = PatchSamples::<f64, 1024>::new(&fp, MAX_ORDER).unwrap();
        form_factor(&a, &b, &s).unwrap()
    };
    for order in 1..=MAX_ORDER {
        let a = PatchSamples::<f64, 1024>::new(&cap, order).unwrap();
        let b = PatchSamples::<f64, 1024>::new(&fp, order).unwrap();
        // At order 1–2 a single sample pair overestimates the large close face beyond 1: the
        // kernel refuses that value instead of returning it.
        let f = match form_factor(&a, &b, &s) {
            Ok(f) => f,
            Err(PdmError::InvalidResult) if order <= 2 => continue,
            Err(e) => panic!("order {order}: {e}"),
        };
        assert!(f.is_finite() && f > 0.0 && f <= 1.0, "order {order}: {f}");
        if order >= 16 {
            // Convergence only (the cap straddles no singularity but the rule is not exact).
            assert!((f - converged).abs() < 2e-3 * converged, "order {order}: {f} vs {converged}");
        }
        let exact_area = 2.0 * core::f64::consts::PI * (1.0 - (3.0 * core::f64::consts::PI / 4.0).cos().abs());
        if order >= 12 {
            assert!((a.area() - exact_area).abs() < 1e-13, "order {order}: {} vs {exact_area}", a.area());
        }
    }
    // A degenerate "patch" consisting of the pole line alone has zero area: an error, not NaN.
    let sliver = Patch::new(&s, ParamRect { t0: 0.0, t1: 1e-300, s0: 0.0, s1: 1.0 }).unwrap();
    assert_eq!(PatchSamples::<f64, 25>::new(&sliver, 5).err(), Some(PdmError::Degenerate));
}
