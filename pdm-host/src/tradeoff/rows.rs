//! The sweep's rows, their CSV form (written and read back, for `--append`), and Pareto fronts.

use serde::{Deserialize, Serialize};

/// Columns of `tradeoff.csv`, in order.
pub const COLUMNS: [&str; 16] = [
    "case",
    "precision",
    "mode",
    "order",
    "grid",
    "patches",
    "tolerance",
    "value",
    "reference",
    "rel_error",
    "reference_rel_uncertainty",
    "evaluations",
    "seconds",
    "repeats",
    "threads",
    "label",
];

/// One sweep point (a CSV record: the fields in [`COLUMNS`] order, then the label).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// Case name ([`super::cases::CaseId::name`]).
    pub case: String,
    /// "f64", "f32" (libm) or "f32-micromath" (a `--features micromath` build).
    pub precision: String,
    /// "paper", "pair" or "adaptive".
    pub mode: String,
    /// Gauss order (0 in adaptive mode).
    pub order: usize,
    /// Subdivision ("n" or "MxN/K").
    pub grid: String,
    /// Number of patches.
    pub patches: usize,
    /// Relative tolerance (adaptive mode), else NaN (written empty).
    #[serde(with = "crate::csv_num")]
    pub tolerance: f64,
    /// The computed value with the largest error.
    #[serde(with = "crate::csv_num")]
    pub value: f64,
    /// Its reference.
    #[serde(with = "crate::csv_num")]
    pub reference: f64,
    /// Largest relative error over the case's values.
    #[serde(with = "crate::csv_num")]
    pub rel_error: f64,
    /// Relative uncertainty of that reference (0 for exact ones).
    #[serde(with = "crate::csv_num")]
    pub reference_rel_uncertainty: f64,
    /// Kernel evaluations.
    pub evaluations: u64,
    /// Median wall time, seconds.
    #[serde(with = "crate::csv_num")]
    pub seconds: f64,
    /// Timed repetitions.
    pub repeats: usize,
    /// Threads the point ran on.
    pub threads: usize,
}

impl Row {
    /// A short description of the configuration: "paper f64 p=5 grid 4x8/3".
    #[must_use]
    pub fn label(&self) -> String {
        let what =
            if self.mode == "adaptive" { format!("tol={:.0e}", self.tolerance) } else { format!("p={}", self.order) };
        format!("{} {} {} grid {}", self.mode, self.precision, what, self.grid)
    }

    /// The series this row belongs to in plots: "paper f64".
    #[must_use]
    pub fn series(&self) -> String {
        format!("{} {}", self.mode, self.precision)
    }
}

/// The CSV text (header and rows).
#[must_use]
pub fn to_csv(rows: &[Row]) -> String {
    let mut w = csv::WriterBuilder::new().has_headers(false).from_writer(Vec::new());
    // Writing to memory fails only on a serialization error, which these plain fields cannot raise.
    let _ = w.write_record(COLUMNS);
    for r in rows {
        let _ = w.serialize((r, r.label()));
    }
    w.into_inner().map(|b| String::from_utf8_lossy(&b).into_owned()).unwrap_or_default()
}

/// Reads a CSV written by [`to_csv`] (columns by name; the label is ignored). Errors name the
/// line.
pub fn from_csv(text: &str) -> Result<Vec<Row>, String> {
    let mut r = csv::Reader::from_reader(text.as_bytes());
    let header = r.headers().map_err(|e| format!("CSV header: {e}"))?;
    if header.iter().ne(COLUMNS) {
        return Err(format!("unexpected CSV header {:?}", header.iter().collect::<Vec<_>>().join(",")));
    }
    r.deserialize().map(|row| row.map_err(|e| format!("CSV: {e}"))).collect()
}

/// Indices of the Pareto front of (time, error) points: sorted by time, each point whose error
/// is below that of every faster point (ties in time: the smaller error). Non-finite points are
/// ignored.
#[must_use]
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut idx: Vec<usize> =
        (0..points.len()).filter(|&i| points.get(i).is_some_and(|&(t, e)| t.is_finite() && e.is_finite())).collect();
    let key = |i: &usize| points.get(*i).copied().unwrap_or((f64::INFINITY, f64::INFINITY));
    idx.sort_by(|a, b| {
        let (ka, kb) = (key(a), key(b));
        ka.0.total_cmp(&kb.0).then(ka.1.total_cmp(&kb.1))
    });
    let mut best = f64::INFINITY;
    let mut front = Vec::new();
    for i in idx {
        let (_, e) = key(&i);
        if e < best {
            best = e;
            front.push(i);
        }
    }
    front
}

/// The cheapest row (least time) whose error is at most `target`, if any.
#[must_use]
pub fn cheapest_reaching<'r>(rows: &[&'r Row], target: f64) -> Option<&'r Row> {
    rows.iter().copied().filter(|r| r.rel_error <= target).min_by(|a, b| a.seconds.total_cmp(&b.seconds))
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::indexing_slicing)]
mod tests {
    use super::*;

    fn row(mode: &str, tol: f64, err: f64, secs: f64) -> Row {
        Row {
            case: "far".into(),
            precision: "f64".into(),
            mode: mode.into(),
            order: 5,
            grid: "4x8/3".into(),
            patches: 86,
            tolerance: tol,
            value: 0.1,
            reference: 0.1,
            rel_error: err,
            reference_rel_uncertainty: 0.0,
            evaluations: 123,
            seconds: secs,
            repeats: 3,
            threads: 2,
        }
    }

    #[test]
    fn csv_round_trip() {
        let rows = vec![row("paper", f64::NAN, 1e-3, 0.5), row("adaptive", 1e-6, 0.0, 1.25e-5)];
        let back = from_csv(&to_csv(&rows)).unwrap();
        assert_eq!(back.len(), 2);
        assert!(back[0].tolerance.is_nan());
        assert_eq!(back[1].tolerance, 1e-6);
        assert_eq!(back[1].rel_error, 0.0);
        assert_eq!(back[0].seconds, 0.5);
        assert_eq!(back[1].label(), "adaptive f64 tol=1e-6 grid 4x8/3");
        assert!(from_csv("a,b\n").is_err());
        assert!(from_csv(&to_csv(&rows).replace("5e-1", "half")).is_err());
        // The text: `{:e}` numbers, NaN empty, the label last.
        assert_eq!(
            to_csv(&rows).lines().nth(1),
            Some("far,f64,paper,5,4x8/3,86,,1e-1,1e-1,1e-3,0e0,123,5e-1,3,2,paper f64 p=5 grid 4x8/3")
        );
    }

    #[test]
    fn pareto_front_keeps_the_undominated_points() {
        let pts = [(1.0, 1e-2), (2.0, 1e-1), (3.0, 1e-4), (0.5, 1e-1), (3.0, 1e-5), (f64::NAN, 0.0)];
        assert_eq!(pareto_front(&pts), vec![3, 0, 4]);
        let rows =
            [row("paper", f64::NAN, 1e-2, 1.0), row("paper", f64::NAN, 1e-7, 9.0), row("pair", f64::NAN, 1e-7, 3.0)];
        let refs: Vec<&Row> = rows.iter().collect();
        assert_eq!(cheapest_reaching(&refs, 1e-6).unwrap().mode, "pair");
        assert!(cheapest_reaching(&refs, 1e-9).is_none());
    }
}
