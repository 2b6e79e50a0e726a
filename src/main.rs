//! The `ivt` command line. See `ivt --help` and SPEC §6 for the JSON contract.

mod cli;
mod reproduce;

fn main() -> std::process::ExitCode {
    cli::main()
}
