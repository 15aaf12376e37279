//! Flat facets from mesh files: OBJ (`tobj`, in f64, one group per OBJ object or group), STL
//! (`stl_io`, ASCII or binary, one group) and View3D input files (`.vs3`, [`super::vs3`], one
//! group per output surface). A flat convex quadrilateral face stays one facet,
//! the kernel's `Quadrilateral`; any other face is cut into triangles, each triangle A B C
//! the `Quadrilateral` A B C A, g(t, s) = A + t·(B − A + s·(C − B)), whose normal
//! t·(B − A) × (C − A) points to the side the vertices turn counter-clockwise around: a flat
//! facet with straight edges, so facet pairs that see each other wholly take the contour form
//! in closed form, and an exact occluder.

use std::path::Path;

use pdm_kernel::{vec3, Vec3};

/// A facet: the corners of a flat convex quadrilateral, a triangle repeating its first.
pub type Facet = [Vec3<f64>; 4];

/// The OBJ faces of a model as polygons (their vertex lists, in order).
fn obj_polygons(path: &Path, model: &tobj::Model) -> Result<Vec<Vec<Vec3<f64>>>, String> {
    let p = &model.mesh.positions;
    let vertex = |k: u32| -> Result<Vec3<f64>, String> {
        let k = k as usize * 3;
        match (p.get(k), p.get(k + 1), p.get(k + 2)) {
            (Some(&x), Some(&y), Some(&z)) => Ok(vec3(x, y, z)),
            _ => Err(format!("{}: object {}: a face refers to a missing vertex", path.display(), model.name)),
        }
    };
    let indices = &model.mesh.indices;
    // No arities: every face is a triangle.
    let arities: Vec<usize> = if model.mesh.face_arities.is_empty() {
        vec![3; indices.len() / 3]
    } else {
        model.mesh.face_arities.iter().map(|&a| a as usize).collect()
    };
    let mut polygons = Vec::with_capacity(arities.len());
    let mut start = 0usize;
    for arity in arities {
        let face = indices
            .get(start..start + arity)
            .ok_or_else(|| format!("{}: object {}: a face refers to a missing vertex", path.display(), model.name))?;
        polygons.push(face.iter().map(|&k| vertex(k)).collect::<Result<Vec<_>, _>>()?);
        start += arity;
    }
    Ok(polygons)
}

/// A face as facets: a flat convex quadrilateral stays one (a parallelogram then has an affine
/// map, which the kernel's occluded paths use); any other polygon is cut into the fan of
/// triangles from its first vertex (as OBJ readers triangulate).
#[must_use]
pub fn facets(polygon: &[Vec3<f64>]) -> Vec<Facet> {
    if let [a, b, c, d] = *polygon {
        if check_polygon(&[a, b, c, d]).is_ok() {
            return vec![[a, b, c, d]];
        }
    }
    match polygon.split_first() {
        Some((&a, rest)) => rest.windows(2).map(|w| [a, w[0], w[1], a]).collect(),
        None => Vec::new(),
    }
}

/// A group of a mesh file's faces: one surface of the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Group {
    /// The OBJ object or group, the View3D surface; empty for an STL file.
    pub name: String,
    /// Each face's vertices in order.
    pub faces: Vec<Vec<Vec3<f64>>>,
    /// `false` for a View3D obstruction surface (`O`): it blocks the view and has no row.
    pub radiates: bool,
}

/// A mesh file's faces by group.
pub type Groups = Vec<Group>;

/// The faces of a mesh file by group, as given (see [`facets`] for what they become).
pub fn load(path: &Path) -> Result<Groups, String> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("obj") => {
            let options = tobj::LoadOptions { triangulate: false, single_index: true, ..Default::default() };
            let (models, _) = tobj::load_obj(path, &options).map_err(|e| format!("{}: {e}", path.display()))?;
            let mut groups = Vec::new();
            for model in models {
                let polygons = obj_polygons(path, &model)?;
                if !polygons.is_empty() {
                    groups.push(Group { name: model.name.clone(), faces: polygons, radiates: true });
                }
            }
            Ok(groups)
        }
        Some("stl") => {
            let mut file = std::fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
            let mesh = stl_io::read_stl(&mut file).map_err(|e| format!("{}: not an STL file: {e}", path.display()))?;
            let v = |k: usize| -> Result<Vec3<f64>, String> {
                mesh.vertices
                    .get(k)
                    .map(|p| vec3(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])))
                    .ok_or_else(|| format!("{}: a facet refers to a missing vertex", path.display()))
            };
            let triangles = mesh
                .faces
                .iter()
                .map(|f| Ok(vec![v(f.vertices[0])?, v(f.vertices[1])?, v(f.vertices[2])?]))
                .collect::<Result<Vec<_>, String>>()?;
            Ok(vec![Group { name: String::new(), faces: triangles, radiates: true }])
        }
        Some("vs3") => {
            let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
            let at = |(line, message): (usize, String)| format!("{}:{line}: {message}", path.display());
            let file = super::vs3::parse(&text).map_err(at)?;
            super::vs3::groups(&file).map_err(at)
        }
        _ => Err(format!("{}: unknown mesh format (use .obj, .stl or View3D's .vs3)", path.display())),
    }
}

/// Why four corners (a triangle repeats its first) do not make a flat convex quadrilateral
/// of non-zero area, in words for the error message; the same conditions as
/// `pdm_kernel::Quadrilateral::new`, with a relative tolerance of 1e-9.
pub fn check_polygon(c: &[Vec3<f64>; 4]) -> Result<(), String> {
    let [p0, p1, p2, p3] = *c;
    let n = (p2 - p0).cross(p3 - p1);
    let size = (p2 - p0).norm().max((p3 - p1).norm());
    if !(n.norm() > 1e-9 * size * size) {
        return Err("has zero area (corners on one line or coincident)".into());
    }
    let unit = n.scale(1.0 / n.norm());
    let centre = (p0 + p1 + p2 + p3).scale(0.25);
    if c.iter().any(|p| unit.dot(*p - centre).abs() > 1e-9 * size) {
        return Err("is not flat (a corner lies off the plane of the others)".into());
    }
    for k in 0..4 {
        let (prev, p, next) = (c[(k + 3) % 4], c[k], c[(k + 1) % 4]);
        if unit.dot((p - prev).cross(next - p)) < -1e-9 * size * size {
            return Err(format!("is not convex, or its sides cross (at corner {k})"));
        }
    }
    Ok(())
}
