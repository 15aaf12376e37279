//! View3D input files (`.vs3`), so that a View3D model runs unchanged: the vertex-and-surface
//! format (`F 3`) and the BLAST surface format (`F 3a`), as described in the View3D 3.x manual
//! ("Input File Format") and read by its `getdat.c`.
//!
//! What becomes of each element:
//! - `S` (radiating) surfaces: flat convex quadrilaterals and triangles (fourth vertex 0),
//!   radiating to the side their vertices turn counter-clockwise around, as in View3D.
//! - Combination (`cmb` = k): the surface joins surface k's, one row and column of the matrix
//!   under k's name (View3D combines by view-factor algebra; a surface of several pieces is the
//!   same sum).
//! - Subsurfaces (`base` = k, a window in a wall) and null surfaces (`N`): cut out of their
//!   base, which keeps what is left (triangulated around the holes); a subsurface keeps its own
//!   row, a null surface is dropped. View3D gets the same by view-factor algebra.
//! - Obstruction surfaces (`O`): block the view but have no row or column.
//! - Masking surfaces (`M`, which View3D gives F = 1 to their base): refused, there is no
//!   geometry that has that view factor.
//! - Control parameters: `encl = 1` makes the scene an enclosure (its row sums are checked, not
//!   forced to 1); `emit = 1` (Hottel's script-F with the emissivities), `row`/`col`
//!   selection and View3D's own integration settings (`eps`, `maxU`, `maxO`, `minO`) have no
//!   meaning here and are reported as notes. Emissivities are read and not used.

use pdm_kernel::{vec3, Vec3};

use super::mesh::Group;

/// The kind of a View3D surface line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Vs3Kind {
    /// `S`: radiating.
    Radiating,
    /// `O`: obstruction only.
    Obstruction,
    /// `N`: null (cut out of its base).
    Null,
    /// `M`: masking.
    Mask,
}

/// One surface of a View3D file.
#[derive(Clone, Debug, PartialEq)]
pub struct Vs3Surface {
    /// Its number (1-based, in order).
    pub number: usize,
    /// Its kind.
    pub kind: Vs3Kind,
    /// The corners, counter-clockwise seen from the radiating side (3 or 4).
    pub vertices: Vec<Vec3<f64>>,
    /// The base surface's number (0: none).
    pub base: usize,
    /// The number of the surface it combines with (0: none).
    pub combine: usize,
    /// Emissivity (read, not used).
    pub emissivity: f64,
    /// Name (obstructions have none in the format; they get `obstruction-N`).
    pub name: String,
    /// The 1-based line it starts on.
    pub line: usize,
}

/// A View3D file as read.
#[derive(Clone, Debug, PartialEq)]
pub struct Vs3 {
    /// The last title line.
    pub title: String,
    /// `encl = 1`.
    pub enclosure: bool,
    /// The surfaces in order.
    pub surfaces: Vec<Vs3Surface>,
    /// Control settings pdm does not use, in words.
    pub notes: Vec<String>,
}

/// A line of the file cut into words (blanks and commas separate them), comments removed: from
/// a `!` anywhere, or from a word that starts with `/`.
fn words(line: &str) -> Vec<&str> {
    let data = line.split('!').next().unwrap_or("");
    data.split(|c: char| c.is_whitespace() || c == ',')
        .filter(|w| !w.is_empty())
        .take_while(|w| !w.starts_with('/'))
        .collect()
}

fn number<T: std::str::FromStr>(word: Option<&&str>, what: &str, line: usize) -> Result<T, (usize, String)> {
    let w = word.ok_or_else(|| (line, format!("{what} is missing")))?;
    w.parse::<T>().map_err(|_| (line, format!("{what} `{w}` is not a number of the right kind")))
}

fn real(word: Option<&&str>, what: &str, line: usize) -> Result<f64, (usize, String)> {
    let x: f64 = number(word, what, line)?;
    if x.is_finite() {
        Ok(x)
    } else {
        Err((line, format!("{what} `{x}` is not finite")))
    }
}

