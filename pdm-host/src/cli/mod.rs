//! Command-line parsing and the `validate` command's driver.

mod matrix;
mod progress;

use std::io::Write as _;
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand, ValueEnum};
use pdm_host::validate::{self, report::Report, Mode, Outcome, PaperValues, RunConfig, ValidateError};
use pdm_kernel::MAX_ORDER;

/// Exit code for bad command-line input.
const EXIT_USAGE: u8 = 2;
/// Exit code for a computation that failed.
const EXIT_FAILURE: u8 = 1;

#[derive(Parser, Debug)]
#[command(
    name = "pdm-ff",
    version,
    about = "Radiosity form factors between curved parametric surfaces (Parametric Differential Method)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Recompute the paper's section 4 test (a sphere in a cube) beside the paper's numbers
    /// and exact or independent references.
    Validate(ValidateArgs),
    /// Accuracy against cost sweeps (CSV, SVG, Pareto fronts); curved patches vs polygons.
    Tradeoff(pdm_host::tradeoff::TradeoffArgs),
    /// Form factors of your own scene (a TOML or JSON file): patch and surface matrices with
    /// error estimates, row sums and diagnostics.
    Matrix(matrix::MatrixArgs),
    /// Join the slices written by `matrix --shard K/N` into the scene's matrices.
    Merge(matrix::MergeArgs),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum ModeArg {
    /// The paper's method as written: fixed grid and order, visibility tests at the sample
    /// points, plain sums for edge-adjacent patches.
    Paper,
    /// The best the kernel can do: singular-pair transforms, visibility boundaries in the rule.
    Accurate,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum PrecisionArg {
    F32,
    F64,
    /// f64, then f32, reported side by side.
    Both,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Format {
    /// Tables like the paper's, with our columns added (80 columns).
    Table,
    /// One JSON object on stdout.
    Json,
    /// One row per value.
    Csv,
}

/// Face numbering: 1: z=+3, 6: z=-3 (the faces holding the poles of the sphere's
/// parameterisation), 2: y=-3, 3: y=+3, 4: x=-3, 5: x=+3; opposite pairs 1-6, 2-3, 4-5.
#[derive(Args, Debug)]
#[command(after_help = "Faces: 1: z=+3, 6: z=-3 (the sphere's poles face these), 2: y=-3, 3: y=+3, \
4: x=-3, 5: x=+3. Cube side 6 centred at the origin, sphere of radius R at the centre.")]
struct ValidateArgs {
    /// Method [default: paper; accurate with --tolerance].
    #[arg(long, value_enum)]
    mode: Option<ModeArg>,
    /// Accurate mode with a per-pair relative tolerance: order and subdivision chosen per
    /// patch pair by pdm_kernel::adaptive_exchange (e.g. 1e-8) instead of fixed orders.
    #[arg(long, value_name = "TOL", value_parser = parse_tolerance, allow_hyphen_values = true)]
    tolerance: Option<f64>,
    /// The paper's discretisations: 86 (sphere 4x8 + 3x3 per face) or 280 (sphere 8x8 + 6x6 per face).
    #[arg(long, value_name = "86|280", value_parser = parse_patches, conflicts_with_all = ["sphere_grid", "face_grid"])]
    patches: Option<usize>,
    /// Sphere grid: M cells along phi (pole to pole) x N along theta [default: 4x8].
    #[arg(long, value_name = "MxN", value_parser = parse_sphere_grid, allow_hyphen_values = true)]
    sphere_grid: Option<(usize, usize)>,
    /// Face grid: K x K patches per face [default: 3].
    #[arg(long, value_name = "K", value_parser = parse_face_grid, allow_negative_numbers = true)]
    face_grid: Option<usize>,
    /// Gauss points per axis [default: 5 in paper mode, 8 in accurate mode].
    #[arg(long, value_name = "P", value_parser = parse_order, allow_negative_numbers = true)]
    order: Option<usize>,
    /// Gauss points per variable for patches sharing an edge or vertex (accurate mode).
    #[arg(long, value_name = "P", value_parser = parse_order, default_value = "12", allow_negative_numbers = true)]
    singular_order: usize,
    /// Floating-point width of the computation.
    #[arg(long, value_enum, default_value_t = PrecisionArg::F64)]
    precision: PrecisionArg,
    /// Sphere radius, 0 <= R < 3 (0: the empty cube).
    #[arg(long, value_name = "R", value_parser = parse_radius, default_value = "1", allow_negative_numbers = true)]
    sphere_radius: f64,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
    /// Timed repetitions; times are medians [default: 3 in paper mode, 1 in accurate mode].
    #[arg(long, value_name = "N", value_parser = parse_repeat, allow_negative_numbers = true)]
    repeat: Option<usize>,
    /// Recompute the independent face -> face reference for R = 1 (~2 s) instead of using
    /// the stored values.
    #[arg(long)]
    recompute_reference: bool,
    /// Worker threads (0: all cores).
    #[arg(long, value_name = "N", default_value = "0", value_parser = parse_threads, allow_negative_numbers = true)]
    threads: usize,
}

fn parse_count(s: &str, lo: usize, hi: usize, what: &str) -> Result<usize, String> {
    match s.trim().parse::<i128>() {
        Ok(n) if n >= lo as i128 && n <= hi as i128 => Ok(n as usize),
        Ok(_) => Err(format!("{what} must be an integer in {lo}..={hi}")),
        Err(_) => Err(format!("not an integer ({what} must be in {lo}..={hi})")),
    }
}

fn parse_tolerance(s: &str) -> Result<f64, String> {
    let (lo, hi) = (validate::MIN_TOLERANCE, validate::MAX_TOLERANCE);
    match s.trim().parse::<f64>() {
        Ok(t) if t.is_finite() && (lo..=hi).contains(&t) => Ok(t),
        Ok(_) => Err(format!("the tolerance must be in {lo:e}..={hi:e}")),
        Err(_) => Err(format!("not a number (the tolerance must be in {lo:e}..={hi:e})")),
    }
}

fn parse_absolute(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(t) if t.is_finite() && (0.0..=1.0).contains(&t) => Ok(t),
        Ok(_) => Err("the absolute tolerance must be in 0..=1".into()),
        Err(_) => Err("not a number (the absolute tolerance must be in 0..=1)".into()),
    }
}

fn parse_patches(s: &str) -> Result<usize, String> {
    match s.trim() {
        "86" => Ok(86),
        "280" => Ok(280),
        _ => Err("the paper's discretisations are 86 and 280 (use --sphere-grid/--face-grid for others)".into()),
    }
}

fn parse_face_grid(s: &str) -> Result<usize, String> {
    parse_count(s, 1, validate::MAX_FACE_GRID, "the face grid")
}

fn parse_sphere_grid(s: &str) -> Result<(usize, usize), String> {
    let Some((m, n)) = s.trim().split_once(['x', 'X']) else {
        return Err("expected MxN, e.g. 4x8".into());
    };
    let hi = validate::MAX_SPHERE_GRID;
    Ok((parse_count(m, 1, hi, "M")?, parse_count(n, 1, hi, "N")?))
}

fn parse_order(s: &str) -> Result<usize, String> {
    parse_count(s, 1, MAX_ORDER, "the Gauss order")
}

fn parse_repeat(s: &str) -> Result<usize, String> {
    parse_count(s, 1, validate::MAX_REPEAT, "the repeat count")
}

fn parse_threads(s: &str) -> Result<usize, String> {
    parse_count(s, 0, 1024, "the thread count")
}

fn parse_radius(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(r) if (0.0..3.0).contains(&r) => Ok(r),
        Ok(_) => Err("the sphere radius must satisfy 0 <= R < 3 (the sphere must fit in the cube)".into()),
        Err(_) => Err("not a number".into()),
    }
}

