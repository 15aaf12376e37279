//! Regenerates `pdm-kernel/src/gauss_tables.rs` (the kernel's Gauss–Legendre tables) from the
//! multi-precision reference in `pdm_host::gauss_gen`.
//!
//! `cargo run -p pdm-host --bin gen-gauss-tables` writes the file; with `--check` it only compares
//! and exits with status 1 if the committed file differs (printing the first differing line).

use std::process::ExitCode;

use pdm_host::gauss_gen;

const USAGE: &str = "usage: gen-gauss-tables [--check]\n  \
    (no argument)  write pdm-kernel/src/gauss_tables.rs\n  \
    --check        compare with the committed file; exit 1 on any difference";

fn main() -> ExitCode {
    match run() {
        Ok(code) => code,
        Err(e) => {
            eprintln!("gen-gauss-tables: error: {e}");
            ExitCode::from(2)
        }
    }
}

fn run() -> Result<ExitCode, Box<dyn std::error::Error>> {
    let mut check = false;
    for arg in std::env::args().skip(1) {
        match arg.as_str() {
            "--check" => check = true,
            "-h" | "--help" => {
                println!("{USAGE}");
                return Ok(ExitCode::SUCCESS);
            }
            other => return Err(format!("unknown argument `{other}`\n{USAGE}").into()),
        }
    }

    let text = gauss_gen::render_tables()?;
    let path = gauss_gen::tables_path();
    let shown = path.display();

    if check {
        let committed = std::fs::read_to_string(&path).map_err(|e| format!("cannot read {shown}: {e}"))?;
        return Ok(match gauss_gen::first_difference(&committed, &text) {
            None => {
                println!("{shown} is up to date");
                ExitCode::SUCCESS
            }
            Some((line, old, new)) => {
                eprintln!("{shown} differs from the generator at line {line}:");
                eprintln!("  committed: {old}");
                eprintln!("  generated: {new}");
                eprintln!("run `cargo run -p pdm-host --bin gen-gauss-tables` to regenerate it");
                ExitCode::FAILURE
            }
        });
    }

    let unchanged = std::fs::read_to_string(&path).is_ok_and(|old| old == text);
    if unchanged {
        println!("{shown} is already up to date");
    } else {
        std::fs::write(&path, &text).map_err(|e| format!("cannot write {shown}: {e}"))?;
        println!("wrote {shown}");
    }
    Ok(ExitCode::SUCCESS)
}
