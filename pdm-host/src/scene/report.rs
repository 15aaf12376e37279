//! The matrices of a computed scene and their diagnostics: patch-to-patch and surface-to-surface
//! form factors with error estimates, row sums, reciprocity, the enclosure check, the slowest
//! pairs; written as text, CSV or JSON (atomically: a temporary file renamed into place).

use std::io::Write as _;
use std::path::Path;

use serde::Serialize;

use super::build::Scene;
use super::matrix::{MatrixResult, PairMethod};

/// A square matrix with names and areas, and the absolute error estimate of each entry
/// (`None` where the method has no estimate).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Matrix {
    /// Row and column names.
    pub names: Vec<String>,
    /// Areas (unit²).
    pub areas: Vec<f64>,
    /// `F[i][j]`: the fraction of what leaves i that arrives at j.
    pub factors: Vec<Vec<f64>>,
    /// Estimated absolute error of each `F[i][j]`.
    pub errors: Option<Vec<Vec<f64>>>,
    /// `Σ_j F[i][j]`.
    pub row_sums: Vec<f64>,
}

/// One slow pair.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SlowPair {
    /// The two patches.
    pub patches: [String; 2],
    /// Seconds.
    pub seconds: f64,
    /// Kernel evaluations.
    pub evaluations: u64,
}

/// Diagnostics of a computed scene.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Diagnostics {
    /// How the pairs were integrated.
    pub method: String,
    /// Patches.
    pub patches: usize,
    /// Unordered pairs integrated.
    pub pairs_integrated: usize,
    /// Unordered pairs skipped as zero by geometry (back to back, one convex surface).
    pub pairs_skipped: usize,
    /// Pairs whose estimate missed the tolerance.
    pub pairs_unconverged: usize,
    /// Largest relative error estimate of a nonzero patch entry.
    pub largest_relative_error: Option<f64>,
    /// Largest error estimate of a surface-to-surface form factor F_IJ (absolute: what the
    /// absolute tolerance bounds).
    pub largest_absolute_error: Option<f64>,
    /// Largest |A_i F_ij − A_j F_ji| / max(A_i F_ij, A_j F_ji) over the surface matrix.
    pub largest_reciprocity_residual: f64,
    /// Surfaces whose row misses 1 by more than its error estimate (enclosures only).
    pub enclosure_gaps: Vec<String>,
    /// Surfaces and patches whose row sum exceeds 1 by more than its error estimate (any
    /// scene): what leaves a surface cannot arrive more than once, so such a row means that
    /// two surfaces overlap in its view (overlapping surfaces, or one with `occludes = false`
    /// in front of another).
    pub overfull_rows: Vec<String>,
    /// The slowest pairs.
    pub slowest: Vec<SlowPair>,
    /// Wall time (s).
    pub seconds: f64,
}

/// A computed scene.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SceneReport {
    /// The length unit.
    pub units: String,
    /// Whether the scene is declared an enclosure (otherwise 1 − row sum goes to space).
    pub enclosure: bool,
    /// Surface-to-surface matrix.
    pub surfaces: Matrix,
    /// Patch-to-patch matrix.
    pub patches: Matrix,
    /// Diagnostics.
    pub diagnostics: Diagnostics,
}

/// Slack on the enclosure check beyond the summed estimates (relative).
const ENCLOSURE_SLACK: f64 = 1e-9;

/// Names of the patches: `SURFACE[i,j]`, with the piece for multi-piece surfaces.
#[must_use]
pub fn patch_names(scene: &Scene) -> Vec<String> {
    scene
        .patches
        .iter()
        .map(|p| {
            let s = &scene.surfaces[p.surface];
            if s.pieces.len() > 1 {
                format!("{}[{}:{},{}]", s.name, p.piece, p.cell.0, p.cell.1)
            } else {
                format!("{}[{},{}]", s.name, p.cell.0, p.cell.1)
            }
        })
        .collect()
}

