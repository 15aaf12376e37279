//! The scene file's data model: one serde model read from TOML (for people) or JSON (for
//! programs). Every field is described in `SCENES.md`; unknown fields are errors.

use serde::{Deserialize, Serialize};

/// A scene: named surfaces, each cut into patches.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Length unit of every coordinate (a label: form factors are dimensionless, areas are in
    /// unit²). Default `"m"`.
    #[serde(default = "default_units")]
    pub units: String,
    /// `true` if the surfaces close an enclosure: every row of the surface matrix must then
    /// sum to 1 within its error estimate, and rows that do not are reported as modelling
    /// gaps (leaks, overlaps, mis-oriented surfaces). Default `false`.
    #[serde(default)]
    pub enclosure: bool,
    /// The surfaces (TOML: `[[surface]]` tables).
    #[serde(default, rename = "surface")]
    pub surfaces: Vec<SurfaceSpec>,
}

fn default_units() -> String {
    "m".to_string()
}

/// The kinds of surface.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// A parallelogram `origin + t·edge_t + s·edge_s`, t, s ∈ [0, 1]; a rectangle when the edges
    /// are perpendicular.
    #[serde(alias = "parallelogram")]
    Rectangle,
    /// A disk, annulus (`inner_radius`) or sector (`theta`) in the plane through `center` normal
    /// to `normal`.
    Disk,
    /// A sphere, or a zone (`phi`) or lune (`theta`) of one.
    Sphere,
    /// An open circular tube (`theta` for part of it).
    Cylinder,
    /// A cone or conical frustum (`theta` for part of it).
    Cone,
    /// A flat triangle, `vertices` A, B, C.
    Triangle,
    /// A flat convex quadrilateral, `vertices` P₀ … P₃ in order around it.
    Quadrilateral,
    /// Bicubic Bézier patches: a (3m + 1) × (3n + 1) control net, m × n patches sharing edges.
    Bezier,
    /// Flat facets from a mesh file (OBJ or STL), one surface per OBJ object or group.
    Mesh,
}

impl Kind {
    /// The name used in the file.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Rectangle => "rectangle",
            Self::Disk => "disk",
            Self::Sphere => "sphere",
            Self::Cylinder => "cylinder",
            Self::Cone => "cone",
            Self::Triangle => "triangle",
            Self::Quadrilateral => "quadrilateral",
            Self::Bezier => "bezier",
            Self::Mesh => "mesh",
        }
    }

    /// Whether the other side of an entry is its map with t and s swapped (Bézier nets, facets),
    /// so that a `subdivide` grid is transposed with it.
    #[must_use]
    pub fn flips_by_transpose(self) -> bool {
        matches!(self, Self::Bezier | Self::Mesh | Self::Triangle | Self::Quadrilateral)
    }

    /// Whether the surface bounds a solid (sphere, tube, cone): its sides are `outer` and
    /// `inner`; the others are open sheets with `front` and `back`.
    #[must_use]
    pub fn closed(self) -> bool {
        matches!(self, Self::Sphere | Self::Cylinder | Self::Cone)
    }
}

/// The side a surface radiates from.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum SideSpec {
    /// Sheets: the side the normal points to (rectangle: edge_t × edge_s; disk: `normal`;
    /// triangle, quadrilateral, mesh facet: counter-clockwise vertices; Bézier: ∂g/∂t × ∂g/∂s).
    Front,
    /// Sheets: the other side.
    Back,
    /// Closed kinds: the convex side.
    Outer,
    /// Closed kinds: the concave side.
    Inner,
    /// Both sides, as two surfaces named `NAME/front` and `NAME/back` (sheets) or
    /// `NAME/outer` and `NAME/inner` (closed kinds): a thin plate or shell.
    Both,
}

/// A rotation about an axis through the origin, applied before `translate`.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Rotation {
    /// The axis (any length > 0).
    pub axis: [f64; 3],
    /// The angle in degrees, counter-clockwise looking down the axis.
    pub degrees: f64,
}

