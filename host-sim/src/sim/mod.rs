//! `simulate`: analytic time-domain trace simulator (the "trace simulator").
//!
//! # Design
//! A [`Scenario`] names the tool, the material, the machine (the core's
//! `monitor::Input` drive and spindle models), the signal chain and a timeline of
//! segments (spindle speed, feed, `d_r`, `d_a`, each constant or ramped; air cuts;
//! feed direction) and events (a flute breaking or chipping). [`simulate`] walks the
//! timeline one ADC sample at a time and hands each [`TraceRow`] to a callback; nothing
//! is kept, so a trace of any length runs in constant memory.
//!
//! Per sample:
//! 1. the schedule gives `rpm`, feed, `d_r`, `d_a`, and the spindle angle `theta` and
//!    path position are integrated (trapezoid: exact for linear ramps);
//! 2. [`cutter::Cutter`] integrates the instantaneous elemental forces (eq. 1-3) over
//!    every flute's helix, with per-flute chip loads from runout and damage;
//! 3. [`chain::Board`]: the feed-frame forces become axis loads (the feed force along the
//!    feed velocity, the normal force on the feed direction turned +90 deg, plus `m a`
//!    while the feed ramps) and motor currents through the core's own inverses
//!    ([`FeedDrive::currents_for_loads_a`], [`SpindleModel::signal_for_force`]), so a
//!    replay through `FeedDrive::feed_force_n` / `SpindleModel::tangential_force_n`
//!    inverts exactly what was simulated; a dynamometer gives the forces themselves;
//! 4. [`chain`]: first-order lag, Gaussian noise, ADC quantisation and clipping (or the
//!    CNC's integer spindle load at a low rate) in the board, encoder pulses with jitter
//!    and dropouts ([`chain::sync_gen`]);
//! 5. the row carries the ground truth in its `true_*` fields.
//!
//! Tooth averages of a steady cut equal eq. 7 (tests/simulate.rs): each point of the
//! edge sweeps every angle once per revolution, so the time average is the arc integral
//! of eq. 7 whatever the helix, as long as the coefficients are held at the nominal `t_a`
//! (the default; `coefficients_at = "instantaneous"` is the more realistic model).
//!
//! [`FeedDrive::currents_for_loads_a`]: estimator_core::drive::FeedDrive::currents_for_loads_a
//! [`SpindleModel::signal_for_force`]: estimator_core::drive::SpindleModel::signal_for_force

pub mod chain;
pub mod cutter;
pub mod scenario;

pub use scenario::{
    CoefficientsAt, Event, EventKind, Material, OutputSpec, Profile, Scenario, Segment,
    SignalChain, ToolSpec, Workpiece, MAX_FLUTES,
};

use crate::trace::{TraceKind, TraceRow, TraceWriter, Truth};
use anyhow::Result;
use chain::{Board, BoardInput};
use cutter::{Cut, Cutter};
use scenario::Resolved;
use std::f64::consts::TAU;
use std::io::Write;

/// What a run produced, for the command's report and the tests.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SimSummary {
    /// Rows handed out.
    pub rows: u64,
    /// Length of the trace [s].
    pub duration_s: f64,
    /// Sync pulses in the trace.
    pub sync_pulses: u64,
    /// Sync pulses lost (dropouts).
    pub sync_dropped: u64,
    /// Samples at an ADC rail: feed X, feed Y, spindle.
    pub clipped: [u64; 3],
    /// Levels to give the monitor as `clip` (feed X, feed Y, spindle): a reading at or
    /// beyond is a clipped one; infinite for an unclipped channel.
    pub clip_levels: [f64; 3],
    /// Largest tangential force [N].
    pub peak_ft_n: f64,
    /// Largest feed force magnitude [N].
    pub peak_fx_n: f64,
}

/// Per-flute damage state.
#[derive(Clone, Copy, Debug, Default)]
struct Damage {
    broken: bool,
    chip_mm: f64,
    chip_fraction: f64,
}

/// Levels to configure as the monitor's `clip` (feed X, feed Y, spindle) for a trace of
/// this scenario: the ADC rails, infinite for a channel that cannot clip.
pub fn clip_levels(sc: &Scenario) -> [f64; 3] {
    chain::board_adcs(&sc.input, &sc.signal).map(|a| a.clip_level())
}

