//! Link setup for the thumbv7em build: the top-level `memory.x` (STM32F405RG map) is put on the
//! linker search path and cortex-m-rt's `link.x` plus defmt's `defmt.x` are added.
//!
//! Note: the host build (an empty `main`) must not see these scripts, so everything is gated
//! on the target OS cargo is building for, not on the OS the build script runs on.

use std::{env, fs, path::PathBuf};

fn main() {
    if env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none") {
        return;
    }
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR"));
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("OUT_DIR"));
    let memory_x = manifest.join("../memory.x");
    // Copied rather than pointed at, so that only OUT_DIR is on the search path.
    fs::copy(&memory_x, out.join("memory.x")).expect("copy ../memory.x to OUT_DIR");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={}", memory_x.display());
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
