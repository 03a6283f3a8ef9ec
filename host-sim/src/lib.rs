//! host-sim: runs estimator-core on the desktop.
//!
//! The library holds every command's logic, so that tests call it directly; `main.rs` only
//! parses arguments and reports errors.
//!
//! - [`gen_poly`]: fits the `f_xt` polynomials and writes `estimator-core/src/fxt_poly.rs`.
//! - [`estimate`]: per-tooth forces in a CSV -> immersion estimates.
//! - [`calibrate`]: friction, spindle idle and cutting coefficients from the user's machine.
//! - [`config`]: the TOML files (tool, coefficients).
//! - [`machine_rs`]: a machine file as Rust source for the firmware build (`machine-rs`).
//! - [`lstsq`]: least squares by Householder QR, for the fit.
//! - [`trace`]: the raw trace CSV (reader, writer) and the binary samples of the QEMU image.
//! - [`replay`]: a trace through the streaming Monitor (`replay`, `bench-replay`), writing
//!   [`records`] (per-tooth CSV) and a [`plot`]; [`kistler`] reads dynamometer exports.
//! - [`sim`]: the analytic trace simulator (`simulate`).
//! - [`demo`]: a built-in cut simulated, replayed, tabulated and plotted (`demo`).
//! - [`teach`]: a good cut's force envelope (teach-in) into the machine file (`teach`).
//! - [`telemetry`]: the board's UART telemetry capture -> records CSV (`decode-telemetry`).

pub mod calibrate;
pub mod config;
pub mod demo;
pub mod estimate;
pub mod evaluate;
pub mod gen_poly;
pub mod kistler;
pub mod lstsq;
pub mod machine_rs;
pub mod plot;
pub mod records;
pub mod replay;
pub mod sim;
pub mod teach;
pub mod telemetry;
pub mod trace;
pub mod voxel;

pub use demo::write_then_rename;