/// One named surface. Which geometry fields a kind takes is listed in `SCENES.md`; a field that
/// the kind does not take is an error.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SurfaceSpec {
    /// Unique name (rows and columns of the matrices are named by it).
    pub name: String,
    /// The kind of surface.
    pub kind: Kind,
    /// The radiating side. Default `front` (sheets) or `outer` (closed kinds).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub side: Option<SideSpec>,
    /// Patches along (t, s): `[m, n]`. Default `[1, 1]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub subdivide: Option<[usize; 2]>,
    /// Alternative to `subdivide`: the largest patch side, in `units` (measured along the
    /// parameter lines through the middle of each piece).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub patch_size: Option<f64>,
    /// Whether the surface blocks the view between other surfaces. Default `true`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub occludes: Option<bool>,
    /// Whether the surface has rows and columns in the matrices. `false`: it only blocks the
    /// view (an obstruction, View3D's `O` surface; it must occlude). Default `true`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radiates: Option<bool>,
    /// Mesh: name each surface made from the file's groups `NAME/GROUP` (`true`, the default)
    /// or `GROUP` alone (`false`, as `pdm-ff matrix FILE.vs3` does).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prefix: Option<bool>,
    /// Rotation about the origin, applied to the geometry before `translate`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotate: Option<Rotation>,
    /// Translation applied last.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub translate: Option<[f64; 3]>,

    /// Rectangle: the corner at t = s = 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub origin: Option<[f64; 3]>,
    /// Rectangle: the edge along t.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub edge_t: Option<[f64; 3]>,
    /// Rectangle: the edge along s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub edge_s: Option<[f64; 3]>,
    /// Disk, sphere: the centre.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub center: Option<[f64; 3]>,
    /// Disk: the normal (the front side's direction).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<[f64; 3]>,
    /// Sphere (pole direction, default z), cylinder and cone (from the base upwards): the axis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<[f64; 3]>,
    /// Cylinder, cone: the centre of the base circle.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base: Option<[f64; 3]>,
    /// Disk (outer), sphere, cylinder: the radius.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// Disk: the inner radius of an annulus. Default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inner_radius: Option<f64>,
    /// Cone: the radius at the base.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_radius: Option<f64>,
    /// Cone: the radius at the top (0: the apex).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub top_radius: Option<f64>,
    /// Cylinder, cone: the height along the axis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height: Option<f64>,
    /// Disk, sphere, cylinder, cone: the range of the angle around the axis, in degrees
    /// (`[from, to]`, 0 ≤ from < to ≤ 360). Default the whole turn.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub theta: Option<[f64; 2]>,
    /// Sphere: the range of the polar angle from the axis, in degrees (0 ≤ from < to ≤ 180).
    /// Default `[0, 180]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phi: Option<[f64; 2]>,
    /// Triangle (3 points), quadrilateral (4 points, convex, in one plane): the corners in
    /// order; the front side is the one they turn counter-clockwise around.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vertices: Option<Vec<[f64; 3]>>,
    /// Bézier: the control net, (3m + 1) rows along t of (3n + 1) points along s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub control: Option<Vec<Vec<[f64; 3]>>>,
    /// Mesh: the OBJ or STL file, relative to the scene file's folder. Facets radiate to the
    /// side their vertex order turns counter-clockwise around (`front`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
}

impl SurfaceSpec {
    /// The geometry fields that are set, by name (to reject those a kind does not take).
    #[must_use]
    pub fn geometry_fields(&self) -> Vec<&'static str> {
        let mut set = Vec::new();
        let mut check = |present: bool, name: &'static str| {
            if present {
                set.push(name);
            }
        };
        check(self.origin.is_some(), "origin");
        check(self.edge_t.is_some(), "edge_t");
        check(self.edge_s.is_some(), "edge_s");
        check(self.center.is_some(), "center");
        check(self.normal.is_some(), "normal");
        check(self.axis.is_some(), "axis");
        check(self.base.is_some(), "base");
        check(self.radius.is_some(), "radius");
        check(self.inner_radius.is_some(), "inner_radius");
        check(self.base_radius.is_some(), "base_radius");
        check(self.top_radius.is_some(), "top_radius");
        check(self.height.is_some(), "height");
        check(self.theta.is_some(), "theta");
        check(self.phi.is_some(), "phi");
        check(self.vertices.is_some(), "vertices");
        check(self.control.is_some(), "control");
        check(self.file.is_some(), "file");
        set
    }
}

/// The geometry fields each kind takes (required ones first; see `SCENES.md`).
#[must_use]
pub fn fields_of(kind: Kind) -> (&'static [&'static str], &'static [&'static str]) {
    match kind {
        Kind::Rectangle => (&["origin", "edge_t", "edge_s"], &[]),
        Kind::Disk => (&["center", "normal", "radius"], &["inner_radius", "theta"]),
        Kind::Sphere => (&["center", "radius"], &["axis", "phi", "theta"]),
        Kind::Cylinder => (&["base", "axis", "radius", "height"], &["theta"]),
        Kind::Cone => (&["base", "axis", "base_radius", "top_radius", "height"], &["theta"]),
        Kind::Triangle | Kind::Quadrilateral => (&["vertices"], &[]),
        Kind::Bezier => (&["control"], &[]),
        Kind::Mesh => (&["file"], &[]),
    }
}
