//! Error-against-time plots (log–log SVG, plotters' SVG backend: text is emitted as SVG text
//! elements, no font files are read).

use std::path::Path;

use plotters::prelude::*;

/// Smallest error drawn (exact results are drawn here).
pub const ERROR_FLOOR: f64 = 1e-17;

/// Point marker.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Marker {
    /// Filled circle.
    Circle,
    /// Triangle.
    Triangle,
    /// Cross.
    Cross,
    /// Filled square.
    Square,
}

/// One set of points in a panel.
#[derive(Clone, Debug)]
pub struct PlotSeries {
    /// Legend text.
    pub name: String,
    /// Colour.
    pub color: RGBColor,
    /// Marker of the points.
    pub marker: Marker,
    /// (seconds, relative error).
    pub points: Vec<(f64, f64)>,
    /// Connect the points in order (a curve rather than a scatter).
    pub line: bool,
}

/// A horizontal reference line (dashed).
#[derive(Clone, Debug)]
pub struct HLine {
    /// Height (relative error).
    pub y: f64,
    /// Colour.
    pub color: RGBColor,
    /// Legend text (empty: no legend entry).
    pub name: String,
}

/// A staircase line (a Pareto front): legend text (empty: none), colour, points sorted by time.
pub type Front = (String, RGBColor, Vec<(f64, f64)>);

/// One chart.
#[derive(Clone, Debug)]
pub struct Panel {
    /// Caption.
    pub title: String,
    /// Point sets.
    pub series: Vec<PlotSeries>,
    /// Staircase lines (each a Pareto front), with colour and legend text.
    pub fronts: Vec<Front>,
    /// Horizontal lines.
    pub hlines: Vec<HLine>,
}

fn clamp(p: (f64, f64)) -> (f64, f64) {
    (p.0.max(1e-9), p.1.max(ERROR_FLOOR))
}

/// Staircase through front points sorted by time: min error reached by a given time.
fn staircase(front: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for (k, &p) in front.iter().enumerate() {
        let p = clamp(p);
        if k > 0 {
            if let Some(&(_, prev_e)) = out.last() {
                out.push((p.0, prev_e));
            }
        }
        out.push(p);
    }
    out
}

fn err<E: std::fmt::Debug>(e: E) -> String {
    format!("plot: {e:?}")
}

/// Draws `panels` in a grid of `cols` columns, each `panel_size` pixels, into the SVG `path`.
pub fn draw(path: &Path, panels: &[Panel], cols: usize, panel_size: (u32, u32)) -> Result<(), String> {
    let cols = cols.max(1).min(panels.len().max(1));
    let rows = panels.len().div_ceil(cols).max(1);
    let size = (panel_size.0 * cols as u32, panel_size.1 * rows as u32);
    let root = SVGBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let areas = root.split_evenly((rows, cols));
    for (area, panel) in areas.iter().zip(panels) {
        draw_panel(area, panel)?;
    }
    root.present().map_err(err)?;
    Ok(())
}

fn draw_panel<DB: DrawingBackend>(area: &DrawingArea<DB, plotters::coord::Shift>, panel: &Panel) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let all = panel
        .series
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .chain(panel.fronts.iter().flat_map(|f| f.2.iter().copied()))
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .map(clamp);
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, 0.0f64, f64::INFINITY, 0.0f64);
    for (x, y) in all {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    for h in &panel.hlines {
        y0 = y0.min(h.y.max(ERROR_FLOOR));
        y1 = y1.max(h.y);
    }
    if !(x0.is_finite() && y0.is_finite() && x1 > 0.0 && y1 > 0.0) {
        (x0, x1, y0, y1) = (1e-6, 1.0, 1e-16, 1.0);
    }
    let (x0, x1) = (x0 / 2.0, x1 * 2.0);
    let (y0, y1) = (y0 / 5.0, (y1 * 5.0).min(1e3));
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, ("sans-serif", 17))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(62)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("wall time [s] (median)")
        .y_desc("relative error")
        .x_label_formatter(&|x| format!("{x:.0e}"))
        .y_label_formatter(&|y| format!("{y:.0e}"))
        .label_style(("sans-serif", 12))
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.12))
        .draw()
        .map_err(err)?;
    for h in &panel.hlines {
        let style = h.color.stroke_width(1);
        let line = DashedLineSeries::new(vec![(x0, h.y), (x1, h.y)], 6, 4, style);
        let drawn = chart.draw_series(line).map_err(err)?;
        if !h.name.is_empty() {
            let c = h.color;
            drawn.label(h.name.clone()).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], c));
        }
    }
    for s in &panel.series {
        let pts: Vec<(f64, f64)> =
            s.points.iter().copied().filter(|p| p.0.is_finite() && p.1.is_finite()).map(clamp).collect();
        let c = s.color;
        if s.line {
            chart.draw_series(LineSeries::new(pts.clone(), c.stroke_width(1))).map_err(err)?;
        }
        let drawn = match s.marker {
            Marker::Circle => chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled()))),
            Marker::Triangle => chart.draw_series(pts.iter().map(|&p| TriangleMarker::new(p, 4, c.stroke_width(1)))),
            Marker::Cross => chart.draw_series(pts.iter().map(|&p| Cross::new(p, 3, c.stroke_width(1)))),
            Marker::Square => chart
                .draw_series(pts.iter().map(|&p| EmptyElement::at(p) + Rectangle::new([(-3, -3), (3, 3)], c.filled()))),
        }
        .map_err(err)?;
        let m = s.marker;
        drawn.label(s.name.clone()).legend(move |(x, y)| -> DynElement<'static, _, (i32, i32)> {
            match m {
                Marker::Circle => Circle::new((x + 8, y), 3, c.filled()).into_dyn(),
                Marker::Triangle => TriangleMarker::new((x + 8, y), 4, c.stroke_width(1)).into_dyn(),
                Marker::Cross => Cross::new((x + 8, y), 3, c.stroke_width(1)).into_dyn(),
                Marker::Square => Rectangle::new([(x + 5, y - 3), (x + 11, y + 3)], c.filled()).into_dyn(),
            }
        });
    }
    for (name, color, front) in &panel.fronts {
        let c = *color;
        let drawn = chart.draw_series(LineSeries::new(staircase(front), c.stroke_width(2))).map_err(err)?;
        if !name.is_empty() {
            drawn
                .label(name.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], c.stroke_width(2)));
        }
        chart.draw_series(front.iter().map(|&p| Circle::new(clamp(p), 5, c.stroke_width(1)))).map_err(err)?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.4))
        .label_font(("sans-serif", 11))
        .draw()
        .map_err(err)?;
    Ok(())
}