/// Parses the command line and runs it; the process exit code.
pub fn main() -> ExitCode {
    quiet_on_a_closed_pipe();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return clap_error(&e),
    };
    match cli.command {
        Command::Validate(args) => run_validate(&args),
        Command::Matrix(args) => matrix::run(&args),
        Command::Merge(args) => matrix::run_merge(&args),
        Command::Tradeoff(args) => match pdm_host::tradeoff::run(&args) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::FAILURE
            }
        },
    }
}

/// A reader that stops early (`pdm-ff matrix scene.toml | head -4`) closes the pipe, and
/// Rust's `println!`/`eprintln!` panic on the next write. Such a panic ends the program as a
/// process killed by SIGPIPE would (exit code 141, no message: the reader is gone); every
/// other panic goes to the default hook. (The scene tables are written without panicking,
/// so that `--output` is still written after a closed stdout.)
fn quiet_on_a_closed_pipe() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        if message.starts_with("failed printing to std") && message.contains("Broken pipe") {
            std::process::exit(EXIT_CLOSED_PIPE);
        }
        default(info);
    }));
}

/// Exit code after a closed output pipe: 128 + SIGPIPE, as a shell reports a process the
/// signal ended.
const EXIT_CLOSED_PIPE: i32 = 141;

/// Help and version go to stdout with success; errors become one line on stderr.
fn clap_error(e: &clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
            let _ = e.print();
            ExitCode::SUCCESS
        }
        ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand | ErrorKind::MissingSubcommand => {
            let _ = e.print();
            ExitCode::from(EXIT_USAGE)
        }
        _ => {
            eprintln!("{}", one_line(&e.render().to_string()));
            ExitCode::from(EXIT_USAGE)
        }
    }
}