/// Runs the scenario, handing every row to `out` in time order; stops at the first error
/// `out` returns. Validates the scenario first (errors name the key).
pub fn simulate(sc: &Scenario, mut out: impl FnMut(&TraceRow) -> Result<()>) -> Result<SimSummary> {
    sc.validate()?;
    let segs = sc.resolve()?;
    let fs = sc.sample_rate_hz;
    let dt = 1.0 / fs;
    let rows = sc.samples();
    let r_mm = sc.tool.radius_mm;
    let n = sc.tool.flutes as usize;
    let mut cutter = Cutter::new(
        &sc.tool,
        sc.material.coefficients(),
        sc.coefficients_at,
        sc.element_mm,
    );
    let spans = sc.workpiece.as_ref().map(|w| w.spans_mm.as_slice());
    let mut events: Vec<&scenario::Event> = sc.events.iter().collect();
    events.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    let mut next_event = 0;
    let mut damage = [Damage::default(); MAX_FLUTES];
    // The damage after each event, with the rotation it happened at: a flute's chip is
    // what the flute before it left when it passed, a pitch of rotation earlier, so the
    // cutter needs every flute's edge as it was up to a revolution ago.
    let mut history: Vec<(f64, [Damage; MAX_FLUTES])> = vec![(f64::NEG_INFINITY, damage)];
    let mut missing = [[0.0f64; MAX_FLUTES]; MAX_FLUTES + 1];
    let pitch = TAU / n as f64;

    let sig = &sc.signal;
    let mut board = Board::new(&sc.input, sig, fs, r_mm, sc.seed);
    let mut sync = chain::sync_gen(sc.sync, sc.tool.flutes, sig, sc.seed);

    let mut summary = SimSummary {
        rows,
        duration_s: rows as f64 * dt,
        clip_levels: clip_levels(sc),
        ..SimSummary::default()
    };
    let mut motion = Motion::new(&segs, dt);
    for i in 0..rows {
        let Step {
            t,
            seg: g,
            rpm,
            feed,
            dr,
            da,
            theta,
            path,
        } = motion.step(i);
        let len = g.t1 - g.t0;
        let tc = feed / (n as f64 * rpm);

        while next_event < events.len() && events[next_event].time_s <= t {
            let e = events[next_event];
            let d = &mut damage[e.flute as usize];
            match e.kind {
                EventKind::Break => d.broken = true,
                EventKind::Chip => {
                    d.chip_mm = d.chip_mm.max(e.length_mm.unwrap_or(0.0));
                    d.chip_fraction = d.chip_fraction.max(e.fraction.unwrap_or(0.0));
                }
            }
            next_event += 1;
            history.push((theta, damage));
        }
        let mut intact = 0u32;
        for (j, d) in damage.iter().take(n).enumerate() {
            if !d.broken && d.chip_mm == 0.0 && d.chip_fraction == 0.0 {
                intact |= 1 << j;
            }
        }
        // Row `k`: the damage as it was `k` pitches of rotation ago.
        for (k, row) in missing.iter_mut().take(n + 1).enumerate() {
            let then = theta - k as f64 * pitch;
            let state = history
                .iter()
                .rev()
                .find(|(at, _)| *at <= then)
                .map_or(&damage, |(_, s)| s);
            for (m, d) in row.iter_mut().zip(state).take(n) {
                *m = if d.broken {
                    f64::INFINITY
                } else {
                    d.chip_mm.max(d.chip_fraction * da)
                };
            }
        }

        let cut = Cut {
            theta,
            mode: g.mode,
            rr: dr / r_mm,
            da_mm: da,
            tc_mm: tc,
            path_mm: path,
        };
        let f = cutter.forces(&cut, &missing[..=n], spans);
        summary.peak_ft_n = summary.peak_ft_n.max(f.ft.abs());
        summary.peak_fx_n = summary.peak_fx_n.max(f.fx.abs());

        // Machine: feed direction, velocities, inertia; then the board.
        let (uy, ux) = g.angle_rad.sin_cos();
        let v = [feed * ux, feed * uy];
        let (feed_out, spindle_out) = board.sample(
            i,
            &BoardInput {
                fx_n: f.fx,
                fy_n: f.fy,
                ft_n: f.ft,
                dir: [ux, uy],
                velocity_mm_min: v,
                accel_m_s2: (g.feed.1 - g.feed.0) / len / 60_000.0,
                rpm,
                alpha_rad_s2: (g.rpm.1 - g.rpm.0) / len * TAU / 60.0,
            },
        );
        let pulse = sync.step(i, theta);

        let truth = if sc.output.truth {
            let touching =
                spans.is_none_or(|sp| sp.iter().any(|&[p, q]| path + r_mm > p && path < q));
            Truth {
                dr_mm: if touching { dr as f32 } else { 0.0 },
                da_mm: da as f32,
                tc_mm: tc as f32,
                rpm: rpm as f32,
                flutes_intact: intact,
                fx_n: f.fx as f32,
                fy_n: f.fy as f32,
                ft_n: f.ft as f32,
            }
        } else {
            Truth::default()
        };
        let row = TraceRow {
            time_s: t,
            sync: pulse,
            feed: feed_out,
            feed_velocity_mm_min: if sc.output.velocity {
                v.map(|x| x as f32)
            } else {
                [f32::NAN; 2]
            },
            spindle: spindle_out,
            truth,
        };
        out(&row)?;
    }
    summary.clipped = board.clipped();
    summary.sync_pulses = sync.emitted;
    summary.sync_dropped = sync.dropped;
    Ok(summary)
}