/// Parses a View3D input file; `Err((line, message))`.
pub fn parse(text: &str) -> Result<Vs3, (usize, String)> {
    let lines: Vec<&str> = text.lines().collect();
    // First pass: the format, to read surfaces the right way.
    let mut format_3a = false;
    for (k, line) in lines.iter().enumerate() {
        let w = words(line);
        match w.first().and_then(|s| s.chars().next()).map(|c| c.to_ascii_uppercase()) {
            Some('F') => match w.get(1).map(|s| s.to_ascii_lowercase()).as_deref() {
                Some("3") => format_3a = false,
                Some("3a") => format_3a = true,
                other => {
                    return Err((
                        k + 1,
                        format!("geometry format `{}` is not supported (F 3 or F 3a)", other.unwrap_or("")),
                    ))
                }
            },
            Some('E' | '*') => break,
            _ => {}
        }
    }
    let mut out = Vs3 { title: String::new(), enclosure: false, surfaces: Vec::new(), notes: Vec::new() };
    let mut vertices: Vec<Vec3<f64>> = Vec::new();
    let mut k = 0;
    while let Some(line) = lines.get(k) {
        let at = k + 1;
        k += 1;
        let w = words(line);
        let Some(first) = w.first() else { continue };
        let c = first.chars().next().map_or(' ', |c| c.to_ascii_uppercase());
        match c {
            'T' => out.title = line.trim_start().get(1..).unwrap_or("").trim().to_string(),
            'F' | 'X' => {}
            'E' | '*' => break,
            'C' => {
                // name = value pairs, separated by blanks, '=' or ','.
                let all = line.split(['!', '/']).next().unwrap_or("");
                let parts: Vec<&str> = all
                    .trim_start()
                    .get(1..)
                    .unwrap_or("")
                    .split([' ', '\t', '=', ','])
                    .filter(|s| !s.is_empty())
                    .collect();
                for pair in parts.chunks(2) {
                    let (name, value) = (pair.first().copied().unwrap_or(""), pair.get(1).copied());
                    let value: f64 = number(value.as_ref(), &format!("control `{name}`"), at)?;
                    match name.to_ascii_lowercase().as_str() {
                        "encl" => out.enclosure = value != 0.0,
                        "emit" if value != 0.0 => out.notes.push(
                            "emit = 1 (Hottel's script-F with the emissivities) is not computed: pdm prints black-body view factors"
                                .into(),
                        ),
                        "row" | "col" if value != 0.0 => out.notes.push(format!(
                            "{name} = {value}: pdm computes every row and column"
                        )),
                        "eps" | "maxu" | "maxo" | "mino" => out.notes.push(format!(
                            "{name} = {value} is View3D's integration setting: pdm's accuracy is set by --tolerance or --order"
                        )),
                        "emit" | "row" | "col" | "out" | "list" | "prjd" | "maxv" => {}
                        _ => out.notes.push(format!("unknown control word `{name}` ignored (as View3D does)")),
                    }
                }
            }
            'V' => {
                if format_3a {
                    return Err((at, "vertex lines (V) belong to format F 3, not F 3a".into()));
                }
                let n: usize = number(w.get(1), "vertex number", at)?;
                if n != vertices.len() + 1 {
                    return Err((at, format!("vertex {n} out of sequence (expected {})", vertices.len() + 1)));
                }
                let x = real(w.get(2), "x", at)?;
                let y = real(w.get(3), "y", at)?;
                let z = real(w.get(4), "z", at)?;
                vertices.push(vec3(x, y, z));
            }
            'S' | 'O' | 'N' | 'M' => {
                let kind = match c {
                    'S' => Vs3Kind::Radiating,
                    'O' => Vs3Kind::Obstruction,
                    'N' => Vs3Kind::Null,
                    _ => Vs3Kind::Mask,
                };
                let n: usize = number(w.get(1), "surface number", at)?;
                if n != out.surfaces.len() + 1 {
                    return Err((at, format!("surface {n} out of sequence (expected {})", out.surfaces.len() + 1)));
                }
                // The common data after the geometry (F 3) or the shape letter (F 3a).
                let data_at = if format_3a { 3 } else { 6 };
                let (base, combine, emissivity, name) = if kind == Vs3Kind::Obstruction {
                    (0, 0, 0.0, format!("obstruction-{n}"))
                } else {
                    let base: usize = number(w.get(data_at), "base surface", at)?;
                    let combine: usize = number(w.get(data_at + 1), "combine surface", at)?;
                    let emissivity = real(w.get(data_at + 2), "emissivity", at)?;
                    let name = w.get(data_at + 3).map_or_else(|| format!("surface-{n}"), |s| (*s).to_string());
                    (base, combine, emissivity, name)
                };
                let corners = if format_3a {
                    let shape = w.get(2).map(|s| s.to_ascii_uppercase());
                    let needed = match shape.as_deref() {
                        Some("R") => 7,
                        Some("T") => 11,
                        Some("Q") => 13,
                        other => {
                            return Err((at, format!("shape `{}` is not R, T or Q", other.unwrap_or(""))));
                        }
                    };
                    // The geometry's numbers, from the next lines on.
                    let mut values = Vec::new();
                    while values.len() < needed {
                        let Some(next) = lines.get(k) else {
                            return Err((at, format!("surface {n}: the file ends before its {needed} numbers")));
                        };
                        k += 1;
                        for word in words(next) {
                            values.push(real(Some(&word), &format!("surface {n}'s geometry"), k)?);
                        }
                    }
                    // As View3D, the numbers the shape needs; the rest of the line is ignored.
                    values.truncate(needed);
                    blast_corners(shape.as_deref() == Some("R"), &values)
                } else {
                    let mut corners = Vec::new();
                    for (slot, word) in w.iter().enumerate().skip(2).take(4) {
                        let v: usize = number(Some(word), &format!("vertex {}", slot - 1), at)?;
                        if v == 0 && slot == 5 {
                            continue; // a triangle
                        }
                        let p = v.checked_sub(1).and_then(|v| vertices.get(v)).ok_or_else(|| {
                            (at, format!("surface {n} refers to vertex {v}, which is not defined above it"))
                        })?;
                        corners.push(*p);
                    }
                    if corners.len() < 3 {
                        return Err((at, format!("surface {n} needs 3 or 4 vertex numbers")));
                    }
                    corners
                };
                out.surfaces.push(Vs3Surface {
                    number: n,
                    kind,
                    vertices: corners,
                    base,
                    combine,
                    emissivity,
                    name,
                    line: at,
                });
            }
            _ => return Err((at, format!("unknown line `{first}` (T, C, F, V, S, O, N, M, E, ! or / expected)"))),
        }
    }
    if out.surfaces.is_empty() {
        return Err((lines.len().max(1), "the file has no surfaces".into()));
    }
    Ok(out)
}

