//! Regression tests for values the kernel once returned wrong as `Ok` on general geometry
//! (issue 11), each against an independent reference: catalogue closed forms from
//! `pdm_host::reference::closed_form` (which shares no code with the kernel).

use pdm_host::reference::closed_form as exact;
use pdm_kernel::{pair_exchange, vec3, Disk, PairSettings, ParamRect, Patch, Real, Sphere, Surface, Vec3};

fn v<T: Real>(p: [f64; 3]) -> Vec3<T> {
    vec3(T::from_f64(p[0]), T::from_f64(p[1]), T::from_f64(p[2]))
}

fn rel(got: f64, reference: f64) -> f64 {
    ((got - reference) / reference).abs()
}

fn accurate(order: usize) -> PairSettings {
    PairSettings { order, singular_order: 12, boundaries: true }
}

/// Σ pair_exchange over an m × n grid on a and a p × q grid on b, both argument orders.
fn grid_exchange<T: Real, SA: Surface<T>, SB: Surface<T>>(
    a: &SA,
    (m, n): (usize, usize),
    b: &SB,
    (p, q): (usize, usize),
    settings: PairSettings,
) -> (f64, f64) {
    let (mut ab, mut ba) = (0.0, 0.0);
    for pa in Patch::whole(a).unwrap().grid(m, n).unwrap() {
        for pb in Patch::whole(b).unwrap().grid(p, q).unwrap() {
            ab += pair_exchange::<T, _, _, _, 1024>(&pa, &pb, settings, &()).unwrap().value.to_f64();
            ba += pair_exchange::<T, _, _, _, 1024>(&pb, &pa, settings, &()).unwrap().value.to_f64();
        }
    }
    (ab, ba)
}

/// A sphere above a coaxial disk: every sphere patch straddles the back-face cut, and the disk's
/// centre edge (r = 0) and the sphere's poles have zero normals. F_sphere→disk is the
/// catalogue's sphere-to-coaxial-disk form ½(1 − 1/√(1 + (a/h)²)).
#[test]
fn sphere_to_coaxial_disk_in_both_orders() {
    let (radius, h, a) = (0.5, 1.0, 1.0);
    let exact = 0.5 * (1.0 - 1.0 / (1.0 + (a / h) * (a / h)).sqrt());
    let area_sphere = 4.0 * core::f64::consts::PI * radius * radius;
    for (grid_s, grid_d) in [((2, 4), (1, 4)), ((4, 8), (2, 8)), ((1, 2), (1, 1))] {
        let sphere = Sphere::<f64>::outer(v([0.0, 0.0, h]), radius).unwrap();
        let disk = Disk::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), a).unwrap();
        let (ab, ba) = grid_exchange(&sphere, grid_s, &disk, grid_d, accurate(12));
        let (e_ab, e_ba) = (rel(ab / area_sphere, exact), rel(ba / area_sphere, exact));
        println!("sphere {grid_s:?} -> disk {grid_d:?}: {e_ab:.1e} / reversed {e_ba:.1e}");
        assert!(e_ab < 1e-9 && e_ba < 1e-9, "{grid_s:?} -> {grid_d:?}: {e_ab:.1e} / {e_ba:.1e}");
    }
}

/// A sphere resting on a disk, its pole on the disk's centre (the catalogue's sphere to coaxial
/// disk, ½(1 − 1/√(1 + (a/h)²)) with h the sphere's radius). The pole and the centre are
/// corners of both whole patches, where each has a side collapsed to the point, and the vertex
/// transforms took them for a corner contact: 18 % high at order 12 (11 % at 16, refused at 8),
/// also 1e-8 apart. Surfaces touching face to face are a tangency, integrated as a separate
/// pair graded towards it.
#[test]
fn sphere_resting_on_a_disk_centre() {
    let (radius, a) = (1.0, 0.5);
    let exact = 0.5 * (1.0 - 1.0 / (1.0 + (a / radius) * (a / radius)).sqrt());
    let area_sphere = 4.0 * core::f64::consts::PI * radius * radius;
    let sphere = Sphere::<f64>::outer(v([0.0, 0.0, radius]), radius).unwrap();
    let disk = Disk::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), a).unwrap();
    let (ab, ba) = grid_exchange(&sphere, (1, 1), &disk, (1, 1), accurate(8));
    let (e_ab, e_ba) = (rel(ab / area_sphere, exact), rel(ba / area_sphere, exact));
    println!("sphere resting on a disk: {e_ab:.1e} / reversed {e_ba:.1e}");
    assert!(e_ab < 1e-5 && e_ba < 1e-5, "{e_ab:.1e} / {e_ba:.1e}");
}

/// The polar sphere cell against a disk sector starting at the centre (zero normal on the
/// sector's r = 0 edge), against the same sector starting at r = 1e-12: the two differ by
/// less than the area removed.
#[test]
fn zero_normal_edge_of_the_inner_patch() {
    let sphere = Sphere::<f64>::outer(v([0.0, 0.0, 1.0]), 0.5).unwrap();
    let disk = Disk::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), 1.0).unwrap();
    let quarter = core::f64::consts::FRAC_PI_4;
    let cell =
        Patch::new(&sphere, ParamRect { t0: 0.0, t1: core::f64::consts::PI * 0.75, s0: 0.0, s1: quarter }).unwrap();
    let from_centre = Patch::new(&disk, ParamRect { t0: 0.0, t1: 1.0, s0: 0.0, s1: quarter }).unwrap();
    let from_near = Patch::new(&disk, ParamRect { t0: 1e-12, t1: 1.0, s0: 0.0, s1: quarter }).unwrap();
    for order in [6, 10, 14] {
        let s = accurate(order);
        let f0 = pair_exchange::<f64, _, _, _, 1024>(&cell, &from_centre, s, &()).unwrap().value;
        let f1 = pair_exchange::<f64, _, _, _, 1024>(&cell, &from_near, s, &()).unwrap().value;
        let r0 = pair_exchange::<f64, _, _, _, 1024>(&from_centre, &cell, s, &()).unwrap().value;
        println!("order {order}: {f0:.12e} {f1:.12e} reversed {r0:.12e}");
        assert!(f1 > 1e-3);
        assert!(rel(f0, f1) < 1e-9, "order {order}: {f0} vs {f1}");
        // The flat sector is integrated outside in both argument orders.
        assert!(rel(r0, f0) < 1e-12, "order {order}: reversed {r0} vs {f0}");
    }
}

use pdm_kernel::{adaptive_exchange, Adaptive, Parallelogram};

fn square(o: [f64; 3], et: [f64; 3], es: [f64; 3]) -> Parallelogram<f64> {
    Parallelogram::new(v(o), v(et), v(es)).unwrap()
}