/// The first line of a clap error, with its "[possible values: …]" line appended if any.
fn one_line(text: &str) -> String {
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    let mut line = lines.next().unwrap_or("error: invalid arguments").to_string();
    if let Some(values) = lines.find(|l| l.starts_with("[possible values:")) {
        line.push(' ');
        line.push_str(values);
    }
    line
}

/// Reference computations expected to take longer than this are announced on stderr.
const ANNOUNCE_SECONDS: f64 = 10.0;

/// The reference values, with a spinner (terminal) while the independent reference is being
/// integrated, and a one-line note of its expected duration when that is long.
fn reference(radius: f64, recompute: bool) -> validate::Reference {
    if !validate::reference::computes(radius, recompute) {
        return validate::reference::compute(radius, recompute);
    }
    let expected = validate::reference::estimated_seconds(radius, recompute);
    let about = if expected < 90.0 { format!("{expected:.0} s") } else { format!("{:.0} min", expected / 60.0) };
    if expected > ANNOUNCE_SECONDS {
        eprintln!(
            "note: the independent face -> face reference for R = {radius} takes about {about} \
             (2-core machine; only R = 1 is stored)"
        );
    }
    let spinner = progress::Spinner::new(format!("face -> face reference for R = {radius}, about {about}"));
    let r = validate::reference::compute(radius, recompute);
    spinner.finish();
    r
}

/// Accurate mode's orders in the overview (`pdm-ff validate` with no options): its defaults,
/// which keep every value of the 280-patch scene within 4e-11 in about a second on two cores
/// (BENCHMARKS.md; orders 7/8 are within 1.5e-10 in three quarters of the time, 5/6 within
/// 7e-7 in under half).
const OVERVIEW_ORDER: usize = 8;
/// See [`OVERVIEW_ORDER`].
const OVERVIEW_SINGULAR_ORDER: usize = 12;