/// F 3a: the corners from the plane's origin (x, y, z), azimuth (clockwise from +y), tilt
/// (0 facing up), and the width and height of a rectangle or the (x, y) pairs of a polygon in
/// the plane, as View3D's `GetVS3Da` places them.
fn blast_corners(rectangle: bool, values: &[f64]) -> Vec<Vec3<f64>> {
    let g = |i: usize| values.get(i).copied().unwrap_or(0.0);
    let (x0, y0, z0, azimuth, tilt) = (g(0), g(1), g(2), g(3).to_radians(), g(4).to_radians());
    let (ca, sa, ct, st) = (-azimuth.cos(), azimuth.sin(), tilt.cos(), tilt.sin());
    let local: Vec<(f64, f64)> = if rectangle {
        let (w, h) = (g(5), g(6));
        vec![(0.0, h), (0.0, 0.0), (w, 0.0), (w, h)]
    } else {
        values
            .get(5..)
            .unwrap_or(&[])
            .chunks(2)
            .map(|p| (p.first().copied().unwrap_or(0.0), p.get(1).copied().unwrap_or(0.0)))
            .collect()
    };
    local.into_iter().map(|(u, v)| vec3(x0 + u * ca - v * ct * sa, y0 + u * sa + v * ct * ca, z0 + v * st)).collect()
}

