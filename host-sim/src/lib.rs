//! host-sim: runs estimator-core on the desktop.
//!
//! The library holds every command's logic, so that tests call it directly; `main.rs` only
//! parses arguments and reports errors.
//!
//! - [`gen_poly`]: fits the `f_xt` polynomials and writes `estimator-core/src/fxt_poly.rs`.
//! - [`estimate`]: per-tooth forces in a CSV -> immersion estimates.
//! - [`config`]: the TOML files (tool, coefficients).
//! - [`lstsq`]: least squares by Householder QR, for the fit.

pub mod config;
pub mod estimate;
pub mod gen_poly;
pub mod lstsq;
pub mod trace;
pub mod voxel;
