//! `pdm-ff tradeoff`: accuracy against cost. Sweeps Gauss order, subdivision, precision and mode on
//! the paper's scene and on catalogue pairs, measuring for each point the relative error against
//! an exact or independent reference, the kernel evaluations and the wall time (median of
//! repeats); writes a CSV, an error-against-time SVG (log–log, Pareto front marked) and the
//! fronts as Markdown. A second study (curved patches against polygons, with a Monte Carlo ray
//! estimator) writes its own CSV, SVG and table.
//!
//! Files in `--out` (default `target/tradeoff`):
//!
//! | file | content |
//! |------|---------|
//! | `tradeoff.csv` | one row per sweep point ([`rows::COLUMNS`]) |
//! | `tradeoff.svg` | one panel per case: error against time, series per mode and precision, Pareto front |
//! | `front.md` | per case: cheapest configuration for 1e-3, 1e-6, 1e-12; the front |
//! | `polygons.csv`, `polygons.svg`, `polygons.md` | the curved-versus-polygons study ([`study`]) |
//!
//! **Precisions.** f64 and f32 in one build. The micromath backend for f32 is a compile-time
//! feature of the kernel that replaces every f32 elementary function of the build, so its rows
//! come from a second build: `cargo run --release -p pdm-host --features micromath -- tradeoff
//! --append`. Such a build sweeps only f32 (labelled `f32-micromath`; f64 is unaffected by the
//! feature) and, with `--append`, keeps the rows of other precisions already in `tradeoff.csv`
//! and redraws the plot and tables from the merged rows. The active backend is detected from
//! `<f32 as Real>::ELEMENTARY_ERROR`.
//!
//! **Modes** ([`engine::Method`]): `paper` (eq. 16 at a fixed order on a fixed grid), `pair`
//! (`pair_exchange` with visibility boundaries and singular transforms), `adaptive`
//! (`adaptive_exchange` at tolerances 1e-1 … 1e-12; f32 stops at 1e-6).
//!
//! **Timing.** Catalogue pairs run on one thread; the scene cases run on all cores (rayon over
//! patch pairs, as `pdm-ff validate`), the kernel itself single-threaded. A point is repeated
//! `--repeats` times (once if it takes over a second) and its median time recorded; a series
//! stops after a point slower than the series budget (20 s, 2 s with `--quick`).

pub mod cases;
pub mod engine;
pub mod mc;
pub mod plot;
pub mod polygon;
pub mod report;
pub mod rows;
pub mod study;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, ValueEnum};
use pdm_kernel::{Real, MAX_ORDER};

use cases::{measure, CaseId};
use rows::Row;

/// Floating-point width of a sweep.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum PrecisionArg {
    /// f64.
    F64,
    /// f32 (with the build's backend: libm, or micromath in a `--features micromath` build).
    F32,
}

/// Options of `pdm-ff tradeoff`.
#[derive(Args, Debug, Clone)]
#[command(after_help = "Merging the micromath rows: run once normally, then\n  \
cargo run --release -p pdm-host --features micromath -- tradeoff --append\n\
which adds f32-micromath rows to OUT/tradeoff.csv and redraws the plot from all rows.")]
pub struct TradeoffArgs {
    /// Directory for the CSV, SVG and Markdown files (created if missing).
    #[arg(long, value_name = "DIR", default_value = "target/tradeoff")]
    pub out: PathBuf,
    /// Timed repetitions per point (the median is recorded; points over 1 s run once).
    #[arg(long, value_name = "N", default_value_t = 3, value_parser = clap::value_parser!(u16).range(1..=1000))]
    pub repeats: u16,
    /// A reduced sweep that finishes in well under 30 s (tests, CI).
    #[arg(long)]
    pub quick: bool,
    /// Highest Gauss order swept (the scene cases stop at 12).
    #[arg(long, value_name = "P", default_value_t = 20, value_parser = parse_order)]
    pub max_order: usize,
    /// Keep the rows of other (case, precision) combinations already in OUT/tradeoff.csv and
    /// redraw from the merged rows (for the micromath build's rows).
    #[arg(long)]
    pub append: bool,
    /// Cases to sweep [default: all].
    #[arg(long, value_enum, value_delimiter = ',', value_name = "CASE,...")]
    pub cases: Vec<CaseId>,
    /// Precisions to sweep [default: f64,f32; f32 only in a micromath build].
    #[arg(long, value_enum, value_delimiter = ',', value_name = "P,...")]
    pub precision: Vec<PrecisionArg>,
    /// Skip the curved-versus-polygons study (and its Monte Carlo curve).
    #[arg(long)]
    pub no_polygons: bool,
    /// Worker threads for the scene cases and the study (0: all cores).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub threads: usize,
    /// No progress lines on stderr.
    #[arg(long)]
    pub quiet: bool,
}