/// Area-weighted normal of a planar polygon (Newell's method): its length is twice the area.
fn newell(p: &[Vec3<f64>]) -> Vec3<f64> {
    let mut n = vec3(0.0, 0.0, 0.0);
    for (k, a) in p.iter().enumerate() {
        let b = p.get((k + 1) % p.len()).copied().unwrap_or(*a);
        n = n + a.cross(b);
    }
    n
}

/// The base polygon minus its holes, as triangles counter-clockwise about the base's normal.
fn cut_holes(base: &Vs3Surface, holes: &[&Vs3Surface]) -> Result<Vec<Vec<Vec3<f64>>>, (usize, String)> {
    let normal = newell(&base.vertices);
    let area2 = normal.norm();
    if !(area2 > 0.0) {
        return Err((base.line, format!("surface {} has zero area", base.number)));
    }
    let unit = normal.scale(1.0 / area2);
    let origin = base.vertices.first().copied().unwrap_or(vec3(0.0, 0.0, 0.0));
    let size = base.vertices.iter().map(|p| (*p - origin).norm()).fold(0.0, f64::max);
    let frame = pdm_kernel::Frame::from_axis(unit)
        .map_err(|_| (base.line, format!("surface {} has zero area", base.number)))?;
    let (u, w) = (frame.u, frame.w);
    let flat = |p: Vec3<f64>| [u.dot(p - origin), w.dot(p - origin)];
    let mut coords: Vec<f64> = base.vertices.iter().flat_map(|p| flat(*p)).collect();
    let mut starts = Vec::new();
    let mut hole_area2 = 0.0;
    for hole in holes {
        let n = newell(&hole.vertices);
        let same = (n - unit.scale(n.norm())).norm() <= 1e-9 * n.norm();
        let opposite = (n + unit.scale(n.norm())).norm() <= 1e-9 * n.norm();
        if !same && !opposite {
            return Err((
                hole.line,
                format!("surface {} is not in the plane of its base {}", hole.number, base.number),
            ));
        }
        if hole.kind == Vs3Kind::Radiating && !same {
            return Err((
                hole.line,
                format!(
                    "subsurface {} faces the other way from its base {} (View3D requires the same)",
                    hole.number, base.number
                ),
            ));
        }
        for p in &hole.vertices {
            let off = unit.dot(*p - origin);
            let inside = base.vertices.iter().enumerate().all(|(k, a)| {
                let b = base.vertices.get((k + 1) % base.vertices.len()).copied().unwrap_or(*a);
                unit.dot((b - *a).cross(*p - *a)) >= -1e-9 * size * size
            });
            if off.abs() > 1e-9 * size || !inside {
                return Err((
                    hole.line,
                    format!("surface {} does not lie within its base surface {}", hole.number, base.number),
                ));
            }
        }
        starts.push(coords.len() / 2);
        coords.extend(hole.vertices.iter().flat_map(|p| flat(*p)));
        hole_area2 += n.norm();
    }
    let triangles = earcutr::earcut(&coords, &starts, 2)
        .map_err(|_| (base.line, format!("surface {}: its subsurfaces cannot be cut out of it", base.number)))?;
    let points: Vec<Vec3<f64>> =
        base.vertices.iter().chain(holes.iter().flat_map(|h| h.vertices.iter())).copied().collect();
    let mut out = Vec::new();
    let mut total = 0.0;
    for t in triangles.chunks(3) {
        let corner = |i: usize| t.get(i).and_then(|&k| points.get(k)).copied();
        let (Some(a), Some(b), Some(c)) = (corner(0), corner(1), corner(2)) else { continue };
        let n = (b - a).cross(c - a);
        let twice = unit.dot(n);
        if twice.abs() <= 1e-12 * area2 {
            continue; // a sliver along a hole touching the base's side
        }
        total += twice.abs();
        out.push(if twice > 0.0 { vec![a, b, c] } else { vec![a, c, b] });
    }
    if (total - (area2 - hole_area2)).abs() > 1e-9 * area2 {
        return Err((base.line, format!("surface {}: its subsurfaces overlap each other or its sides", base.number)));
    }
    Ok(out)
}

