//! From the file's model to the scene's geometry: placement, sides, pieces and patches, every
//! value checked with an error that names the surface and the field.

use std::path::Path;

use pdm_kernel::{vec3, Frame, ParamRect, Vec3};

use super::model::{fields_of, Kind, SceneFile, SideSpec, SurfaceSpec};
use super::shape::{Geom, Rect};

/// Most patches a scene may have: the matrices have patches² entries (12 000 patches: 1.2 GB
/// each in f64), and `pdm-ff matrix` also checks the memory a run needs against what the
/// machine has before it starts.
pub const MAX_PATCHES: usize = 12_000;
/// Most patches along one side of one piece.
pub const MAX_SUBDIVISION: usize = 1_000;

/// A surface of the scene: one radiating side of one named entry of the file.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneSurface {
    /// The name (`NAME/front`, `NAME/back`, `NAME/outer`, `NAME/inner` for the two sides of one
    /// entry).
    pub name: String,
    /// The kind.
    pub kind: Kind,
    /// Index of the file's entry: the two sides of one entry share it (one geometry, one
    /// occluder).
    pub entry: usize,
    /// The group within the entry (a mesh file's object; 0 otherwise): the two sides of one
    /// group are the two surfaces with the same entry and group.
    pub group: usize,
    /// Whether it blocks the view between other surfaces.
    pub occludes: bool,
    /// Its pieces: one kernel surface each (several for a Bézier net), with the parameter range
    /// used and the subdivision.
    pub pieces: Vec<Piece>,
}

/// One kernel surface of a scene surface.
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    /// The geometry.
    pub geom: Geom,
    /// The part of its parameter domain that belongs to the scene.
    pub rect: Rect,
    /// Patches along t and s.
    pub grid: (usize, usize),
}

/// A patch of the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScenePatch {
    /// Index into [`Scene::surfaces`].
    pub surface: usize,
    /// Index into that surface's pieces.
    pub piece: usize,
    /// Its cell (i, j) of the piece's grid.
    pub cell: (usize, usize),
    /// Its parameter rectangle.
    pub rect: Rect,
}

/// A scene ready to compute.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// The length unit.
    pub units: String,
    /// Whether the surfaces close an enclosure.
    pub enclosure: bool,
    /// The surfaces with rows and columns in the matrices (a two-sided entry gives two).
    pub surfaces: Vec<SceneSurface>,
    /// Surfaces that only block the view (`radiates = false`, View3D's obstruction surfaces):
    /// no patches, no rows.
    pub obstructions: Vec<SceneSurface>,
    /// All patches, surface by surface, piece by piece, row by row.
    pub patches: Vec<ScenePatch>,
}

impl Scene {
    /// Surface `k` of the surfaces followed by the obstructions.
    #[must_use]
    pub fn any_surface(&self, k: usize) -> &SceneSurface {
        self.surfaces.get(k).unwrap_or_else(|| &self.obstructions[k - self.surfaces.len()])
    }

    /// The surfaces followed by the obstructions (the occluders' owners).
    pub fn all_surfaces(&self) -> impl Iterator<Item = &SceneSurface> {
        self.surfaces.iter().chain(&self.obstructions)
    }

    /// The geometry of a patch.
    #[must_use]
    pub fn geom(&self, p: &ScenePatch) -> &Geom {
        &self.surfaces[p.surface].pieces[p.piece].geom
    }
}

/// A semantic error in one surface entry: which entry, which field, what is wrong.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EntryError {
    /// Index of the entry in the file.
    pub entry: usize,
    /// Its name, if it has one.
    pub name: String,
    /// The field at fault (empty for the entry as a whole).
    pub field: String,
    /// What is wrong.
    pub message: String,
}

fn fail<T>(i: usize, spec: &SurfaceSpec, field: &str, message: impl Into<String>) -> Result<T, EntryError> {
    Err(EntryError { entry: i, name: spec.name.clone(), field: field.to_string(), message: message.into() })
}

fn finite3(v: [f64; 3]) -> bool {
    v.iter().all(|x| x.is_finite())
}

