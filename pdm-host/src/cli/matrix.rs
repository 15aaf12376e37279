//! The `matrix` command: form factors of the user's own scene.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use pdm_host::scene::{self, matrix::MatrixError, matrix::PairMethod, matrix::Shard, report};

use super::{parse_absolute, parse_order, parse_threads, parse_tolerance, EXIT_FAILURE, EXIT_USAGE};

/// Floating-point width.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Precision {
    /// Single precision (f32): about 1e-5 at best.
    F32,
    /// Double precision (f64).
    F64,
}

/// `pdm-ff matrix SCENE`.
#[derive(Args, Debug)]
#[command(after_help = "The scene file (TOML, or JSON by its .json extension) is described field by field in \
SCENES.md; examples in examples/scenes/.")]
pub struct MatrixArgs {
    /// The scene file (.toml or .json).
    pub scene: PathBuf,
    /// Per-pair relative tolerance of the tolerance mode (the default mode) [default: 1e-6].
    #[arg(long, value_name = "TOL", value_parser = parse_tolerance, conflicts_with = "order", allow_hyphen_values = true)]
    pub tolerance: Option<f64>,
    /// Absolute tolerance on each surface-to-surface form factor F_IJ of the tolerance mode: an
    /// entry within it counts as converged even where the relative tolerance is not met (an
    /// entry that is zero or tiny, a sliver seen past a rim, cannot meet a relative one)
    /// [default: 1e-2 x the tolerance; 0: relative only].
    #[arg(long, value_name = "ABS", value_parser = parse_absolute, conflicts_with = "order", allow_hyphen_values = true)]
    pub absolute: Option<f64>,
    /// Fixed Gauss order per axis instead of a tolerance (no error estimates).
    #[arg(long, value_name = "P", value_parser = parse_order, allow_negative_numbers = true)]
    pub order: Option<usize>,
    /// With --order: Gauss points per variable for touching pairs.
    #[arg(long, value_name = "P", value_parser = parse_order, default_value = "12", requires = "order", allow_negative_numbers = true)]
    pub singular_order: usize,
    /// Floating-point width of the computation.
    #[arg(long, value_enum, default_value_t = Precision::F64)]
    pub precision: Precision,
    /// Write the matrices: .csv (one row per nonzero entry, surfaces then patches), .json
    /// (names, areas, both matrices, error estimates, diagnostics), .npz (NumPy: names, areas,
    /// matrices, row sums, error estimates per level) or .npy (the surface matrix alone).
    /// Written atomically.
    #[arg(long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Compute only slice K of N of the pairs (1 <= K <= N), for running the slices as a job
    /// array; needs --output FILE.json; join them with `pdm-ff merge`.
    #[arg(long, value_name = "K/N", value_parser = parse_shard, requires = "output")]
    pub shard: Option<Shard>,
    /// Worker threads (0: all cores).
    #[arg(long, value_name = "N", default_value = "0", value_parser = parse_threads, allow_negative_numbers = true)]
    pub threads: usize,
}

fn parse_shard(s: &str) -> Result<Shard, String> {
    let Some((k, n)) = s.trim().split_once('/') else { return Err("expected K/N, e.g. 3/8".into()) };
    let n = super::parse_count(n, 1, 1_000_000, "N")?;
    let k = super::parse_count(k, 1, n, "K")?;
    Ok(Shard { index: k - 1, count: n })
}

/// `pdm-ff merge`.
#[derive(Args, Debug)]
pub struct MergeArgs {
    /// The slice files written by `pdm-ff matrix --shard K/N --output FILE.json`, all N of them.
    #[arg(required = true)]
    pub slices: Vec<PathBuf>,
    /// Write the joined matrices (.csv or .json), as `pdm-ff matrix --output` does.
    #[arg(long, value_name = "FILE")]
    pub output: Option<PathBuf>,
}

