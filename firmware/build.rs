//! Puts the selected board's `memory.x` on the linker search path (cortex-m-rt's
//! `link.x` includes it) and adds defmt's linker script for the rig image.
use std::{env, fs, path::PathBuf};

fn main() {
    let qemu = env::var_os("CARGO_FEATURE_QEMU").is_some();
    let rig = env::var_os("CARGO_FEATURE_RIG").is_some();
    let board = match (qemu, rig) {
        (true, false) => "qemu",
        (false, true) => "rig",
        _ => panic!("enable exactly one board feature: --features qemu or --features rig"),
    };
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap());
    let memory = format!("boards/{board}/memory.x");
    fs::copy(&memory, out.join("memory.x")).unwrap();
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={memory}");
    println!("cargo:rerun-if-changed=build.rs");
    if rig {
        println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
    }
}
