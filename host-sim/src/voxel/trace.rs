//! The voxel simulator's raw trace (docs/formats.md, "Raw trace CSV"): the step stream
//! resampled to the board's ADC rate and put through the analytic simulator's board
//! ([`crate::sim::chain::Board`]), so that `replay` reads it as it reads a `simulate` trace.
//!
//! # From a step to samples
//! A voxel step (1/24 revolution) gives the force on the tool in machine axes averaged over
//! the step. The board samples at a fixed rate (`--sample-rate-hz`, 20 kHz: about 8
//! samples per step at 6000 rpm). Every sample whose time falls in a step,
//! `t_prev <= t_i < t_step`, gets that step's forces (**zero-order hold** of the step
//! average): the integral of the force, and so every tooth average, is kept to within a
//! sample at each step edge, and no sample sees a force before the step that made it.
//!
//! # Frames
//! The step's force on the tool becomes the feed-frame force on the work, as
//! `estimator_core::geometry` and the analytic simulator have it: with `u` the unit XY
//! feed velocity (tool relative to the work) and `n` = `u` turned +90 deg,
//!
//! ```text
//! F_work = -F_tool,   F_ax = u . F_work,   F_ay = n . F_work,   F_at = torque / R
//! ```
//!
//! (`F_ax > 0` resists the feed; light down milling gives `F_ax < 0`). While the tool does
//! not move in XY (plunge, dwell) the last feed direction is kept (+X before the first
//! XY move).
//!
//! # Sync pulses
//! From the voxel's own spindle angle ([`VoxelSample::spindle_angle_rad`], interpolated
//! linearly within the step, exact at constant speed) through the analytic simulator's
//! encoder ([`crate::sim::chain::sync_gen`]): per tooth (default) a pulse at the first
//! sample at or after each time a flute's tip passes the reference, or per revolution
//! flute 0's; with the board's jitter and dropouts. The reference is the voxel's: a tip at
//! machine angle `-sync_phase_deg` (clockwise from +X; default +X), the angle at which the
//! step stream's `tooth_sync` fires with the default phase.
//!
//! # Truth columns
//! `true_dr_mm`, `true_da_mm` measured from the voxels (held from one `tooth_sync` to the
//! next; `true_dr_mm` NaN while the tool does not move in XY), `true_tc_mm` the XY feed per
//! tooth `|v_xy| / (N rpm)` (NaN with the spindle stopped), `true_rpm`,
//! `true_flutes_intact`, and `true_fx_n`, `true_fy_n`, `true_ft_n` the feed-frame forces
//! above (what the board was given). The material removal rate has no column in the raw
//! format: it is in the step CSV (`--steps-csv`) and the run's summary.
//!
//! # Not modelled
//! The toolpath's feed and spindle speed change in steps (no acceleration), which add no
//! inertia load, as in the analytic simulator: `signal.moving_mass_kg` and
//! `signal.spindle_inertia_kg_m2` have no effect here.

use super::cutter::Cutter;
use super::VoxelSample;
use crate::sim::chain::{self, Board, BoardInput, SyncGen};
use crate::sim::{Scenario, SignalChain, ToolSpec};
use crate::trace::{TraceKind, TraceRow, Truth};
use anyhow::{bail, Context, Result};
use estimator_core::monitor::Input;
use estimator_core::tooth::SyncMode;
use estimator_core::MonitorConfig;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The board the voxel trace goes through (`--board FILE`): the `input`, `signal`, `sync`
/// and `seed` of a simulate scenario, same types and TOML shape (every key optional).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoardSpec {
    /// Analog inputs: motor currents (feed drive and spindle models) or a dynamometer.
    /// Default: `MonitorConfig::default().input` (one-axis feed, current-sensed spindle,
    /// placeholder constants).
    #[serde(default = "default_input")]
    pub input: Input,
    /// Lag, noise, ADC, load meter, encoder. Default: ideal (no lag, noise, quantisation or
    /// clipping; a perfect encoder).
    #[serde(default)]
    pub signal: SignalChain,
    /// Encoder pulses per tooth (default) or per revolution.
    #[serde(default)]
    pub sync: SyncMode,
    /// Seed of the noise, jitter and dropout streams (default 1).
    #[serde(default = "default_seed")]
    pub seed: u64,
}

fn default_input() -> Input {
    MonitorConfig::default().input
}