/// The tool's motion at one sample.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Step<'a> {
    /// Time [s].
    pub t: f64,
    /// The segment it is in.
    pub seg: &'a Resolved,
    /// Spindle speed [rpm] and feed [mm/min], radial and axial depth [mm] there.
    pub rpm: f64,
    pub feed: f64,
    pub dr: f64,
    pub da: f64,
    /// Rotation of flute 0's tip since the start [rad].
    pub theta: f64,
    /// Travel of the tool centre along the path since the start [mm].
    pub path: f64,
}

/// The timeline sample by sample: speeds interpolated in their segment, rotation and
/// travel integrated between samples by the trapezoid rule. The one place both are
/// integrated: the forces and the evaluation's choice of a moment in the cut agree.
pub(crate) struct Motion<'a> {
    segs: &'a [Resolved],
    dt: f64,
    si: usize,
    theta: f64,
    path: f64,
    prev: Option<(f64, f64)>,
}

impl<'a> Motion<'a> {
    /// From the start of `segs` (not empty: `Scenario::resolve` of a validated scenario),
    /// samples `dt` apart.
    pub fn new(segs: &'a [Resolved], dt: f64) -> Self {
        Motion {
            segs,
            dt,
            si: 0,
            theta: 0.0,
            path: 0.0,
            prev: None,
        }
    }

    /// Sample `i` (called for `i = 0, 1, 2, ...` in turn).
    pub fn step(&mut self, i: u64) -> Step<'a> {
        let t = i as f64 * self.dt;
        while self.si + 1 < self.segs.len() && t >= self.segs[self.si].t1 {
            self.si += 1;
        }
        let g = &self.segs[self.si];
        let len = g.t1 - g.t0;
        let u = ((t - g.t0) / len).clamp(0.0, 1.0);
        let lerp = |(a, b): (f64, f64)| a + (b - a) * u;
        let (rpm, feed) = (lerp(g.rpm), lerp(g.feed));
        if let Some((rpm_prev, feed_prev)) = self.prev {
            self.theta += 0.5 * (rpm_prev + rpm) * TAU / 60.0 * self.dt;
            self.path += 0.5 * (feed_prev + feed) / 60.0 * self.dt;
        }
        self.prev = Some((rpm, feed));
        Step {
            t,
            seg: g,
            rpm,
            feed,
            dr: lerp(g.dr),
            da: lerp(g.da),
            theta: self.theta,
            path: self.path,
        }
    }
}

/// The first sample at or after `from_s` at which flute `flute`'s tip has turned to
/// immersion angle `angle_rad` (flute 0's tip at 0 at the start; flute `j` trails it by
/// `j` pitches), or `None` if the scenario ends first.
pub fn time_at_angle(sc: &Scenario, from_s: f64, flute: u8, angle_rad: f64) -> Result<Option<f64>> {
    sc.validate()?;
    let segs = sc.resolve()?;
    let pitch = TAU / f64::from(sc.tool.flutes);
    let mut motion = Motion::new(&segs, 1.0 / sc.sample_rate_hz);
    // Turns of the tip past the angle, counted continuously (no wrap to compare across).
    let turns = |theta: f64| (theta - f64::from(flute) * pitch - angle_rad) / TAU;
    let mut before: Option<f64> = None;
    for i in 0..sc.samples() {
        let s = motion.step(i);
        let now = turns(s.theta);
        if s.t >= from_s {
            if let Some(b) = before {
                if now.floor() > b.floor() {
                    return Ok(Some(s.t));
                }
            }
            before = Some(now);
        }
    }
    Ok(None)
}

/// The columns a scenario's trace has: currents or forces by its `input`, the second feed
/// axis if the drive has one, velocity and truth as `[output]` says.
pub fn trace_kind(sc: &Scenario) -> TraceKind {
    TraceKind::for_input(&sc.input, sc.output.velocity, sc.output.truth)
}

/// Simulates `sc` into a raw trace CSV (docs/formats.md) on `w`; returns the summary and
/// the writer, flushed.
pub fn write_trace<W: Write>(sc: &Scenario, w: W) -> Result<(SimSummary, W)> {
    let mut tw = TraceWriter::new(w, trace_kind(sc), sc.sample_rate_hz)?;
    let summary = simulate(sc, |row| tw.write_row(row))?;
    Ok((summary, tw.finish()?))
}