fn describe(method: PairMethod) -> String {
    match method {
        PairMethod::Tolerance { relative, absolute } => {
            format!("tolerance {relative:e} per pair or {absolute:e} on each surface factor (adaptive_exchange)")
        }
        PairMethod::Order { order, singular_order } => {
            format!("order {order}, singular order {singular_order} (pair_exchange, no error estimate)")
        }
    }
}

/// Assembles the matrices and diagnostics.
#[must_use]
pub fn assemble(scene: &Scene, result: &MatrixResult, method: PairMethod) -> SceneReport {
    let n = scene.patches.len();
    let m = scene.surfaces.len();
    let has_errors = matches!(method, PairMethod::Tolerance { .. });
    let mut exchange = vec![vec![0.0; n]; n];
    let mut error = vec![vec![0.0; n]; n];
    let mut s_exchange = vec![vec![0.0; m]; m];
    let mut s_error = vec![vec![0.0; m]; m];
    let mut unconverged = 0;
    for p in &result.pairs {
        let e = p.error.unwrap_or(0.0);
        exchange[p.i][p.j] = p.exchange;
        exchange[p.j][p.i] = p.exchange;
        error[p.i][p.j] = e;
        error[p.j][p.i] = e;
        let (si, sj) = (scene.patches[p.i].surface, scene.patches[p.j].surface);
        s_exchange[si][sj] += p.exchange;
        s_error[si][sj] += e;
        if p.i != p.j {
            s_exchange[sj][si] += p.exchange;
            s_error[sj][si] += e;
        }
        if has_errors && !p.converged {
            unconverged += 1;
        }
    }
    let areas = result.areas.clone();
    let mut s_areas = vec![0.0; m];
    for (p, a) in scene.patches.iter().zip(&areas) {
        s_areas[p.surface] += a;
    }
    // Each patch pair's exchange is within [0, min(A_i, A_j)] (the kernel clamps it there
    // within its estimate), but their sum over a surface pair may pass min(A_I, A_J) by its
    // estimate (a sphere inside a sphere: F = 1 to 1e-9 above). Clamped the same way: the
    // true value is within the bound, so the estimate still covers it; beyond the estimate
    // (and rounding) it stands, and the row is flagged below.
    for i in 0..m {
        for j in 0..m {
            let bound = s_areas[i].min(s_areas[j]);
            let over = s_exchange[i][j] - bound;
            // The rounding of the sum counts too (pairs exact to rounding have no estimate).
            if over > 0.0 && over <= s_error[i][j] + 1024.0 * f64::EPSILON * bound {
                s_exchange[i][j] = bound;
            }
        }
    }
    let divide = |e: &[Vec<f64>], a: &[f64]| -> Vec<Vec<f64>> {
        e.iter().zip(a).map(|(row, &ai)| row.iter().map(|x| x / ai).collect()).collect()
    };
    let make = |names: Vec<String>, a: Vec<f64>, e: &[Vec<f64>], err: &[Vec<f64>]| {
        let factors = divide(e, &a);
        let row_sums = factors.iter().map(|r| r.iter().sum()).collect();
        Matrix { names, errors: has_errors.then(|| divide(err, &a)), areas: a, factors, row_sums }
    };
    let patches = make(patch_names(scene), areas, &exchange, &error);
    let surfaces = make(scene.surfaces.iter().map(|s| s.name.clone()).collect(), s_areas, &s_exchange, &s_error);

    let mut residual: f64 = 0.0;
    for i in 0..m {
        for j in 0..m {
            let (a, b) = (surfaces.areas[i] * surfaces.factors[i][j], surfaces.areas[j] * surfaces.factors[j][i]);
            let scale = a.abs().max(b.abs());
            if scale > 0.0 {
                residual = residual.max((a - b).abs() / scale);
            }
        }
    }
    let largest_relative_error = has_errors.then(|| {
        result
            .pairs
            .iter()
            .filter(|p| p.exchange > 0.0)
            .map(|p| p.error.unwrap_or(0.0) / p.exchange)
            .fold(0.0, f64::max)
    });
    let largest_absolute_error = surfaces.errors.as_ref().map(|e| e.iter().flatten().copied().fold(0.0, f64::max));
    let mut enclosure_gaps = Vec::new();
    if scene.enclosure {
        for i in 0..m {
            let allowed = surfaces.errors.as_ref().map_or(0.0, |e| e[i].iter().sum::<f64>()) + ENCLOSURE_SLACK;
            let miss = (surfaces.row_sums[i] - 1.0).abs();
            // Without estimates (fixed orders), a row is flagged beyond 1e-6.
            let allowed = if has_errors { allowed } else { 1e-6 };
            if miss > allowed {
                enclosure_gaps.push(format!(
                    "{}: row sum {:.9} misses 1 by {miss:.2e} (estimate allows {allowed:.1e})",
                    surfaces.names[i], surfaces.row_sums[i]
                ));
            }
        }
    }
    let mut overfull_rows = Vec::new();
    for (level, matrix) in [("surface", &surfaces), ("patch", &patches)] {
        for (i, &sum) in matrix.row_sums.iter().enumerate() {
            let allowed = match &matrix.errors {
                Some(e) => e[i].iter().sum::<f64>() + ENCLOSURE_SLACK,
                None => 1e-6,
            };
            if sum - 1.0 > allowed {
                overfull_rows.push(format!(
                    "{level} {}: row sum {sum:.9} exceeds 1 by {:.2e} (estimate allows {allowed:.1e})",
                    matrix.names[i],
                    sum - 1.0
                ));
            }
        }
    }
    let mut slow: Vec<_> = result.pairs.iter().collect();
    slow.sort_by(|a, b| b.seconds.total_cmp(&a.seconds));
    let slowest = slow
        .iter()
        .take(5)
        .map(|p| SlowPair {
            patches: [patches.names[p.i].clone(), patches.names[p.j].clone()],
            seconds: p.seconds,
            evaluations: p.evaluations,
        })
        .collect();
    let diagnostics = Diagnostics {
        method: describe(method),
        patches: n,
        pairs_integrated: result.pairs.len(),
        pairs_skipped: result.skipped,
        pairs_unconverged: unconverged,
        largest_relative_error,
        largest_absolute_error,
        largest_reciprocity_residual: residual,
        enclosure_gaps,
        overfull_rows,
        slowest,
        seconds: result.seconds,
    };
    SceneReport { units: scene.units.clone(), enclosure: scene.enclosure, surfaces, patches, diagnostics }
}

