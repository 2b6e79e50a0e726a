//! The `ivt` command line. See `ivt --help` and SPEC §6 for the JSON contract.

fn main() -> std::process::ExitCode {
    ivt::cli::main()
}
