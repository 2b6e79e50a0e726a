//! The `ivt` command line. See `ivt --help` and SPEC §6 for the JSON contract.
//!
//! No input may reach a panic in the command layer or the reproduction
//! report: every failure is a `CliError` (exit 2) or a `ReproError`, which
//! these lints enforce outside tests.
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing,
        clippy::unreachable,
        clippy::todo,
        clippy::unimplemented
    )
)]

mod cli;
mod reproduce;

fn main() -> std::process::ExitCode {
    cli::main()
}
