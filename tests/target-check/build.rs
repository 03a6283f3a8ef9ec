//! Build setup.
//!
//! - The trace blob of the `monitor-replay` and `icount-bench` programs: `TRACE_BIN=path`
//!   (a TMS1 file from `host-sim trace-bin`; relative paths are taken from the workspace
//!   root) is copied to `OUT_DIR/trace.bin`; without it a tiny built-in trace is written
//!   there, so that plain builds work. Its size is checked against the flash it must fit in.
//! - Link setup for the thumbv7em build: the top-level `memory.x` (STM32F405RG map, which
//!   QEMU's netduinoplus2 machine shares) is put on the linker search path and cortex-m-rt's
//!   `link.x` is added. Nothing of this happens for the host build.

use std::{env, fs, path::PathBuf};

/// Largest blob accepted [bytes]: the image's flash is 1 MiB and the code (with
/// estimator-core and the formatting) takes about 100 KiB of it.
const MAX_BLOB: u64 = 800 * 1024;

fn main() {
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR"));
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("OUT_DIR"));
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=TRACE_BIN");
    trace_blob(&manifest, &out);

    if env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none") {
        return;
    }
    let memory_x = manifest.join("../../memory.x");
    // Copied rather than pointed at, so that only OUT_DIR is on the search path.
    fs::copy(&memory_x, out.join("memory.x")).expect("copy ../../memory.x to OUT_DIR");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={}", memory_x.display());
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
}

/// Writes `OUT_DIR/trace.bin` from `TRACE_BIN` or the built-in trace.
fn trace_blob(manifest: &std::path::Path, out: &std::path::Path) {
    let dst = out.join("trace.bin");
    let Some(src) = env::var_os("TRACE_BIN").filter(|s| !s.is_empty()) else {
        fs::write(&dst, builtin_blob()).expect("write OUT_DIR/trace.bin");
        return;
    };
    let src = manifest.join("../..").join(PathBuf::from(src));
    println!("cargo:rerun-if-changed={}", src.display());
    let len = fs::metadata(&src)
        .unwrap_or_else(|e| panic!("TRACE_BIN={}: {e}", src.display()))
        .len();
    assert!(
        len <= MAX_BLOB,
        "TRACE_BIN={} is {len} bytes; at most {MAX_BLOB} fit in flash beside the code \
         (24 bytes per sample: shorten the trace or lower its sample rate)",
        src.display()
    );
    fs::copy(&src, &dst).unwrap_or_else(|e| panic!("copy TRACE_BIN={}: {e}", src.display()));
}

/// A tiny TMS1 trace (same layout as `src/tms1.rs`): 4 kS/s, a pulse every 100 samples
/// (600 rpm, 4 flutes), constant currents and feed. Enough for a few records.
fn builtin_blob() -> Vec<u8> {
    let rate = 4000.0f32;
    let count = 801u32;
    let mut b = Vec::with_capacity(12 + 24 * count as usize);
    b.extend_from_slice(b"TMS1");
    b.extend_from_slice(&rate.to_le_bytes());
    b.extend_from_slice(&count.to_le_bytes());
    for i in 0..count {
        let sync = if i % 100 == 0 { 1.0f32 } else { 0.0 };
        for v in [0.02f32, 0.0, 360.0, 0.0, 0.4, sync] {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    b
}
