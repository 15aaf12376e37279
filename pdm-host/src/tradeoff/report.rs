//! Plots and Markdown tables from the rows: the per-case error-against-time panels with their
//! Pareto fronts, "for 1e-3 use …" tables, and the polygon study's figure and table.

use std::fmt::Write as _;

use plotters::style::RGBColor;

use super::cases::CaseId;
use super::plot::{HLine, Marker, Panel, PlotSeries};
use super::rows::{cheapest_reaching, pareto_front, Row};
use super::study::StudyRow;

/// Targets of the front tables.
pub const TARGETS: [f64; 3] = [1e-3, 1e-6, 1e-12];

fn mode_color(mode: &str) -> RGBColor {
    match mode {
        "paper" => RGBColor(31, 119, 180),
        "pair" => RGBColor(214, 39, 40),
        _ => RGBColor(44, 160, 44),
    }
}

fn precision_marker(precision: &str) -> Marker {
    match precision {
        "f64" => Marker::Circle,
        "f32" => Marker::Triangle,
        _ => Marker::Cross,
    }
}

/// Cases present in `rows`, in report order.
#[must_use]
pub fn cases_in(rows: &[Row]) -> Vec<CaseId> {
    CaseId::ALL.into_iter().filter(|c| rows.iter().any(|r| r.case == c.name())).collect()
}

/// One panel per case: a series per (mode, precision), the case's Pareto front, and the
/// reference's uncertainty as a dashed line where it is not exact.
#[must_use]
pub fn sweep_panels(rows: &[Row]) -> Vec<Panel> {
    let mut panels = Vec::new();
    for case in cases_in(rows) {
        let mine: Vec<&Row> = rows.iter().filter(|r| r.case == case.name()).collect();
        let mut keys: Vec<(String, String)> = Vec::new();
        for r in &mine {
            let k = (r.mode.clone(), r.precision.clone());
            if !keys.contains(&k) {
                keys.push(k);
            }
        }
        let series = keys
            .iter()
            .map(|(mode, precision)| PlotSeries {
                name: format!("{mode} {precision}"),
                color: mode_color(mode),
                marker: precision_marker(precision),
                points: mine
                    .iter()
                    .filter(|r| &r.mode == mode && &r.precision == precision)
                    .map(|r| (r.seconds, r.rel_error))
                    .collect(),
                line: false,
            })
            .collect();
        let pts: Vec<(f64, f64)> = mine.iter().map(|r| (r.seconds, r.rel_error)).collect();
        let front = pareto_front(&pts).into_iter().filter_map(|i| pts.get(i).copied()).collect();
        let unc = mine.iter().map(|r| r.reference_rel_uncertainty).fold(0.0, f64::max);
        let hlines = if unc > 0.0 {
            vec![HLine { y: unc, color: RGBColor(120, 120, 120), name: "reference uncertainty".into() }]
        } else {
            Vec::new()
        };
        panels.push(Panel {
            title: case.title().into(),
            series,
            fronts: vec![("Pareto front".into(), RGBColor(0, 0, 0), front)],
            hlines,
        });
    }
    panels
}

fn sci(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else {
        format!("{x:.1e}")
    }
}

/// Markdown: per case, the cheapest configuration reaching each target, and the Pareto front.
#[must_use]
pub fn front_tables(rows: &[Row]) -> String {
    let mut s = String::new();
    for case in cases_in(rows) {
        let mine: Vec<&Row> = rows.iter().filter(|r| r.case == case.name()).collect();
        let unc = mine.iter().map(|r| r.reference_rel_uncertainty).fold(0.0, f64::max);
        let _ = writeln!(s, "### {}\n", case.title());
        let _ = writeln!(s, "| target | cheapest configuration reaching it | rel. error | time [s] | evaluations |");
        let _ = writeln!(s, "|---|---|---|---|---|");
        for target in TARGETS {
            if unc > target {
                let _ = writeln!(s, "| {target:.0e} | not measurable: the reference is uncertain to {unc:.1e} | | | |");
                continue;
            }
            match cheapest_reaching(&mine, target) {
                Some(r) => {
                    let _ = writeln!(
                        s,
                        "| {target:.0e} | {} | {} | {} | {} |",
                        r.label(),
                        sci(r.rel_error),
                        sci(r.seconds),
                        r.evaluations
                    );
                }
                None => {
                    let best = mine.iter().map(|r| r.rel_error).fold(f64::INFINITY, f64::min);
                    let _ = writeln!(s, "| {target:.0e} | not reached (best {}) | | | |", sci(best));
                }
            }
        }
        let pts: Vec<(f64, f64)> = mine.iter().map(|r| (r.seconds, r.rel_error)).collect();
        let front = pareto_front(&pts);
        let labels: Vec<String> = front
            .iter()
            .filter_map(|&i| mine.get(i))
            .map(|r| format!("{} ({}, {} s)", r.label(), sci(r.rel_error), sci(r.seconds)))
            .collect();
        let _ = writeln!(s, "\nPareto front ({} of {} points): {}\n", front.len(), mine.len(), labels.join("; "));
    }
    s
}