/// The text summary: the surface matrix with row sums, then the diagnostics.
#[must_use]
pub fn text(report: &SceneReport) -> String {
    let s = &report.surfaces;
    let d = &report.diagnostics;
    let mut out = String::new();
    let width = s.names.iter().map(String::len).max().unwrap_or(4).max(12);
    out += &format!("Surface-to-surface form factors F[row -> column] ({}; areas in {}^2)\n\n", d.method, report.units);
    out += &format!("{:width$}  {:>12}", "", "area");
    for name in &s.names {
        out += &format!("  {name:>width$}");
    }
    out += &format!("  {:>width$}", "row sum");
    // An open scene: what leaves each surface and reaches none, 1 − row sum.
    let open = !report.enclosure;
    out += &if open { format!("  {:>width$}\n", "to space") } else { "\n".to_string() };
    for i in 0..s.names.len() {
        out += &format!("{:width$}  {:>12.6e}", s.names[i], s.areas[i]);
        for f in &s.factors[i] {
            out += &format!("  {f:>width$.10}");
        }
        out += &format!("  {:>width$.10}", s.row_sums[i]);
        out += &if open { format!("  {:>width$.10}\n", 1.0 - s.row_sums[i]) } else { "\n".to_string() };
    }
    if let Some(errors) = &s.errors {
        out += "\nEstimated absolute error of each entry:\n";
        for (name, row) in s.names.iter().zip(errors) {
            out += &format!("{name:width$}  {:>12}", "");
            for e in row {
                out += &format!("  {e:>width$.1e}");
            }
            out += "\n";
        }
    }
    out += &format!(
        "\n{} patches; {} pairs integrated, {} skipped (cannot see each other); {:.2} s\n",
        d.patches, d.pairs_integrated, d.pairs_skipped, d.seconds
    );
    if let Some(e) = d.largest_relative_error {
        out += &format!(
            "largest relative error estimate of an entry: {e:.1e}; largest estimate of a surface factor: {:.1e}; \
             pairs above the tolerance: {}\n",
            d.largest_absolute_error.unwrap_or(0.0),
            d.pairs_unconverged
        );
    }
    out += &format!(
        "largest reciprocity residual |A_i F_ij - A_j F_ji| / A_i F_ij: {:.1e} (each pair is computed once)\n",
        d.largest_reciprocity_residual
    );
    if !d.enclosure_gaps.is_empty() {
        out += "WARNING: the scene is declared an enclosure, but these rows do not sum to 1 within their estimates \
                (a leak, an overlap or a surface facing the wrong way):\n";
        for g in &d.enclosure_gaps {
            out += &format!("  {g}\n");
        }
    }
    if !d.overfull_rows.is_empty() {
        out += &format!(
            "WARNING: {} rows sum to more than 1 beyond their estimates: surfaces overlap in their view \
             (overlapping surfaces, or a surface with occludes = false in front of another):\n",
            d.overfull_rows.len()
        );
        for g in d.overfull_rows.iter().take(10) {
            out += &format!("  {g}\n");
        }
        if d.overfull_rows.len() > 10 {
            out += &format!("  ... and {} more (all in the JSON output)\n", d.overfull_rows.len() - 10);
        }
    }
    for p in &d.slowest {
        out += &format!(
            "slow pair: {} <-> {}: {:.3} s, {} evaluations\n",
            p.patches[0], p.patches[1], p.seconds, p.evaluations
        );
    }
    out
}

