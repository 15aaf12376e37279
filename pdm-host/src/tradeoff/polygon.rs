//! Polygonised spheres for the curved-versus-polygons study: flat facets as kernel surfaces,
//! UV spheres and icospheres, and the exact form factor of a polyhedron to a cube face.
//!
//! A facet is the bilinear map g(t, s) = p00 + t(p10 − p00) + s(p01 − p00) + ts·d with
//! d = p11 − p10 − p01 + p00 over [0, 1]² ([`Facet`]). Its four corners are coplanar (a UV
//! sphere's cells are isosceles trapezoids; an icosphere's cells are triangles), so the facet is
//! flat; a triangle is the degenerate case p01 = p00, g = A + t(B − A) + ts(C − B), whose normal
//! n = t·(B − A) × (C − B) vanishes at the corner t = 0 (integrable; Gauss nodes are interior).
//!
//! The exact factor of the polyhedron to a face ([`exact_polyhedron_to_face`]) is computed with
//! the host's contour reference ([`crate::reference::contour`], no kernel code), each facet
//! against the part of the face in front of the facet's plane (Sutherland–Hodgman clip); the
//! polyhedron is convex, so nothing else blocks.

use pdm_kernel::{vec3, ParamRect, PdmError, Real, Surface, Vec3};

use crate::reference::contour::{polygon_area, polygon_form_factor};

/// A flat facet with four coplanar corners (a triangle when `p01 == p00`), radiating towards
/// (p10 − p00) × (p01 − p00) for a quad (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Facet<T> {
    p00: Vec3<T>,
    e_t: Vec3<T>,
    e_s: Vec3<T>,
    d: Vec3<T>,
}

impl<T: Real> Facet<T> {
    /// The bilinear facet through the corners g(0,0) = p00, g(1,0) = p10, g(0,1) = p01,
    /// g(1,1) = p11 (coplanar, not checked).
    #[must_use]
    pub fn bilinear(p00: Vec3<T>, p10: Vec3<T>, p01: Vec3<T>, p11: Vec3<T>) -> Self {
        Self { p00, e_t: p10 - p00, e_s: p01 - p00, d: p11 - p10 - p01 + p00 }
    }

    /// The triangle (a, b, c) as the collapsed facet g = a + t(b − a) + ts(c − b); it radiates
    /// towards (b − a) × (c − b), i.e. counter-clockwise a → b → c seen from the radiating side.
    #[must_use]
    pub fn triangle(a: Vec3<T>, b: Vec3<T>, c: Vec3<T>) -> Self {
        Self::bilinear(a, b, a, c)
    }
}

impl<T: Real> Surface<T> for Facet<T> {
    fn domain(&self) -> ParamRect<T> {
        ParamRect { t0: T::ZERO, t1: T::ONE, s0: T::ZERO, s1: T::ONE }
    }
    #[inline]
    fn point(&self, t: T, s: T) -> Vec3<T> {
        self.p00 + self.e_t.scale(t) + self.e_s.scale(s) + self.d.scale(t * s)
    }
    #[inline]
    fn normal(&self, t: T, s: T) -> Vec3<T> {
        (self.e_t + self.d.scale(s)).cross(self.e_s + self.d.scale(t))
    }
}

/// A tessellated unit-radius sphere: its facets (as corner lists, counter-clockwise seen from
/// outside) and a name.
#[derive(Clone, Debug, PartialEq)]
pub struct Polyhedron {
    /// "uv-8x16", "ico-2", …
    pub name: String,
    /// Family: "uv" or "ico".
    pub family: &'static str,
    /// Facets, 3 or 4 corners each, counter-clockwise seen from outside.
    pub facets: Vec<Vec<[f64; 3]>>,
}

fn on_sphere(centre: [f64; 3], radius: f64, phi: f64, theta: f64) -> [f64; 3] {
    [
        centre[0] + radius * phi.sin() * theta.cos(),
        centre[1] + radius * phi.sin() * theta.sin(),
        centre[2] + radius * phi.cos(),
    ]
}