fn v3(v: [f64; 3]) -> Vec3<f64> {
    vec3(v[0], v[1], v[2])
}

/// Rodrigues' rotation about a unit axis k by angle a.
fn rotate(v: Vec3<f64>, k: Vec3<f64>, a: f64) -> Vec3<f64> {
    let (s, c) = a.sin_cos();
    v.scale(c) + k.cross(v).scale(s) + k.scale(k.dot(v) * (1.0 - c))
}

/// Placement: rotation about the origin, then translation.
struct Place {
    axis: Vec3<f64>,
    angle: f64,
    shift: Vec3<f64>,
}

impl Place {
    fn vector(&self, v: Vec3<f64>) -> Vec3<f64> {
        if self.angle == 0.0 {
            v
        } else {
            rotate(v, self.axis, self.angle)
        }
    }
    fn point(&self, p: Vec3<f64>) -> Vec3<f64> {
        self.vector(p) + self.shift
    }
}

/// Reads a required vector field.
fn vector(i: usize, spec: &SurfaceSpec, name: &str, value: Option<[f64; 3]>) -> Result<Vec3<f64>, EntryError> {
    match value {
        None => fail(i, spec, name, format!("missing (kind {} needs it)", spec.kind.name())),
        Some(v) if !finite3(v) => fail(i, spec, name, format!("{v:?} is not finite")),
        Some(v) => Ok(v3(v)),
    }
}

/// Reads a required positive length.
fn positive(i: usize, spec: &SurfaceSpec, name: &str, value: Option<f64>) -> Result<f64, EntryError> {
    match value {
        None => fail(i, spec, name, format!("missing (kind {} needs it)", spec.kind.name())),
        Some(x) if !(x.is_finite() && x > 0.0) => fail(i, spec, name, format!("{x} must be positive and finite")),
        // The radius of a sphere or disk, whose square (an area) is 0 or infinite in f64.
        Some(x) if matches!(spec.kind, Kind::Sphere | Kind::Disk) && !(x * x > 0.0 && (x * x).is_finite()) => fail(
            i,
            spec,
            name,
            format!("{x:e} is out of range: its square, an area, is not a finite non-zero f64 (use other units)"),
        ),
        Some(x) => Ok(x),
    }
}

/// A non-zero direction.
fn direction(i: usize, spec: &SurfaceSpec, name: &str, v: Vec3<f64>) -> Result<Frame<f64>, EntryError> {
    match Frame::from_axis(v) {
        Ok(f) => Frame::from_axis(f.axis).or_else(|_| fail(i, spec, name, "is a zero vector")),
        Err(_) => fail(i, spec, name, format!("[{}, {}, {}] is a zero vector", v.x, v.y, v.z)),
    }
}

/// An angle range in degrees within [0, limit], as radians.
fn angles(
    i: usize,
    spec: &SurfaceSpec,
    name: &str,
    value: Option<[f64; 2]>,
    limit: f64,
) -> Result<(f64, f64), EntryError> {
    let [a, b] = value.unwrap_or([0.0, limit]);
    if !(a.is_finite() && b.is_finite() && a >= 0.0 && b <= limit && a < b) {
        return fail(i, spec, name, format!("[{a}, {b}] must satisfy 0 <= from < to <= {limit} (degrees)"));
    }
    // The whole range exactly (the kernel recognises closed surfaces by their domain).
    let radians = |x: f64| {
        if x == 180.0 {
            core::f64::consts::PI
        } else if x == 360.0 {
            2.0 * core::f64::consts::PI
        } else {
            x.to_radians()
        }
    };
    Ok((radians(a), radians(b)))
}

/// The frame with the placement applied to all three vectors (θ = 0 along the rotated u).
fn placed_frame(frame: Frame<f64>, place: &Place) -> Frame<f64> {
    Frame { u: place.vector(frame.u), w: place.vector(frame.w), axis: place.vector(frame.axis) }
}

