//! The `matrix` command: form factors of the user's own scene.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use pdm_host::scene::{self, matrix::MatrixError, matrix::PairMethod, report};

use super::{parse_order, parse_threads, parse_tolerance, EXIT_FAILURE, EXIT_USAGE};

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
    /// Fixed Gauss order per axis instead of a tolerance (no error estimates).
    #[arg(long, value_name = "P", value_parser = parse_order, allow_negative_numbers = true)]
    pub order: Option<usize>,
    /// With --order: Gauss points per variable for touching pairs.
    #[arg(long, value_name = "P", value_parser = parse_order, default_value = "12", requires = "order", allow_negative_numbers = true)]
    pub singular_order: usize,
    /// Floating-point width of the computation.
    #[arg(long, value_enum, default_value_t = Precision::F64)]
    pub precision: Precision,
    /// Write the matrices: .csv (one row per nonzero entry, surfaces then patches) or .json
    /// (names, areas, both matrices, error estimates, diagnostics). Written atomically.
    #[arg(long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Worker threads (0: all cores).
    #[arg(long, value_name = "N", default_value = "0", value_parser = parse_threads, allow_negative_numbers = true)]
    pub threads: usize,
}

/// Runs the command.
pub fn run(args: &MatrixArgs) -> ExitCode {
    let scene = match scene::load(&args.scene) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(EXIT_USAGE);
        }
    };
    if let Some(out) = &args.output {
        if !matches!(out.extension().and_then(|e| e.to_str()), Some("csv" | "json")) {
            eprintln!("error: --output {}: unknown format (use a .csv or .json file name)", out.display());
            return ExitCode::from(EXIT_USAGE);
        }
    }
    let method = match args.order {
        Some(order) => PairMethod::Order { order, singular_order: args.singular_order },
        None => PairMethod::Tolerance(args.tolerance.unwrap_or(1e-6)),
    };
    let n = scene.patches.len() as u64;
    let bar = super::progress::Bar::with_units(n * (n + 1) / 2, "pairs");
    let progress = |k: u64| bar.set_position(k);
    let result = match args.precision {
        Precision::F32 => scene::matrix::compute::<f32>(&scene, method, args.threads, &progress),
        Precision::F64 => scene::matrix::compute::<f64>(&scene, method, args.threads, &progress),
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
    let report = report::assemble(&scene, &result, method);
    print!("{}", report::text(&report));
    if let Some(out) = &args.output {
        let written =
            report::encode(&report, out).and_then(|bytes| report::write_atomic(out, &bytes).map_err(|e| e.to_string()));
        if let Err(e) = written {
            eprintln!("error: --output {}: {e}", out.display());
            return ExitCode::from(EXIT_FAILURE);
        }
        eprintln!("wrote {}", out.display());
    }
    ExitCode::SUCCESS
}