/// The UV sphere with `m` bands in φ (pole to pole) and `n` sectors in θ, vertices on the
/// sphere at φ_i = iπ/m, θ_j = 2πj/n (the paper's eq. 19 grid): triangles at the poles,
/// planar trapezoids elsewhere. `m ≥ 2`, `n ≥ 3`.
#[must_use]
pub fn uv_sphere(centre: [f64; 3], radius: f64, m: usize, n: usize) -> Polyhedron {
    let m = m.max(2);
    let n = n.max(3);
    let v = |i: usize, j: usize| {
        let phi = std::f64::consts::PI * i as f64 / m as f64;
        let theta = 2.0 * std::f64::consts::PI * (j % n) as f64 / n as f64;
        on_sphere(centre, radius, phi, theta)
    };
    let mut facets = Vec::with_capacity(m * n);
    for i in 0..m {
        for j in 0..n {
            // Outward orientation: (φ, θ) increasing is ∂φ × ∂θ = outward (eq. 21), so the
            // corners (i, j) → (i+1, j) → (i+1, j+1) → (i, j+1) run counter-clockwise outside.
            let mut f = vec![v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)];
            if i == 0 {
                f.remove(3); // north pole: (0, j) and (0, j+1) coincide
            } else if i == m - 1 {
                f.remove(2); // south pole
            }
            facets.push(f);
        }
    }
    Polyhedron { name: format!("uv-{m}x{n}"), family: "uv", facets }
}

/// The icosphere of subdivision `level` (20·4^level triangles): an icosahedron whose triangles
/// are split into four by their edge midpoints pushed onto the sphere, `level` times.
#[must_use]
pub fn icosphere(centre: [f64; 3], radius: f64, level: u32) -> Polyhedron {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let raw = [
        [-1.0, g, 0.0],
        [1.0, g, 0.0],
        [-1.0, -g, 0.0],
        [1.0, -g, 0.0],
        [0.0, -1.0, g],
        [0.0, 1.0, g],
        [0.0, -1.0, -g],
        [0.0, 1.0, -g],
        [g, 0.0, -1.0],
        [g, 0.0, 1.0],
        [-g, 0.0, -1.0],
        [-g, 0.0, 1.0],
    ];
    let unit = |p: [f64; 3]| {
        let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        [p[0] / l, p[1] / l, p[2] / l]
    };
    let idx: [[usize; 3]; 20] = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut tris: Vec<[[f64; 3]; 3]> =
        idx.iter().map(|t| t.map(|k| unit(raw.get(k).copied().unwrap_or_default()))).collect();
    for _ in 0..level {
        let mid = |a: [f64; 3], b: [f64; 3]| unit([a[0] + b[0], a[1] + b[1], a[2] + b[2]]);
        let mut next = Vec::with_capacity(tris.len() * 4);
        for [a, b, c] in tris {
            let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        tris = next;
    }
    let place = |p: [f64; 3]| [centre[0] + radius * p[0], centre[1] + radius * p[1], centre[2] + radius * p[2]];
    let facets = tris
        .into_iter()
        .map(|[a, b, c]| {
            let (a, b, c) = (place(a), place(b), place(c));
            // Orient outwards: counter-clockwise seen from outside.
            let n = cross(sub(b, a), sub(c, a));
            let out = sub(a, centre);
            if dot(n, out) >= 0.0 {
                vec![a, b, c]
            } else {
                vec![a, c, b]
            }
        })
        .collect();
    Polyhedron { name: format!("ico-{level}"), family: "ico", facets }
}

/// The fixed generic rotation applied to the study's polyhedra: 0.7 rad about the axis
/// (1, 2, 3)/√14 (Rodrigues). Without it the icosphere's factor to each whole cube face is
/// exactly 1/6 by symmetry (the icosahedron's symmetry group contains the cube's coordinate
/// reflections and its 3-fold axes), which would hide its polygonisation error.
#[must_use]
pub fn generic_rotation() -> [[f64; 3]; 3] {
    let l = 14f64.sqrt();
    let (x, y, z) = (1.0 / l, 2.0 / l, 3.0 / l);
    let (s, c) = 0.7f64.sin_cos();
    let k = 1.0 - c;
    [
        [c + x * x * k, x * y * k - z * s, x * z * k + y * s],
        [y * x * k + z * s, c + y * y * k, y * z * k - x * s],
        [z * x * k - y * s, z * y * k + x * s, c + z * z * k],
    ]
}

impl Polyhedron {
    /// The polyhedron rotated by `r` about `centre`.
    #[must_use]
    pub fn rotated(&self, centre: [f64; 3], r: [[f64; 3]; 3]) -> Self {
        let rot = |p: [f64; 3]| {
            let q = sub(p, centre);
            [centre[0] + dot(r[0], q), centre[1] + dot(r[1], q), centre[2] + dot(r[2], q)]
        };
        Self {
            name: self.name.clone(),
            family: self.family,
            facets: self.facets.iter().map(|f| f.iter().map(|&p| rot(p)).collect()).collect(),
        }
    }

    /// Number of facets.
    #[must_use]
    pub fn len(&self) -> usize {
        self.facets.len()
    }

    /// `true` without facets.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.facets.is_empty()
    }

    /// The facets as kernel surfaces in precision `T` (radiating outwards).
    pub fn surfaces<T: Real>(&self) -> Result<Vec<Facet<T>>, PdmError> {
        let v = |p: [f64; 3]| vec3(T::from_f64(p[0]), T::from_f64(p[1]), T::from_f64(p[2]));
        self.facets
            .iter()
            .map(|f| match f.as_slice() {
                [a, b, c] => Ok(Facet::triangle(v(*a), v(*b), v(*c))),
                // Corners counter-clockwise a → b → c → d: g(0,0) = a, g(1,0) = b, g(1,1) = c,
                // g(0,1) = d, normal (b − a) × (d − a) points to the counter-clockwise side.
                [a, b, c, d] => Ok(Facet::bilinear(v(*a), v(*b), v(*d), v(*c))),
                _ => Err(PdmError::Degenerate),
            })
            .collect()
    }

    /// Total facet area (exact, Newell).
    #[must_use]
    pub fn area(&self) -> f64 {
        self.facets.iter().map(|f| polygon_area(f)).sum()
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Newell normal (unnormalised) of a planar polygon.
fn newell(p: &[[f64; 3]]) -> [f64; 3] {
    let mut n = [0.0; 3];
    for (a, &b) in p.iter().zip(p.iter().cycle().skip(1)) {
        let c = cross(*a, b);
        n = [n[0] + c[0], n[1] + c[1], n[2] + c[2]];
    }
    n
}

/// The part of the convex polygon `poly` where `n·(x − o) > 0` (Sutherland–Hodgman), in order.
#[must_use]
pub fn clip_to_half_space(poly: &[[f64; 3]], o: [f64; 3], n: [f64; 3]) -> Vec<[f64; 3]> {
    let side = |x: [f64; 3]| dot(n, sub(x, o));
    let mut out = Vec::with_capacity(poly.len() + 1);
    for (&a, &b) in poly.iter().zip(poly.iter().cycle().skip(1)) {
        let (sa, sb) = (side(a), side(b));
        if sa > 0.0 {
            out.push(a);
        }
        if (sa > 0.0) != (sb > 0.0) {
            let t = sa / (sa - sb);
            out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])]);
        }
    }
    out
}