/// Unit cube, floor → ceiling with the four walls as occluders (they touch both patches'
/// edges and cut nothing): C-11 for unit squares at distance 1.
#[test]
fn enclosure_walls_as_occluders() {
    let floor = square([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let ceiling = square([0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]);
    let walls = [
        square([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
        square([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
        square([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
        square([0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
    ];
    let exact = exact::parallel_rectangles(1.0, 1.0, 1.0);
    let (a, b) = (Patch::whole(&floor).unwrap(), Patch::whole(&ceiling).unwrap());
    for n in 1..=4 {
        let f = pair_exchange::<f64, _, _, _, 1024>(&a, &b, accurate(12), &walls[..n]).unwrap().value;
        println!("{n} walls: pair_exchange {:.1e}", rel(f, exact));
        assert!(rel(f, exact) < 1e-9);
        let e = adaptive_exchange::<f64, _, _, _, 1024>(&a, &b, Adaptive::new(1e-8), &walls[..n]).unwrap();
        println!("{n} walls: adaptive {:.1e} (estimate {:.1e})", rel(e.value, exact), e.error.unwrap() / exact);
        assert!(rel(e.value, exact) < 1e-7);
    }
}

/// A sphere just above a plate: the shadow and the terminator crowd the plate's lines.
/// Reference: the sphere → rectangle solid-angle form (`sphere_to_polygon`).
#[test]
#[ignore = "slow (about 15 s alone): .ci/run runs it, `-- --ignored slow_`"]
fn slow_sphere_just_above_a_plate() {
    for gap in [1e-1, 1e-2, 1e-5, 1e-8] {
        let sphere = Sphere::<f64>::outer(v([0.0, 0.0, 1.0 + gap]), 1.0).unwrap();
        let plate = square([-2.0, -2.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]);
        let poly = [[-2.0, -2.0, 0.0], [2.0, -2.0, 0.0], [2.0, 2.0, 0.0], [-2.0, 2.0, 0.0]];
        let exact = exact::sphere_to_polygon([0.0, 0.0, 1.0 + gap], &poly);
        let mut total = 0.0;
        for cell in Patch::whole(&sphere).unwrap().grid(4, 8).unwrap() {
            match pair_exchange::<f64, _, _, _, 1024>(&cell, &Patch::whole(&plate).unwrap(), accurate(10), &sphere)
                .map(|e| e.value)
            {
                Ok(x) => total += x,
                Err(e) => panic!("gap {gap:e}, cell {:?}: {e}", cell.rect()),
            }
        }
        let f = total / (4.0 * core::f64::consts::PI);
        println!("gap {gap:e}: {f} vs {exact}: {:.1e}", rel(f, exact));
        assert!(rel(f, exact) < 1e-7, "gap {gap:e}");
    }
}

use pdm_kernel::{Cylinder, Side};

/// Whole periodic surfaces as one patch: a whole disk and the whole cylinder wall it closes
/// (1 − C-41 for the wall's far end... here the disk → wall factor 1 − F_disk→opposite disk,
/// C-41 with r₁ = r₂ = R, h = H), and two whole coaxial disks (C-41), both argument orders.
#[test]
fn whole_periodic_surfaces_as_one_patch() {
    let (radius, height) = (1.0, 1.3);
    let disk = Disk::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), radius).unwrap();
    let top = Disk::new(v([0.0, 0.0, height]), v([0.0, 0.0, -1.0]), radius).unwrap();
    let wall = Cylinder::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), radius, height, Side::Inner).unwrap();
    let area_disk = core::f64::consts::PI * radius * radius;
    let f_disks = exact::coaxial_disks(radius, radius, height);
    let (d, t, w) = (Patch::whole(&disk).unwrap(), Patch::whole(&top).unwrap(), Patch::whole(&wall).unwrap());
    let s = PairSettings { order: 16, singular_order: 14, boundaries: true };
    let dw = pair_exchange::<f64, _, _, _, 1024>(&d, &w, s, &()).unwrap().value / area_disk;
    let wd = pair_exchange::<f64, _, _, _, 1024>(&w, &d, s, &()).unwrap().value / area_disk;
    let dt = pair_exchange::<f64, _, _, _, 1024>(&d, &t, s, &()).unwrap().value / area_disk;
    let td = pair_exchange::<f64, _, _, _, 1024>(&t, &d, s, &()).unwrap().value / area_disk;
    println!("values {dw} {wd} {dt} {td}, exact {} {}", 1.0 - f_disks, f_disks);
    println!(
        "disk -> wall {:.1e} / {:.1e}, disk -> disk {:.1e} / {:.1e}",
        rel(dw, 1.0 - f_disks),
        rel(wd, 1.0 - f_disks),
        rel(dt, f_disks),
        rel(td, f_disks)
    );
    assert!(rel(dw, 1.0 - f_disks) < 1e-8 && rel(wd, 1.0 - f_disks) < 1e-8);
    assert!(rel(dt, f_disks) < 1e-8 && rel(td, f_disks) < 1e-8);
}

/// Facing unit squares from a gap of 1e-1 down to 1e-8 of their size (C-11), in both argument
/// orders, and strips of aspect up to 1e8 at distance 1 (C-11 with a ≠ b): never above 1,
/// never far off.
#[test]
fn nearly_coincident_plates_and_long_strips() {
    let s = accurate(10);
    for h in [1e-1, 1e-2, 1e-3, 1e-5, 1e-8] {
        let lower = square([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let upper = square([0.0, 0.0, h], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]);
        let (a, b) = (Patch::whole(&lower).unwrap(), Patch::whole(&upper).unwrap());
        let ab = pair_exchange::<f64, _, _, _, 1024>(&a, &b, s, &()).unwrap().value;
        let ba = pair_exchange::<f64, _, _, _, 1024>(&b, &a, s, &()).unwrap().value;
        let exact = exact::parallel_rectangles(1.0, 1.0, h);
        println!("gap {h:e}: {:.1e} / {:.1e}", rel(ab, exact), rel(ba, exact));
        // C-11's closed form itself keeps about ε/h² fewer digits (1e-10 at h = 1e-8).
        let allowed = if h < 1e-6 { 1e-9 } else { 1e-11 };
        assert!(rel(ab, exact) < allowed && rel(ba, exact) < allowed, "gap {h}");
    }
    // Strips of aspect up to 1e8: right to 1e-9, or refused because the contour terms cancel
    // beyond half the digits; never returned wrong.
    for aspect in [1e2, 1e4, 1e6, 1e8] {
        let (long, thin) = (aspect.sqrt(), 1.0 / aspect.sqrt());
        let lower = square([0.0, 0.0, 0.0], [long, 0.0, 0.0], [0.0, thin, 0.0]);
        let upper = square([0.0, 0.0, 1.0], [0.0, thin, 0.0], [long, 0.0, 0.0]);
        let (a, b) = (Patch::whole(&lower).unwrap(), Patch::whole(&upper).unwrap());
        let exact = exact::parallel_rectangles(long, thin, 1.0);
        match pair_exchange::<f64, _, _, _, 1024>(&a, &b, s, &()).map(|e| e.value) {
            Ok(x) => {
                let f = x / (long * thin);
                println!("strips {long:e} x {thin:e}: F = {f:.9e} vs {exact:.9e}: {:.1e}", rel(f, exact));
                assert!(rel(f, exact) < 1e-8, "aspect {aspect}");
            }
            Err(e) => {
                println!("strips {long:e} x {thin:e}: {e}");
                assert_eq!(e, pdm_kernel::PdmError::Unresolvable);
                assert!(aspect > 1e4, "aspect {aspect} refused");
            }
        }
    }
}

/// A whole disk closing a whole cylinder wall across a gap (the disk just below the wall's
/// rim): F_disk→wall is 1 − F_disk→(the wall's far rim disk) − F_disk→(the ring of the gap),
/// i.e. by the C-41 algebra F = F(disk → disk at gap) − F(disk → disk at gap + H), both coaxial
/// disks of the same radius.
#[test]
fn whole_disk_closing_a_wall_across_a_gap() {
    let (radius, height) = (1.0, 1.3);
    let s = PairSettings { order: 16, singular_order: 14, boundaries: true };
    for gap in [1e-3, 1e-6] {
        let disk = Disk::new(v([0.0, 0.0, -gap]), v([0.0, 0.0, 1.0]), radius).unwrap();
        let wall = Cylinder::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), radius, height, Side::Inner).unwrap();
        let exact = exact::coaxial_disks(radius, radius, gap) - exact::coaxial_disks(radius, radius, gap + height);
        let area = core::f64::consts::PI * radius * radius;
        let (d, w) = (Patch::whole(&disk).unwrap(), Patch::whole(&wall).unwrap());
        let dw = pair_exchange::<f64, _, _, _, 1024>(&d, &w, s, &()).unwrap().value / area;
        let wd = pair_exchange::<f64, _, _, _, 1024>(&w, &d, s, &()).unwrap().value / area;
        println!("gap {gap:e}: {dw} / {wd} vs {exact}: {:.1e} / {:.1e}", rel(dw, exact), rel(wd, exact));
        assert!(rel(dw, exact) < 1e-6 && rel(wd, exact) < 1e-6, "gap {gap}");
    }
}

/// The same pair at gaps of the wall's size (0.3, 0.1): the pair is not touching, the disk is
/// flat with a curved rim, and from points of the wall near the rim the disk is closer than
/// its size. The inner integral over the disk is then the point-to-region form along its
/// outline (graded line integrals): exact to rounding at every outer order, with 7.7e8
/// evaluations at order 16 and gap 0.1 before, under 5e7 now. Reference: the C-41 algebra above.
#[test]
fn whole_disk_below_a_wall_at_gaps_of_its_size() {
    let radius = 1.0;
    for (gap, height) in [(0.3, 1.0), (0.1, 1.0)] {
        let disk = Disk::new(v([0.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]), radius).unwrap();
        let wall = Cylinder::new(v([0.0, 0.0, gap]), v([0.0, 0.0, 1.0]), radius, height, Side::Inner).unwrap();
        let exact = exact::coaxial_disks(radius, radius, gap) - exact::coaxial_disks(radius, radius, gap + height);
        let area = core::f64::consts::PI * radius * radius;
        let (d, w) = (Patch::whole(&disk).unwrap(), Patch::whole(&wall).unwrap());
        for order in [8, 12, 16] {
            let s = PairSettings { order, singular_order: 12, boundaries: true };
            let pdm_kernel::Estimate { value: dw, evaluations: n_dw, .. } =
                pdm_kernel::pair_exchange::<f64, _, _, _, 1024>(&d, &w, s, &()).unwrap();
            let pdm_kernel::Estimate { value: wd, evaluations: n_wd, .. } =
                pdm_kernel::pair_exchange::<f64, _, _, _, 1024>(&w, &d, s, &()).unwrap();
            let (dw, wd) = (dw / area, wd / area);
            println!(
                "gap {gap}, order {order}: {:.1e} / {:.1e}, evaluations {n_dw} / {n_wd}",
                rel(dw, exact),
                rel(wd, exact)
            );
            assert!(rel(dw, exact) < 1e-12 && rel(wd, exact) < 1e-12, "gap {gap} order {order}");
            assert!(n_dw.max(n_wd) < 50_000_000, "{n_dw} / {n_wd} evaluations");
        }
    }
}

/// The paper's scene with the sphere as an occluder of its own cells (as a scene where every
/// surface occludes makes it): sphere R = 1 cut 4 × 8 → the floor of the cube of side 6 cut 2 × 2.
/// The facing test and the sphere's chord condition share a root on every line of the floor;
/// that once made `Err(CapacityExceeded)`. Reference: Ω/4π = 1/6 by symmetry.
#[test]
fn sphere_cells_with_the_sphere_as_occluder() {
    let sphere = Sphere::outer(v::<f64>([0.0; 3]), 1.0).unwrap();
    let floor = square([-3.0, -3.0, -3.0], [6.0, 0.0, 0.0], [0.0, 6.0, 0.0]);
    let (mut ab, mut ba) = (0.0, 0.0);
    for ps in Patch::whole(&sphere).unwrap().grid(4, 8).unwrap() {
        for pf in Patch::whole(&floor).unwrap().grid(2, 2).unwrap() {
            ab += pair_exchange::<f64, _, _, _, 1024>(&ps, &pf, PairSettings::ACCURATE, &sphere).unwrap().value;
            ba += pair_exchange::<f64, _, _, _, 1024>(&pf, &ps, PairSettings::ACCURATE, &sphere).unwrap().value;
        }
    }
    let area = 4.0 * core::f64::consts::PI;
    println!(
        "sphere -> floor, sphere occluding: {:.1e} / {:.1e}",
        rel(ab / area, 1.0 / 6.0),
        rel(ba / area, 1.0 / 6.0)
    );
    assert!(rel(ab / area, 1.0 / 6.0) < 1e-9 && rel(ba / area, 1.0 / 6.0) < 1e-9);
}

/// Half a cylinder wall (r = ½, h = 1) standing 0.1 above a 4 × 4 floor: the floor outside the
/// boundary path sees none of the wall from the strip behind it and under it, a kink curve
/// across the outer integrand (0.40 / 0.48 / 0.51 / 0.47 at orders 8 / 12 / 16 / 20, 5 % off
/// the Monte Carlo value 0.31127 ± 7.3e-4 of the battery). The wall outside converges: both
/// argument orders and orders 12 and 20 agree.
#[test]
fn cylinder_wall_above_a_floor_in_both_orders() {
    let cyl = Cylinder::new(v([0.0, 0.0, 0.1]), v([0.0, 0.0, 1.0]), 0.5, 1.0, Side::Outer).unwrap();
    let floor = square([-2.0, -2.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]);
    let wall = Patch::new(&cyl, ParamRect::new(0.0, core::f64::consts::PI, 0.0, 1.0).unwrap()).unwrap();
    let pf = Patch::whole(&floor).unwrap();
    let area = 0.5 * core::f64::consts::PI;
    let at = |order: usize| {
        let ab = pair_exchange::<f64, _, _, _, 1024>(&wall, &pf, accurate(order), &()).unwrap().value / area;
        let ba = pair_exchange::<f64, _, _, _, 1024>(&pf, &wall, accurate(order), &()).unwrap().value / area;
        (ab, ba)
    };
    let ((a12, b12), (a20, b20)) = (at(12), at(20));
    println!("cylinder wall -> floor: F = {a20:.9} (order 20), {a12:.9} (12), reversed {b20:.9}");
    assert!(rel(a12, a20) < 3e-6 && rel(b20, a20) < 1e-9 && rel(b12, a12) < 1e-9);
    // Monte Carlo (battery, 4e5 rays): 0.31127 ± 7.3e-4.
    assert!((a20 - 0.31127).abs() < 4.0 * 7.3e-4, "{a20}");
}

/// The tolerance mode on a touching pair when the order limit is reached before the
/// tolerance: C-14 (perpendicular unit squares sharing an edge) at 1e-11 with `max_order` 8 /
/// 10. Halving one square left a partial shared edge that the plain rule then integrated:
/// 1.6e-3 off with an estimate of 1.0e-3. Splitting both squares (cells sharing whole edges)
/// gives 4.7e-11 with estimate 5.1e-9, and the estimate bounds the error whether or not the
/// tolerance is met.
/// Open (FUZZING.md finding 18): splitting both patches fixes this case but makes the f32
/// tolerance mode refuse the paper's edge pair at depth 2 (the contour form of the separate
/// cells cancels beyond f32), so the fix is not in; this asserts the correct behaviour.
#[test]
fn touching_pair_split_at_the_order_limit() {
    let floor = square([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let wall = square([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
    let (a, b) = (Patch::whole(&floor).unwrap(), Patch::whole(&wall).unwrap());
    let exact = exact::perpendicular_rectangles(1.0, 1.0, 1.0);
    for (max_order, max_depth) in [(8, 1), (8, 2), (10, 2)] {
        let settings = Adaptive { tolerance: 1e-11, max_order, max_depth, absolute: 0.0 };
        let e = adaptive_exchange::<f64, _, _, _, 400>(&a, &b, settings, &()).unwrap();
        let actual = (e.value - exact).abs();
        println!("max order {max_order}, depth {max_depth}: error {actual:.1e}, estimate {:.1e}", e.error.unwrap());
        assert!(actual <= e.error.unwrap(), "error {actual:e} above the estimate {:e}", e.error.unwrap());
        assert!(rel(e.value, exact) < 1e-8);
    }
}

/// A partial shared edge: perpendicular rectangles meeting at a corner, the floor's short edge
/// lying along the wall's longer one (a non-conforming grid's contact). Classified as touching
/// at a vertex, it went to the vertex transform, which does not expect a line of contact:
/// 5.2e-3 / 3.0e-3 / 1.4e-3 off at orders 12 / 16 / 24, and the tolerance mode's estimate
/// (2.2e-8) below its error (4.1e-8). Reference: catalogue C-14 (perpendicular rectangles
/// sharing an edge) by superposition, written out in the test.
#[test]
fn partial_shared_edge() {
    use pdm_kernel::{adaptive_exchange, Adaptive};
    // C-14 with the common edge of length l: A_w·F(w → h) for a floor of width w and a wall of
    // height h, both l long: w·l·F.
    let c14 = |l: f64, w: f64, h: f64| w * l * exact::perpendicular_rectangles(l, w, h);
    let (lf, w, h, lw) = (1.0 / 3.0, 0.5, 0.35, 1.0);
    // Floor F = [0, lf] × [0, w], wall W = [0, lw] along x, height h. Extend the floor to
    // [0, lw]: E = F ∪ G with G = [lf, lw] × [0, w]. W = W1 ∪ W2 over [0, lf] and [lf, lw].
    // E·W = c14(lw), F·W1 = c14(lf), G·W2 = c14(lw − lf), and by symmetry F·W2 = G·W1, so
    // E·W = F·W1 + G·W2 + 2·F·W2 gives F·W2 and F·W = F·W1 + F·W2.
    let f_w2 = (c14(lw, w, h) - c14(lf, w, h) - c14(lw - lf, w, h)) / 2.0;
    let exact = c14(lf, w, h) + f_w2;
    let floor = square([0.0, 0.0, 0.0], [lf, 0.0, 0.0], [0.0, w, 0.0]);
    let wall = square([0.0, 0.0, 0.0], [0.0, 0.0, h], [lw, 0.0, 0.0]);
    let (a, b) = (Patch::whole(&floor).unwrap(), Patch::whole(&wall).unwrap());
    for order in [8, 12, 16] {
        let s = PairSettings { order, singular_order: order, boundaries: true };
        let ab = pair_exchange::<f64, _, _, _, 1024>(&a, &b, s, &()).unwrap().value;
        let ba = pair_exchange::<f64, _, _, _, 1024>(&b, &a, s, &()).unwrap().value;
        println!("order {order}: {:.1e} / reversed {:.1e}", rel(ab, exact), rel(ba, exact));
        assert!(rel(ab, exact) < 1e-10 && rel(ba, exact) < 1e-10, "order {order}: {ab} / {ba} vs {exact}");
    }
    for tolerance in [1e-4, 1e-8, 1e-11] {
        let e = adaptive_exchange::<f64, _, _, _, 256>(&a, &b, Adaptive::new(tolerance), &()).unwrap();
        let actual = (e.value - exact).abs();
        println!("tolerance {tolerance:e}: error {actual:.1e}, estimate {:.1e}", e.error.unwrap());
        assert!(
            actual <= e.error.unwrap(),
            "tolerance {tolerance:e}: error {actual:e} above the estimate {:e}",
            e.error.unwrap()
        );
        assert!(e.converged && actual <= tolerance * exact);
    }
}

/// Facing plates closer than f32 resolves: unit squares half overlapping, 1e-6 apart. Each lay
/// within the other's plane to the working precision, so the contour form did not take them
/// and the 4-D rules returned `Ok` 1.3e-2 off (exact 0.375, C-11 algebra: the overlap is
/// ½ × ¾ of a unit square, and the gap's correction is below 1e-5). Now `Err(Unresolvable)`;
/// at a 1e-3 gap the f32 value is right.
#[test]
fn f32_facing_plates_below_the_resolution() {
    use pdm_kernel::{adaptive_exchange, Adaptive, Parallelogram, PdmError};
    let plates = |gap: f32| {
        (
            Parallelogram::<f32>::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0)).unwrap(),
            Parallelogram::<f32>::new(vec3(0.5, 0.25, gap), vec3(0.0, 1.0, 0.0), vec3(1.0, 0.0, 0.0)).unwrap(),
        )
    };
    let s = accurate(12);
    let (a, b) = plates(1e-6);
    let (pa, pb) = (Patch::whole(&a).unwrap(), Patch::whole(&b).unwrap());
    let x = pair_exchange::<f32, _, _, _, 256>(&pa, &pb, s, &()).map(|e| e.value);
    let y = pair_exchange::<f32, _, _, _, 256>(&pb, &pa, s, &()).map(|e| e.value);
    let z = adaptive_exchange::<f32, _, _, _, 256>(&pa, &pb, Adaptive::new(1e-4), &());
    println!("gap 1e-6: {x:?} / {y:?} / {z:?}");
    assert_eq!(x, Err(PdmError::Unresolvable));
    assert_eq!(y, Err(PdmError::Unresolvable));
    assert!(z.is_err(), "{z:?}");
    let (a, b) = plates(1e-3);
    let (pa, pb) = (Patch::whole(&a).unwrap(), Patch::whole(&b).unwrap());
    let x = pair_exchange::<f32, _, _, _, 256>(&pa, &pb, s, &()).unwrap().value;
    println!("gap 1e-3: {x}");
    // C-11 algebra at gap 1e-3: 0.37499913 (f64 contour reference); f32 within 1e-5.
    assert!(rel(f64::from(x), 0.375) < 1e-5, "{x}");
}

/// A value exactly at the physical bound: the whole inner sphere (r = ½) radiates only to the
/// concentric outer sphere's inside (R = 1.3), F = 1, A·F = A_inner = min(A_a, A_b). At order
/// 12 the quadrature overshot the bound by ≈ 1e-6 and `pair_exchange` returned
/// `Err(InvalidResult)`; an overshoot within 1e-4 is quadrature error and the bound is
/// returned.
#[test]
#[ignore = "slow (about 25 s alone): .ci/run runs it, `-- --ignored slow_`"]
fn slow_concentric_spheres_value_at_the_bound() {
    let inner = Sphere::<f64>::outer(v([0.0, 0.0, 0.0]), 0.5).unwrap();
    let outer = Sphere::<f64>::inner(v([0.0, 0.0, 0.0]), 1.3).unwrap();
    let (a, b) = (Patch::whole(&inner).unwrap(), Patch::whole(&outer).unwrap());
    let exact = core::f64::consts::PI; // 4π·0.5²·F, F = 1
    for order in [12, 16] {
        let ab = pair_exchange::<f64, _, _, _, 1024>(&a, &b, accurate(order), &()).unwrap().value;
        let ba = pair_exchange::<f64, _, _, _, 1024>(&b, &a, accurate(order), &()).unwrap().value;
        println!("order {order}: {:.1e} / reversed {:.1e}", rel(ab, exact), rel(ba, exact));
        assert!(ab <= exact && ba <= exact, "{ab} / {ba} above A_inner = {exact}");
        assert!(rel(ab, exact) < 1e-5 && rel(ba, exact) < 1e-5, "order {order}: {ab} / {ba}");
    }
}

/// A screen that transmits at random on every scale: in the plane z = 0.5 between two parallel
/// unit squares, whether a segment passes is a hash of where it crosses the plane, rounded to
/// 1e-13 (rounding noise in a visibility test looks like this where a boundary grazes a
/// surface). Its line polynomials are not available, so the inner rule brackets the visibility
/// changes on a probe grid; they overflow the breakpoint buffers on most parts at every
/// halving. Such a part is integrated by the plain rule with the visibility tested at each node
/// instead of failing with `CapacityExceeded`. Half the segments pass, so the value is about
/// half the unoccluded one (catalogue C-11).
struct NoisyScreen;

impl pdm_kernel::Occluder<f64> for NoisyScreen {
    fn blocks(&self, p: Vec3<f64>, q: Vec3<f64>) -> bool {
        if (p.z - 0.5) * (q.z - 0.5) >= 0.0 {
            return false;
        }
        let u = (0.5 - p.z) / (q.z - p.z);
        let (x, y) = (p.x + (q.x - p.x) * u, p.y + (q.y - p.y) * u);
        // splitmix64 of the crossing point on a 1e-13 grid.
        let mut h = ((x * 1e13).round() as i64 as u64) ^ ((y * 1e13).round() as i64 as u64).rotate_left(32);
        h = h.wrapping_add(0x9e37_79b9_7f4a_7c15);
        h = (h ^ (h >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        h = (h ^ (h >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        (h ^ (h >> 31)) & 1 == 0
    }
}

#[test]
fn visibility_changes_beyond_every_halving() {
    let bottom = square([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let top = square([0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]);
    let (a, b) = (Patch::whole(&bottom).unwrap(), Patch::whole(&top).unwrap());
    let half = 0.5 * exact::parallel_rectangles(1.0, 1.0, 1.0);
    // The boundary path itself (pair_exchange would split the outer patch 3 × 3 first, nine
    // times the work for the same check).
    let got = pdm_kernel::internals::boundary_exchange::<f64, _, _, _, 1024>(&a, &b, 8, &NoisyScreen).unwrap();
    assert!(rel(got, half) < 0.1, "{got} against {half}");
}

/// Lambert's form for a differential area at p with unit normal n to a convex polygon, clipped
/// to the half-space in front of p (n·(q − p) > 0): (1/2π) Σ γ_i n·(r_i × r_{i+1})/|r_i × r_{i+1}|.
fn point_to_clipped_polygon(p: [f64; 3], n: [f64; 3], poly: &[[f64; 3]]) -> f64 {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross =
        |a: [f64; 3], b: [f64; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    // Sutherland–Hodgman against the plane n·(q − p) = 0.
    let mut clipped: Vec<[f64; 3]> = Vec::new();
    for i in 0..poly.len() {
        let (q0, q1) = (poly[i], poly[(i + 1) % poly.len()]);
        let (d0, d1) = (dot(n, sub(q0, p)), dot(n, sub(q1, p)));
        if d0 > 0.0 {
            clipped.push(q0);
        }
        if (d0 > 0.0) != (d1 > 0.0) {
            let x = d0 / (d0 - d1);
            clipped.push([q0[0] + x * (q1[0] - q0[0]), q0[1] + x * (q1[1] - q0[1]), q0[2] + x * (q1[2] - q0[2])]);
        }
    }
    let mut sum = 0.0;
    for i in 0..clipped.len() {
        let (r0, r1) = (sub(clipped[i], p), sub(clipped[(i + 1) % clipped.len()], p));
        let c = cross(r0, r1);
        let norm = dot(c, c).sqrt();
        if norm > 0.0 {
            // The angle between r0 and r1 by atan2 (acos loses half the digits of small angles,
            // the short edges of a clipped sliver).
            let gamma = norm.atan2(dot(r0, r1));
            sum += gamma * dot(n, c) / norm;
        }
    }
    sum.abs() / (2.0 * core::f64::consts::PI)
}

/// A_sphere cell · F_{cell → polygon}: the cell cut into k × k sub-cells, 8-point Gauss–Legendre
/// per axis on each (pdm_host's rule), the polygon by [`point_to_clipped_polygon`] at each node.
/// Sphere g(φ, θ) = c + R (sin φ cos θ, sin φ sin θ, cos φ) (the kernel's standard frame).
fn sphere_cell_to_polygon(
    c: [f64; 3],
    radius: f64,
    (f0, f1, t0, t1): (f64, f64, f64, f64),
    poly: &[[f64; 3]],
    k: usize,
) -> f64 {
    let rule = pdm_host::reference::quadrature::GaussLegendre::new(8);
    let mut total = 0.0;
    for i in 0..k {
        let (a0, a1) = (f0 + (f1 - f0) * i as f64 / k as f64, f0 + (f1 - f0) * (i + 1) as f64 / k as f64);
        for j in 0..k {
            let (b0, b1) = (t0 + (t1 - t0) * j as f64 / k as f64, t0 + (t1 - t0) * (j + 1) as f64 / k as f64);
            total += rule.integrate(a0, a1, |phi| {
                rule.integrate(b0, b1, |theta| {
                    let n = [phi.sin() * theta.cos(), phi.sin() * theta.sin(), phi.cos()];
                    let p = [c[0] + radius * n[0], c[1] + radius * n[1], c[2] + radius * n[2]];
                    radius * radius * phi.sin() * point_to_clipped_polygon(p, n, poly)
                })
            });
        }
    }
    total
}

/// A sphere cell close above a plate cell, the cell's lowest point over the plate near two of
/// its edges, gaps 1e-1 to 1e-3 of the sphere's radius: the outer integrand has a layer on the
/// gap's scale (under the closest point, and where the cell passes over the plate's edges).
/// Reference: [`sphere_cell_to_polygon`] at 64² and 128² sub-cells (shares no code with the
/// kernel; the two agree to the printed difference, asserted below 1e-10).
#[test]
fn sphere_cell_close_above_a_plate_cell() {
    use core::f64::consts::PI;
    let poly = [[0.5, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.5, 0.0], [0.5, 0.5, 0.0]];
    let plate = square(poly[0], [0.5, 0.0, 0.0], [0.0, 0.5, 0.0]);
    let rect = (0.75 * PI, PI, 1.75 * PI, 2.0 * PI);
    for gap in [1e-1, 3e-2, 1e-3] {
        let c = [0.95, 0.1, 0.3 + gap];
        let coarse = sphere_cell_to_polygon(c, 0.3, rect, &poly, 64);
        let reference = sphere_cell_to_polygon(c, 0.3, rect, &poly, 128);
        println!("gap {gap:e}: reference {reference:.12e} (64² vs 128²: {:.1e})", rel(coarse, reference));
        assert!(rel(coarse, reference) < 1e-10);
        let sphere = Sphere::<f64>::outer(v(c), 0.3).unwrap();
        let cell = Patch::new(&sphere, ParamRect { t0: rect.0, t1: rect.1, s0: rect.2, s1: rect.3 }).unwrap();
        let pc = Patch::whole(&plate).unwrap();
        for (order, allowed) in [(12, 1e-5), (16, 1e-6)] {
            let ab = pair_exchange::<f64, _, _, _, 1024>(&cell, &pc, accurate(order), &()).unwrap().value;
            let ba = pair_exchange::<f64, _, _, _, 1024>(&pc, &cell, accurate(order), &()).unwrap().value;
            println!("  order {order}: {:.1e} / reversed {:.1e}", rel(ab, reference), rel(ba, reference));
            assert!(rel(ab, reference) < allowed && rel(ba, reference) < allowed, "gap {gap:e} order {order}");
        }
    }
}

/// A small square emitter under a large receiver with an occluder between whose shadow lies
/// wholly inside the receiver, in both argument orders: the boundary path integrates the
/// smaller patch outside whichever is passed first (a large receiver outside had kinks along
/// the shadow's edge on its whole area: 4.9e-6 / 5.0e-5 at orders 12 / 16 with the tilted
/// plate). Reference: every ray from the emitter that meets the occluder would meet the
/// receiver, so A_e·F = ∫_e F(p → receiver) − F(p → occluder) dp, Lambert's polygon form at
/// each point ([`point_to_clipped_polygon`]), the emitter by 8-point Gauss on 16² cells.
/// A tube and a tilted disk as occluders: both argument orders agree to the last digits.
#[test]
fn occluded_pair_integrates_the_smaller_patch_outside() {
    use pdm_kernel::{AnyOccluder, Cylinder, Side};
    let receiver_poly = [[-1.5, -1.5, 2.0], [-1.5, 1.5, 2.0], [1.5, 1.5, 2.0], [1.5, -1.5, 2.0]];
    let (o, et, es) = ([-0.15, -0.1, 1.0], [0.3, 0.1, 0.1], [-0.05, 0.25, 0.15]);
    let add = |a: [f64; 3], b: [f64; 3]| [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
    let occluder_poly = [o, add(o, et), add(add(o, et), es), add(o, es)];
    let rule = pdm_host::reference::quadrature::GaussLegendre::new(8);
    let k = 16;
    let mut reference = 0.0;
    for i in 0..k {
        let (x0, x1) = (-0.5 + i as f64 / k as f64, -0.5 + (i + 1) as f64 / k as f64);
        for j in 0..k {
            let (y0, y1) = (-0.5 + j as f64 / k as f64, -0.5 + (j + 1) as f64 / k as f64);
            reference += rule.integrate(x0, x1, |x| {
                rule.integrate(y0, y1, |y| {
                    let (p, n) = ([x, y, 0.0], [0.0, 0.0, 1.0]);
                    point_to_clipped_polygon(p, n, &receiver_poly) - point_to_clipped_polygon(p, n, &occluder_poly)
                })
            });
        }
    }
    let emitter = square([-0.5, -0.5, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let receiver = square([-1.5, -1.5, 2.0], [0.0, 3.0, 0.0], [3.0, 0.0, 0.0]);
    let plate = square(o, et, es);
    let (e, r) = (Patch::whole(&emitter).unwrap(), Patch::whole(&receiver).unwrap());
    for order in [12, 16] {
        let ab = pair_exchange::<f64, _, _, _, 1024>(&e, &r, accurate(order), &plate).unwrap().value;
        let ba = pair_exchange::<f64, _, _, _, 1024>(&r, &e, accurate(order), &plate).unwrap().value;
        println!("tilted plate, order {order}: {:.1e} / reversed {:.1e}", rel(ab, reference), rel(ba, reference));
        assert!(rel(ab, reference) < 1e-12 && rel(ba, reference) < 1e-12, "{ab} / {ba} vs {reference}");
    }
    let tube = Cylinder::new(v([-0.3, 0.0, 1.0]), v([1.0, 0.0, 0.0]), 0.15, 0.6, Side::Outer).unwrap();
    let disk = Disk::new(v([0.1, 0.0, 1.2]), v([0.3, 0.2, 1.0]), 0.25).unwrap();
    for (name, occ) in [("tube", AnyOccluder::Cylinder(tube)), ("tilted disk", AnyOccluder::Disk(disk))] {
        let ab = pair_exchange::<f64, _, _, _, 1024>(&e, &r, accurate(12), &occ).unwrap().value;
        let ba = pair_exchange::<f64, _, _, _, 1024>(&r, &e, accurate(12), &occ).unwrap().value;
        println!("{name}, order 12: {ab:.15e} / reversed {ba:.15e}");
        assert!(rel(ab, ba) < 1e-14, "{name}: {ab} / {ba}");
    }
}

/// A whole cylinder wall standing a small gap above a floor much larger than it: from every
/// point of the wall the floor straddles the back-face cut (the wall's normal is horizontal),
/// and near the bottom rim the floor is closer than the wall's size, so a rule over the floor
/// needs refining towards each point. The inner integral over the flat floor is then exact
/// (point-to-polygon form); before, the refinement took 2.9e8 evaluations at order 16 for the
/// same value. Reference: the wall by 8-point Gauss–Legendre on cells split in θ where the
/// clip line through a point's foot passes a floor corner (kinks of the outer integrand) and
/// graded geometrically in z towards the bottom rim, Lambert's form at each node
/// ([`point_to_clipped_polygon`]); two refinements agree to the asserted 1e-11.
#[test]
fn cylinder_wall_standing_close_above_a_larger_floor() {
    use core::f64::consts::PI;
    use pdm_kernel::{Cylinder, Side};
    let (radius, height, half) = (0.5, 1.0, 2.0);
    let poly = [[-half, -half, 0.0], [half, -half, 0.0], [half, half, 0.0], [-half, half, 0.0]];
    let floor = square(poly[0], [2.0 * half, 0.0, 0.0], [0.0, 2.0 * half, 0.0]);
    let rule = pdm_host::reference::quadrature::GaussLegendre::new(8);
    // θ where the clip line x cos θ + y sin θ = R passes a corner.
    let mut thetas = vec![0.0, 2.0 * PI];
    for c in poly {
        let (a, phi) = ((c[0] * c[0] + c[1] * c[1]).sqrt(), c[1].atan2(c[0]));
        for th in [phi + (radius / a).acos(), phi - (radius / a).acos()] {
            thetas.push(th.rem_euclid(2.0 * PI));
        }
    }
    thetas.sort_by(f64::total_cmp);
    let reference = |gap: f64, m: usize| -> f64 {
        let mut zs = vec![0.0];
        let mut step = gap;
        while zs.last().copied().unwrap_or(height) + step < height {
            zs.push(zs.last().copied().unwrap_or(0.0) + step);
            step *= 3.0;
        }
        zs.push(height);
        let mut total = 0.0;
        for th in thetas.windows(2) {
            for z in zs.windows(2) {
                for i in 0..m {
                    let (t0, t1) = (
                        th[0] + (th[1] - th[0]) * i as f64 / m as f64,
                        th[0] + (th[1] - th[0]) * (i + 1) as f64 / m as f64,
                    );
                    for j in 0..m {
                        let (z0, z1) = (
                            z[0] + (z[1] - z[0]) * j as f64 / m as f64,
                            z[0] + (z[1] - z[0]) * (j + 1) as f64 / m as f64,
                        );
                        total += rule.integrate(t0, t1, |t| {
                            rule.integrate(z0, z1, |zz| {
                                let n = [t.cos(), t.sin(), 0.0];
                                let p = [radius * n[0], radius * n[1], gap + zz];
                                radius * point_to_clipped_polygon(p, n, &poly)
                            })
                        });
                    }
                }
            }
        }
        total
    };
    for gap in [1e-1, 1e-3] {
        let (coarse, fine) = (reference(gap, 4), reference(gap, 8));
        println!("gap {gap:e}: reference A·F {fine:.12e} (two refinements: {:.1e})", rel(coarse, fine));
        assert!(rel(coarse, fine) < 1e-11);
        let wall = Cylinder::new(vec3(0.0, 0.0, gap), vec3(0.0, 0.0, 1.0), radius, height, Side::Outer).unwrap();
        let (a, b) = (Patch::whole(&wall).unwrap(), Patch::whole(&floor).unwrap());
        for (order, allowed) in [(12, 2e-6), (16, 5e-7)] {
            let pdm_kernel::Estimate { value: ab, evaluations: n_ab, .. } =
                pdm_kernel::pair_exchange::<f64, _, _, _, 1024>(&a, &b, accurate(order), &()).unwrap();
            let pdm_kernel::Estimate { value: ba, evaluations: n_ba, .. } =
                pdm_kernel::pair_exchange::<f64, _, _, _, 1024>(&b, &a, accurate(order), &()).unwrap();
            println!(
                "  order {order}: {:.1e} / reversed {:.1e}, evaluations {n_ab} / {n_ba}",
                rel(ab, fine),
                rel(ba, fine)
            );
            assert!(rel(ab, fine) < allowed && rel(ba, fine) < allowed, "gap {gap:e} order {order}");
            // The point-to-polygon form costs a few evaluations per outer point.
            assert!(n_ab.max(n_ba) < 2_000_000, "{n_ab} / {n_ba} evaluations");
        }
    }
}

/// A cell of the paper's 8 × 8 sphere just below its equator against a cell of the 6 × 6 top
/// face that it sees only in a sliver near its terminator, in the tolerance mode at tight
/// tolerances, both argument orders. Once the pair is halved, a half sees the other patch in
/// so thin a sliver that every sample pair at the route's order faces away: the route used to
/// be judged on the samples alone, the half summed to zero with a zero estimate, and the pair
/// came back 1.0e-4 off with an estimate of 5.4e-13 (tolerance 1e-12). Reference:
/// [`sphere_cell_to_polygon`] at 128² and 256² sub-cells (shares no code with the kernel).
#[test]
fn sphere_cell_seeing_a_face_cell_in_a_sliver_in_the_tolerance_mode() {
    use core::f64::consts::PI;
    let poly = [[-2.0, 2.0, 3.0], [-1.0, 2.0, 3.0], [-1.0, 3.0, 3.0], [-2.0, 3.0, 3.0]];
    let rect = (0.5 * PI, 0.625 * PI, 0.0, 0.25 * PI);
    let coarse = sphere_cell_to_polygon([0.0; 3], 1.0, rect, &poly, 128);
    let reference = sphere_cell_to_polygon([0.0; 3], 1.0, rect, &poly, 256);
    let uncertainty = (coarse - reference).abs();
    println!("reference {reference:.15e} (128² vs 256²: {:.1e})", rel(coarse, reference));
    assert!(rel(coarse, reference) < 1e-11);
    let sphere = Sphere::<f64>::outer(v([0.0; 3]), 1.0).unwrap();
    let cell = Patch::new(&sphere, ParamRect { t0: rect.0, t1: rect.1, s0: rect.2, s1: rect.3 }).unwrap();
    let top = square([-3.0, -3.0, 3.0], [0.0, 6.0, 0.0], [6.0, 0.0, 0.0]);
    let face_cell = Patch::new(&top, ParamRect { t0: 5.0 / 6.0, t1: 1.0, s0: 1.0 / 6.0, s1: 2.0 / 6.0 }).unwrap();
    for tol in [1e-8, 1e-10, 1e-12] {
        let ab = adaptive_exchange::<f64, _, _, _, 400>(&cell, &face_cell, Adaptive::new(tol), &()).unwrap();
        let ba = adaptive_exchange::<f64, _, _, _, 400>(&face_cell, &cell, Adaptive::new(tol), &()).unwrap();
        for (name, e, r) in [("cell → face", ab, reference), ("face → cell", ba, reference)] {
            let (error, estimate) = ((e.value - r).abs(), e.error.unwrap());
            println!("tol {tol:e} {name}: {:.1e} off, estimate {:.1e}", error / r, estimate / r);
            assert!(error <= estimate + 2.0 * uncertainty, "tol {tol:e} {name}: {error:e} off, estimate {estimate:e}");
        }
    }
}

/// A sphere cell that the receiver's plane cuts: the rectangle lies in the plane z = 0.3 beside
/// the sphere (R 1), facing up, so only the part of the cell above the parallel φ* = acos 0.3
/// sees it, and from there the cell's tangent planes clip it. The cell goes outside with the
/// point-to-polygon form, and the parallel (where the rectangle starts facing the cell) and the
/// four circles where the tangent plane passes a corner are its outer events; none lines up
/// with the cell's edges. Reference: [`sphere_cell_to_polygon`] with the rectangle's own facing
/// test, split at φ* (a cut the reference knows from the geometry, not from the kernel), at
/// 64² and 128² sub-cells (shares no code with the kernel). Both argument orders, the fixed
/// orders and the tolerance mode, whose estimate must cover its error.
#[test]
fn sphere_cell_cut_by_the_receivers_plane() {
    use pdm_kernel::{adaptive_exchange, Adaptive};
    let poly = [[-0.6, 1.3, 0.3], [0.4, 1.3, 0.3], [0.4, 2.3, 0.3], [-0.6, 2.3, 0.3]];
    let (f0, f1, t0, t1) = (0.9, 1.5, 1.1, 2.2);
    let split = 0.3f64.acos();
    // Below φ* the cell is behind the rectangle's plane: only [f0, φ*] contributes.
    assert_behind_plane((split, f1, t0, t1), &poly);
    let coarse = sphere_cell_to_polygon([0.0; 3], 1.0, (f0, split, t0, t1), &poly, 64);
    let reference = sphere_cell_to_polygon([0.0; 3], 1.0, (f0, split, t0, t1), &poly, 128);
    let uncertainty = (coarse - reference).abs();
    println!("reference {reference:.15e} (64² vs 128²: {:.1e})", rel(coarse, reference));
    assert!(rel(coarse, reference) < 1e-11);
    let sphere = Sphere::<f64>::outer(v([0.0; 3]), 1.0).unwrap();
    let cell = Patch::new(&sphere, ParamRect { t0: f0, t1: f1, s0: t0, s1: t1 }).unwrap();
    let plate = square(poly[0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let receiver = Patch::whole(&plate).unwrap();
    for order in [8, 12] {
        let ab = pair_exchange::<f64, _, _, _, 256>(&cell, &receiver, accurate(order), &()).unwrap().value;
        let ba = pair_exchange::<f64, _, _, _, 256>(&receiver, &cell, accurate(order), &()).unwrap().value;
        println!(
            "order {order}: cell → plate {:.1e} off, plate → cell {:.1e} off",
            rel(ab, reference),
            rel(ba, reference)
        );
        let bound = if order == 8 { 1e-8 } else { 1e-11 };
        assert!(rel(ab, reference) < bound && rel(ba, reference) < bound, "order {order}: {ab:e} {ba:e}");
    }
    for tol in [1e-6, 1e-9, 1e-11] {
        let ab = adaptive_exchange::<f64, _, _, _, 400>(&cell, &receiver, Adaptive::new(tol), &()).unwrap();
        let ba = adaptive_exchange::<f64, _, _, _, 400>(&receiver, &cell, Adaptive::new(tol), &()).unwrap();
        for (name, e) in [("cell → plate", ab), ("plate → cell", ba)] {
            let (error, estimate) = ((e.value - reference).abs(), e.error.unwrap());
            println!("tol {tol:e} {name}: {:.1e} off, estimate {:.1e}", error / reference, estimate / reference);
            assert!(error <= estimate + 2.0 * uncertainty, "tol {tol:e} {name}: {error:e} off, estimate {estimate:e}");
            assert!(error <= tol * reference + 2.0 * uncertainty, "tol {tol:e} {name}: {error:e} off");
        }
    }
}

/// Checks that the part (φ₀, φ₁, θ₀, θ₁) of the unit sphere at the origin lies behind the
/// polygon's plane (the polygon faces none of it) at its corners and centre: the plane is
/// z = const and the part's highest points are at φ₀.
fn assert_behind_plane((f0, f1, t0, t1): (f64, f64, f64, f64), poly: &[[f64; 3]]) {
    let (c, radius) = ([0.0; 3], 1.0);
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let (e1, e2) = (sub(poly[1], poly[0]), sub(poly[3], poly[0]));
    let n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
    for (phi, theta) in [(f0, t0), (f0, t1), (f1, t0), (f1, t1), (0.5 * (f0 + f1), 0.5 * (t0 + t1))] {
        let p = [
            c[0] + radius * phi.sin() * theta.cos(),
            c[1] + radius * phi.sin() * theta.sin(),
            c[2] + radius * phi.cos(),
        ];
        let h: f64 = (0..3).map(|i| n[i] * (p[i] - poly[0][i])).sum();
        assert!(h <= 1e-12, "part not behind the polygon's plane: {h:e}");
    }
}

/// Sphere cells that see a face cell only in a sliver along their terminator, with the sphere
/// itself passed as the occluder (as a caller does who lists every surface of a scene): a
/// segment that leaves an outer sphere's surface through the facing test never re-enters the
/// ball, so the result must be the unoccluded one. The occluded paths used to take these pairs
/// and see the sliver only through their samples: the fixed order was up to 9.5e-4 off (the
/// scene's cell (3, 4) against face 2's cell (3, 5)), and the tolerance mode returned 0 with an
/// estimate of 0 (converged) for a pair of value 3.9e-12. Reference:
/// [`sphere_cell_to_polygon`] at 128² and 256² sub-cells (shares no code with the kernel).
#[test]
fn sphere_cells_in_a_sliver_with_their_own_sphere_as_occluder() {
    use core::f64::consts::PI;
    let sphere = Sphere::<f64>::outer(v([0.0; 3]), 1.0).unwrap();
    // (cell φ₀, φ₁, θ₀, θ₁; face cell corners o, o + e_t, o + e_t + e_s, o + e_s)
    let cases = [
        (
            (3.0 * PI / 8.0, 0.5 * PI, PI, 1.25 * PI),
            [[2.0, -3.0, 0.0], [2.0, -3.0, 1.0], [3.0, -3.0, 1.0], [3.0, -3.0, 0.0]],
        ),
        (
            (0.5 * PI, 0.625 * PI, 0.0, 0.25 * PI),
            [[-2.0, 2.0, 3.0], [-1.0, 2.0, 3.0], [-1.0, 3.0, 3.0], [-2.0, 3.0, 3.0]],
        ),
    ];
    for (rect, poly) in cases {
        let coarse = sphere_cell_to_polygon([0.0; 3], 1.0, rect, &poly, 128);
        let reference = sphere_cell_to_polygon([0.0; 3], 1.0, rect, &poly, 256);
        let uncertainty = (coarse - reference).abs();
        println!("reference {reference:.15e} (128² vs 256²: {:.1e})", rel(coarse, reference));
        assert!(reference > 0.0 && rel(coarse, reference) < 1e-6);
        let cell = Patch::new(&sphere, ParamRect { t0: rect.0, t1: rect.1, s0: rect.2, s1: rect.3 }).unwrap();
        let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        // The face cell faces the sphere's centre (the reference's polygon has no side).
        let (e1, e2) = (sub(poly[1], poly[0]), sub(poly[3], poly[0]));
        let n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        let towards = -(n[0] * poly[0][0] + n[1] * poly[0][1] + n[2] * poly[0][2]) > 0.0;
        let plate = if towards { square(poly[0], e1, e2) } else { square(poly[0], e2, e1) };
        let face_cell = Patch::whole(&plate).unwrap();
        for order in [8, 12] {
            for (name, own, free) in [
                (
                    "cell → face",
                    pair_exchange::<f64, _, _, _, 256>(&cell, &face_cell, accurate(order), &sphere).unwrap().value,
                    pair_exchange::<f64, _, _, _, 256>(&cell, &face_cell, accurate(order), &()).unwrap().value,
                ),
                (
                    "face → cell",
                    pair_exchange::<f64, _, _, _, 256>(&face_cell, &cell, accurate(order), &sphere).unwrap().value,
                    pair_exchange::<f64, _, _, _, 256>(&face_cell, &cell, accurate(order), &()).unwrap().value,
                ),
            ] {
                println!(
                    "order {order} {name}: {:.1e} off, unoccluded {:.1e} off",
                    rel(own, reference),
                    rel(free, reference)
                );
                assert!(
                    (own - reference).abs() <= 1e-6 * reference + 2.0 * uncertainty,
                    "order {order} {name}: {own:e}"
                );
                assert_eq!(own, free, "order {order} {name}: the own sphere changed the value");
            }
        }
        for tol in [1e-4, 1e-8, 1e-11] {
            let ab = adaptive_exchange::<f64, _, _, _, 400>(&cell, &face_cell, Adaptive::new(tol), &sphere).unwrap();
            let ba = adaptive_exchange::<f64, _, _, _, 400>(&face_cell, &cell, Adaptive::new(tol), &sphere).unwrap();
            for (name, e) in [("cell → face", ab), ("face → cell", ba)] {
                let (error, estimate) = ((e.value - reference).abs(), e.error.unwrap());
                println!("tol {tol:e} {name}: {:.1e} off, estimate {:.1e}", error / reference, estimate / reference);
                assert!(
                    error <= estimate + 2.0 * uncertainty,
                    "tol {tol:e} {name}: {error:e} off, estimate {estimate:e}"
                );
                assert!(
                    !e.converged || error <= tol * reference + 2.0 * uncertainty,
                    "tol {tol:e} {name}: {error:e} off"
                );
            }
        }
    }
}

/// Pairs across flat occluders and a sphere, whose inner integral is b less the polygons'
/// shadows and the sphere's cone, in closed form (`boundary/shadows.rs`). References by
/// symmetry, no kernel code: between two parallel unit squares 1 apart, a screen in the middle
/// plane covering x > 0.5 blocks a segment exactly where its crossing has x > 0.5, i.e. where
/// x_a + x_b > 1; the mirror x → 1 − x of both squares swaps those segments with the others,
/// so the screen passes exactly half of C-11. A sphere centred on the mirror plane keeps that:
/// with it, the pair is exactly half the pair across the sphere alone (which pdm takes by the
/// cone subtraction, another path). Both the parallelogram and the quadrilateral screen, both
/// argument orders, fixed orders and the tolerance mode, whose estimate must cover the error.
mod polygon_shadows {
    use super::*;
    use pdm_kernel::{adaptive_exchange, Adaptive, AnyOccluder, Parallelogram, Quadrilateral};

    fn squares() -> (Parallelogram<f64>, Parallelogram<f64>) {
        let bottom = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0)).unwrap();
        let top = Parallelogram::new(vec3(0.0, 0.0, 1.0), vec3(0.0, 1.0, 0.0), vec3(1.0, 0.0, 0.0)).unwrap();
        (bottom, top)
    }

    fn screens() -> [AnyOccluder<f64>; 2] {
        let flat = Parallelogram::new(vec3(0.5, -50.0, 0.5), vec3(50.0, 0.0, 0.0), vec3(0.0, 100.0, 0.0)).unwrap();
        let quad = Quadrilateral::new([
            vec3(0.5, -50.0, 0.5),
            vec3(50.5, -50.0, 0.5),
            vec3(50.5, 50.0, 0.5),
            vec3(0.5, 50.0, 0.5),
        ])
        .unwrap();
        [AnyOccluder::Parallelogram(flat), AnyOccluder::Quadrilateral(quad)]
    }

    #[test]
    fn a_screen_over_half_the_view_passes_half_of_it() {
        let (bottom, top) = squares();
        let (a, b) = (Patch::whole(&bottom).unwrap(), Patch::whole(&top).unwrap());
        let half = 0.5 * exact::parallel_rectangles(1.0, 1.0, 1.0);
        for screen in screens() {
            // The outer rule has the screen's events (lines where its shadow edge passes b's
            // corners: a's edges here) and converges exponentially with the order.
            for (order, bound) in [(4, 1e-4), (8, 1e-9), (12, 1e-14)] {
                let settings = PairSettings { order, singular_order: order, boundaries: true };
                for (name, e) in [
                    ("a → b", pair_exchange::<f64, _, _, _, 256>(&a, &b, settings, &screen).unwrap()),
                    ("b → a", pair_exchange::<f64, _, _, _, 256>(&b, &a, settings, &screen).unwrap()),
                ] {
                    println!("order {order} {name}: {:.1e} off, {} evaluations", rel(e.value, half), e.evaluations);
                    assert!(rel(e.value, half) < bound, "order {order} {name}: {:e} against {half:e}", e.value);
                }
            }
            for tol in [1e-4, 1e-10] {
                let e = adaptive_exchange::<f64, _, _, _, 256>(&a, &b, Adaptive::new(tol), &screen).unwrap();
                let (error, estimate) = ((e.value - half).abs(), e.error.unwrap());
                println!("tol {tol:e}: {:.1e} off, estimate {:.1e}", error / half, estimate / half);
                assert!(
                    e.converged && error <= estimate && error <= tol * half,
                    "tol {tol:e}: {error:e}, {estimate:e}"
                );
            }
        }
    }

    #[test]
    fn a_screen_and_a_sphere_on_the_mirror_plane_pass_half_of_the_sphere_alone() {
        let (bottom, top) = squares();
        let (a, b) = (Patch::whole(&bottom).unwrap(), Patch::whole(&top).unwrap());
        let sphere = Sphere::outer(vec3(0.5, 0.45, 0.3), 0.15).unwrap();
        let alone = adaptive_exchange::<f64, _, _, _, 256>(&a, &b, Adaptive::new(1e-10), &sphere).unwrap();
        let (reference, uncertainty) = (0.5 * alone.value, 0.5 * alone.error.unwrap());
        println!(
            "sphere alone: {:e}, estimate {:.1e}, converged {}",
            alone.value,
            alone.error.unwrap(),
            alone.converged
        );
        for screen in screens() {
            let both = (screen, AnyOccluder::Sphere(sphere));
            for tol in [1e-4, 1e-7] {
                let e = adaptive_exchange::<f64, _, _, _, 256>(&a, &b, Adaptive::new(tol), &both).unwrap();
                let (error, estimate) = ((e.value - reference).abs(), e.error.unwrap());
                println!(
                    "tol {tol:e}: {:.1e} off, estimate {:.1e}, {} evaluations",
                    error / reference,
                    estimate / reference,
                    e.evaluations
                );
                assert!(error <= estimate + uncertainty, "tol {tol:e}: {error:e} off, estimate {estimate:e}");
                assert!(!e.converged || error <= tol * reference + uncertainty, "tol {tol:e}: {error:e} off");
            }
        }
    }

    /// A touching pair across a flat occluder, which takes the boundary path whole
    /// (`pair::route`, `contact_across_shadows`): perpendicular unit squares sharing an edge
    /// (C-14), and a screen in their bisecting plane x = z over y > 0.5, its edge on the shared
    /// edge. Every segment between the squares crosses the bisecting plane once, and is blocked
    /// exactly where it crosses at y > 0.5; the mirror y → 1 − y maps the pair onto itself and
    /// those segments onto the others, so the screen passes exactly half of C-14.
    #[test]
    fn a_screen_on_the_shared_edge_passes_half_of_c14() {
        let floor = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0)).unwrap();
        let wall = Parallelogram::new(vec3(0.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0), vec3(0.0, 0.0, 1.0)).unwrap();
        let (a, b) = (Patch::whole(&floor).unwrap(), Patch::whole(&wall).unwrap());
        let screen = Parallelogram::new(vec3(0.0, 0.5, 0.0), vec3(10.0, 0.0, 10.0), vec3(0.0, 10.0, 0.0)).unwrap();
        let half = 0.5 * exact::perpendicular_rectangles(1.0, 1.0, 1.0);
        for order in [6, 10] {
            let settings = PairSettings { order, singular_order: order, boundaries: true };
            for (name, e) in [
                ("floor → wall", pair_exchange::<f64, _, _, _, 256>(&a, &b, settings, &screen).unwrap()),
                ("wall → floor", pair_exchange::<f64, _, _, _, 256>(&b, &a, settings, &screen).unwrap()),
            ] {
                println!("order {order} {name}: {:.1e} off, {} evaluations", rel(e.value, half), e.evaluations);
                assert!(rel(e.value, half) < 1e-4, "order {order} {name}: {:e} against {half:e}", e.value);
            }
        }
        for tol in [1e-3, 1e-6] {
            let e = adaptive_exchange::<f64, _, _, _, 256>(&a, &b, Adaptive::new(tol), &screen).unwrap();
            let (error, estimate) = ((e.value - half).abs(), e.error.unwrap());
            println!(
                "tol {tol:e}: {:.1e} off, estimate {:.1e}, converged {}, {} evaluations",
                error / half,
                estimate / half,
                e.converged,
                e.evaluations
            );
            assert!(error <= estimate, "tol {tol:e}: {error:e} off, estimate {estimate:e}");
            assert!(!e.converged || error <= tol * half, "tol {tol:e}: {error:e} off");
        }
    }

    /// Two opposite walls of a 4 × 5 × 2.5 room (5 apart) across a table top (a closed slab
    /// 0.04 thick at desk height) and a spherical lamp above and beyond it. No segment from
    /// wall to wall meets both (one through the slab rises at most 0.76 over the first 1.5
    /// towards the lamp, and would need to rise 1.19 more over the next 1.1 to reach it), so
    /// what they block together is what each blocks alone: F_both = F_slab + F_lamp − F_none
    /// (an identity; F_none in closed form, C-10). Each side is computed alone by its own path,
    /// the slab's and the lamp's exact to 1e-12 at these orders. Before, the closed form
    /// for b less polygon shadows and a sphere's cone oriented each visible piece from its
    /// first three corners, which a cut through a corner repeats: from points at the slab's
    /// height J came out up to a third of b's solid angle off, and the pair 3 % low.
    #[test]
    fn a_table_and_a_lamp_between_two_walls_block_what_each_blocks_alone() {
        let p = |o: [f64; 3], t: [f64; 3], s: [f64; 3]| {
            AnyOccluder::Parallelogram(
                Parallelogram::new(vec3(o[0], o[1], o[2]), vec3(t[0], t[1], t[2]), vec3(s[0], s[1], s[2])).unwrap(),
            )
        };
        let (z0, z1) = (0.72, 0.76);
        let slab = [
            p([1.0, 1.5, z0], [0.0, 0.9, 0.0], [1.4, 0.0, 0.0]),
            p([1.0, 1.5, z1], [1.4, 0.0, 0.0], [0.0, 0.9, 0.0]),
            p([1.0, 1.5, z0], [1.4, 0.0, 0.0], [0.0, 0.0, z1 - z0]),
            p([1.0, 2.4, z0], [0.0, 0.0, z1 - z0], [1.4, 0.0, 0.0]),
            p([1.0, 1.5, z0], [0.0, 0.0, z1 - z0], [0.0, 0.9, 0.0]),
            p([2.4, 1.5, z0], [0.0, 0.9, 0.0], [0.0, 0.0, z1 - z0]),
        ];
        let lamp = AnyOccluder::Sphere(Sphere::outer(vec3(2.0, 3.5, 2.1), 0.15).unwrap());
        let both: Vec<AnyOccluder<f64>> = slab.iter().copied().chain([lamp]).collect();
        let south = Parallelogram::new(vec3(4.0, 0.0, 0.0), vec3(-4.0, 0.0, 0.0), vec3(0.0, 0.0, 2.5)).unwrap();
        let north = Parallelogram::new(vec3(0.0, 5.0, 2.5), vec3(0.0, 0.0, -2.5), vec3(4.0, 0.0, 0.0)).unwrap();
        let (a, b) = (Patch::whole(&south).unwrap(), Patch::whole(&north).unwrap());
        let area = 10.0;
        let none = exact::parallel_rectangles(4.0, 2.5, 5.0);
        let settings = PairSettings { order: 12, singular_order: 12, boundaries: true };
        let alone =
            |o: &[AnyOccluder<f64>]| pair_exchange::<f64, _, _, _, 1024>(&a, &b, settings, o).unwrap().value / area;
        let expected = alone(&slab) + alone(&[lamp]) - none;
        for order in [8, 12, 16] {
            let settings = PairSettings { order, singular_order: order, boundaries: true };
            let f = pair_exchange::<f64, _, _, _, 1024>(&a, &b, settings, both.as_slice()).unwrap().value / area;
            println!("order {order}: {f:.12} against {expected:.12}: {:.1e}", rel(f, expected));
            assert!(rel(f, expected) < BOTH_BOUND, "order {order}: {f:e} against {expected:e}");
        }
    }

    /// How near [`a_table_and_a_lamp_between_two_walls_block_what_each_blocks_alone`] must
    /// come: the slab's and the lamp's outer events are placed together (their shadows never
    /// meet), and the pair converges exponentially (measured 9e-13 / 1e-15 / 1e-15).
    const BOTH_BOUND: f64 = 1e-11;

    /// A closed box floating in a closed room: every row of the enclosure sums to 1 (an
    /// identity, no reference code). The room's faces touch each other along edges with the
    /// box between them (the contour form less the blocked part, `boundary/blocked.rs`), face
    /// pairs across the room see past the box (its facets' outer events,
    /// `boundary/polygon_events.rs`), and the box's facets see the room directly. Before both,
    /// the ceiling's row missed 1 by 6e-6 with the pairs above the tolerance.
    #[test]
    fn a_box_in_a_room_leaves_every_row_summing_to_one() {
        let p = |o: [f64; 3], t: [f64; 3], s: [f64; 3]| {
            AnyOccluder::Parallelogram(
                Parallelogram::new(vec3(o[0], o[1], o[2]), vec3(t[0], t[1], t[2]), vec3(s[0], s[1], s[2])).unwrap(),
            )
        };
        let (x0, y0, z0, dx, dy, dz) = (1.5, 2.0, 0.5, 1.0, 1.0, 0.7);
        let surfaces = [
            p([0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 5.0, 0.0]),
            p([0.0, 0.0, 2.5], [0.0, 5.0, 0.0], [4.0, 0.0, 0.0]),
            p([0.0, 0.0, 0.0], [0.0, 0.0, 2.5], [4.0, 0.0, 0.0]),
            p([0.0, 5.0, 0.0], [4.0, 0.0, 0.0], [0.0, 0.0, 2.5]),
            p([0.0, 0.0, 0.0], [0.0, 5.0, 0.0], [0.0, 0.0, 2.5]),
            p([4.0, 0.0, 0.0], [0.0, 0.0, 2.5], [0.0, 5.0, 0.0]),
            p([x0, y0, z0 + dz], [dx, 0.0, 0.0], [0.0, dy, 0.0]),
            p([x0, y0, z0], [0.0, dy, 0.0], [dx, 0.0, 0.0]),
            p([x0, y0, z0], [dx, 0.0, 0.0], [0.0, 0.0, dz]),
            p([x0, y0 + dy, z0], [0.0, 0.0, dz], [dx, 0.0, 0.0]),
            p([x0, y0, z0], [0.0, 0.0, dz], [0.0, dy, 0.0]),
            p([x0 + dx, y0, z0], [0.0, dy, 0.0], [0.0, 0.0, dz]),
        ];
        let surface = |k: usize| match &surfaces[k] {
            AnyOccluder::Parallelogram(s) => s,
            _ => unreachable!(),
        };
        let n = surfaces.len();
        // |e_t × e_s| of each, in the order above.
        let areas = [20.0, 20.0, 10.0, 10.0, 12.5, 12.5, dx * dy, dx * dy, dx * dz, dx * dz, dy * dz, dy * dz];
        let area = |k: usize| areas[k];
        for (mode, tol, bound) in [("order 10", None, 1e-9), ("tolerance 1e-10", Some(1e-10), 1e-9)] {
            let mut rows = vec![0.0; n];
            let mut errors = vec![0.0; n];
            let started = std::time::Instant::now();
            for i in 0..n {
                for j in i + 1..n {
                    let others: Vec<AnyOccluder<f64>> =
                        (0..n).filter(|&k| k != i && k != j).map(|k| surfaces[k]).collect();
                    let (a, b) = (Patch::whole(surface(i)).unwrap(), Patch::whole(surface(j)).unwrap());
                    let (value, error) = match tol {
                        None => {
                            let settings = PairSettings { order: 10, singular_order: 10, boundaries: true };
                            (
                                pair_exchange::<f64, _, _, _, 256>(&a, &b, settings, others.as_slice()).unwrap().value,
                                0.0,
                            )
                        }
                        Some(tol) => {
                            let e =
                                adaptive_exchange::<f64, _, _, _, 1024>(&a, &b, Adaptive::new(tol), others.as_slice())
                                    .unwrap();
                            assert!(e.converged, "{mode}: pair {i}-{j} not converged, estimate {:e}", e.error.unwrap());
                            (e.value, e.error.unwrap())
                        }
                    };
                    rows[i] += value / area(i);
                    rows[j] += value / area(j);
                    errors[i] += error / area(i);
                    errors[j] += error / area(j);
                }
            }
            println!("{mode}: {:.2} s", started.elapsed().as_secs_f64());
            for k in 0..n {
                println!("  row {k}: misses 1 by {:.1e} (estimates {:.1e})", rows[k] - 1.0, errors[k]);
                assert!((rows[k] - 1.0).abs() < bound, "{mode}: row {k} sums to {}", rows[k]);
                assert!(
                    tol.is_none() || (rows[k] - 1.0).abs() <= errors[k] + 1e-14,
                    "{mode}: row {k} beyond its estimates"
                );
            }
        }
    }
}

/// Pairs of `examples/scenes/room.toml`'s room (4 × 5 × 2.5, a table top as a closed slab, a
/// cabinet standing in a hole of the floor without a bottom, a spherical lamp), each facet a
/// parallelogram, the others as occluders.
/// The six facets of the axis-aligned box from corner `lo` with sides `d`, each radiating
/// outwards (top, bottom, the sides at y = lo, y = hi, x = lo, x = hi), as parallelograms from
/// one corner and two edge vectors.
fn box_facets(lo: [f64; 3], d: [f64; 3]) -> [pdm_kernel::Parallelogram<f64>; 6] {
    let p = |o: [f64; 3], t: [f64; 3], s: [f64; 3]| {
        pdm_kernel::Parallelogram::new(vec3(o[0], o[1], o[2]), vec3(t[0], t[1], t[2]), vec3(s[0], s[1], s[2])).unwrap()
    };
    let ([x0, y0, z0], [dx, dy, dz]) = (lo, d);
    [
        p([x0, y0, z0 + dz], [dx, 0.0, 0.0], [0.0, dy, 0.0]),
        p([x0, y0, z0], [0.0, dy, 0.0], [dx, 0.0, 0.0]),
        p([x0, y0, z0], [dx, 0.0, 0.0], [0.0, 0.0, dz]),
        p([x0, y0 + dy, z0], [0.0, 0.0, dz], [dx, 0.0, 0.0]),
        p([x0, y0, z0], [0.0, 0.0, dz], [0.0, dy, 0.0]),
        p([x0 + dx, y0, z0], [0.0, dy, 0.0], [0.0, 0.0, dz]),
    ]
}

/// Convex polygons in a plane, for the independent references below (written for these tests;
/// nothing shared with the kernel).
mod plane_polygons {
    pub type P2 = (f64, f64);

    pub fn cross(o: P2, a: P2, b: P2) -> f64 {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    }

    /// The convex polygon `poly` clipped by the convex polygon `by` (both counter-clockwise;
    /// Sutherland–Hodgman).
    pub fn clip(poly: &[P2], by: &[P2]) -> Vec<P2> {
        let mut out = poly.to_vec();
        for k in 0..by.len() {
            let (a, b) = (by[k], by[(k + 1) % by.len()]);
            let input = std::mem::take(&mut out);
            for i in 0..input.len() {
                let (v, w) = (input[i], input[(i + 1) % input.len()]);
                let (dv, dw) = (cross(a, b, v), cross(a, b, w));
                if dv >= 0.0 {
                    out.push(v);
                }
                if (dv >= 0.0) != (dw >= 0.0) {
                    let f = dv / (dv - dw);
                    out.push((v.0 + (w.0 - v.0) * f, v.1 + (w.1 - v.1) * f));
                }
            }
        }
        out
    }

    /// The convex hull, counter-clockwise (Andrew's monotone chain).
    pub fn hull(mut points: Vec<P2>) -> Vec<P2> {
        points.sort_by(|a, b| a.partial_cmp(b).unwrap());
        let mut h: Vec<P2> = vec![];
        for &q in &points {
            while h.len() >= 2 && cross(h[h.len() - 2], h[h.len() - 1], q) <= 0.0 {
                h.pop();
            }
            h.push(q);
        }
        let lower = h.len() + 1;
        for &q in points.iter().rev().skip(1) {
            while h.len() >= lower && cross(h[h.len() - 2], h[h.len() - 1], q) <= 0.0 {
                h.pop();
            }
            h.push(q);
        }
        h.pop();
        h
    }
}

mod furnished_room {
    use super::*;
    use pdm_kernel::{adaptive_exchange, Adaptive, AnyOccluder, Parallelogram};

    const VERTICES: [[f64; 3]; 28] = [
        [0., 5., 0.],
        [0., 0., 0.],
        [3.3, 0., 0.],
        [3.3, 5., 0.],
        [4., 5., 0.],
        [3.9, 5., 0.],
        [3.9, 0., 0.],
        [4., 0., 0.],
        [3.3, 1., 0.],
        [3.9, 1., 0.],
        [3.3, 2.2, 0.],
        [3.9, 2.2, 0.],
        [4., 0., 2.5],
        [0., 0., 2.5],
        [0., 5., 2.5],
        [4., 5., 2.5],
        [2.4, 2.4, 0.72],
        [2.4, 1.5, 0.72],
        [1., 1.5, 0.72],
        [1., 2.4, 0.72],
        [1., 2.4, 0.76],
        [1., 1.5, 0.76],
        [2.4, 1.5, 0.76],
        [2.4, 2.4, 0.76],
        [3.3, 2.2, 1.8],
        [3.3, 1., 1.8],
        [3.9, 1., 1.8],
        [3.9, 2.2, 1.8],
    ];

    /// The facets as in room.obj (1-based corners, counter-clockwise about the side each
    /// radiates to).
    const FACETS: [(&str, [usize; 4]); 20] = [
        ("floor0", [1, 2, 3, 4]),
        ("floor1", [5, 6, 7, 8]),
        ("floor2", [9, 3, 7, 10]),
        ("floor3", [4, 11, 12, 6]),
        ("ceiling", [13, 14, 15, 16]),
        ("south", [8, 2, 14, 13]),
        ("north", [15, 1, 5, 16]),
        ("west", [14, 2, 1, 15]),
        ("east", [5, 8, 13, 16]),
        ("table0", [17, 18, 19, 20]),
        ("table1", [21, 22, 23, 24]),
        ("table2", [22, 19, 18, 23]),
        ("table3", [17, 20, 21, 24]),
        ("table4", [20, 19, 22, 21]),
        ("table5", [23, 18, 17, 24]),
        ("cab0", [25, 26, 27, 28]),
        ("cab1", [26, 9, 10, 27]),
        ("cab2", [28, 12, 11, 25]),
        ("cab3", [11, 9, 26, 25]),
        ("cab4", [27, 10, 12, 28]),
    ];

    fn facet(name: &str) -> Parallelogram<f64> {
        let (_, f) = FACETS.iter().find(|(n, _)| *n == name).unwrap();
        let p = |k: usize| vec3(VERTICES[k - 1][0], VERTICES[k - 1][1], VERTICES[k - 1][2]);
        Parallelogram::new(p(f[0]), p(f[1]) - p(f[0]), p(f[3]) - p(f[0])).unwrap()
    }

    /// The facets whose names start with one of `prefixes`, except `a` and `b`.
    fn occluders(prefixes: &[&str], a: &str, b: &str) -> Vec<AnyOccluder<f64>> {
        FACETS
            .iter()
            .filter(|(n, _)| *n != a && *n != b && prefixes.iter().any(|p| n.starts_with(p)))
            .map(|(n, _)| AnyOccluder::Parallelogram(facet(n)))
            .collect()
    }

    fn exchange(a: &str, b: &str, order: usize, occluders: &[AnyOccluder<f64>]) -> f64 {
        let (fa, fb) = (facet(a), facet(b));
        let (pa, pb) = (Patch::whole(&fa).unwrap(), Patch::whole(&fb).unwrap());
        let settings = PairSettings { order, singular_order: order, boundaries: true };
        pair_exchange::<f64, _, _, _, 1024>(&pa, &pb, settings, occluders).unwrap().value
    }

    /// The tolerance mode's (value, estimate, converged).
    fn tolerance(a: &str, b: &str, tol: f64, occluders: &[AnyOccluder<f64>]) -> (f64, f64, bool) {
        let (fa, fb) = (facet(a), facet(b));
        let (pa, pb) = (Patch::whole(&fa).unwrap(), Patch::whole(&fb).unwrap());
        let e = adaptive_exchange::<f64, _, _, _, 1024>(&pa, &pb, Adaptive::new(tol), occluders).unwrap();
        (e.value, e.error.unwrap(), e.converged)
    }

    /// J(p) · π-free point factor from p (on a horizontal facet facing +z at height `h`) to the
    /// part above `h` of the rectangle y ∈ [0, 5], z ∈ [0, 2.5] of the plane x = 4 (facing −x),
    /// less the shadow of the axis-aligned box `lo`…`hi` (every corner between p and the wall):
    /// the convex hull of the corners projected from p, clipped to that rectangle, by Lambert's
    /// point-to-polygon form. Written for this test only; shares nothing with the kernel.
    fn point_past_box(p: [f64; 3], h: f64, lo: [f64; 3], hi: [f64; 3]) -> f64 {
        use super::plane_polygons::{clip, hull, P2};
        let lambert = |poly: &[P2]| {
            let m = poly.len();
            let mut sum = 0.0;
            for k in 0..m {
                let ((y0, z0), (y1, z1)) = (poly[k], poly[(k + 1) % m]);
                let r0 = [4.0 - p[0], y0 - p[1], z0 - p[2]];
                let r1 = [4.0 - p[0], y1 - p[1], z1 - p[2]];
                let c = [r0[1] * r1[2] - r0[2] * r1[1], r0[2] * r1[0] - r0[0] * r1[2], r0[0] * r1[1] - r0[1] * r1[0]];
                let cn = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
                if cn > 0.0 {
                    sum += cn.atan2(r0[0] * r1[0] + r0[1] * r1[1] + r0[2] * r1[2]) * c[2] / cn;
                }
            }
            (sum / (2.0 * std::f64::consts::PI)).abs()
        };
        let mut points = vec![];
        for x in [lo[0], hi[0]] {
            for y in [lo[1], hi[1]] {
                for z in [lo[2], hi[2]] {
                    let t = (4.0 - p[0]) / (x - p[0]);
                    points.push((p[1] + t * (y - p[1]), p[2] + t * (z - p[2])));
                }
            }
        }
        let wall = [(0.0, h), (5.0, h), (5.0, 2.5), (0.0, 2.5)];
        let shadow = clip(&hull(points), &wall);
        lambert(&wall) - if shadow.len() >= 3 { lambert(&shadow) } else { 0.0 }
    }

    /// A_a·F over a = [x0, x1] × [y0, y1] at height h by the composite 3 × 3 Gauss rule on
    /// n × n cells (J has kinks across a: the rule converges algebraically, and two n give
    /// its uncertainty).
    fn table_past_box(a: [f64; 4], h: f64, lo: [f64; 3], hi: [f64; 3], n: usize) -> f64 {
        let rule = [(-(0.6f64).sqrt(), 5.0 / 9.0), (0.0, 8.0 / 9.0), ((0.6f64).sqrt(), 5.0 / 9.0)];
        let (dx, dy) = ((a[1] - a[0]) / n as f64, (a[3] - a[2]) / n as f64);
        let mut total = 0.0;
        for i in 0..n {
            for j in 0..n {
                for &(u, wu) in &rule {
                    for &(v, wv) in &rule {
                        let x = a[0] + dx * (i as f64 + (u + 1.0) / 2.0);
                        let y = a[2] + dy * (j as f64 + (v + 1.0) / 2.0);
                        total += wu * wv / 4.0 * dx * dy * point_past_box([x, y, h], h, lo, hi);
                    }
                }
            }
        }
        total
    }

    /// The table top against the east wall past the cabinet: the wall runs from the floor to
    /// the ceiling, so it straddles the table top's plane, and the table sees only the part
    /// above it, b clipped by a's plane (the same polygon from every point of a). Its outer
    /// events are those of that part; before, a straddling b declined them, and the pair
    /// converged algebraically (orders 8 / 12 / 16: 7e-5, 2.5e-5, 1.8e-5 off the
    /// independent value). The value must converge exponentially in the order and meet an
    /// independent computation: the shadow as the hull of the cabinet's corners projected
    /// from p, Lambert's form over the wall's part less it, and a composite rule over a
    /// (`table_past_box`, uncertainty 2e-7 from 96 against 192 cells a side). With the table's
    /// other facets and the floor's among the occluders, the same.
    #[test]
    fn a_table_top_sees_the_wall_above_it_past_the_cabinet() {
        let (a, b) = ("table1", "east");
        let (cabinet, all) = (occluders(&["cab"], a, b), occluders(&["cab", "table", "floor"], a, b));
        // The same cabinet built as a user might, each side from one corner and two edge
        // vectors: shared corners come out a unit of rounding apart (2.2 − 1.2 ≠ 1.0), and
        // must still be recognised as one solid.
        let p = |o: [f64; 3], t: [f64; 3], s: [f64; 3]| {
            Parallelogram::new(vec3(o[0], o[1], o[2]), vec3(t[0], t[1], t[2]), vec3(s[0], s[1], s[2])).unwrap()
        };
        let built = [
            p([3.3, 2.2, 1.8], [0.0, -1.2, 0.0], [0.6, 0.0, 0.0]),
            p([3.3, 1.0, 1.8], [0.0, 0.0, -1.8], [0.6, 0.0, 0.0]),
            p([3.9, 2.2, 1.8], [0.0, 0.0, -1.8], [-0.6, 0.0, 0.0]),
            p([3.3, 2.2, 0.0], [0.0, -1.2, 0.0], [0.0, 0.0, 1.8]),
            p([3.9, 1.0, 1.8], [0.0, 0.0, -1.8], [0.0, 1.2, 0.0]),
        ];
        assert_ne!(2.2 - 1.2, 1.0, "the corners must disagree by rounding");
        let built: Vec<AnyOccluder<f64>> = built.into_iter().map(AnyOccluder::Parallelogram).collect();
        let independent = table_past_box([1.0, 2.4, 1.5, 2.4], 0.76, [3.3, 1.0, 0.0], [3.9, 2.2, 1.8], 192);
        let coarser = table_past_box([1.0, 2.4, 1.5, 2.4], 0.76, [3.3, 1.0, 0.0], [3.9, 2.2, 1.8], 96);
        let uncertainty = (independent - coarser).abs().max(1e-12 * independent);
        println!("independent: {independent:.15e}, uncertainty {:.1e}", uncertainty / independent);
        let reference = exchange(a, b, 16, &all);
        assert!(
            (reference - independent).abs() <= 2.0 * uncertainty,
            "order 16: {reference:e} against {independent:e} ± {uncertainty:e}"
        );
        for order in [8, 12] {
            for (name, occ) in [("cabinet", &cabinet), ("all", &all), ("built", &built)] {
                let f = exchange(a, b, order, occ);
                println!("order {order}, {name}: {:.1e} off order 16", rel(f, reference));
                let bound = if order == 8 { 1e-9 } else { 1e-12 };
                assert!(rel(f, reference) < bound, "order {order}, {name}: {f:e} against {reference:e}");
            }
        }
        for tol in [1e-4, 1e-9] {
            let (f, estimate, converged) = tolerance(a, b, tol, &all);
            println!("tolerance {tol:e}: {:.1e} off, estimate {:.1e}", rel(f, reference), estimate / f);
            assert!(converged && (f - reference).abs() <= estimate + 1e-13 * f, "tolerance {tol:e}");
        }
    }

    /// The same table top against a strip of the wall (y 1.5…2.5, floor to ceiling) past a
    /// sphere (a lamp) whose shadow passes the corners where the strip's sides meet the table
    /// top's plane: the sphere's events (its shadow through the corners of the strip's part
    /// above that plane, tangent to its edges) are placed for that part. Before, a straddling
    /// b declined them, and the pair converged algebraically: orders 8 / 12 / 16 were 8.4e-8,
    /// 1.6e-8, 3.3e-8 off order 20, and the tolerance mode at 1e-10 stopped unconverged
    /// (estimate 1.8e-6).
    #[test]
    fn a_table_top_sees_the_wall_above_it_past_a_lamp() {
        let (fa, fb) = (facet("table1"), facet("east"));
        let cell = ParamRect { t0: 0.5, t1: 0.7, s0: 0.0, s1: 1.0 };
        let (pa, pb) = (Patch::whole(&fa).unwrap(), Patch::new(&fb, cell).unwrap());
        let lamp = [AnyOccluder::Sphere(Sphere::outer(vec3(3.3, 1.9, 0.85), 0.3).unwrap())];
        let at = |order: usize| {
            let settings = PairSettings { order, singular_order: order, boundaries: true };
            pair_exchange::<f64, _, _, _, 1024>(&pa, &pb, settings, lamp.as_slice()).unwrap().value
        };
        let reference = at(20);
        for (order, bound) in [(8, 1e-8), (12, 1e-11), (16, 1e-12)] {
            let f = at(order);
            println!("order {order}: {:.1e} off order 20", rel(f, reference));
            assert!(rel(f, reference) < bound, "order {order}: {f:e} against {reference:e}");
        }
        let e = adaptive_exchange::<f64, _, _, _, 1024>(&pa, &pb, Adaptive::new(1e-10), lamp.as_slice()).unwrap();
        let (f, estimate) = (e.value, e.error.unwrap());
        println!("tolerance 1e-10: {:.1e} off, estimate {:.1e}", rel(f, reference), estimate / f);
        assert!(e.converged && (f - reference).abs() <= estimate + 1e-13 * f);
    }

    /// Two closed boxes between a 4 × 4 floor and ceiling 3 apart, side by side (x 0.5…1 and
    /// 3…3.5, both at heights 1…2): a segment meeting both would run 2 sideways per unit of
    /// height, 6 over the room's height, wider than the room; so what they block together is
    /// what each blocks alone, F_both = F_1 + F_2 − F_none (an identity; F_none in closed
    /// form, C-11). With each box's outer events placed (the separating-axis test proves that
    /// their shadows never meet), the pair converges exponentially. Before, two solids were
    /// declined and the rule sampled across their events.
    #[test]
    fn two_boxes_side_by_side_block_what_each_blocks_alone() {
        let p = |o: [f64; 3], t: [f64; 3], s: [f64; 3]| {
            Parallelogram::new(vec3(o[0], o[1], o[2]), vec3(t[0], t[1], t[2]), vec3(s[0], s[1], s[2])).unwrap()
        };
        let boxed = |x0: f64| box_facets([x0, 1.5, 1.0], [0.5, 1.0, 1.0]).map(AnyOccluder::Parallelogram);
        let (first, second) = (boxed(0.5), boxed(3.0));
        let both: Vec<AnyOccluder<f64>> = first.iter().chain(second.iter()).copied().collect();
        let floor = p([0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]);
        let ceiling = p([0.0, 0.0, 3.0], [0.0, 4.0, 0.0], [4.0, 0.0, 0.0]);
        let (a, b) = (Patch::whole(&floor).unwrap(), Patch::whole(&ceiling).unwrap());
        let at = |order: usize, occ: &[AnyOccluder<f64>]| {
            let settings = PairSettings { order, singular_order: order, boundaries: true };
            pair_exchange::<f64, _, _, _, 1024>(&a, &b, settings, occ).unwrap().value
        };
        let none = exact::parallel_rectangles(4.0, 4.0, 3.0) * 16.0;
        let expected = at(16, &first) + at(16, &second) - none;
        for order in [8, 12] {
            let f = at(order, &both);
            println!("order {order}: {:.1e} off inclusion–exclusion", rel(f, expected));
            assert!(rel(f, expected) < 1e-10, "order {order}: {f:e} against {expected:e}");
        }
        let e = adaptive_exchange::<f64, _, _, _, 1024>(&a, &b, Adaptive::new(1e-9), both.as_slice()).unwrap();
        let (f, estimate) = (e.value, e.error.unwrap());
        println!("tolerance 1e-9: {:.1e} off, estimate {:.1e}", rel(f, expected), estimate / f);
        assert!(
            e.converged && (f - expected).abs() <= estimate + 1e-13 * f,
            "{f:e} ± {estimate:e} against {expected:e}"
        );
    }

    /// A cabinet standing in a hole of the floor, the floor's facets sharing its bottom edges:
    /// its facets make one convex solid, the floor's lie around it and cut nothing. The
    /// small floor facet in front of it against the north wall must come out the same with
    /// and without the floor's other facets among the occluders, and converge exponentially:
    /// with the wall outside, since the cabinet's foot touches the facet's edge, where J is
    /// singular (with the facet outside, 1e-4 off at order 8, 5e-6 at order 20). Before, the
    /// floor's facets joined the cabinet into one non-convex set and the pair took 3 × 3
    /// cells, 2e-8 apart from order to order. (With the cabinet alone and the facet outside,
    /// the tolerance mode at 1e-4 stopped on two orders agreeing by accident, its estimate
    /// 1.5e-6 below the error of 4.4e-6; a pair whose occluder touches the outer patch no
    /// longer takes the route for exponential convergence.)
    #[test]
    fn a_cabinet_standing_in_the_floor_casts_one_solid_shadow() {
        let (a, b) = ("floor2", "north");
        let (cabinet, with_floor) = (occluders(&["cab"], a, b), occluders(&["cab", "floor"], a, b));
        let reference = exchange(a, b, 20, &cabinet);
        for order in [8, 12] {
            for (name, occ) in [("cabinet", &cabinet), ("cabinet and floor", &with_floor)] {
                let f = exchange(a, b, order, occ);
                println!("order {order}, {name}: {:.1e} off order 20", rel(f, reference));
                assert!(rel(f, reference) < 1e-12, "order {order}, {name}: {f:e} against {reference:e}");
            }
        }
        for tol in [1e-4, 1e-8] {
            let (f, estimate, converged) = tolerance(a, b, tol, &with_floor);
            println!("tolerance {tol:e}: {:.1e} off, estimate {:.1e}", rel(f, reference), estimate / f);
            assert!(converged && (f - reference).abs() <= estimate + 1e-13 * f, "tolerance {tol:e}");
        }
    }
}

/// An occluder touching one patch of an equal pair (a box standing on the floor, the ceiling
/// above it): the other patch goes outside, whichever comes first.
mod boxes_on_the_floor {
    use super::plane_polygons::{clip, hull, P2};
    use super::*;
    use pdm_kernel::{adaptive_exchange, Adaptive, AnyOccluder, Parallelogram};

    /// The point factor from p (on the ceiling z = 3, facing down) to a polygon of the floor
    /// z = 0: Lambert's form, ½π Σ γ_k n̂·(R_k × R_{k+1})/|R_k × R_{k+1}|.
    fn lambert(p: [f64; 3], poly: &[P2]) -> f64 {
        let mut sum = 0.0;
        for k in 0..poly.len() {
            let ((x0, y0), (x1, y1)) = (poly[k], poly[(k + 1) % poly.len()]);
            let r0 = [x0 - p[0], y0 - p[1], -p[2]];
            let r1 = [x1 - p[0], y1 - p[1], -p[2]];
            let c = [r0[1] * r1[2] - r0[2] * r1[1], r0[2] * r1[0] - r0[0] * r1[2], r0[0] * r1[1] - r0[1] * r1[0]];
            let cn = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
            if cn > 0.0 {
                sum += cn.atan2(r0[0] * r1[0] + r0[1] * r1[1] + r0[2] * r1[2]) * c[2] / cn;
            }
        }
        (sum / (2.0 * std::f64::consts::PI)).abs()
    }

    /// A_ceiling·F to the floor (both [0, 4]², 3 apart) past two axis-aligned boxes (lo, hi)
    /// below the ceiling: J(p) is Lambert's form over the floor less the two shadows (each the
    /// hull of the box's corners projected from p, clipped to the floor), by inclusion–exclusion
    /// of convex polygons; the composite 3 × 3 Gauss rule on n × n cells of the ceiling
    /// (algebraic in n: J kinks across it). Written for this test; shares nothing with the
    /// kernel.
    fn ceiling_past_boxes(boxes: [([f64; 3], [f64; 3]); 2], n: usize) -> f64 {
        let floor = [(0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (0.0, 4.0)];
        let j = |p: [f64; 3]| {
            let shadow = |(lo, hi): ([f64; 3], [f64; 3])| {
                let mut points = vec![];
                for x in [lo[0], hi[0]] {
                    for y in [lo[1], hi[1]] {
                        for z in [lo[2], hi[2]] {
                            let t = p[2] / (p[2] - z);
                            points.push((p[0] + t * (x - p[0]), p[1] + t * (y - p[1])));
                        }
                    }
                }
                clip(&hull(points), &floor)
            };
            let (s0, s1) = (shadow(boxes[0]), shadow(boxes[1]));
            let both = if s0.len() >= 3 && s1.len() >= 3 { clip(&s0, &s1) } else { vec![] };
            let l = |poly: &[P2]| if poly.len() >= 3 { lambert(p, poly) } else { 0.0 };
            l(&floor) - l(&s0) - l(&s1) + l(&both)
        };
        let rule = [(-(0.6f64).sqrt(), 5.0 / 9.0), (0.0, 8.0 / 9.0), ((0.6f64).sqrt(), 5.0 / 9.0)];
        let h = 4.0 / n as f64;
        let mut total = 0.0;
        for i in 0..n {
            for k in 0..n {
                for &(u, wu) in &rule {
                    for &(v, wv) in &rule {
                        let (x, y) = (h * (i as f64 + (u + 1.0) / 2.0), h * (k as f64 + (v + 1.0) / 2.0));
                        total += wu * wv / 4.0 * h * h * j([x, y, 3.0]);
                    }
                }
            }
        }
        total
    }

    /// A 4 × 4 floor and ceiling 3 apart past two axis-aligned boxes (lo, hi), with the
    /// independent value of A_ceiling·F and its uncertainty (192 against 96 cells).
    struct FloorAndCeiling {
        floor: Parallelogram<f64>,
        ceiling: Parallelogram<f64>,
        occluders: Vec<AnyOccluder<f64>>,
        independent: f64,
        uncertainty: f64,
    }

    impl FloorAndCeiling {
        fn new(boxes: [([f64; 3], [f64; 3]); 2]) -> Self {
            let p = |o: [f64; 3], t: [f64; 3], s: [f64; 3]| {
                Parallelogram::new(vec3(o[0], o[1], o[2]), vec3(t[0], t[1], t[2]), vec3(s[0], s[1], s[2])).unwrap()
            };
            let mut occluders = vec![];
            for (lo, hi) in boxes {
                let d = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
                occluders.extend(box_facets(lo, d).map(AnyOccluder::Parallelogram));
            }
            let independent = ceiling_past_boxes(boxes, 192);
            let uncertainty = (independent - ceiling_past_boxes(boxes, 96)).abs();
            println!("independent {independent:.12e} ± {:.1e}", uncertainty / independent);
            Self {
                floor: p([0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]),
                ceiling: p([0.0, 0.0, 3.0], [0.0, 4.0, 0.0], [4.0, 0.0, 0.0]),
                occluders,
                independent,
                uncertainty,
            }
        }

        fn floor(&self) -> Patch<'_, f64, Parallelogram<f64>> {
            Patch::whole(&self.floor).unwrap()
        }

        fn ceiling(&self) -> Patch<'_, f64, Parallelogram<f64>> {
            Patch::whole(&self.ceiling).unwrap()
        }
    }

    /// A 4 × 4 floor and ceiling 3 apart, a box standing on the floor and a box floating above
    /// it whose shadows meet. Equal patches took the first argument outside: with the floor
    /// first, the floor, along whose contact with the box J is singular (the events declined:
    /// orders 8 / 12 / 16 / 24 were 6.5e-3, 6.5e-4, 1.9e-3, 3.5e-4 off the independent value);
    /// with the ceiling first, the ceiling. The ceiling goes outside either way, and the two
    /// argument orders agree to rounding; with the events where the two shadows meet placed,
    /// the value is within the reference's uncertainty from order 8.
    #[test]
    fn the_patch_a_box_stands_on_goes_inside() {
        let room = FloorAndCeiling::new([([1.0, 1.0, 0.0], [2.0, 2.0, 1.0]), ([1.6, 1.4, 1.6], [2.6, 2.6, 2.1])]);
        let (f, c, occluders, independent, uncertainty) =
            (room.floor(), room.ceiling(), &room.occluders, room.independent, room.uncertainty);
        for (order, bound) in [(8, 1e-6), (12, 1e-6)] {
            let s = PairSettings { order, singular_order: order, boundaries: true };
            let floor_first = pair_exchange::<f64, _, _, _, 1024>(&f, &c, s, occluders.as_slice()).unwrap().value;
            let ceiling_first = pair_exchange::<f64, _, _, _, 1024>(&c, &f, s, occluders.as_slice()).unwrap().value;
            println!(
                "order {order}: {:.1e} / {:.1e} off",
                rel(floor_first, independent),
                rel(ceiling_first, independent)
            );
            assert!(rel(floor_first, ceiling_first) < 1e-14, "order {order}: {floor_first:e}, {ceiling_first:e}");
            assert!(rel(floor_first, independent) < bound, "order {order}: {floor_first:e} against {independent:e}");
        }
        for (x, y) in [(&f, &c), (&c, &f)] {
            let e = adaptive_exchange::<f64, _, _, _, 1024>(x, y, Adaptive::new(1e-4), occluders.as_slice()).unwrap();
            let (value, estimate) = (e.value, e.error.unwrap());
            println!("tolerance 1e-4: {:.1e} off, estimate {:.1e}", rel(value, independent), estimate / value);
            assert!((value - independent).abs() <= estimate + 2.0 * uncertainty);
        }
    }

    /// Two floating boxes between the floor and the ceiling whose shadows on the floor overlap
    /// from most of the ceiling: J changes structure where a vertex of one shadow crosses an
    /// edge of the other and where two shadow edges cross on the floor's edge, as well as at
    /// each shadow's own events. With those curves placed the outer integral converges with the
    /// order (orders 4 and 6 agree to 1e-10) onto the independent value; sampled across them,
    /// it was algebraic (orders 8 / 16 / 24: 4.6e-4 / 1.9e-5 / 2.4e-5 off), and the tolerance
    /// mode did not converge at 1e-4 (estimate 2.6e-3). It now converges at 1e-8 with its
    /// estimate above the difference to the reference (less its uncertainty).
    #[test]
    fn two_boxes_whose_shadows_meet_converge_with_the_order() {
        let room = FloorAndCeiling::new([([0.8, 1.0, 0.5], [1.8, 2.2, 1.2]), ([1.5, 1.6, 1.5], [2.7, 2.5, 2.2])]);
        let (f, c, occluders, independent, uncertainty) =
            (room.floor(), room.ceiling(), &room.occluders, room.independent, room.uncertainty);
        let at = |order| {
            let s = PairSettings { order, singular_order: order, boundaries: true };
            pair_exchange::<f64, _, _, _, 1024>(&c, &f, s, occluders.as_slice()).unwrap().value
        };
        let (q4, q6) = (at(4), at(6));
        println!(
            "orders 4 / 6: {:.1e} / {:.1e} off, {:.1e} apart",
            rel(q4, independent),
            rel(q6, independent),
            rel(q4, q6)
        );
        assert!(rel(q4, q6) < 1e-9, "orders 4 and 6: {q4:e}, {q6:e}");
        assert!((q6 - independent).abs() <= 2.0 * uncertainty + 1e-12, "{q6:e} against {independent:e}");
        let e = adaptive_exchange::<f64, _, _, _, 1024>(&f, &c, Adaptive::new(1e-8), occluders.as_slice()).unwrap();
        let (value, estimate) = (e.value, e.error.unwrap());
        println!("tolerance 1e-8: {:.1e} off, estimate {:.1e}", rel(value, independent), estimate / value);
        assert!(e.converged && estimate <= 1e-8 * value);
        assert!((value - independent).abs() <= estimate + 2.0 * uncertainty);
        assert!(rel(value, q6) < 1e-9);
    }
}

/// f32 pairs far from the origin for their size: every point is computed at the magnitude of
/// its coordinates, up to ε·|x| off, which at 10⁴ sizes from the origin moves corners and
/// gaps by 1e-3 of the patches' size. The tolerance mode's estimate must cover that
/// (`adaptive::position_allowance`); it covered only the arithmetic (128 ε, 1.5e-5 relative)
/// and lay 5–50× below the error. Catalogue references: C-11 (parallel squares), C-14
/// (perpendicular squares sharing an edge), C-41 (coaxial disks); 1 cm geometry at 12
/// placements 3 to 150 m from the origin in six directions.
#[test]
fn f32_estimates_cover_the_rounding_of_far_coordinates() {
    use pdm_kernel::{adaptive_exchange, Adaptive, Parallelogram};
    let k = 0.01;
    let c11 = exact::parallel_rectangles(1.0, 1.0, 1.0) * k * k;
    let c14 = exact::perpendicular_rectangles(1.0, 1.0, 1.0) * k * k;
    let c41 = exact::coaxial_disks(0.5, 0.4, 0.8) * core::f64::consts::PI * 0.25 * k * k;
    let directions = [[0.83, 0.52, -0.21], [-0.37, 0.91, 0.18], [0.11, -0.29, 0.95], [-0.7, -0.5, 0.51]];
    let mut worst: f64 = 0.0;
    let mut worst_error: f64 = 0.0;
    for (i, d) in directions.iter().enumerate() {
        for (j, distance) in [3.1, 27.3, 151.7].into_iter().enumerate() {
            if (i + j) % 4 == 3 {
                continue;
            }
            let o = [d[0] * distance, d[1] * distance, d[2] * distance];
            let at = |p: [f64; 3]| v::<f32>([o[0] + p[0] * k, o[1] + p[1] * k, o[2] + p[2] * k]);
            let edge = |p: [f64; 3]| v::<f32>([p[0] * k, p[1] * k, p[2] * k]);
            let floor = Parallelogram::new(at([0.0, 0.0, 0.0]), edge([1.0, 0.0, 0.0]), edge([0.0, 1.0, 0.0])).unwrap();
            let ceiling =
                Parallelogram::new(at([0.0, 0.0, 1.0]), edge([0.0, 1.0, 0.0]), edge([1.0, 0.0, 0.0])).unwrap();
            let wall = Parallelogram::new(at([0.0, 0.0, 0.0]), edge([0.0, 0.0, 1.0]), edge([1.0, 0.0, 0.0])).unwrap();
            let lower = Disk::new(at([0.0, 0.0, 0.0]), vec3(0.0, 0.0, 1.0), (0.5 * k) as f32).unwrap();
            let upper = Disk::new(at([0.0, 0.0, 0.8]), vec3(0.0, 0.0, -1.0), (0.4 * k) as f32).unwrap();
            let settings = Adaptive::new(1e-4);
            let mut check = |name: &str, e: pdm_kernel::Estimate<f32>, reference: f64| {
                let error = (f64::from(e.value) - reference).abs();
                let estimate = f64::from(e.error.unwrap());
                println!(
                    "{name} at {distance} m: error {:.2e}, estimate {:.2e} (relative)",
                    error / reference,
                    estimate / reference
                );
                assert!(error <= estimate, "{name} at {o:?}: error {error:e} above the estimate {estimate:e}");
                assert!(estimate <= 0.05 * reference, "{name} at {o:?}: estimate {estimate:e} of {reference:e}");
                worst = worst.max(error / estimate);
                worst_error = worst_error.max(error / reference);
            };
            let (pf, pc, pw) =
                (Patch::whole(&floor).unwrap(), Patch::whole(&ceiling).unwrap(), Patch::whole(&wall).unwrap());
            let e = adaptive_exchange::<f32, _, _, _, 144>(&pf, &pc, settings, &()).unwrap();
            check("C-11", e, c11);
            let e = adaptive_exchange::<f32, _, _, _, 144>(&pf, &pw, settings, &()).unwrap();
            check("C-14", e, c14);
            let (pl, pu) = (Patch::whole(&lower).unwrap(), Patch::whole(&upper).unwrap());
            let e = adaptive_exchange::<f32, _, _, _, 144>(&pl, &pu, settings, &()).unwrap();
            check("C-41", e, c41);
        }
    }
    println!("largest error / estimate {worst:.3}, largest relative error {worst_error:.2e}");
    // The placements do reach errors the arithmetic's allowance (1.5e-5) does not cover.
    assert!(worst_error > 1e-4, "{worst_error:e}");
}
