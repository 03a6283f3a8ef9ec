//! Build setup for the thumbv7em bins.
//!
//! - Link: the top-level `memory.x` (STM32F405RG map, which QEMU's netduinoplus2 shares) is
//!   put on the linker search path, with cortex-m-rt's `link.x` and defmt's `defmt.x`.
//! - The QEMU variant's trace: `FIRMWARE_TRACE=path` (a TMS1 blob, `host-sim trace-bin`;
//!   relative paths from the workspace root) is copied to `OUT_DIR/trace.bin`; without it a
//!   tiny built-in trace is written there, so that plain builds work. Its size is checked
//!   against the flash it must fit in.
//!
//! - The machine configuration: `FIRMWARE_MACHINE_RS=path` (Rust source written by
//!   `host-sim machine-rs` from a machine file; relative paths from the workspace root) is
//!   copied to `OUT_DIR/machine.rs`; without it the core's default `MachineConfig` is
//!   written there. `config.rs` includes it.
//!
//! Note: the host build (empty mains) must not see the link scripts, so they are gated on
//! the target OS cargo is building for, not on the OS the build script runs on.

use std::{env, fs, path::PathBuf};

/// Largest trace accepted [bytes]: 1 MiB of flash less about 100 KiB of code.
const MAX_TRACE: u64 = 900 * 1024;

fn main() {
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR"));
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("OUT_DIR"));
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=FIRMWARE_TRACE");
    println!("cargo:rerun-if-env-changed=FIRMWARE_MACHINE_RS");
    trace(&manifest, &out);
    machine(&manifest, &out);

    if env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none") {
        return;
    }
    let memory_x = manifest.join("../memory.x");
    // Copied rather than pointed at, so that only OUT_DIR is on the search path.
    fs::copy(&memory_x, out.join("memory.x")).expect("copy ../memory.x to OUT_DIR");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={}", memory_x.display());
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}

/// Writes `OUT_DIR/machine.rs` from `FIRMWARE_MACHINE_RS` or the default configuration.
fn machine(manifest: &std::path::Path, out: &std::path::Path) {
    let dst = out.join("machine.rs");
    let Some(src) = env::var_os("FIRMWARE_MACHINE_RS").filter(|s| !s.is_empty()) else {
        let default =
            "/// The machine configuration the board is built with (the core's default).\n\
                       pub fn machine() -> estimator_core::MachineConfig {\n    \
                       estimator_core::MachineConfig::default()\n}\n\
                       /// No machine file: nothing to compare with.\n\
                       pub const MACHINE_DEBUG: Option<&str> = None;\n";
        fs::write(&dst, default).expect("write OUT_DIR/machine.rs");
        return;
    };
    let src = manifest.join("..").join(PathBuf::from(src));
    println!("cargo:rerun-if-changed={}", src.display());
    fs::copy(&src, &dst).unwrap_or_else(|e| {
        panic!(
            "FIRMWARE_MACHINE_RS={}: {e} (write it with `host-sim machine-rs --config <machine \
             file> --output <it>`)",
            src.display()
        )
    });
}

/// Writes `OUT_DIR/trace.bin` from `FIRMWARE_TRACE` or the built-in trace.
fn trace(manifest: &std::path::Path, out: &std::path::Path) {
    let dst = out.join("trace.bin");
    let Some(src) = env::var_os("FIRMWARE_TRACE").filter(|s| !s.is_empty()) else {
        fs::write(&dst, builtin()).expect("write OUT_DIR/trace.bin");
        return;
    };
    let src = manifest.join("..").join(PathBuf::from(src));
    println!("cargo:rerun-if-changed={}", src.display());
    let len = fs::metadata(&src)
        .unwrap_or_else(|e| panic!("FIRMWARE_TRACE={}: {e}", src.display()))
        .len();
    assert!(
        len <= MAX_TRACE,
        "FIRMWARE_TRACE={} is {len} bytes; at most {MAX_TRACE} fit in flash beside the code \
         (24 bytes per sample: shorten the trace or lower its sample rate)",
        src.display()
    );
    fs::copy(&src, &dst).unwrap_or_else(|e| panic!("copy FIRMWARE_TRACE={}: {e}", src.display()));
}

/// A tiny TMS1 trace (layout in tests/target-check/src/tms1.rs): 5 kS/s, a pulse every 125
/// samples (600 rpm, 4 flutes), constant currents and feed. Enough for a few records.
fn builtin() -> Vec<u8> {
    let rate = 5000.0f32;
    let count = 2001u32;
    let mut b = Vec::with_capacity(12 + 24 * count as usize);
    b.extend_from_slice(b"TMS1");
    b.extend_from_slice(&rate.to_le_bytes());
    b.extend_from_slice(&count.to_le_bytes());
    for i in 0..count {
        let sync = if i % 125 == 0 { 1.0f32 } else { 0.0 };
        for v in [0.02f32, 0.0, 360.0, 0.0, 0.4, sync] {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    b
}