fn study_color(row: &StudyRow, uv_rank: usize, ico_rank: usize) -> RGBColor {
    const UV: [RGBColor; 4] =
        [RGBColor(255, 170, 90), RGBColor(255, 127, 14), RGBColor(200, 90, 0), RGBColor(130, 55, 0)];
    const ICO: [RGBColor; 5] = [
        RGBColor(200, 170, 225),
        RGBColor(160, 110, 200),
        RGBColor(128, 70, 180),
        RGBColor(95, 40, 140),
        RGBColor(60, 15, 95),
    ];
    match row.family.as_str() {
        "uv" => UV.get(uv_rank).copied().unwrap_or(UV[3]),
        "ico" => ICO.get(ico_rank).copied().unwrap_or(ICO[4]),
        "mc" => RGBColor(0, 0, 0),
        _ => match row.approach.as_str() {
            "curved-paper" => RGBColor(31, 119, 180),
            "curved-pair" => RGBColor(214, 39, 40),
            _ => RGBColor(44, 160, 44),
        },
    }
}

/// Approaches in `rows`, in order of first appearance.
fn approaches(rows: &[StudyRow]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for r in rows {
        if !out.contains(&r.approach) {
            out.push(r.approach.clone());
        }
    }
    out
}

/// The polygon study's panel: every approach's points and Pareto front, each polyhedron's exact
/// floor as a dashed line in its colour, and the Monte Carlo curve.
#[must_use]
pub fn study_panel(rows: &[StudyRow]) -> Panel {
    let mut series = Vec::new();
    let mut fronts = Vec::new();
    let mut hlines = Vec::new();
    let (mut uv, mut ico) = (0, 0);
    for a in approaches(rows) {
        let mine: Vec<&StudyRow> = rows.iter().filter(|r| r.approach == a).collect();
        let Some(first) = mine.first() else { continue };
        let color = study_color(first, uv, ico);
        match first.family.as_str() {
            "uv" => uv += 1,
            "ico" => ico += 1,
            _ => {}
        }
        let pts: Vec<(f64, f64)> = mine.iter().map(|r| (r.seconds, r.rel_error)).collect();
        let marker = match first.family.as_str() {
            "curved" => Marker::Circle,
            "uv" => Marker::Triangle,
            "ico" => Marker::Cross,
            _ => Marker::Square,
        };
        let name = match first.family.as_str() {
            "uv" | "ico" => format!("{a} ({} facets)", first.elements),
            "mc" => "Monte Carlo rays".into(),
            _ => a.clone(),
        };
        let is_mc = first.family == "mc";
        series.push(PlotSeries { name, color, marker, points: pts.clone(), line: is_mc });
        if !is_mc {
            let front = pareto_front(&pts).into_iter().filter_map(|i| pts.get(i).copied()).collect();
            fronts.push((String::new(), color, front));
        }
        if first.polygon_floor.is_finite() {
            hlines.push(HLine { y: first.polygon_floor, color, name: String::new() });
        }
    }
    Panel {
        title: "sphere -> 54 face cells: curved patches vs flat facets vs rays (dashed: each polyhedron's exact floor)"
            .into(),
        series,
        fronts,
        hlines,
    }
}

fn cheapest_study<'r>(rows: &[&'r StudyRow], target: f64) -> Option<&'r StudyRow> {
    rows.iter().copied().filter(|r| r.rel_error <= target).min_by(|a, b| a.seconds.total_cmp(&b.seconds))
}

fn study_config(r: &StudyRow) -> String {
    match (r.family.as_str(), r.order) {
        ("mc", _) => format!("{:.0e} rays", r.rays as f64),
        ("curved", 0) => format!("tol={:.0e}, {}", r.tolerance, r.grid),
        ("curved", p) => format!("p={p}, {}", r.grid),
        (_, p) => format!("p={p}"),
    }
}

/// Targets of the polygon study's table.
pub const STUDY_TARGETS: [f64; 5] = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6];

/// Markdown table of the polygon study: per approach, the exact floor, the best error reached,
/// and the cheapest time (with its configuration) to reach each of [`STUDY_TARGETS`].
#[must_use]
pub fn study_table(rows: &[StudyRow]) -> String {
    let targets = STUDY_TARGETS;
    let mut s = String::new();
    let head: Vec<String> = targets.iter().map(|t| format!("time to {t:.0e}")).collect();
    let _ = writeln!(s, "| approach | elements | exact floor | best error | {} |", head.join(" | "));
    let _ = writeln!(s, "|---|---|---|---|{}", "---|".repeat(targets.len()));
    for a in approaches(rows) {
        let mine: Vec<&StudyRow> = rows.iter().filter(|r| r.approach == a).collect();
        let Some(first) = mine.first() else { continue };
        let floor = if first.polygon_floor.is_finite() { sci(first.polygon_floor) } else { "—".into() };
        let best = mine.iter().map(|r| r.rel_error).fold(f64::INFINITY, f64::min);
        let elements = if first.family == "mc" {
            "—".to_string()
        } else {
            let mut e: Vec<usize> = mine.iter().map(|r| r.elements).collect();
            e.dedup();
            e.iter().map(ToString::to_string).collect::<Vec<_>>().join("/")
        };
        let mut cells = Vec::new();
        for t in targets {
            cells.push(match cheapest_study(&mine, t) {
                Some(r) => format!("{} s ({})", sci(r.seconds), study_config(r)),
                None => "never".into(),
            });
        }
        let _ = writeln!(s, "| {a} | {elements} | {floor} | {} | {} |", sci(best), cells.join(" | "));
    }
    s
}