/// The geometry of one side of an entry: `back` (sheets) or `inner` (closed kinds) flips it.
fn geometry(i: usize, spec: &SurfaceSpec, flip: bool, place: &Place, base: &Path) -> Result<Groups, EntryError> {
    let (required, optional) = fields_of(spec.kind);
    for field in spec.geometry_fields() {
        if !required.contains(&field) && !optional.contains(&field) {
            return fail(i, spec, field, format!("does not belong to kind {}", spec.kind.name()));
        }
    }
    let full = |g: Geom| Ok(vec![(String::new(), true, vec![(g, g.domain())])]);
    match spec.kind {
        Kind::Rectangle => {
            let origin = place.point(vector(i, spec, "origin", spec.origin)?);
            let edge_t = place.vector(vector(i, spec, "edge_t", spec.edge_t)?);
            let edge_s = place.vector(vector(i, spec, "edge_s", spec.edge_s)?);
            for (name, edge) in [("edge_t", edge_t), ("edge_s", edge_s)] {
                if !(edge.norm() > 0.0) {
                    return fail(i, spec, name, "is zero (or too small to square): zero area");
                }
            }
            let area = edge_t.cross(edge_s).norm();
            if !(area.is_finite()) {
                return fail(i, spec, "edge_s", "with edge_t spans an area too large to represent");
            }
            if !(area > 1e-12 * edge_t.norm() * edge_s.norm()) {
                return fail(i, spec, "edge_s", "is parallel to edge_t: zero area");
            }
            let (edge_t, edge_s) = if flip { (edge_s, edge_t) } else { (edge_t, edge_s) };
            full(Geom::Parallelogram { origin, edge_t, edge_s })
        }
        Kind::Disk => {
            let center = place.point(vector(i, spec, "center", spec.center)?);
            let normal = vector(i, spec, "normal", spec.normal)?;
            let outer = positive(i, spec, "radius", spec.radius)?;
            let inner = spec.inner_radius.unwrap_or(0.0);
            if !(inner.is_finite() && inner >= 0.0 && inner < outer) {
                return fail(i, spec, "inner_radius", format!("{inner} must satisfy 0 <= inner_radius < radius"));
            }
            let axis = place.vector(normal);
            let frame = direction(i, spec, "normal", if flip { -axis } else { axis })?;
            let (a, b) = angles(i, spec, "theta", spec.theta, 360.0)?;
            let g = Geom::Disk { center, frame, inner, outer };
            Ok(vec![(String::new(), true, vec![(g, ParamRect { t0: inner, t1: outer, s0: a, s1: b })])])
        }
        Kind::Sphere => {
            let center = place.point(vector(i, spec, "center", spec.center)?);
            let radius = positive(i, spec, "radius", spec.radius)?;
            let axis = match spec.axis {
                Some(v) if !finite3(v) => return fail(i, spec, "axis", format!("{v:?} is not finite")),
                Some(v) => v3(v),
                None => vec3(0.0, 0.0, 1.0),
            };
            let frame = placed_frame(direction(i, spec, "axis", axis)?, place);
            let (p0, p1) = angles(i, spec, "phi", spec.phi, 180.0)?;
            let (a, b) = angles(i, spec, "theta", spec.theta, 360.0)?;
            let g = Geom::Sphere { center, radius, frame, inner: flip };
            Ok(vec![(String::new(), true, vec![(g, ParamRect { t0: p0, t1: p1, s0: a, s1: b })])])
        }
        Kind::Cylinder | Kind::Cone => {
            let base = place.point(vector(i, spec, "base", spec.base)?);
            let axis = place.vector(vector(i, spec, "axis", spec.axis)?);
            let frame = direction(i, spec, "axis", axis)?;
            let height = positive(i, spec, "height", spec.height)?;
            let (a, b) = angles(i, spec, "theta", spec.theta, 360.0)?;
            let g = if spec.kind == Kind::Cylinder {
                let radius = positive(i, spec, "radius", spec.radius)?;
                Geom::Cylinder { base, frame, radius, height, inner: flip }
            } else {
                let r = |name: &str, v: Option<f64>| match v {
                    None => fail(i, spec, name, "missing (kind cone needs it)"),
                    Some(x) if !(x.is_finite() && x >= 0.0) => {
                        fail(i, spec, name, format!("{x} must be non-negative and finite"))
                    }
                    Some(x) => Ok(x),
                };
                let (base_radius, top_radius) =
                    (r("base_radius", spec.base_radius)?, r("top_radius", spec.top_radius)?);
                if base_radius + top_radius <= 0.0 {
                    return fail(i, spec, "top_radius", "base_radius and top_radius are both zero");
                }
                Geom::Cone { base, frame, base_radius, top_radius, height, inner: flip }
            };
            Ok(vec![(String::new(), true, vec![(g, ParamRect { t0: a, t1: b, s0: 0.0, s1: height })])])
        }
        Kind::Triangle | Kind::Quadrilateral => {
            let count = if spec.kind == Kind::Triangle { 3 } else { 4 };
            let Some(points) = &spec.vertices else {
                return fail(i, spec, "vertices", format!("missing (kind {} needs it)", spec.kind.name()));
            };
            if points.len() != count {
                return fail(i, spec, "vertices", format!("must be {count} points, got {}", points.len()));
            }
            if let Some(k) = points.iter().position(|p| !finite3(*p)) {
                return fail(i, spec, "vertices", format!("point [{k}] is not finite"));
            }
            let v: Vec<Vec3<f64>> = points.iter().map(|p| place.point(v3(*p))).collect();
            let corners = if let [a, b, c] = v[..] { [a, b, c, a] } else { [v[0], v[1], v[2], v[3]] };
            if let Err(problem) = super::mesh::check_polygon(&corners) {
                return fail(i, spec, "vertices", problem);
            }
            full(Geom::Quadrilateral { corners: if flip { reversed(corners) } else { corners } })
        }
        Kind::Bezier => {
            let Some(net) = &spec.control else { return fail(i, spec, "control", "missing (kind bezier needs it)") };
            let rows = net.len();
            let cols = net.first().map_or(0, Vec::len);
            if rows < 4 || (rows - 1) % 3 != 0 || cols < 4 || (cols - 1) % 3 != 0 || net.iter().any(|r| r.len() != cols)
            {
                return fail(
                    i,
                    spec,
                    "control",
                    format!("must be (3m + 1) rows of (3n + 1) points each (m, n >= 1), got {rows} rows of {cols}"),
                );
            }
            if let Some((r, c)) =
                net.iter().enumerate().find_map(|(r, row)| row.iter().position(|p| !finite3(*p)).map(|c| (r, c)))
            {
                return fail(i, spec, "control", format!("point [{r}][{c}] is not finite"));
            }
            let mut out = Vec::new();
            for pi in 0..(rows - 1) / 3 {
                for pj in 0..(cols - 1) / 3 {
                    let mut control = [[vec3(0.0, 0.0, 0.0); 4]; 4];
                    for (a, row) in control.iter_mut().enumerate() {
                        for (b, p) in row.iter_mut().enumerate() {
                            // Flipped: transposed (t and s swap, the normal turns over).
                            let (r, c) = if flip { (3 * pi + b, 3 * pj + a) } else { (3 * pi + a, 3 * pj + b) };
                            *p = place.point(v3(net[r][c]));
                        }
                    }
                    let g = Geom::Bezier { control };
                    out.push((g, g.domain()));
                }
            }
            let nets: Vec<Geom> = out.iter().map(|(g, _)| *g).collect();
            if let Some(problem) = super::fold::bezier_problem(&nets) {
                return fail(i, spec, "control", format!("the net {problem}"));
            }
            Ok(vec![(String::new(), true, out)])
        }
        Kind::Mesh => {
            let Some(name) = &spec.file else { return fail(i, spec, "file", "missing (kind mesh needs it)") };
            let path = base.join(name);
            let groups = match super::mesh::load(&path) {
                Ok(g) if g.is_empty() => return fail(i, spec, "file", format!("{}: has no facets", path.display())),
                Ok(g) => g,
                Err(e) => return fail(i, spec, "file", e),
            };
            let several = groups.len() > 1;
            let prefixed = spec.prefix.unwrap_or(true);
            let mut out = Vec::new();
            for super::mesh::Group { name: group, faces: polygons, radiates } in groups {
                let mut pieces = Vec::new();
                for (k, polygon) in polygons.iter().enumerate() {
                    if polygon.iter().any(|p| !p.is_finite()) {
                        return fail(
                            i,
                            spec,
                            "file",
                            format!("{}: face {} has a non-finite vertex", path.display(), k + 1),
                        );
                    }
                    if polygon.len() < 3 {
                        return fail(
                            i,
                            spec,
                            "file",
                            format!("{}: face {} has {} vertices", path.display(), k + 1, polygon.len()),
                        );
                    }
                    let placed: Vec<_> = polygon.iter().map(|p| place.point(*p)).collect();
                    for corners in super::mesh::facets(&placed) {
                        if let Err(problem) = super::mesh::check_polygon(&corners) {
                            return fail(
                                i,
                                spec,
                                "file",
                                format!("{}: face {} ({group}): {problem}", path.display(), k + 1),
                            );
                        }
                        let g = Geom::Quadrilateral { corners: if flip { reversed(corners) } else { corners } };
                        pieces.push((g, g.domain()));
                    }
                }
                let name = match (prefixed, several) {
                    (true, true) => format!("/{group}"),
                    (true, false) => String::new(),
                    (false, _) => group,
                };
                out.push((name, radiates, pieces));
            }
            Ok(out)
        }
    }
}