fn parse_order(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(p) if (1..=MAX_ORDER).contains(&p) => Ok(p),
        _ => Err(format!("the order must be an integer in 1..={MAX_ORDER}")),
    }
}

/// `true` if this build's f32 elementary functions are micromath's.
#[must_use]
pub fn micromath_active() -> bool {
    <f32 as Real>::ELEMENTARY_ERROR > 1e-4
}

/// The precision label of f32 rows in this build: "f32" or "f32-micromath".
#[must_use]
pub fn f32_label() -> &'static str {
    if micromath_active() {
        "f32-micromath"
    } else {
        "f32"
    }
}

/// The sweep's CSV name in `--out`.
pub const CSV: &str = "tradeoff.csv";
/// The plot's name.
pub const SVG: &str = "tradeoff.svg";
/// The front tables' name.
pub const FRONT_MD: &str = "front.md";
/// The study's CSV name.
pub const POLYGONS_CSV: &str = "polygons.csv";
/// The study's plot.
pub const POLYGONS_SVG: &str = "polygons.svg";
/// The study's table.
pub const POLYGONS_MD: &str = "polygons.md";

fn write(path: &Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// Runs `pdm-ff tradeoff` (see the module docs): sweeps, writes the files, prints the front tables.
pub fn run(args: &TradeoffArgs) -> Result<(), String> {
    let threads =
        if args.threads == 0 { std::thread::available_parallelism().map_or(1, usize::from) } else { args.threads };
    // Every sweep runs on this pool; its stacks hold the largest capacity the engine
    // instantiates (f64 needs more than f32), see `crate::validate::stack`.
    let stack = crate::validate::stack::thread_stack::<f64>(pdm_kernel::MAX_ORDER * pdm_kernel::MAX_ORDER);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .stack_size(stack)
        .build()
        .map_err(|e| format!("cannot start {threads} worker threads: {e}"))?;
    pool.install(|| run_in_pool(args))
}

fn run_in_pool(args: &TradeoffArgs) -> Result<(), String> {
    std::fs::create_dir_all(&args.out).map_err(|e| format!("cannot create {}: {e}", args.out.display()))?;
    let verbose = !args.quiet;
    let log = |s: &str| {
        if verbose {
            eprintln!("{s}");
        }
    };
    let micromath = micromath_active();
    let precisions: Vec<PrecisionArg> = if !args.precision.is_empty() {
        args.precision.clone()
    } else if micromath {
        vec![PrecisionArg::F32]
    } else {
        vec![PrecisionArg::F64, PrecisionArg::F32]
    };
    let cases: Vec<CaseId> = if args.cases.is_empty() { CaseId::ALL.to_vec() } else { args.cases.clone() };
    log(&format!(
        "tradeoff: f32 backend {} (ELEMENTARY_ERROR {:.1e}); {} worker threads; {} sweep",
        if micromath { "micromath" } else { "libm" },
        <f32 as Real>::ELEMENTARY_ERROR,
        rayon::current_num_threads(),
        if args.quick { "quick" } else { "full" }
    ));
    let budget = if args.quick { 2.0 } else { 20.0 };
    let repeats = usize::from(args.repeats);
    let start = Instant::now();
    let mut new_rows = Vec::new();
    for &case in &cases {
        let references = cases::references(case);
        for &precision in &precisions {
            let label = match precision {
                PrecisionArg::F64 => "f64",
                PrecisionArg::F32 => f32_label(),
            };
            let single = precision == PrecisionArg::F32;
            for series in cases::sweep(case, args.quick, args.max_order, single) {
                let t0 = Instant::now();
                let mut done = 0;
                for &method in &series.methods {
                    let measured = match precision {
                        PrecisionArg::F64 => measure::<f64>(case, method, series.grid, repeats),
                        PrecisionArg::F32 => measure::<f32>(case, method, series.grid, repeats),
                    };
                    let where_ = || format!("{} {label} {} grid {}", case.name(), method.name(), series.grid.label());
                    let m = match measured {
                        Ok(m) => m,
                        // A setting too coarse for the pair (the plain rule on a close pair at
                        // a low order) gives a value the kernel refuses: no point, not a failure.
                        Err(e) if e.contains(engine::REFUSED) => {
                            log(&format!("  {}: {e}; point skipped", where_()));
                            continue;
                        }
                        Err(e) => return Err(format!("{}: {e}", where_())),
                    };
                    let row = to_row(case, label, method, series.grid, &m, &references);
                    let slow = row.seconds > budget;
                    new_rows.push(row);
                    done += 1;
                    if slow {
                        break;
                    }
                }
                let mode = series.methods.first().map_or("", |m| m.name());
                log(&format!(
                    "  {} {label} {mode} grid {}: {done}/{} points, {:.2} s",
                    case.name(),
                    series.grid.label(),
                    series.methods.len(),
                    t0.elapsed().as_secs_f64()
                ));
            }
        }
    }
    log(&format!("tradeoff: sweep done in {:.1} s", start.elapsed().as_secs_f64()));

    let csv_path = args.out.join(CSV);
    let mut rows = Vec::new();
    if args.append && csv_path.exists() {
        let old = std::fs::read_to_string(&csv_path).map_err(|e| format!("cannot read {}: {e}", csv_path.display()))?;
        let produced: Vec<(String, String)> = new_rows.iter().map(|r| (r.case.clone(), r.precision.clone())).collect();
        rows.extend(
            rows::from_csv(&old)?.into_iter().filter(|r| !produced.contains(&(r.case.clone(), r.precision.clone()))),
        );
    }
    rows.extend(new_rows);
    rows.sort_by_key(|r| CaseId::from_name(&r.case));
    write(&csv_path, &rows::to_csv(&rows))?;
    plot::draw(&args.out.join(SVG), &report::sweep_panels(&rows), 2, (820, 560))?;
    let mut front = String::new();
    let _ = writeln!(
        front,
        "Pareto fronts of `pdm-ff tradeoff` ({} rows; precisions: {}).\n",
        rows.len(),
        distinct(rows.iter().map(|r| r.precision.as_str()))
    );
    front.push_str(&report::front_tables(&rows));
    write(&args.out.join(FRONT_MD), &front)?;
    if verbose {
        print!("{front}");
    }

    if !args.no_polygons && precisions.contains(&PrecisionArg::F64) {
        let t0 = Instant::now();
        let settings = study::StudySettings {
            quick: args.quick,
            repeats,
            series_budget: budget / 2.0,
            max_order: args.max_order,
            verbose,
        };
        let study_rows = study::run(&settings)?;
        write(&args.out.join(POLYGONS_CSV), &study::to_csv(&study_rows))?;
        plot::draw(&args.out.join(POLYGONS_SVG), &[report::study_panel(&study_rows)], 1, (1200, 800))?;
        let table = report::study_table(&study_rows);
        write(&args.out.join(POLYGONS_MD), &table)?;
        if verbose {
            println!("### Curved patches against polygons (sphere -> 54 face cells)\n\n{table}");
        }
        log(&format!("tradeoff: polygon study done in {:.1} s", t0.elapsed().as_secs_f64()));
    }
    log(&format!("tradeoff: files in {}", args.out.display()));
    Ok(())
}

fn distinct<'a>(items: impl Iterator<Item = &'a str>) -> String {
    let mut out: Vec<&str> = Vec::new();
    for i in items {
        if !out.contains(&i) {
            out.push(i);
        }
    }
    out.join(", ")
}

fn to_row(
    case: CaseId,
    precision: &str,
    method: engine::Method,
    grid: cases::Grid,
    m: &cases::Measured,
    references: &[(f64, f64)],
) -> Row {
    let mut worst = (f64::NAN, f64::NAN, -1.0, 0.0);
    for (&v, &(r, u)) in m.solution.values.iter().zip(references) {
        let e = ((v - r) / r).abs();
        if !(e <= worst.2) {
            worst = (v, r, e, u);
        }
    }
    Row {
        case: case.name().into(),
        precision: precision.into(),
        mode: method.name().into(),
        order: method.order(),
        grid: grid.label(),
        patches: m.patches,
        tolerance: method.tolerance().unwrap_or(f64::NAN),
        value: worst.0,
        reference: worst.1,
        rel_error: worst.2,
        reference_rel_uncertainty: worst.3,
        evaluations: m.solution.evaluations,
        seconds: crate::validate::median(m.seconds.clone()),
        repeats: m.seconds.len(),
        threads: if case.is_scene() { rayon::current_num_threads() } else { 1 },
    }
}