fn output_format_ok(out: &std::path::Path) -> bool {
    let ext = out.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    matches!(ext.as_deref(), Some("csv" | "json" | "npy" | "npz"))
}

fn write_report(report: &report::SceneReport, out: &std::path::Path) -> ExitCode {
    let written =
        report::encode(report, out).and_then(|bytes| report::write_atomic(out, &bytes).map_err(|e| e.to_string()));
    if let Err(e) = written {
        eprintln!("error: --output {}: {e}", out.display());
        return ExitCode::from(EXIT_FAILURE);
    }
    eprintln!("wrote {}", out.display());
    ExitCode::SUCCESS
}

/// Runs `merge`.
pub fn run_merge(args: &MergeArgs) -> ExitCode {
    if let Some(out) = &args.output {
        if !output_format_ok(out) {
            eprintln!("error: --output {}: unknown format (use a .csv, .json, .npy or .npz file name)", out.display());
            return ExitCode::from(EXIT_USAGE);
        }
    }
    let mut slices = Vec::new();
    for path in &args.slices {
        let read = std::fs::read(path).map_err(|e| e.to_string()).and_then(|bytes| {
            serde_json::from_slice::<scene::SliceFile>(&bytes).map_err(|e| format!("not a slice file: {e}"))
        });
        match read {
            Ok(s) => slices.push(s),
            Err(e) => {
                eprintln!("error: {}: {e}", path.display());
                return ExitCode::from(EXIT_USAGE);
            }
        }
    }
    let (Some(first), Some(first_path)) = (slices.first().cloned(), args.slices.first()) else {
        return ExitCode::from(EXIT_USAGE);
    };
    if let Some((path, _)) = args
        .slices
        .iter()
        .zip(&slices)
        .find(|(_, s)| s.scene != first.scene || s.method != first.method || s.precision != first.precision)
    {
        eprintln!("error: {}: another scene, method or precision than {}", path.display(), first_path.display());
        return ExitCode::from(EXIT_USAGE);
    }
    let folder = first.folder.clone().unwrap_or_else(|| PathBuf::from("."));
    let scene = match scene::build::build_in(&first.scene, &folder) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {}: the scene in it does not build: {}", first_path.display(), e.message);
            return ExitCode::from(EXIT_USAGE);
        }
    };
    let merged = match scene::matrix::merge(slices.into_iter().map(|s| s.result).collect()) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(EXIT_USAGE);
        }
    };
    let report = report::assemble(&scene, &merged, first.method);
    let printed = print_table(&report);
    let written = match &args.output {
        Some(out) => write_report(&report, out),
        None => ExitCode::SUCCESS,
    };
    printed.unwrap_or(written)
}

/// The memory the system can still give (Linux: `MemAvailable` of `/proc/meminfo`), in bytes;
/// `None` where it cannot be read.
fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Runs the command.
/// Prints the report's tables to stdout. A closed pipe (`| head`) is no error: the reader has
/// what it wanted, and `--output` is still written; any other failure (a full disk) is, after
/// `--output` is written: `Some(code)` then.
fn print_table(report: &report::SceneReport) -> Option<ExitCode> {
    match std::io::Write::write_all(&mut std::io::stdout(), report::text(report).as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            eprintln!("error: cannot print the tables: {e}");
            Some(ExitCode::from(EXIT_FAILURE))
        }
        _ => None,
    }
}