/// F polyhedron → planar convex `face` (vertices counter-clockwise seen from its radiating
/// side), exactly: (1/A) Σ_f A_f F_{f → face ∩ front(f)} by the contour reference, each facet
/// paired with the part of the face in front of the facet's plane. The polyhedron must be convex
/// and lie in front of the face's plane.
#[must_use]
pub fn exact_polyhedron_to_face(poly: &Polyhedron, face: &[[f64; 3]]) -> f64 {
    let mut exchange = 0.0;
    let mut area = 0.0;
    for f in &poly.facets {
        let a = polygon_area(f);
        area += a;
        let n = newell(f);
        let clipped = clip_to_half_space(face, f.first().copied().unwrap_or_default(), n);
        if clipped.len() < 3 || polygon_area(&clipped) <= 1e-14 * polygon_area(face) {
            continue;
        }
        exchange += a * polygon_form_factor(f, &clipped);
    }
    exchange / area
}

/// The K × K cells of face `k` (1..6) of the validation cube, in the order of
/// `PatchGrid::new(face, K, K)` (t index outer), each counter-clockwise seen from inside.
#[must_use]
pub fn cube_face_cells(k: usize, cells: usize) -> Vec<Vec<[f64; 3]>> {
    let Some((o, t, s)) = crate::validate::scene::FACES.get(k.wrapping_sub(1)).copied() else {
        return Vec::new();
    };
    let n = cells.max(1);
    let at = |i: usize, j: usize| {
        let (a, b) = (i as f64 / n as f64, j as f64 / n as f64);
        [o[0] + a * t[0] + b * s[0], o[1] + a * t[1] + b * s[1], o[2] + a * t[2] + b * s[2]]
    };
    let mut out = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            out.push(vec![at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    out
}

/// The same quantity as [`exact_polyhedron_to_face`] by the kernel's sum on the clipped pieces:
/// each facet against the part of `cell` in front of the facet's plane, fan-triangulated, with
/// `order_facet` Gauss points per axis on the facet and `order_cell` on each triangle. The clip
/// removes the only non-smooth part of the integrand (the back-face cut), so the sum converges
/// exponentially; it is checked against the contour reference in the tests and is far faster.
pub fn clipped_polyhedron_to_polygon(
    poly: &Polyhedron,
    cell: &[[f64; 3]],
    order_facet: usize,
    order_cell: usize,
) -> Result<f64, PdmError> {
    use pdm_kernel::{exchange, Patch, PatchSamples};
    const CAP: usize = 400;
    let v = |p: [f64; 3]| vec3(p[0], p[1], p[2]);
    let facets = poly.surfaces::<f64>()?;
    let mut total = 0.0;
    let mut area = 0.0;
    for (f, surface) in poly.facets.iter().zip(&facets) {
        area += polygon_area(f);
        let n = newell(f);
        let clipped = clip_to_half_space(cell, f.first().copied().unwrap_or_default(), n);
        if clipped.len() < 3 || polygon_area(&clipped) <= 1e-14 * polygon_area(cell) {
            continue;
        }
        let sa = PatchSamples::<f64, CAP>::new(&Patch::whole(surface)?, order_facet)?;
        let Some((&first, rest)) = clipped.split_first() else { continue };
        for (&b, &c) in rest.iter().zip(rest.iter().skip(1)) {
            // Drop slivers left by clipping at a vertex.
            if norm(cross(sub(b, first), sub(c, first))) <= 1e-12 * polygon_area(cell) {
                continue;
            }
            let tri = Facet::triangle(v(first), v(b), v(c));
            let sb = PatchSamples::<f64, CAP>::new(&Patch::whole(&tri)?, order_cell)?;
            total += exchange(&sa, &sb, &())?;
        }
    }
    Ok(total / area)
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// Corners of face `k` (1..6) of the validation cube, counter-clockwise seen from inside (the
/// radiating side), from [`crate::validate::scene::FACES`].
#[must_use]
pub fn cube_face_polygon(k: usize) -> Option<Vec<[f64; 3]>> {
    let (o, t, s) = *crate::validate::scene::FACES.get(k.wrapping_sub(1))?;
    let add = |a: [f64; 3], b: [f64; 3]| [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
    // g(0,0) = o, g(1,0) = o + t, g(1,1) = o + t + s, g(0,1) = o + s; normal t × s points in.
    Some(vec![o, add(o, t), add(add(o, t), s), add(o, s)])
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::indexing_slicing)]
mod tests {
    use super::*;
    use crate::reference::closed_form::sphere_to_polygon;
    use pdm_kernel::{AutoNormal, ParametricMap, Scalar};

    /// The facet's closed-form normal equals the dual-number one.
    #[test]
    fn facet_normal_matches_dual_numbers() {
        struct Map(Facet<f64>);
        impl ParametricMap<f64> for Map {
            fn domain(&self) -> ParamRect<f64> {
                ParamRect { t0: 0.0, t1: 1.0, s0: 0.0, s1: 1.0 }
            }
            fn map<S: Scalar<f64>>(&self, t: S, s: S) -> Vec3<S> {
                let k = |v: f64| S::constant(v);
                let f = &self.0;
                let c = |o: f64, a: f64, b: f64, d: f64| k(o) + k(a) * t + k(b) * s + k(d) * t * s;
                vec3(
                    c(f.p00.x, f.e_t.x, f.e_s.x, f.d.x),
                    c(f.p00.y, f.e_t.y, f.e_s.y, f.d.y),
                    c(f.p00.z, f.e_t.z, f.e_s.z, f.d.z),
                )
            }
        }
        let quad = Facet::bilinear(vec3(0.0, 0.0, 0.0), vec3(2.0, 0.0, 0.1), vec3(0.2, 1.0, 0.0), vec3(1.5, 1.0, 0.0));
        let tri = Facet::triangle(vec3(0.0, 0.0, 0.0), vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.5));
        for f in [quad, tri] {
            let auto = AutoNormal(Map(f));
            for (t, s) in [(0.1, 0.2), (0.5, 0.5), (0.9, 0.3)] {
                let (n, na) = (f.normal(t, s), auto.normal(t, s));
                assert!((n - na).norm() < 1e-14, "{n:?} vs {na:?}");
                assert!((f.point(t, s) - auto.point(t, s)).norm() < 1e-14);
            }
        }
    }

    #[test]
    fn tessellations_are_closed_and_outward() {
        for poly in [uv_sphere([0.0; 3], 1.0, 4, 8), icosphere([0.0; 3], 1.0, 2)] {
            // Closed surface: Σ of the Newell vectors vanishes; outward: each faces away.
            let mut sum = [0.0; 3];
            for f in &poly.facets {
                let n = newell(f);
                sum = [sum[0] + n[0], sum[1] + n[1], sum[2] + n[2]];
                assert!(dot(n, f[0]) > 0.0, "{}", poly.name);
            }
            assert!(dot(sum, sum).sqrt() < 1e-12, "{}: {sum:?}", poly.name);
            assert!(poly.area() < 4.0 * std::f64::consts::PI);
        }
        assert_eq!(icosphere([0.0; 3], 1.0, 3).len(), 1280);
        assert_eq!(uv_sphere([0.0; 3], 1.0, 8, 16).len(), 128);
        // Kernel surfaces radiate outwards and have the polygon's area.
        let poly = uv_sphere([0.0; 3], 1.0, 4, 8);
        for (f, s) in poly.facets.iter().zip(poly.surfaces::<f64>().unwrap()) {
            let patch = pdm_kernel::Patch::whole(&s).unwrap();
            assert!((patch.area(4).unwrap() - polygon_area(f)).abs() < 1e-14);
            assert!(s.normal(0.5, 0.5).dot(s.point(0.5, 0.5)) > 0.0);
        }
    }

    /// The clipped kernel sum agrees with the contour reference.
    #[test]
    fn clipped_kernel_sum_matches_contour() {
        let poly = icosphere([0.0; 3], 1.0, 0).rotated([0.0; 3], generic_rotation());
        let uv = uv_sphere([0.0; 3], 1.0, 3, 6).rotated([0.0; 3], generic_rotation());
        for p in [&poly, &uv] {
            for face in [1, 2, 5] {
                for cell in cube_face_cells(face, 3).iter().step_by(4) {
                    let exact = exact_polyhedron_to_face(p, cell);
                    let kernel = clipped_polyhedron_to_polygon(p, cell, 8, 16).unwrap();
                    assert!(((kernel - exact) / exact).abs() < 1e-10, "{}: {kernel} vs {exact}", p.name);
                }
            }
        }
    }

    /// The clipped exact factor is the solid-angle value for a facet fully facing the face, and
    /// the polyhedron's factor tends to 1/6 as the tessellation refines.
    #[test]
    fn exact_polyhedron_factor_converges_to_one_sixth() {
        let face = cube_face_polygon(6).unwrap();
        let cell = cube_face_cells(2, 3).swap_remove(4);
        let exact = sphere_to_polygon([0.0; 3], &cell);
        let mut last = f64::INFINITY;
        for level in 0..3 {
            let ico = icosphere([0.0; 3], 1.0, level).rotated([0.0; 3], generic_rotation());
            let e = (exact_polyhedron_to_face(&ico, &cell) - exact).abs() / exact;
            assert!(e < last, "level {level}: {e}");
            last = e;
        }
        assert!(last < 1e-2);
        // The face sums over the cube are 1 for any closed convex polyhedron.
        let poly = uv_sphere([0.0; 3], 1.0, 3, 5);
        let total: f64 = (1..=6).map(|k| exact_polyhedron_to_face(&poly, &cube_face_polygon(k).unwrap())).sum();
        assert!((total - 1.0).abs() < 1e-12, "{total}");
        // Whole faces see the unrotated icosphere exactly 1/6 by symmetry; rotated, not.
        let ico = icosphere([0.0; 3], 1.0, 1);
        assert!((exact_polyhedron_to_face(&ico, &face) - 1.0 / 6.0).abs() < 1e-14);
        let turned = ico.rotated([0.0; 3], generic_rotation());
        assert!((exact_polyhedron_to_face(&turned, &face) - 1.0 / 6.0).abs() > 1e-5);
        assert!((turned.area() - ico.area()).abs() < 1e-13);
        // Cells tile the face with its orientation.
        let cells = cube_face_cells(6, 3);
        assert_eq!(cells.len(), 9);
        let cell_sum: f64 = cells.iter().map(|c| sphere_to_polygon([0.0; 3], c)).sum();
        assert!((cell_sum - 1.0 / 6.0).abs() < 1e-15);
        // Sanity of the face polygon orientation: the sphere sees 1/6 of it.
        assert!((sphere_to_polygon([0.0; 3], &face) - 1.0 / 6.0).abs() < 1e-15);
    }
}
