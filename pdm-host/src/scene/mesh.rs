//! Flat facets from mesh files: OBJ (`tobj`, in f64, every face triangulated, one group per OBJ
//! object or group) and STL (`stl_io`, ASCII or binary, one group). Each triangle becomes a
//! bicubic Bézier net with one side collapsed to a vertex, g(t, s) = A + t·(B − A + s·(C − B)),
//! whose normal t·(B − A) × (C − A) points to the side the vertices A, B, C turn
//! counter-clockwise around.

use std::path::Path;

use pdm_kernel::{vec3, Vec3};

/// A triangle's vertices.
pub type Triangle = [Vec3<f64>; 3];

/// The facets of a mesh file by group: (group name, triangles).
pub fn load(path: &Path) -> Result<Vec<(String, Vec<Triangle>)>, String> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("obj") => {
            let options = tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() };
            let (models, _) = tobj::load_obj(path, &options).map_err(|e| format!("{}: {e}", path.display()))?;
            let mut groups = Vec::new();
            for model in models {
                let p = &model.mesh.positions;
                let vertex = |k: u32| -> Result<Vec3<f64>, String> {
                    let k = k as usize * 3;
                    match (p.get(k), p.get(k + 1), p.get(k + 2)) {
                        (Some(&x), Some(&y), Some(&z)) => Ok(vec3(x, y, z)),
                        _ => {
                            Err(format!("{}: object {}: a face refers to a missing vertex", path.display(), model.name))
                        }
                    }
                };
                let mut triangles = Vec::new();
                for face in model.mesh.indices.chunks(3) {
                    if let [a, b, c] = *face {
                        triangles.push([vertex(a)?, vertex(b)?, vertex(c)?]);
                    }
                }
                if !triangles.is_empty() {
                    groups.push((model.name.clone(), triangles));
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
                .map(|f| Ok([v(f.vertices[0])?, v(f.vertices[1])?, v(f.vertices[2])?]))
                .collect::<Result<Vec<_>, String>>()?;
            Ok(vec![(String::new(), triangles)])
        }
        _ => Err(format!("{}: unknown mesh format (use .obj or .stl)", path.display())),
    }
}

/// The Bézier net of a triangle (module docs): control point (i, j) = g(i/3, j/3), exact
/// because g is of degree one in each parameter.
#[must_use]
pub fn triangle_net(t: &Triangle) -> [[Vec3<f64>; 4]; 4] {
    let [a, b, c] = *t;
    let mut net = [[a; 4]; 4];
    for (i, row) in net.iter_mut().enumerate() {
        for (j, p) in row.iter_mut().enumerate() {
            let (u, v) = (i as f64 / 3.0, j as f64 / 3.0);
            *p = a + (b - a + (c - b).scale(v)).scale(u);
        }
    }
    net
}