/// Long-form CSV: one row per ordered pair with a nonzero factor, surfaces first (`level`
/// surface, then patch).
pub fn csv(report: &SceneReport) -> Result<Vec<u8>, csv::Error> {
    #[derive(Serialize)]
    struct Row<'a> {
        level: &'a str,
        from: &'a str,
        to: &'a str,
        area_from: f64,
        factor: f64,
        error: Option<f64>,
    }
    let mut w = csv::Writer::from_writer(Vec::new());
    for (level, m) in [("surface", &report.surfaces), ("patch", &report.patches)] {
        for i in 0..m.names.len() {
            for j in 0..m.names.len() {
                let factor = m.factors[i][j];
                if factor != 0.0 {
                    w.serialize(Row {
                        level,
                        from: &m.names[i],
                        to: &m.names[j],
                        area_from: m.areas[i],
                        factor,
                        error: m.errors.as_ref().map(|e| e[i][j]),
                    })?;
                }
            }
        }
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

/// One array of the NumPy output: its name in the `.npz` archive and its `.npy` bytes.
type NpyArray = (String, Vec<u8>);

/// An `.npy` file of `values` in row-major order with the given shape (`<f8`).
fn npy_f64(shape: &[u64], values: impl IntoIterator<Item = f64>) -> std::io::Result<Vec<u8>> {
    use npyz::WriterBuilder as _;
    let mut out = Vec::new();
    let mut w = npyz::WriteOptions::<f64>::new().default_dtype().shape(shape).writer(&mut out).begin_nd()?;
    w.extend(values)?;
    w.finish()?;
    Ok(out)
}

/// An `.npy` file of strings (`<U{longest}`, NumPy's fixed-width unicode).
fn npy_strings(values: &[String]) -> std::io::Result<Vec<u8>> {
    use npyz::WriterBuilder as _;
    let width = values.iter().map(|v| v.chars().count()).max().unwrap_or(0).max(1);
    let dtype = npyz::DType::Plain(
        format!("<U{width}").parse().map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidInput, e))?,
    );
    let mut out = Vec::new();
    let mut w =
        npyz::WriteOptions::<str>::new().dtype(dtype).shape(&[values.len() as u64]).writer(&mut out).begin_nd()?;
    for v in values {
        w.push(v.as_str())?;
    }
    w.finish()?;
    Ok(out)
}

