//! The raw trace: one row per ADC sample, what the board sees plus, from a simulator, the
//! ground truth. Format: docs/formats.md ("Raw trace CSV").
//!
//! This file fixes the row type and the column names; the streaming reader and writer
//! live beside them.
//!
//! # Design
//! - [`TraceReader`] streams a file a line at a time (one reused buffer, no allocation per
//!   row): `#` comment lines and `# key = value` metadata, then the header, then rows. The
//!   header says what the file carries ([`TraceKind`]); columns it does not know are
//!   ignored. Only the file's structure is an error (a missing column, a row with the wrong
//!   number of fields, an empty field, text where a number belongs), named by file, line
//!   and column. NaN and inf are numbers: they pass through to the Monitor, which flags the
//!   tooth period (`input_fault`), as the board does with a bad ADC reading.
//! - [`TraceWriter`] writes what the reader reads, f32 values in Rust's shortest round-trip
//!   form (`{}`) and the time as an f64 the same way: write -> read is bit-exact.
//! - The fast path is hand-rolled (split on `,`, `str::parse`), not the `csv` crate: replay
//!   speed is parse speed (BENCHMARKS.md, "Replay throughput"). No quoting: a raw trace is
//!   all numbers.
//! - [`encode_samples`] packs samples for the QEMU image (format in docs/formats.md).
//!
//! [`RowSource`] is what replay reads: this reader, or a converted recording
//! ([`crate::kistler::KistlerReader`]).

use anyhow::{anyhow, bail, Context, Result};
use estimator_core::Sample;
use std::collections::VecDeque;
use std::fs::File;
use std::io::{BufRead, BufReader, Write};
use std::path::Path;

/// One sample of a raw trace.
///
/// Input channels follow [`estimator_core::Sample`]; which of `feed_x_a`/`fx_n` and
/// `spindle_a`/`spindle_load_pct` a file carries is told by its header.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct TraceRow {
    /// Time since the start of the trace [s].
    pub time_s: f64,
    /// Tooth-sync (or revolution) pulse at this sample.
    pub sync: bool,
    /// Feed-axis currents X, Y [A] (motor route) or feed-frame forces `F_ax`, `F_ay` [N]
    /// (dynamometer route).
    pub feed: [f32; 2],
    /// Feed velocity X, Y [mm/min]; NaN when the file has no velocity columns.
    pub feed_velocity_mm_min: [f32; 2],
    /// Spindle current [A] or spindle load [%].
    pub spindle: f32,
    /// Ground truth, NaN where unknown.
    pub truth: Truth,
}

/// Ground truth carried by simulated traces (`true_*` columns).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Truth {
    /// Radial depth of cut [mm].
    pub dr_mm: f32,
    /// Axial depth of cut [mm].
    pub da_mm: f32,
    /// Feed per tooth [mm/tooth].
    pub tc_mm: f32,
    /// Spindle speed [rpm].
    pub rpm: f32,
    /// Bit i set while flute i is intact (0xff.. for an unknown count: all set).
    pub flutes_intact: u32,
    /// Feed-frame forces on the tool, feed direction and normal [N].
    pub fx_n: f32,
    /// Normal to the feed [N].
    pub fy_n: f32,
    /// Tangential force (spindle torque / R) [N].
    pub ft_n: f32,
}

impl Default for Truth {
    fn default() -> Self {
        Truth {
            dr_mm: f32::NAN,
            da_mm: f32::NAN,
            tc_mm: f32::NAN,
            rpm: f32::NAN,
            flutes_intact: u32::MAX,
            fx_n: f32::NAN,
            fy_n: f32::NAN,
            ft_n: f32::NAN,
        }
    }
}

/// Column names, in the order the writer emits them.
pub mod columns {
    /// Time [s].
    pub const TIME: &str = "time_s";
    /// Sync pulse, 0 or 1.
    pub const SYNC: &str = "sync";
    /// Feed-axis currents [A].
    pub const FEED_X_A: &str = "feed_x_a";
    /// Second feed axis [A] (optional).
    pub const FEED_Y_A: &str = "feed_y_a";
    /// Feed-frame forces [N] (dynamometer route, instead of the currents).
    pub const FX_N: &str = "fx_n";
    /// Normal force [N] (dynamometer route).
    pub const FY_N: &str = "fy_n";
    /// Feed velocities [mm/min] (optional: the config's nominal feed otherwise).
    pub const FEED_VX: &str = "feed_vx_mm_min";
    /// Second axis velocity.
    pub const FEED_VY: &str = "feed_vy_mm_min";
    /// Spindle current [A].
    pub const SPINDLE_A: &str = "spindle_a";
    /// Spindle load [%] (paper 003), instead of the current.
    pub const SPINDLE_LOAD: &str = "spindle_load_pct";
    /// Ground truth columns.
    pub const TRUE_DR: &str = "true_dr_mm";
    /// Truth: axial depth.
    pub const TRUE_DA: &str = "true_da_mm";
    /// Truth: feed per tooth.
    pub const TRUE_TC: &str = "true_tc_mm";
    /// Truth: spindle speed.
    pub const TRUE_RPM: &str = "true_rpm";
    /// Truth: intact-flute bitmask (decimal integer).
    pub const TRUE_FLUTES: &str = "true_flutes_intact";
    /// Truth: feed force.
    pub const TRUE_FX: &str = "true_fx_n";
    /// Truth: normal force.
    pub const TRUE_FY: &str = "true_fy_n";
    /// Truth: tangential force.
    pub const TRUE_FT: &str = "true_ft_n";
}