fn default_seed() -> u64 {
    1
}

impl Default for BoardSpec {
    fn default() -> Self {
        BoardSpec {
            input: default_input(),
            signal: SignalChain::default(),
            sync: SyncMode::default(),
            seed: default_seed(),
        }
    }
}

impl BoardSpec {
    /// Parses a board file; errors name `file` and the line.
    pub fn from_toml(text: &str, file: &str) -> Result<BoardSpec> {
        crate::config::parse_toml(text, file)
    }

    /// Reads a board file.
    pub fn load(path: &Path) -> Result<BoardSpec> {
        let file = path.display().to_string();
        let text =
            std::fs::read_to_string(path).with_context(|| format!("cannot read board {file}"))?;
        Self::from_toml(&text, &file)
    }

    /// Checks the board for `cutter` at `sample_rate_hz` with spindle speeds up to
    /// `max_rpm`, with the scenario's own rules (errors name the key: `signal.adc_bits`).
    pub fn validate(&self, cutter: &Cutter, sample_rate_hz: f64, max_rpm: f64) -> Result<()> {
        if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
            bail!("--sample-rate-hz: must be a finite number > 0 (got {sample_rate_hz})");
        }
        // A one-segment scenario carrying this board: Scenario::validate checks the board's
        // parts against the sample rate and the tooth period as it does for `simulate`.
        let sc = Scenario {
            sample_rate_hz,
            seed: self.seed,
            mode: Default::default(),
            coefficients_at: Default::default(),
            element_mm: 0.05,
            tool: ToolSpec {
                radius_mm: cutter.radius_mm,
                flutes: cutter.flutes,
                helix_deg: cutter.helix_deg,
                runout_mm: Vec::new(),
            },
            material: Default::default(),
            input: self.input.clone(),
            sync: self.sync,
            signal: self.signal.clone(),
            workpiece: None,
            output: Default::default(),
            segments: vec![crate::sim::Segment {
                duration_s: 1.0,
                rpm: Some(crate::sim::Profile::Constant(if max_rpm > 0.0 {
                    max_rpm
                } else {
                    1.0
                })),
                feed_mm_min: Some(crate::sim::Profile::Constant(0.0)),
                dr_mm: Some(crate::sim::Profile::Constant(0.0)),
                da_mm: Some(crate::sim::Profile::Constant(0.0)),
                feed_angle_deg: None,
                mode: None,
                label: None,
            }],
            events: Vec::new(),
        };
        sc.validate()
    }

    /// Whether the feed drive has two axes (a dynamometer reads the feed frame: no axes).
    pub fn two_axis(&self) -> bool {
        match &self.input {
            Input::Motor { feed, .. } => feed.two_axis,
            Input::Dynamometer => true,
        }
    }

    /// The columns of the trace: currents or forces by `input`, velocities, truth.
    pub fn trace_kind(&self) -> TraceKind {
        TraceKind::for_input(&self.input, true, true)
    }
}

/// What the resampler produced.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TraceSummary {
    /// Rows handed out.
    pub rows: u64,
    /// Sample rate [Hz].
    pub sample_rate_hz: f64,
    /// Sync pulses in the trace.
    pub sync_pulses: u64,
    /// Sync pulses lost (dropouts).
    pub sync_dropped: u64,
    /// Samples at an ADC rail: feed X, feed Y, spindle.
    pub clipped: [u64; 3],
    /// Levels to give the monitor as `clip` (infinite for a channel that cannot clip).
    pub clip_levels: [f64; 3],
}

/// Turns the voxel step stream into raw trace rows (see the module doc): feed it every
/// [`VoxelSample`] in order with [`Self::step`]. Constant memory.
pub struct TraceSampler {
    board: Board,
    sync: SyncGen,
    t0: f64,
    radius_mm: f64,
    flutes: f64,
    /// Next sample's index.
    next: u64,
    /// End time and spindle angle of the last step.
    prev_t: f64,
    prev_angle: f64,
    /// Feed direction (unit, machine XY).
    dir: [f64; 2],
    sample_rate_hz: f64,
}

