//! estimator-core: the physics and the estimators shared by the firmware and host-sim.
//!
//! Data flows one way: samples -> forces -> tooth averages -> immersion -> alarms. This
//! crate holds every stage; the firmware and host-sim only feed it. `no_std`, no heap,
//! and nothing on the signal path can panic: bad input gives a flagged, finite result.
//!
//! - [`geometry`], [`coefficients`], [`forward`]: the mechanistic model of paper 000 (eq. 1-9).
//! - [`estimator`]: immersion ratios from the averages (eq. 10-13), with [`invert`],
//!   [`poly`] (fitted for the motor route, constants in [`fxt_poly`]) and [`table3`].
//! - [`tooth`], [`window`]: tooth-synchronous averages, and where their window begins;
//!   [`handover`]: the chip a broken flute hands on, inside the period.
//! - [`status`]: what every estimate carries.
#![no_std]

#[cfg(test)]
extern crate std;

pub mod alarm;
pub mod coefficients;
pub mod conformance;
pub mod drive;
pub mod estimator;
pub mod fmath;
pub mod forward;
pub mod frontend;
pub mod fxt_poly;
/// `f_xt` polynomials of calibrated coefficients, compiled in from `ESTIMATOR_FXT_POLY`
/// (see build.rs); empty without it.
pub mod fxt_poly_user {
    include!(concat!(env!("OUT_DIR"), "/fxt_poly_user.rs"));
}
pub mod geometry;
pub mod handover;
pub mod invert;
pub mod monitor;
pub mod pipeline;
pub mod poly;
pub mod probe;
pub mod status;
pub mod table;
pub mod table3;
pub mod tooth;
pub mod window;

pub use coefficients::{CuttingCoefficients, LinearCoefficients, PowerLaw, TABLE2};
pub use estimator::{Estimate, Estimator, EstimatorConfig, Measured, Method, Solver};
pub use forward::{average_forces, average_forces_linear, AverageForces, Engagement};
pub use frontend::{AnalogInput, FeedEncoder, FrontEnd};
pub use geometry::{MillingMode, Tool};
pub use monitor::{Monitor, MonitorConfig, MonitorState, Sample, ToothRecord};
pub use pipeline::{MachineConfig, Pipeline, PipelineState};
pub use status::Status;

/// A configuration parameter that cannot be used, named.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConfigError {
    /// The named parameter is NaN or infinite.
    NonFinite(&'static str),
    /// The named parameter is outside its allowed range.
    OutOfRange(&'static str),
    /// `Solver::Polynomial` asked for, but no fitted set matches the coefficients and mode.
    NoPolynomial,
    /// `Solver::Table3` asked for outside down milling with Table 2 coefficients.
    Table3NotApplicable,
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ConfigError::NonFinite(p) => write!(f, "parameter `{p}` is not finite"),
            ConfigError::OutOfRange(p) => write!(f, "parameter `{p}` is out of range"),
            ConfigError::NoPolynomial => f.write_str(
                "no fitted f_xt polynomial for these coefficients and milling mode \
                 (regenerate with `host-sim gen-poly`, or use solver `inversion`)",
            ),
            ConfigError::Table3NotApplicable => f.write_str(
                "Table 3 applies only to down milling with the paper's Table 2 coefficients",
            ),
        }
    }
}