pub fn run(args: &MatrixArgs) -> ExitCode {
    let (model, scene) = match scene::load_model(&args.scene) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(EXIT_USAGE);
        }
    };
    for note in scene::vs3_notes(&args.scene) {
        eprintln!("note: {}: {note}", args.scene.display());
    }
    if let Some(out) = &args.output {
        if !output_format_ok(out) {
            eprintln!("error: --output {}: unknown format (use a .csv, .json, .npy or .npz file name)", out.display());
            return ExitCode::from(EXIT_USAGE);
        }
        if args.shard.is_some() && out.extension().and_then(|e| e.to_str()) != Some("json") {
            eprintln!("error: --output {}: a slice (--shard) is written as .json", out.display());
            return ExitCode::from(EXIT_USAGE);
        }
        if let Err(e) = report::check_writable(out) {
            eprintln!("error: --output {}: cannot write there: {e}", out.display());
            return ExitCode::from(EXIT_USAGE);
        }
    }
    let method = match args.order {
        Some(order) => PairMethod::Order { order, singular_order: args.singular_order },
        None => {
            let relative = args.tolerance.unwrap_or(1e-6);
            let absolute = args.absolute.unwrap_or(scene::matrix::DEFAULT_ABSOLUTE * relative);
            PairMethod::Tolerance { relative, absolute }
        }
    };
    let n = scene.patches.len() as u64;
    let needed = scene::matrix::memory_needed(scene.patches.len(), args.shard.map_or(1, |s| s.count));
    if let Some(available) = available_memory() {
        if needed > available {
            eprintln!(
                "error: {}: {} patches need about {:.1} GB for the pair results and matrices, {:.1} GB is available \
                 (use fewer patches, or a machine with more memory)",
                args.scene.display(),
                n,
                needed as f64 / 1e9,
                available as f64 / 1e9
            );
            return ExitCode::from(EXIT_FAILURE);
        }
    }
    let bar = super::progress::Bar::with_units(n * (n + 1) / 2, "pairs");
    let progress = |k: u64| bar.set_position(k);
    let result = match args.precision {
        Precision::F32 => scene::matrix::compute::<f32>(&scene, method, args.shard, args.threads, &progress),
        Precision::F64 => scene::matrix::compute::<f64>(&scene, method, args.shard, args.threads, &progress),
    };
    bar.finish();
    let result = match result {
        Ok(r) => r,
        Err(MatrixError::Pair(e)) => {
            let names = report::patch_names(&scene);
            let name = |i: usize| names.get(i).map_or("?", String::as_str);
            if e.i == e.j {
                eprintln!("error: {}: patch {}: {}", args.scene.display(), name(e.i), e.error);
            } else {
                eprintln!("error: {}: pair {} <-> {}: {}", args.scene.display(), name(e.i), name(e.j), e.error);
            }
            return ExitCode::from(EXIT_FAILURE);
        }
        Err(MatrixError::Threads(e)) => {
            eprintln!("error: {e}");
            return ExitCode::from(EXIT_FAILURE);
        }
    };
    if let (Some(shard), Some(out)) = (args.shard, &args.output) {
        let precision = match args.precision {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        };
        let pairs = result.pairs.len();
        let (skipped, seconds) = (result.skipped, result.seconds);
        // Where `merge` finds the scene's mesh files, wherever it runs from.
        let folder = args.scene.parent().map(|p| if p.as_os_str().is_empty() { std::path::Path::new(".") } else { p });
        let folder = folder.and_then(|p| std::fs::canonicalize(p).ok());
        let slice = scene::SliceFile { scene: model, method, precision: precision.into(), folder, result };
        let written = serde_json::to_vec(&slice)
            .map_err(|e| e.to_string())
            .and_then(|bytes| report::write_atomic(out, &bytes).map_err(|e| e.to_string()));
        if let Err(e) = written {
            eprintln!("error: --output {}: {e}", out.display());
            return ExitCode::from(EXIT_FAILURE);
        }
        println!(
            "slice {}/{} of {}: {pairs} pairs integrated, {skipped} skipped, {seconds:.2} s; wrote {} (join the {} slices with pdm-ff merge)",
            shard.index + 1,
            shard.count,
            args.scene.display(),
            out.display(),
            shard.count
        );
        return ExitCode::SUCCESS;
    }
    let report = report::assemble(&scene, &result, method);
    let printed = print_table(&report);
    let written = match &args.output {
        Some(out) => write_report(&report, out),
        None => ExitCode::SUCCESS,
    };
    printed.unwrap_or(written)
}