/// The same quadrilateral radiating to the other side: P₀ kept, the others reversed, which
/// transposes its map (t and s swap).
fn reversed([p0, p1, p2, p3]: [Vec3<f64>; 4]) -> [Vec3<f64>; 4] {
    [p0, p3, p2, p1]
}

/// Pieces of one entry's side by group (a mesh file's objects; one unnamed group otherwise):
/// the name's suffix (or the whole name, for a mesh with `prefix = false`), whether the group
/// radiates (a View3D obstruction does not), the pieces.
type Groups = Vec<(String, bool, Vec<(Geom, Rect)>)>;

/// Arc length of the parameter line through the middle of `rect` along t (`along_t`) or s.
fn mid_length(geom: &Geom, rect: Rect, along_t: bool) -> f64 {
    let Ok(shape) = geom.shape::<f64>() else { return 0.0 };
    use pdm_kernel::Surface as _;
    const SEGMENTS: usize = 64;
    let (tm, sm) = ((rect.t0 + rect.t1) / 2.0, (rect.s0 + rect.s1) / 2.0);
    let at = |x: f64| {
        if along_t {
            shape.point(rect.t0 + (rect.t1 - rect.t0) * x, sm)
        } else {
            shape.point(tm, rect.s0 + (rect.s1 - rect.s0) * x)
        }
    };
    (0..SEGMENTS).map(|k| (at((k + 1) as f64 / SEGMENTS as f64) - at(k as f64 / SEGMENTS as f64)).norm()).sum()
}

