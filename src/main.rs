//! The `ivt` command line. See `ivt --help` and SPEC §6 for the JSON contract.
//! The command layer lives in the library ([`ivt::cli`], hidden from its
//! docs) so that the fuzz target of the argument vector (`fuzz/`) reaches it.

fn main() -> std::process::ExitCode {
    ivt::cli::main()
}