impl TraceSampler {
    /// A sampler for `cutter` through `board` at `sample_rate_hz`, the path starting at
    /// `t_start_s` (sample `i` is at `t_start_s + i / sample_rate_hz`). The board is taken
    /// as valid ([`BoardSpec::validate`]).
    pub fn new(board: &BoardSpec, cutter: &Cutter, sample_rate_hz: f64, t_start_s: f64) -> Self {
        TraceSampler {
            board: Board::new(
                &board.input,
                &board.signal,
                sample_rate_hz,
                cutter.radius_mm,
                board.seed,
            ),
            sync: chain::sync_gen(board.sync, cutter.flutes, &board.signal, board.seed),
            t0: t_start_s,
            radius_mm: cutter.radius_mm,
            flutes: f64::from(cutter.flutes),
            next: 0,
            prev_t: t_start_s,
            prev_angle: 0.0,
            dir: [1.0, 0.0],
            sample_rate_hz,
        }
    }

    /// Takes one step and hands `out` the rows of the samples in it (none, or several),
    /// in order; stops at the first error `out` returns.
    pub fn step(
        &mut self,
        s: &VoxelSample,
        mut out: impl FnMut(&TraceRow) -> Result<()>,
    ) -> Result<()> {
        let (t_prev, t1) = (self.prev_t, s.time_s);
        let (a0, a1) = (self.prev_angle, s.spindle_angle_rad);
        self.prev_t = t1;
        self.prev_angle = a1;
        let v = [s.feed_vx_mm_min, s.feed_vy_mm_min];
        let speed = v[0].hypot(v[1]);
        if speed > 1e-9 {
            self.dir = [v[0] / speed, v[1] / speed];
        }
        let [ux, uy] = self.dir;
        // On the work, feed frame: F_work = -F_tool; x along u, y along n = (-uy, ux).
        // (`0 - f`, not `-f`: no `-0` in the trace while nothing is cut.)
        let (fx, fy) = (0.0 - s.fx_n, 0.0 - s.fy_n);
        let input = BoardInput {
            fx_n: ux * fx + uy * fy,
            fy_n: -uy * fx + ux * fy,
            ft_n: s.torque_nm * 1e3 / self.radius_mm,
            dir: self.dir,
            velocity_mm_min: v,
            accel_m_s2: 0.0,
            rpm: s.spindle_rpm,
            alpha_rad_s2: 0.0,
        };
        let truth = Truth {
            dr_mm: s.true_dr_mm as f32,
            da_mm: s.true_da_mm as f32,
            tc_mm: if s.spindle_rpm > 0.0 {
                (speed / (self.flutes * s.spindle_rpm)) as f32
            } else {
                f32::NAN
            },
            rpm: s.spindle_rpm as f32,
            flutes_intact: u32::from(s.flutes_intact),
            fx_n: input.fx_n as f32,
            fy_n: input.fy_n as f32,
            ft_n: input.ft_n as f32,
        };
        let span = t1 - t_prev;
        loop {
            let i = self.next;
            let t = self.t0 + i as f64 / self.sample_rate_hz;
            if t >= t1 {
                break;
            }
            let frac = if span > 0.0 {
                ((t - t_prev) / span).clamp(0.0, 1.0)
            } else {
                1.0
            };
            let (feed, spindle) = self.board.sample(i, &input);
            let row = TraceRow {
                time_s: t,
                sync: self.sync.step(i, a0 + (a1 - a0) * frac),
                feed,
                feed_velocity_mm_min: v.map(|x| x as f32),
                spindle,
                truth,
            };
            self.next += 1;
            out(&row)?;
        }
        Ok(())
    }

    /// Counters so far.
    pub fn summary(&self) -> TraceSummary {
        TraceSummary {
            rows: self.next,
            sample_rate_hz: self.sample_rate_hz,
            sync_pulses: self.sync.emitted,
            sync_dropped: self.sync.dropped,
            clipped: self.board.clipped(),
            clip_levels: self.board.clip_levels(),
        }
    }
}

/// Warns (returns the message) when a one-axis feed drive is given XY motion it cannot
/// carry: its trace has the X axis only, and the monitor reads the feed along +-X.
pub fn one_axis_warning(board: &BoardSpec, moves_y: bool) -> Option<String> {
    if moves_y && !board.two_axis() {
        return Some(
            "the toolpath feeds along Y but the board's feed drive has one axis (X): the \
             trace carries the X current only (give a --board with \
             input.motor.feed.two_axis = true)"
                .to_string(),
        );
    }
    None
}