/// Builds the scene: checks every entry, places it, splits two-sided entries, subdivides; mesh
/// files are looked up in the current folder.
pub fn build(file: &SceneFile) -> Result<Scene, EntryError> {
    build_in(file, Path::new("."))
}

/// [`build`], with mesh files looked up relative to `base` (the scene file's folder).
pub fn build_in(file: &SceneFile, base: &Path) -> Result<Scene, EntryError> {
    if file.surfaces.is_empty() {
        return Err(EntryError {
            entry: 0,
            name: String::new(),
            field: "surface".into(),
            message: "the scene has no surfaces".into(),
        });
    }
    let mut surfaces = Vec::new();
    let mut obstructions = Vec::new();
    for (i, spec) in file.surfaces.iter().enumerate() {
        if spec.name.trim().is_empty() {
            return fail(i, spec, "name", "is empty");
        }
        if let Some(j) = file.surfaces[..i].iter().position(|s| s.name == spec.name) {
            return fail(i, spec, "name", format!("is already used by surface #{}", j + 1));
        }
        let place = match (spec.rotate, spec.translate) {
            (Some(r), _) if !(finite3(r.axis) && r.degrees.is_finite()) => {
                return fail(i, spec, "rotate", "axis and degrees must be finite")
            }
            (Some(r), _) if v3(r.axis).norm() == 0.0 => return fail(i, spec, "rotate.axis", "is a zero vector"),
            (_, Some(t)) if !finite3(t) => return fail(i, spec, "translate", format!("{t:?} is not finite")),
            (r, t) => Place {
                axis: r.map_or(vec3(0.0, 0.0, 1.0), |r| v3(r.axis).scale(1.0 / v3(r.axis).norm())),
                angle: r.map_or(0.0, |r| r.degrees.to_radians()),
                shift: t.map_or(vec3(0.0, 0.0, 0.0), v3),
            },
        };
        let closed = spec.kind.closed();
        let sides: Vec<(bool, &str)> = match (spec.side, closed) {
            (None | Some(SideSpec::Front), false) => vec![(false, "")],
            (Some(SideSpec::Back), false) => vec![(true, "")],
            (None | Some(SideSpec::Outer), true) => vec![(false, "")],
            (Some(SideSpec::Inner), true) => vec![(true, "")],
            (Some(SideSpec::Both), false) => vec![(false, "/front"), (true, "/back")],
            (Some(SideSpec::Both), true) => vec![(false, "/outer"), (true, "/inner")],
            (Some(other), _) => {
                let allowed = if closed { "outer, inner or both" } else { "front, back or both" };
                return fail(
                    i,
                    spec,
                    "side",
                    format!("{other:?} is not a side of kind {} ({allowed})", spec.kind.name()),
                );
            }
        };
        if spec.subdivide.is_some() && spec.patch_size.is_some() {
            return fail(i, spec, "patch_size", "give either subdivide or patch_size, not both");
        }
        if let Some([m, n]) = spec.subdivide {
            if !(1..=MAX_SUBDIVISION).contains(&m) || !(1..=MAX_SUBDIVISION).contains(&n) {
                return fail(i, spec, "subdivide", format!("[{m}, {n}] must lie in 1..={MAX_SUBDIVISION}"));
            }
        }
        if spec.prefix.is_some() && spec.kind != Kind::Mesh {
            return fail(i, spec, "prefix", format!("applies to kind mesh only, not {}", spec.kind.name()));
        }
        if let Some(size) = spec.patch_size {
            if !(size.is_finite() && size > 0.0) {
                return fail(i, spec, "patch_size", format!("{size} must be positive and finite"));
            }
        }
        for (flip, suffix) in sides {
            for (group, (group_name, group_radiates, list)) in
                geometry(i, spec, flip, &place, base)?.into_iter().enumerate()
            {
                let mut pieces = Vec::new();
                for (geom, rect) in list {
                    let grid =
                        match (spec.subdivide, spec.patch_size) {
                            // A flipped Bézier net or facet is transposed: its grid too, so that its
                            // cells are the front's.
                            (Some([m, n]), _) if flip && spec.kind.flips_by_transpose() => (n, m),
                            (Some([m, n]), _) => (m, n),
                            (None, Some(size)) => {
                                let count = |along_t| (mid_length(&geom, rect, along_t) / size).ceil().max(1.0);
                                let (m, n) = (count(true), count(false));
                                if m > MAX_SUBDIVISION as f64 || n > MAX_SUBDIVISION as f64 {
                                    return fail(
                                i,
                                spec,
                                "patch_size",
                                format!("{size} gives {m} x {n} patches per piece, more than {MAX_SUBDIVISION} a side"),
                            );
                                }
                                (m as usize, n as usize)
                            }
                            (None, None) => (1, 1),
                        };
                    // The kernel's own checks (a zero-area Bézier net is found when sampled).
                    if let Err(e) = geom.shape::<f64>() {
                        return fail(i, spec, "", format!("the kernel rejects the geometry: {e}"));
                    }
                    pieces.push(Piece { geom, rect, grid });
                }
                let occludes = spec.occludes.unwrap_or(true);
                let radiates = group_radiates && spec.radiates.unwrap_or(true);
                if !radiates && !occludes {
                    return fail(
                        i,
                        spec,
                        "radiates",
                        "is false and so is occludes: the surface would do nothing (an obstruction must occlude)",
                    );
                }
                let name = if spec.kind == Kind::Mesh && !spec.prefix.unwrap_or(true) {
                    format!("{group_name}{suffix}")
                } else {
                    format!("{}{group_name}{suffix}", spec.name)
                };
                if let Some(other) = surfaces.iter().chain(&obstructions).find(|s: &&SceneSurface| s.name == name) {
                    return fail(
                        i,
                        spec,
                        "name",
                        format!("gives the surface name `{name}`, which surface #{} already has", other.entry + 1),
                    );
                }
                let list = if radiates { &mut surfaces } else { &mut obstructions };
                list.push(SceneSurface { name, kind: spec.kind, entry: i, group, occludes, pieces });
            }
        }
    }
    let mut patches = Vec::new();
    for (si, s) in surfaces.iter().enumerate() {
        for (pi, piece) in s.pieces.iter().enumerate() {
            let (m, n) = piece.grid;
            for a in 0..m {
                for b in 0..n {
                    patches.push(ScenePatch {
                        surface: si,
                        piece: pi,
                        cell: (a, b),
                        rect: piece.rect.cell(a, b, m, n),
                    });
                }
            }
            if patches.len() > MAX_PATCHES {
                let spec = &file.surfaces[s.entry];
                return fail(
                    s.entry,
                    spec,
                    "subdivide",
                    format!("the scene would have more than {MAX_PATCHES} patches"),
                );
            }
        }
    }
    if surfaces.is_empty() {
        return Err(EntryError {
            entry: 0,
            name: String::new(),
            field: "surface".into(),
            message: "the scene has no radiating surfaces (only obstructions)".into(),
        });
    }
    Ok(Scene { units: file.units.clone(), enclosure: file.enclosure, surfaces, obstructions, patches })
}