/// The file's surfaces as the scene's groups: one per output surface (combinations joined,
/// subsurfaces and null surfaces cut out of their bases), then the obstructions.
pub fn groups(file: &Vs3) -> Result<Vec<Group>, (usize, String)> {
    let by_number = |n: usize| file.surfaces.get(n.wrapping_sub(1));
    for s in &file.surfaces {
        if s.kind == Vs3Kind::Mask {
            return Err((s.line, format!("surface {}: masking surfaces (M) are not supported", s.number)));
        }
        if s.base != 0 {
            // Bases come first, except obstructions, which View3D lists after every other surface.
            let Some(b) = by_number(s.base).filter(|b| s.base < s.number || b.kind == Vs3Kind::Obstruction) else {
                return Err((
                    s.line,
                    format!("surface {}: base surface {} must come before it (or be an obstruction)", s.number, s.base),
                ));
            };
            if b.kind == Vs3Kind::Null {
                return Err((s.line, format!("surface {}: a null surface cannot be a base", s.number)));
            }
        } else if s.kind == Vs3Kind::Null {
            return Err((s.line, format!("surface {}: a null surface needs a base surface", s.number)));
        }
        if s.combine != 0 {
            let Some(c) = by_number(s.combine).filter(|_| s.combine < s.number) else {
                return Err((
                    s.line,
                    format!("surface {}: combine surface {} must come before it", s.number, s.combine),
                ));
            };
            if c.combine != 0 {
                return Err((
                    s.line,
                    format!("surface {}: combinations may not chain (surface {} combines too)", s.number, c.number),
                ));
            }
            if s.kind != Vs3Kind::Radiating || c.kind != Vs3Kind::Radiating {
                return Err((s.line, format!("surface {}: only radiating surfaces combine", s.number)));
            }
        }
    }
    for s in &file.surfaces {
        let corners = match *s.vertices.as_slice() {
            [a, b, c] => [a, b, c, a],
            [a, b, c, d] => [a, b, c, d],
            _ => return Err((s.line, format!("surface {} needs 3 or 4 vertices", s.number))),
        };
        if let Err(problem) = super::mesh::check_polygon(&corners) {
            return Err((s.line, format!("surface {} {problem}", s.number)));
        }
    }
    let mut out: Vec<Group> = Vec::new();
    let mut index_of = vec![usize::MAX; file.surfaces.len() + 1];
    // Each surface's subsurfaces and null surfaces, by the base's number (one pass, not one per
    // surface: building models run to thousands of surfaces).
    let mut holes_of: Vec<Vec<&Vs3Surface>> = vec![Vec::new(); file.surfaces.len() + 1];
    for h in file.surfaces.iter().filter(|h| h.base != 0) {
        if let Some(list) = holes_of.get_mut(h.base) {
            list.push(h);
        }
    }
    for s in &file.surfaces {
        let holes = holes_of.get(s.number).map_or(&[][..], Vec::as_slice);
        let faces = if holes.is_empty() { vec![s.vertices.clone()] } else { cut_holes(s, holes)? };
        match s.kind {
            Vs3Kind::Null | Vs3Kind::Mask => {}
            Vs3Kind::Obstruction => out.push(Group { name: s.name.clone(), faces, radiates: false }),
            Vs3Kind::Radiating if s.combine != 0 => {
                let Some(group) = index_of.get(s.combine).and_then(|&g| out.get_mut(g)) else {
                    return Err((
                        s.line,
                        format!("surface {}: combine surface {} is not a radiating surface", s.number, s.combine),
                    ));
                };
                group.faces.extend(faces);
            }
            Vs3Kind::Radiating => {
                if let Some(other) = out.iter().position(|g| g.name == s.name) {
                    return Err((
                        s.line,
                        format!(
                            "surface {}: name `{}` is used by an earlier surface ({})",
                            s.number,
                            s.name,
                            other + 1
                        ),
                    ));
                }
                if let Some(slot) = index_of.get_mut(s.number) {
                    *slot = out.len();
                }
                out.push(Group { name: s.name.clone(), faces, radiates: true });
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::indexing_slicing)]
mod tests {
    use super::*;

    const PINNEY_3: &str = "T Pinney & Bean test 4
C  encl=1 list=2 eps=1.e-4 maxu=8 maxo=8 mino=0 emit=1
F  3
V  1   0.   3.   3.
V  2   1.   3.   3.
V  3   0.   3.   0.
V  4   1.   3.   0.
V  5   0.   1.   0.
V  6   1.   1.   0.
V  7   3.   1.   0.
V  8   0.   0.   0.
V  9   1.   0.   0.
V 10   3.   0.   0.
V 11   0.   0.   3.
V 12   1.   0.   3.
V 13   3.   0.   3.
V 14   0.   1.   3.
V 15   1.   1.   3.
V 16   3.   1.   3.
S  1   11  13  10   8   0   0   0.90  srf-1
S  2   10  13  16   7   0   0   0.90  srf-2
S  3    6   7  16  15   0   0   0.90  srf-3
S  4    4   6  15   2   0   0   0.90  srf-4
S  5    3   4   2   1   0   0   0.90  srf-5
S  6    8   3   1  11   0   0   0.90  srf-6
S  7   11  14  15  12   0   0   0.90  srf-7
S  8    8   9   6   5   0   0   0.90  srf-8
S  9    1   2  15  14   0   7   0.90  srf-7b    ! surfaces that combine
S 10   15  16  13  12   0   7   0.90  srf-7c
S 11    5   6   4   3   0   8   0.90  srf-8b
S 12    9  10   7   6   0   8   0.90  srf-8c
End of data
";

    const PINNEY_3A: &str = "T Pinney & Bean test 4 (BLAST format)
C  encl=1 list=2 eps=1.e-5
F  3a
S  1  R   0   0  0.90  srf-1
  3. 0. 0.    0  90    3. 3.
S  2  R   0   0  0.90  srf-2
  3. 1. 0.  270  90    1. 3.
S  3  r   0   0  0.90  srf-3
  1. 1. 0.  180  90    2. 3.
S  4  R   0   0  0.90  srf-4
  1. 3. 0.  270  90    2. 3.
S  5  R   0   0  0.90  srf-5
  0. 3. 0.  180  90    1. 3.
S  6  R   0   0  0.90  srf-6
  0. 0. 0.   90  90    3. 3.
S  7  Q   0   0  0.90  srf-7
  3. 0. 3.    0  180
  2. 0.   3. 0.   3. 1.   2. 1.
S  8  Q   0   0  0.90  srf-8
  0. 0. 0.  180   0
  0. 0.   1. 0.   1. 1.   0. 1.
S  9  Q   0   7  0.90  srf-7b
  3. 0. 3.    0  180
  2. 1.   3. 1.   3. 3.   2. 3.
S 10  Q   0   7  0.90  srf-7c
  3. 0. 3.    0  180
  0. 0.   2. 0.   2. 1.   0. 1.
S 11  Q   0   8  0.90  srf-8b
  0. 0. 0.  180.  0.
  0. 1.   1. 1.   1. 3.   0. 3.
S 12  q   0   8  0.90  srf-8c
  0. 0. 0.  180.  0.
  1. 0.   3. 0.   3. 1.   1. 1.
End of data
";

    fn area_normal(faces: &[Vec<Vec3<f64>>]) -> Vec3<f64> {
        faces.iter().fold(vec3(0.0, 0.0, 0.0), |n, f| n + newell(f).scale(0.5))
    }

    #[test]
    fn both_formats_of_the_manuals_l_shaped_room_give_the_same_surfaces() {
        let (a, b) = (parse(PINNEY_3).unwrap(), parse(PINNEY_3A).unwrap());
        assert!(a.enclosure && b.enclosure);
        assert_eq!(a.title, "Pinney & Bean test 4");
        assert!(a.notes.iter().any(|n| n.contains("script-F")));
        let odd = parse(&PINNEY_3.replace("emit=1", "emit=1 frobnicate=2")).unwrap();
        assert!(odd.notes.iter().any(|n| n.contains("`frobnicate` ignored")), "{:?}", odd.notes);
        let (ga, gb) = (groups(&a).unwrap(), groups(&b).unwrap());
        assert_eq!(ga.len(), 8, "12 surfaces, 4 of them combined into 2 others");
        assert_eq!(gb.len(), 8);
        for (x, y) in ga.iter().zip(&gb) {
            assert_eq!(x.name, y.name);
            assert_eq!(x.faces.len(), y.faces.len());
            // The same oriented area: the same plane, side and size.
            let (nx, ny) = (area_normal(&x.faces), area_normal(&y.faces));
            assert!((nx - ny).norm() < 1e-12, "{}: {nx:?} vs {ny:?}", x.name);
        }
        // The L-shaped floor (srf-8 with 8b and 8c) is 1 + 2 + 2 = 5 square units facing up,
        // the ceiling (srf-7 …) the same facing down; the room's walls face into it.
        let floor = ga.iter().find(|g| g.name == "srf-8").unwrap();
        assert!((area_normal(&floor.faces) - vec3(0.0, 0.0, 5.0)).norm() < 1e-12);
        let ceiling = ga.iter().find(|g| g.name == "srf-7").unwrap();
        assert!((area_normal(&ceiling.faces) - vec3(0.0, 0.0, -5.0)).norm() < 1e-12);
        let south = ga.iter().find(|g| g.name == "srf-1").unwrap();
        assert!((area_normal(&south.faces) - vec3(0.0, 9.0, 0.0)).norm() < 1e-12);
    }

    #[test]
    fn subsurfaces_and_null_surfaces_are_cut_out_of_their_base() {
        let text = "F 3
V 1 0 0 0
V 2 4 0 0
V 3 4 3 0
V 4 0 3 0
V 5 1 1 0
V 6 2 1 0
V 7 2 2 0
V 8 1 2 0
V 9 3 1 0
V 10 3.5 1 0
V 11 3.5 2 0
S 1 1 2 3 4 0 0 0.9 wall
S 2 5 6 7 8 1 0 0.9 window
N 3 9 10 11 0 1 0 0.9 hole
O 4 1 2 3 4
E
";
        let g = groups(&parse(text).unwrap()).unwrap();
        let names: Vec<_> = g.iter().map(|g| (g.name.as_str(), g.radiates)).collect();
        assert_eq!(names, [("wall", true), ("window", true), ("obstruction-4", false)]);
        // 12 − 1 − 0.25 square units left of the wall, all of it facing +z.
        let n = area_normal(&g[0].faces);
        assert!((n - vec3(0.0, 0.0, 10.75)).norm() < 1e-12, "{n:?}");
        assert!(g[0].faces.iter().all(|f| newell(f).z > 0.0 && f.len() == 3));
    }

    /// The reader follows View3D where files stray: commas between numbers, a `/` comment
    /// after the data, extra numbers after a shape's, a window in an obstruction (listed
    /// last), a base whose first two vertices coincide.
    #[test]
    fn what_view3d_accepts_is_read() {
        let text = "F 3\nV 1, 0, 0, 0\nV 2 4 0 0 / a comment\nV 3 4 3 0\nV 4 0 3 0\nV 5 1 1 0\nV 6 2 1 0\nV 7 2 2 0\n\
                    S 1 5 6 7 0 2 0 0.9 window\nO 2 1 2 3 4\nE\n";
        let g = groups(&parse(text).unwrap()).unwrap();
        assert_eq!(g.len(), 2);
        assert!(!g[1].radiates && g[1].faces.len() > 1, "the window is cut out of the obstruction");
        let blast = "F 3a\nS 1 T 0 0 0.9 t\n 0 0 0 0 0  0 0 1 0 0 1  0 0\nE\n";
        let v = parse(blast).unwrap();
        assert_eq!(v.surfaces[0].vertices.len(), 3);
        let doubled = "F 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 0 1 0\nV 4 .2 .2 0\nV 5 .4 .2 0\nV 6 .2 .4 0\n\
                       S 1 1 1 2 3 0 0 .9 w\nS 2 4 5 6 0 1 0 .9 win\n";
        let g = groups(&parse(doubled).unwrap()).unwrap();
        assert_eq!(g.len(), 2);
        let backwards = "F 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 0 1 0\nV 4 .2 .2 0\nV 5 .4 .2 0\nV 6 .2 .4 0\n\
                         S 1 1 2 3 0 0 0 .9 w\nS 2 4 6 5 0 1 0 .9 win\n";
        let e = groups(&parse(backwards).unwrap()).unwrap_err();
        assert!(e.1.contains("faces the other way"), "{e:?}");
    }

    #[test]
    fn bad_files_name_the_line() {
        let cases = [
            ("F 3\nV 1 0 0 0\nS 1 1 2 3 0 0 0 0.9 a\n", 3, "vertex 2"),
            ("F 3\nV 2 0 0 0\n", 2, "out of sequence"),
            ("F 3\nV 1 0 0 x\n", 2, "`x`"),
            ("F 4\n", 1, "not supported"),
            ("C encl=x\nF 3\n", 1, "`x`"),
            ("F 3\nQ 1\n", 2, "unknown line"),
            ("F 3\n! nothing\n", 2, "no surfaces"),
            ("F 3a\nS 1 R 0 0 0.9 a\n 0 0 0 0 90\n", 2, "ends before"),
            ("F 3a\nS 1 P 0 0 0.9 a\n", 2, "shape `P`"),
        ];
        for (text, line, words) in cases {
            let e = parse(text).unwrap_err();
            assert_eq!(e.0, line, "{text}: {e:?}");
            assert!(e.1.contains(words), "{text}: {e:?}");
        }
        let group_errors = [
            ("F 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 0 1 0\nM 1 1 2 3 0 0 0 0.9 m\n", "masking"),
            ("F 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 0 1 0\nS 1 1 2 3 0 2 0 0.9 a\nS 2 1 2 3 0 0 0 0.9 b\n", "before it"),
            (
                "F 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 0 1 0\nS 1 1 2 3 0 0 0 0.9 a\nS 2 1 2 3 0 0 1 0.9 b\nS 3 1 2 3 0 0 2 0.9 c\n",
                "chain",
            ),
            (
                "F 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 0 1 0\nV 4 5 5 0\nS 1 1 2 3 0 0 0 0.9 a\nS 2 1 2 4 0 1 0 0.9 b\n",
                "within its base",
            ),
            ("F 3\nV 1 0 0 0\nV 2 1 0 0\nV 3 0 1 0\nS 1 1 2 3 0 0 0 0.9 a\nS 2 1 3 2 0 0 0 0.9 a\n", "is used"),
        ];
        for (text, words) in group_errors {
            let e = groups(&parse(text).unwrap()).unwrap_err();
            assert!(e.1.contains(words), "{text}: {e:?}");
        }
    }
}