fn run_validate(args: &ValidateArgs) -> ExitCode {
    // No option that picks a method, grid, radius, precision or format: the overview.
    let overview = args.mode.is_none()
        && args.tolerance.is_none()
        && args.patches.is_none()
        && args.sphere_grid.is_none()
        && args.face_grid.is_none()
        && args.order.is_none()
        && args.repeat.is_none()
        && args.precision == PrecisionArg::F64
        && args.format == Format::Table
        && args.sphere_radius == 1.0
        && !args.recompute_reference;
    let mode = match (args.mode, args.tolerance) {
        (Some(ModeArg::Paper), _) | (None, None) => Mode::Paper,
        (Some(ModeArg::Accurate), _) | (None, Some(_)) => Mode::Accurate,
    };
    let (sphere_grid, face_grid) = match args.patches {
        Some(280) => ((8, 8), 6),
        _ => (args.sphere_grid.unwrap_or((4, 8)), args.face_grid.unwrap_or(3)),
    };
    let order = args.order.unwrap_or(match mode {
        Mode::Paper => 5,
        Mode::Accurate => 8,
    });
    let config = RunConfig {
        mode,
        sphere_grid,
        face_grid,
        order,
        singular_order: args.singular_order,
        radius: args.sphere_radius,
        tolerance: args.tolerance,
    };
    if let Err(e) = config.check() {
        eprintln!("error: {e}");
        return ExitCode::from(EXIT_USAGE);
    }
    let repeat = args.repeat.unwrap_or(match mode {
        Mode::Paper => 3,
        Mode::Accurate => 1,
    });
    if args.threads > 0 {
        if let Err(e) = rayon::ThreadPoolBuilder::new().num_threads(args.threads).build_global() {
            eprintln!("error: cannot start {} worker threads: {e}", args.threads);
            return ExitCode::from(EXIT_FAILURE);
        }
    }
    let threads = rayon::current_num_threads();

    let reference = reference(config.radius, args.recompute_reference);
    if let validate::reference::Source::Unavailable(why) = &reference.source {
        eprintln!("warning: no independent face -> face reference: {why}");
    }
    let precisions: &[validate::Precision] = match args.precision {
        PrecisionArg::F64 => &[validate::Precision::F64],
        PrecisionArg::F32 => &[validate::Precision::F32],
        PrecisionArg::Both => &[validate::Precision::F64, validate::Precision::F32],
    };
    let patches = args.patches;
    let run = |config: RunConfig, repeat: usize, precisions: &[validate::Precision]| -> Result<Report, ExitCode> {
        let units = validate::compute::work_units(&config) * (repeat * precisions.len()) as u64;
        let bar = progress::Bar::new(units);
        let mut outcomes: Vec<Outcome> = Vec::new();
        for &p in precisions {
            let result = match p {
                validate::Precision::F64 => validate::run::<f64>(&config, repeat, &bar),
                validate::Precision::F32 => validate::run::<f32>(&config, repeat, &bar),
            };
            match result {
                Ok(o) => outcomes.push(o),
                Err(e) => {
                    bar.finish();
                    eprintln!("error: {e}");
                    let code = if matches!(e, ValidateError::BadSetting(_)) { EXIT_USAGE } else { EXIT_FAILURE };
                    return Err(ExitCode::from(code));
                }
            }
        }
        bar.finish();
        Ok(Report {
            config,
            patches,
            repeat,
            threads,
            outcomes,
            reference: reference.clone(),
            paper: PaperValues::for_grid(config.sphere_patches(), config.face_grid, config.radius),
        })
    };
    if overview {
        // The paper's 280-patch grid, once as the paper computed it and once as accurately as
        // about a second allows.
        let grid = RunConfig { sphere_grid: (8, 8), face_grid: 6, ..config };
        let paper_mode = RunConfig { mode: Mode::Paper, order: 5, ..grid };
        let accurate =
            RunConfig { mode: Mode::Accurate, order: OVERVIEW_ORDER, singular_order: OVERVIEW_SINGULAR_ORDER, ..grid };
        let (paper_report, accurate_report) = match (run(paper_mode, 3, precisions), run(accurate, 1, precisions)) {
            (Ok(p), Ok(a)) => (p, a),
            (Err(code), _) | (_, Err(code)) => return code,
        };
        let text = validate::report::overview(&paper_report, &accurate_report);
        let mut stdout = std::io::stdout().lock();
        if stdout.write_all(text.as_bytes()).and_then(|()| stdout.flush()).is_err() {
            return ExitCode::from(EXIT_FAILURE);
        }
        return ExitCode::SUCCESS;
    }
    let report = match run(config, repeat, precisions) {
        Ok(r) => r,
        Err(code) => return code,
    };
    let text = match args.format {
        Format::Table => report.to_table(),
        Format::Csv => report.to_csv(),
        Format::Json => match serde_json::to_string_pretty(&report.to_json()) {
            Ok(s) => s + "\n",
            Err(e) => {
                eprintln!("error: cannot write JSON: {e}");
                return ExitCode::from(EXIT_FAILURE);
            }
        },
    };
    let mut stdout = std::io::stdout().lock();
    if stdout.write_all(text.as_bytes()).and_then(|()| stdout.flush()).is_err() {
        return ExitCode::from(EXIT_FAILURE);
    }
    ExitCode::SUCCESS
}