impl Scene {
    /// The same scene moved so that its bounding box is centred on the origin. Form factors do
    /// not depend on where a scene lies, but the kernel computes every point at the magnitude
    /// of its coordinates: in f32 a 1 cm patch 10 m from the origin has its corners 1e-4 of
    /// its size off. `pdm-ff matrix` computes on the centred copy in f32, where the move (in
    /// f64) costs nothing against f32's resolution; not in f64, where the move itself would
    /// round at the old magnitude, by as much as the kernel does, and part surfaces that
    /// shared an edge to the last bit. Centred, the coordinates are at most half the scene's
    /// extent; a small part far from the rest still carries that extent, and the kernel's
    /// estimates allow for it (`adaptive_exchange`).
    #[must_use]
    pub fn centred(&self) -> Self {
        let origin = vec3(0.0, 0.0, 0.0);
        let (mut lo, mut hi) = ([f64::MAX; 3], [-f64::MAX; 3]);
        for piece in self.surfaces.iter().chain(&self.obstructions).flat_map(|s| &s.pieces) {
            for (k, normal) in [vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0), vec3(0.0, 0.0, 1.0)].into_iter().enumerate() {
                let (a, b) = piece.geom.distance_range(piece.rect, &super::shape::Plane { origin, normal });
                lo[k] = lo[k].min(a);
                hi[k] = hi[k].max(b);
            }
        }
        let centre = vec3((lo[0] + hi[0]) * 0.5, (lo[1] + hi[1]) * 0.5, (lo[2] + hi[2]) * 0.5);
        let mut moved = self.clone();
        if centre.x.is_finite() && centre.y.is_finite() && centre.z.is_finite() {
            let shift = vec3(-centre.x, -centre.y, -centre.z);
            for piece in moved.surfaces.iter_mut().chain(moved.obstructions.iter_mut()).flat_map(|s| &mut s.pieces) {
                piece.geom = piece.geom.translated(shift);
            }
        }
        moved
    }
}
