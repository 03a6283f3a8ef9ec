//! The `f_xt` polynomials of calibrated coefficients.
//!
//! `ESTIMATOR_FXT_POLY=path` (a file written by `host-sim calibrate cutting` or `host-sim
//! gen-poly --coeffs ... --output ...`; relative paths from the workspace root) is copied to
//! `OUT_DIR/fxt_poly_user.rs`, which `fxt_poly_user` includes: the estimator then finds a
//! polynomial for those coefficients besides the committed Table 2 sets. Without it the
//! list is empty and coefficients other than Table 2 use the exact inversion.
//!
//! The file's inner doc comments (`//!`) are dropped: `include!` takes items only.

use std::{env, fs, path::PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=ESTIMATOR_FXT_POLY");
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("OUT_DIR")).join("fxt_poly_user.rs");
    let text = match env::var_os("ESTIMATOR_FXT_POLY").filter(|s| !s.is_empty()) {
        None => "use crate::poly::FxtPoly;\n/// None given.\npub const ALL: &[FxtPoly] = &[];\n"
            .to_string(),
        Some(src) => {
            let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("manifest"));
            let src = manifest.join("..").join(PathBuf::from(src));
            println!("cargo:rerun-if-changed={}", src.display());
            let text = fs::read_to_string(&src).unwrap_or_else(|e| {
                panic!(
                    "ESTIMATOR_FXT_POLY={}: {e} (write it with `host-sim calibrate cutting`)",
                    src.display()
                )
            });
            text.lines()
                .filter(|l| !l.trim_start().starts_with("//!"))
                .map(|l| format!("{l}\n"))
                .collect()
        }
    };
    fs::write(&out, text).expect("write OUT_DIR/fxt_poly_user.rs");
}
