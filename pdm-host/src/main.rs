//! The `pdm-ff` command line. `pdm-ff validate --help` for the paper's validation.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