/// The arrays of the NumPy output: per level (`surface_`, `patch_`) the names, areas, the
/// factor matrix, its row sums and (tolerance mode) the error estimates.
fn npy_arrays(report: &SceneReport) -> std::io::Result<Vec<NpyArray>> {
    let mut arrays = Vec::new();
    for (level, m) in [("surface", &report.surfaces), ("patch", &report.patches)] {
        let n = m.names.len() as u64;
        arrays.push((format!("{level}_names"), npy_strings(&m.names)?));
        arrays.push((format!("{level}_areas"), npy_f64(&[n], m.areas.iter().copied())?));
        arrays.push((format!("{level}_factors"), npy_f64(&[n, n], m.factors.iter().flatten().copied())?));
        arrays.push((format!("{level}_row_sums"), npy_f64(&[n], m.row_sums.iter().copied())?));
        if let Some(e) = &m.errors {
            arrays.push((format!("{level}_errors"), npy_f64(&[n, n], e.iter().flatten().copied())?));
        }
    }
    Ok(arrays)
}

/// The NumPy archive (`numpy.load("x.npz")`): every array of [`npy_arrays`] as `NAME.npy`,
/// deflated.
fn npz(report: &SceneReport) -> Result<Vec<u8>, String> {
    let arrays = npy_arrays(report).map_err(|e| e.to_string())?;
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let options = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    for (name, bytes) in arrays {
        zip.start_file(format!("{name}.npy"), options).map_err(|e| e.to_string())?;
        zip.write_all(&bytes).map_err(|e| e.to_string())?;
    }
    Ok(zip.finish().map_err(|e| e.to_string())?.into_inner())
}

/// Writes `bytes` to `path` atomically: a temporary file in the same folder, renamed into place
/// (an interrupted or failed run leaves no half-written file).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut tmp = tempfile::NamedTempFile::new_in(directory_of(path))?;
    tmp.write_all(bytes)?;
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// The directory a file `path` is written into (`.` for a bare name).
fn directory_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Whether [`write_atomic`] can write `path`: a temporary file can be made in its directory
/// (checked before a long run, so that a mistyped directory fails at once, not after it).
pub fn check_writable(path: &Path) -> std::io::Result<()> {
    tempfile::NamedTempFile::new_in(directory_of(path)).map(drop)
}

/// The output's bytes by the file's extension: `.csv` long-form CSV, `.json` the whole report,
/// `.npy` the surface-to-surface factor matrix, `.npz` every matrix with names, areas, row
/// sums and error estimates, as `surface_*` and `patch_*` arrays (SCENES.md).
pub fn encode(report: &SceneReport, path: &Path) -> Result<Vec<u8>, String> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("csv") => csv(report).map_err(|e| e.to_string()),
        Some("json") => serde_json::to_vec_pretty(report).map_err(|e| e.to_string()),
        // One array: the surface-to-surface factors (the .npz holds everything).
        Some("npy") => {
            let m = &report.surfaces;
            let n = m.names.len() as u64;
            npy_f64(&[n, n], m.factors.iter().flatten().copied()).map_err(|e| e.to_string())
        }
        Some("npz") => npz(report),
        other => Err(format!("unknown output format {:?} (use .csv, .json, .npy or .npz)", other.unwrap_or(""))),
    }
}
