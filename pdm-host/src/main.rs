//! The `pdm` command line. `pdm validate --help` for the paper's validation.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
