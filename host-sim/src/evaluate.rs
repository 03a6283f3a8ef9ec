//! `evaluate-alarms`: the alarm detectors measured on many simulated cuts.
//!
//! # Design
//! Each case is a scenario for [`crate::sim`] built from random draws (tool, speed, feed,
//! engagement, milling mode, runout up to one flute cutting 35 % more, 3 % noise on the
//! tooth averages, current-loop lag, the encoder's pulse at any angle to the flutes, entry
//! into and exit from the work through faces square to the feed, feed and speed changes),
//! then
//! replayed sample by sample through `estimator_core::Pipeline` (the firmware's code) with
//! the board model the scenario was simulated with. Five sets:
//! - normal: no damage; every alarm is a false alarm;
//! - break: one flute breaks in a steady stretch, in its cut (out of the cut it carries no
//!   load): at a random time, moved on to when the flute's tip is at an angle of the
//!   engaged arc drawn with density in proportion to the tip's chip thickness;
//! - chip: one flute loses 30-70 % of its cutting edge (from the tip), the same way;
//! - gone: every flute breaks at once (the tool is lost), the same way;
//! - overload: the configured maximum engagement is 80 % of the cut's in both directions;
//! - taught: teach-in on, the envelope recorded from the same job (another noise seed) and
//!   the job run again unchanged: every alarm is a false alarm;
//! - teach: the same, on stock 40 % deeper than the taught job's (a wrong blank, a missed
//!   roughing pass): a teach-in excursion must be raised;
//! - wear: the cutting forces rise by half over the steady stretches (a wearing edge:
//!   emulated by the axial depth rising while the wear tracker's reference stays the
//!   programmed engagement), `DriftReference::Known`: the wear warning must come, from the
//!   time the true multiplier crosses its warning level.
//!
//! An alarm before the damage (or of another cause than the one expected) is false.
//! Latency is from the damage's first effect on the forces to the moment the output
//! latched: the end of the tooth period that raised the alarm, or the sample of a drop trip
//! inside a period (`estimator_core::handover`; the onset: the true forces, integrated from the damage, have
//! differed from the undamaged run's by a tenth of a tooth period's force; with damage in
//! the cut, within a few samples of it). "Within one revolution" is counted both from
//! that onset and from the damage itself. A flute that breaks late in its cut loses
//! little of that cut (its chip is thin there) and the next flute takes only that: the
//! first revolution may hold little to see before the broken flute comes round.
//! False alarms are counted per hour of cutting (time the truth has the tool in the work).
//!
//! A case is its kind, index and draw seed. Seeds below [`LEGACY_SEEDS`] draw as the
//! first evaluations did (the cases named in tests reproduce), where seeds that differ only
//! in bits 8-14 share their cases' draws with other noise; from there on each case draws
//! its own, so a block of seeds there is held out in its cuts as well as in its noise.

use anyhow::{anyhow, bail, Result};
use estimator_core::alarm::{
    AlarmConfig, AlarmEvent, AlarmOutput, AlarmState, Cause, DriftReference, EnvelopeRecorder,
};
use estimator_core::{
    average_forces, Engagement, EstimatorConfig, MachineConfig, MillingMode, MonitorConfig,
    PipelineState, ToothRecord, TABLE2,
};
use std::fmt::Write as _;

use crate::sim::{self, Scenario};

/// What kind of damage a case has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// None.
    Normal,
    /// One flute breaks.
    Break,
    /// One flute chips.
    Chip,
    /// The whole tool is lost.
    Gone,
    /// The cut is heavier than the configured maximum engagement.
    Overload,
    /// Teach-in on, the taught job run again.
    Taught,
    /// Teach-in on, the job on deeper stock.
    Teach,
    /// The forces rise by half over the cut, against a known engagement.
    Wear,
}

impl Kind {
    /// Set name.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Normal => "normal",
            Kind::Break => "break",
            Kind::Chip => "chip",
            Kind::Gone => "gone",
            Kind::Overload => "overload",
            Kind::Taught => "taught",
            Kind::Teach => "teach",
            Kind::Wear => "wear",
        }
    }

    /// The alarm this set must raise.
    pub fn expected(self) -> Option<Cause> {
        match self {
            Kind::Normal | Kind::Taught => None,
            Kind::Break | Kind::Chip => Some(Cause::Breakage),
            Kind::Gone => Some(Cause::ToolGone),
            Kind::Overload => Some(Cause::Overload),
            Kind::Teach => Some(Cause::TeachExcursion),
            Kind::Wear => Some(Cause::Wear),
        }
    }

    /// Whether the damage has an instant (latency "within one revolution" means something).
    pub fn sudden(self) -> bool {
        matches!(self, Kind::Break | Kind::Chip | Kind::Gone)
    }

    /// The kind of set `name` ([`Kind::name`]).
    pub fn parse(name: &str) -> Option<Kind> {
        KINDS.into_iter().find(|k| k.name() == name)
    }
}

/// How many cases of each kind.
#[derive(Clone, Copy, Debug)]
pub struct SetSizes {
    /// Cases per kind, in [`KINDS`] order.
    pub counts: [usize; 8],
}

/// The kinds, in report order.
pub const KINDS: [Kind; 8] = [
    Kind::Normal,
    Kind::Break,
    Kind::Chip,
    Kind::Gone,
    Kind::Overload,
    Kind::Taught,
    Kind::Teach,
    Kind::Wear,
];

impl SetSizes {
    /// CI's set: small enough for a debug-build minute, every kind present.
    pub const SMALL: SetSizes = SetSizes {
        counts: [10, 10, 5, 4, 4, 3, 3, 3],
    };
    /// The figures in BENCHMARKS.md.
    pub const FULL: SetSizes = SetSizes {
        counts: [120, 120, 60, 30, 30, 30, 30, 30],
    };
}

/// One drawn case.
#[derive(Clone, Debug)]
pub struct Case {
    /// Damage kind.
    pub kind: Kind,
    /// Index within its set and the draw seed: with `kind`, what reproduces the case.
    pub index: usize,
    /// Draw seed.
    pub seed: u64,
    /// The simulated cut.
    pub scenario: Scenario,
    /// The monitor and alarms it is replayed with.
    pub machine: MachineConfig,
    /// When the damage happens [s] (none for normal cases).
    pub damage_s: Option<f64>,
    /// Spindle speed at the damage [rpm] (for "within one revolution").
    pub rpm_at_damage: f64,
    /// Teach-in: the good job the envelope is recorded from (replayed first).
    pub taught: Option<Scenario>,
    /// Mean tangential force of the steady cut (eq. 7) [N].
    pub ft_n: f64,
}

impl Case {
    /// One sample's noise on the feed and on the tangential force [N]: what leaves
    /// [`NOISE_REL`] of the steady tangential force on a tooth average (the feed and
    /// spindle channels' noise in their units, through the board's gains).
    pub fn noise_n(&self) -> f64 {
        self.scenario.signal.feed_noise * FEED_N_PER_A
    }
}

/// What came out of one case.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outcome {
    /// Damage kind.
    pub kind: Kind,
    /// The case's index within its set.
    pub index: usize,
    /// The case's draw seed.
    pub seed: u64,
    /// Cutting time [s].
    pub cutting_s: f64,
    /// The first alarm: time [s] and cause.
    pub first_alarm: Option<(f64, Cause)>,
    /// Damage time [s].
    pub damage_s: Option<f64>,
    /// First instant the damage changes the cutting forces [s]: the broken flute's first
    /// missed cut (a flute that breaks out of the cut changes nothing until it comes
    /// round). Sudden kinds only.
    pub onset_s: Option<f64>,
    /// Tooth period at the damage [s].
    pub tooth_s: f64,
    /// Revolution at the damage [s].
    pub rev_s: f64,
    /// How much the damage changed the forces in its first revolution: the true forces'
    /// departure from the undamaged run's, integrated over the revolution after the
    /// damage, in tooth periods of the steady cut's force. Sudden kinds only.
    pub first_rev_teeth: Option<f64>,
    /// How far the damage stands above the sensors' noise by the goal's deadline, one
    /// revolution past the onset: the true feed and tangential forces' departures from the
    /// undamaged run's, from the damage to the deadline, against one sample's noise
    /// ([`Case::noise_n`]), as the separation (in sigma) of the best detector there can
    /// be, one told in advance when and how the forces will change (a matched filter), on
    /// every sample and on the tooth periods' sums. Sudden kinds only.
    pub separation: Option<Separation>,
}

impl Outcome {
    /// The expected alarm, after the damage: its latency [s].
    pub fn detected_after_s(&self) -> Option<f64> {
        let (t, cause) = self.first_alarm?;
        let d = self.damage_s?;
        (Some(cause) == self.kind.expected() && t >= d).then_some(t - d)
    }

    /// The expected alarm's latency from the damage's first effect on the forces [s]
    /// (from the damage itself where there is no onset).
    pub fn detected_after_onset_s(&self) -> Option<f64> {
        let l = self.detected_after_s()?;
        let wait = match (self.onset_s, self.damage_s) {
            (Some(o), Some(d)) => o - d,
            _ => 0.0,
        };
        Some((l - wait).max(0.0))
    }

    /// An alarm that should not have been raised (before the damage, or of another cause).
    pub fn false_alarm(&self) -> bool {
        match self.first_alarm {
            None => false,
            Some(_) => self.detected_after_s().is_none(),
        }
    }
}

/// Deterministic draws (xorshift64*), so a seed reproduces a set.
struct Draw(u64);

impl Draw {
    fn new(seed: u64) -> Self {
        Draw(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1)
    }
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    fn pick<T: Copy>(&mut self, v: &[T]) -> T {
        v[((self.unit() * v.len() as f64) as usize).min(v.len() - 1)]
    }
}

/// The board every case is simulated and replayed with (one feed axis, current-sensed
/// spindle), as scenario TOML.
const BOARD: &str = r#"
[input.motor.feed]
two_axis = false
[[input.motor.feed.axes]]
torque_constant_nm_per_a = 1.2
screw_lead_mm = 10.0
efficiency = 0.9
current_offset_a = 0.05
coulomb_n = 40.0
viscous_n_per_mm_min = 0.02
stiction_band_mm_min = 1.0
sign = 1.0
[[input.motor.feed.axes]]
torque_constant_nm_per_a = 1.2
screw_lead_mm = 10.0
efficiency = 0.9
current_offset_a = 0.0
coulomb_n = 40.0
viscous_n_per_mm_min = 0.02
stiction_band_mm_min = 1.0
sign = 1.0
[input.motor.spindle.current]
torque_constant_nm_per_a = 0.8
[[input.motor.spindle.current.idle_current_a]]
from_rpm = 0.0
slope = 0.0001
intercept = 0.5
"#;

/// Feed force per ampere of [`BOARD`]'s axis [N/A]: 2 pi eta K_t / L.
const FEED_N_PER_A: f64 = 2.0 * std::f64::consts::PI * 0.9 * 1.2 / 0.010;
/// Spindle torque constant of [`BOARD`] [N m/A].
const SPINDLE_NM_PER_A: f64 = 0.8;
/// ADC sample rate of every case [Hz].
const FS_HZ: f64 = 10_000.0;
/// Noise on the tooth-average forces, relative to the tangential force.
const NOISE_REL: f64 = 0.03;

/// The damage's onset: the instant the true forces, integrated from the damage on, have
/// differed from the undamaged case's by this share of one tooth period's mean tangential
/// force (a sliver of helix still in the cut when the flute breaks is not its missed cut).
const ONSET_SHARE: f64 = 0.1;

/// Revolutions per bin of a taught envelope (the jobs are 140-200 revolutions long).
const TEACH_REVS_PER_BIN: u16 = 2;
/// Teach set: stock this much deeper than the taught job's.
const TEACH_DEEPER: f64 = 1.4;
/// Wear set: relative rise of the cutting forces over the steady stretches.
const WEAR_RISE: f64 = 0.5;
/// Wear set: the tracker's forgetting factor (memory of about 20 revolutions).
const WEAR_LAMBDA: f32 = 0.95;

/// Seeds below this draw their cases as the first evaluations did, so that the cases named
/// in tests and in BENCHMARKS.md reproduce: from the seed XOR the index shifted 8 bits, so
/// seeds that differ only in bits 8-14 share their draws (seeds 1-6528 hold 32 768
/// distinct draws of a 120-case set, and a block of 96 seeds past 256 repeats earlier
/// ones' geometry with other noise). From here on every seed and index draws its own
/// (`draw_keys`).
pub const LEGACY_SEEDS: u64 = 8192;

/// The key of case `index`'s draw and its noise seed, at draw seed `seed`.
fn draw_keys(kind: Kind, index: usize, seed: u64) -> (u64, u64) {
    let of_kind = (kind as u64 + 1).wrapping_mul(0x0051_ed27);
    if seed < LEGACY_SEEDS {
        (
            seed ^ ((index as u64) << 8) ^ of_kind,
            seed.wrapping_add(index as u64 * 7919),
        )
    } else {
        // Index below 256 (the largest set is 120): `seed << 8 | index` is one to one, and
        // past every legacy noise seed (under 8192 + 255 * 7919). Scenario seeds are TOML
        // integers (i64): the top bit stays clear.
        let case = (seed << 8 | (index as u64 & 0xff)) & (u64::MAX >> 1);
        (sim::chain::splitmix64(case) ^ of_kind, case)
    }
}

/// How far ahead of the tool centre the engaged arc reaches [mm], `R s` (`s` the largest
/// `sin(phi)` on the arc, up or down milling alike): the travel over which a cut grows at
/// an entry and shrinks at an exit through a face square to the feed.
fn arc_reach_mm(radius_mm: f64, rr: f64) -> f64 {
    radius_mm
        * if rr >= 1.0 {
            1.0
        } else {
            (rr * (2.0 - rr)).sqrt()
        }
}

/// Draws case `index` of `kind` from `seed`.
pub fn draw_case(kind: Kind, index: usize, seed: u64) -> Result<Case> {
    let (draw_key, seed_case) = draw_keys(kind, index, seed);
    let mut d = Draw::new(draw_key);
    let flutes: u8 = d.pick(&[2, 3, 4]);
    let radius = d.pick(&[4.0, 5.0, 6.0, 8.0]);
    let rpm = d.range(1200.0, 4000.0);
    let tc = d.range(0.04, 0.2);
    let mode = if d.unit() < 0.7 {
        MillingMode::Down
    } else {
        MillingMode::Up
    };
    let rr = d.range(0.2, 1.6);
    let ra = d.range(0.3, 1.5);
    let (dr, da) = (rr * radius, ra * radius);
    let feed = tc * f64::from(flutes) * rpm;
    let tool = estimator_core::Tool {
        radius_mm: radius as f32,
        flutes,
        helix_deg: 30.0,
    };
    let e = Engagement {
        rr: rr as f32,
        ra: ra as f32,
        tc_mm: tc as f32,
    };
    let ft = f64::from(average_forces(&tool, &TABLE2, mode, e).ft_n);
    // Per-sample noise that leaves NOISE_REL of F_at on a tooth average.
    let spt = FS_HZ * 60.0 / (rpm * f64::from(flutes));
    let f_noise = NOISE_REL * ft * spt.sqrt();
    let feed_noise = f_noise / FEED_N_PER_A;
    let spindle_noise = f_noise * radius * 1e-3 / SPINDLE_NM_PER_A;
    // Runout: one flute out by up to 35 % of the chip, the others a little.
    let mut runout = vec![d.range(0.0, 0.35) * tc];
    for _ in 1..flutes {
        runout.push(d.range(-0.05, 0.05) * tc);
    }
    let rev_s = 60.0 / rpm;

    // Timeline: air, entry, steady, a feed change, steady, a speed change, steady, exit,
    // air; each change on or off by draw. The engagement is constant: the tool enters and
    // leaves the work through faces square to the feed (`[workpiece]`), the fastest an
    // engagement can change with a straight face: the cut grows (or shrinks) while the
    // centre travels the arc's reach.
    let reach_mm = arc_reach_mm(radius, rr);
    let feed_change = d.unit() < 0.5;
    let speed_change = d.unit() < 0.5;
    let feed2 = feed * if feed_change { d.range(0.6, 1.5) } else { 1.0 };
    let rpm2 = rpm
        * if speed_change {
            d.range(0.85, 1.15)
        } else {
            1.0
        };
    let steady = [40.0 * rev_s, 25.0 * rev_s, 25.0 * rev_s];
    let entry_s = reach_mm / (feed / 60.0);
    let exit_s = reach_mm / (feed2 / 60.0);
    let mut t = 0.0;
    // (label, duration, rpm, feed); the axial depth is laid on when written.
    let mut parts: Vec<(String, f64, String, String)> = Vec::new();
    let mut seg = |label: &str, dur: f64, rpm: String, feed: String| {
        parts.push((label.to_string(), dur, rpm, feed));
    };
    let air = 10.0 * rev_s;
    seg("air", air, rpm.to_string(), feed.to_string());
    seg("entry", entry_s, rpm.to_string(), feed.to_string());
    t += air + entry_s;
    let steady_1 = (t, t + steady[0]);
    seg("steady", steady[0], rpm.to_string(), feed.to_string());
    t += steady[0];
    let ramp = 5.0 * rev_s;
    seg("feed", ramp, rpm.to_string(), format!("[{feed}, {feed2}]"));
    t += ramp;
    let steady_2 = (t, t + steady[1]);
    seg("steady", steady[1], rpm.to_string(), feed2.to_string());
    t += steady[1];
    seg("speed", ramp, format!("[{rpm}, {rpm2}]"), feed2.to_string());
    t += ramp;
    let steady_3 = (t, t + steady[2]);
    seg("steady", steady[2], rpm2.to_string(), feed2.to_string());
    seg("exit", exit_s, rpm2.to_string(), feed2.to_string());
    seg("air", air, rpm2.to_string(), feed2.to_string());
    // The faces along the path: the first contact at the end of the first air move, the
    // last at the end of the exit (the centre travels `reach_mm` over each).
    let path_mm = |upto: usize| -> f64 {
        let (f1, f2) = (feed / 60.0, feed2 / 60.0);
        let rates = [f1, f1, f1, 0.5 * (f1 + f2), f2, f2, f2, f2, f2];
        parts
            .iter()
            .zip(rates)
            .take(upto)
            .map(|(p, v)| p.1 * v)
            .sum()
    };
    let work_mm = [path_mm(1) + reach_mm, path_mm(8)];

    // Damage: in one of the steady stretches, past its first 5 revolutions.
    let stretch = d.pick(&[steady_1, steady_2, steady_3]);
    let (damage_s, rpm_at) = match kind {
        Kind::Normal | Kind::Taught => (None, rpm),
        // Overloaded (or off the taught envelope) from the moment the cut is entered.
        Kind::Overload | Kind::Teach => (Some(air), rpm),
        // When the true multiplier crosses the warning level.
        Kind::Wear => {
            let warn = f64::from(AlarmConfig::default().drift.warn_multiplier);
            let t = steady_1.0 + (steady_3.1 - steady_1.0) * (warn - 1.0) / WEAR_RISE;
            (Some(t), if t > steady_3.0 { rpm2 } else { rpm })
        }
        _ => {
            let t = d.range(stretch.0 + 5.0 * rev_s, stretch.1 - 5.0 * rev_s);
            let rpm_at = if t > steady_3.0 { rpm2 } else { rpm };
            (Some(t), rpm_at)
        }
    };
    let flute = (d.unit() * f64::from(flutes)) as u8 % flutes;
    let in_arc = d.unit();
    let chip_share = d.range(0.3, 0.7);
    // The encoder's pulse at any angle to the flutes (the tool clamped at any angle).
    let sync_phase_deg = d.range(0.0, 360.0 / f64::from(flutes));
    let mode_name = match mode {
        MillingMode::Down => "down",
        MillingMode::Up => "up",
    };
    let runout_list = runout
        .iter()
        .map(|r| format!("{r}"))
        .collect::<Vec<_>>()
        .join(", ");
    // The timeline with the axial depth `da_at(t0, t1)` of each segment [mm].
    let timeline = |da_at: &dyn Fn(f64, f64) -> String| {
        let mut segs = String::new();
        let mut t0 = 0.0;
        for (label, dur, rpm, feed) in &parts {
            let da = da_at(t0, t0 + dur);
            let _ = write!(
                segs,
                "\n[[segment]]\nlabel = \"{label}\"\nduration_s = {dur}\nrpm = {rpm}\n\
                 feed_mm_min = {feed}\ndr_mm = {dr}\nda_mm = {da}\n"
            );
            t0 += dur;
        }
        let _ = write!(
            segs,
            "\n[workpiece]\nspans_mm = [[{}, {}]]\n",
            work_mm[0], work_mm[1]
        );
        segs
    };
    let scenario_text = |segs: &str, seed: u64| {
        format!(
            "sample_rate_hz = {FS_HZ}\nseed = {seed}\nmode = \"{mode_name}\"\n\
             [tool]\nradius_mm = {radius}\nflutes = {flutes}\nhelix_deg = 30.0\nrunout_mm = [{runout_list}]\n\
             {BOARD}\n[signal]\nfeed_lag_s = {CURRENT_LAG_S}\nspindle_lag_s = {CURRENT_LAG_S}\nfeed_noise = {feed_noise}\n\
             spindle_noise = {spindle_noise}\nsync_jitter_samples = 1\nsync_phase_deg = {sync_phase_deg}\n{segs}"
        )
    };
    let name = format!("{} case {index}", kind.name());
    let constant = |_: f64, _: f64| da.to_string();
    // Wear: the force (here the axial depth) up by WEAR_RISE over the steady stretches,
    // linearly in time, held after.
    let (w0, w1) = (steady_1.0, steady_3.1);
    let worn = |t: f64| da * (1.0 + WEAR_RISE * ((t - w0) / (w1 - w0)).clamp(0.0, 1.0));
    let segs = match kind {
        Kind::Teach => timeline(&|_, _| (TEACH_DEEPER * da).to_string()),
        Kind::Wear => timeline(&|a, b| format!("[{}, {}]", worn(a), worn(b))),
        _ => timeline(&constant),
    };
    // A flute breaks (or chips) under load: out of the cut it carries none, and in the cut
    // the likelier the more it carries. The damage drawn in a stretch happens at the next
    // moment the flute's tip is at an angle of the engaged arc `[a, b]` drawn with density
    // in proportion to the tip's chip, `t_c sin(phi)`: `cos(phi)` uniform between
    // `cos(a)` and `cos(b)`.
    let damage_s = match (kind.sudden(), damage_s) {
        (true, Some(t)) => {
            let clean = Scenario::from_toml(&scenario_text(&segs, seed_case), &name)?;
            let arc = (1.0 - rr).clamp(-1.0, 1.0).acos();
            let (a, b) = match mode {
                MillingMode::Down => (std::f64::consts::PI - arc, std::f64::consts::PI),
                MillingMode::Up => (0.0, arc),
            };
            let phi = (a.cos() + in_arc * (b.cos() - a.cos()))
                .clamp(-1.0, 1.0)
                .acos();
            Some(sim::time_at_angle(&clean, t, flute, phi)?.unwrap_or(t))
        }
        _ => damage_s,
    };
    let mut events = String::new();
    match (kind, damage_s) {
        (Kind::Break, Some(t)) => {
            let _ = write!(
                events,
                "\n[[event]]\ntime_s = {t}\nflute = {flute}\nkind = \"break\"\n"
            );
        }
        (Kind::Chip, Some(t)) => {
            let _ = write!(
                events,
                "\n[[event]]\ntime_s = {t}\nflute = {flute}\nkind = \"chip\"\nfraction = {chip_share}\n"
            );
        }
        (Kind::Gone, Some(t)) => {
            for j in 0..flutes {
                let _ = write!(
                    events,
                    "\n[[event]]\ntime_s = {t}\nflute = {j}\nkind = \"break\"\n"
                );
            }
        }
        _ => {}
    }
    let text = format!("{}{events}", scenario_text(&segs, seed_case));
    let scenario = Scenario::from_toml(&text, &name)?;
    // Teach-in: the good job, recorded with other noise (a different seed).
    let taught = match kind {
        Kind::Taught | Kind::Teach => Some(Scenario::from_toml(
            &scenario_text(&timeline(&constant), seed_case ^ 0x5eed),
            &format!("{name} (taught)"),
        )?),
        _ => None,
    };
    let clip = sim::clip_levels(&scenario);
    let mut alarms = AlarmConfig::default();
    if kind == Kind::Overload {
        alarms.overload.max_rr = (0.8 * rr) as f32;
        alarms.overload.max_ra = (0.8 * ra) as f32;
    }
    if kind == Kind::Wear {
        alarms.drift.reference = DriftReference::Known {
            rr: rr as f32,
            ra: ra as f32,
        };
        // The wear of a tool life compressed into a hundred revolutions: the tracker's
        // memory scaled with it (the default 0.995 a revolution is ~200 revolutions, for
        // wear over minutes).
        alarms.drift.lambda = WEAR_LAMBDA;
    }
    let machine = MachineConfig {
        monitor: MonitorConfig {
            sample_rate_hz: FS_HZ as f32,
            input: scenario.input.clone(),
            estimator: EstimatorConfig {
                tool,
                mode,
                // The not-cutting floor sits above the air-cut noise of a tooth average
                // (a machine's calibration measures it; here the simulator's noise is known).
                force_floor_n: (4.0 * NOISE_REL * ft).max(2.0) as f32,
                ..EstimatorConfig::default()
            },
            clip: clip.map(|c| c as f32),
            // As calibrated: the current loop's lag measured on the machine.
            spindle_lag_s: scenario.signal.spindle_lag_s as f32,
            ..MonitorConfig::default()
        },
        alarms,
        front_end: estimator_core::FrontEnd::default(),
    };
    Ok(Case {
        kind,
        index,
        seed,
        scenario,
        machine,
        damage_s,
        rpm_at_damage: rpm_at,
        taught,
        ft_n: ft,
    })
}

/// Simulates and replays one case.
pub fn run_case(case: &Case) -> Result<Outcome> {
    run_case_with(case, |_, _, _| {})
}

/// [`run_case`], showing `seen` every simulated sample (its truth), what the pipeline made
/// of it (a record and the alarms' output where a tooth period closed) and the alarm
/// state after it.
fn run_case_with(
    case: &Case,
    mut seen: impl FnMut(&crate::trace::TraceRow, Option<&(ToothRecord, AlarmOutput)>, &AlarmState),
) -> Result<Outcome> {
    let mut machine = case.machine.clone();
    // Teach-in: the envelope of the good job, as a user records it.
    if let Some(taught) = &case.taught {
        let good = machine
            .clone()
            .build()
            .map_err(|e| anyhow!("{} case: {e}", case.kind.name()))?;
        let mut st = PipelineState::default();
        let mut rec = EnvelopeRecorder::new(taught.tool.flutes, TEACH_REVS_PER_BIN);
        sim::simulate(taught, |row| {
            if let Some((r, _)) = good.process(&mut st, &row.to_sample()) {
                rec.push(&r);
            }
            Ok(())
        })?;
        machine.alarms.teach.envelope = Some(rec.finish());
    }
    let pipeline = machine
        .build()
        .map_err(|e| anyhow!("{} case: {e}", case.kind.name()))?;
    let mut st = PipelineState::default();
    let mut first_alarm = None;
    let mut cutting_samples = 0u64;
    let fs = f64::from(case.machine.monitor.sample_rate_hz);
    // The onset: the first sample from the damage on whose true forces differ from the
    // same case without damage (noise-free truth; the same timeline sample for sample).
    let clean_forces = match (case.kind.sudden(), case.damage_s) {
        (true, Some(_)) => {
            let mut clean = case.scenario.clone();
            clean.events.clear();
            let mut v = Vec::new();
            sim::simulate(&clean, |row| {
                v.push([row.truth.fx_n, row.truth.ft_n]);
                Ok(())
            })?;
            v
        }
        _ => Vec::new(),
    };
    let mut onset_s = None;
    let mut sample = 0usize;
    let mut deficit = 0.0f64;
    let mut first_rev = 0.0f64;
    // The true forces' departures from the undamaged run's, damage to deadline (sample,
    // feed and tangential [N]), and the periods of every record (last sample, length).
    let mut departures = Vec::new();
    let mut periods = Vec::new();
    let tooth_s = 60.0 / (case.rpm_at_damage * f64::from(case.scenario.tool.flutes));
    let rev_s = 60.0 / case.rpm_at_damage;
    sim::simulate(&case.scenario, |row| {
        if let (Some(d), Some(c)) = (case.damage_s, clean_forces.get(sample)) {
            let (dx, dt) = (row.truth.fx_n - c[0], row.truth.ft_n - c[1]);
            let moved = f64::from(dx.abs() + dt.abs());
            if row.time_s >= d && row.time_s < d + rev_s {
                first_rev += moved / fs;
            }
            if row.time_s >= d && onset_s.is_none_or(|o| row.time_s <= o + rev_s) {
                departures.push((sample as u64, [f64::from(dx), f64::from(dt)]));
            }
            if onset_s.is_none() && row.time_s >= d {
                deficit += moved / fs;
                if deficit > ONSET_SHARE * case.ft_n * tooth_s {
                    onset_s = Some(row.time_s);
                }
            }
        }
        sample += 1;
        cutting_samples += u64::from(row.truth.dr_mm > 0.0);
        let out = pipeline.process(&mut st, &row.to_sample());
        seen(row, out.as_ref(), &st.alarms);
        if let (Some((r, _)), false) = (&out, clean_forces.is_empty()) {
            periods.push((r.end_sample, r.samples));
        }
        if let Some((_, out)) = out {
            if let (None, Some(ev)) = (first_alarm, out.event) {
                // The wear warning counts in the wear set only (elsewhere it does not stop
                // the machine and the cases are not about it).
                if ev.cause != Cause::Wear || case.kind == Kind::Wear {
                    // When the output latched: at the record that raised it, or before, at
                    // a drop trip inside a period whose cause the records after it name.
                    first_alarm = Some((ev.latched_sample as f64 / fs, ev.cause));
                }
            }
        }
        Ok(())
    })?;
    Ok(Outcome {
        kind: case.kind,
        index: case.index,
        seed: case.seed,
        cutting_s: cutting_samples as f64 / fs,
        first_alarm,
        damage_s: case.damage_s,
        onset_s,
        tooth_s,
        rev_s,
        first_rev_teeth: (!clean_forces.is_empty()).then(|| first_rev / (case.ft_n * tooth_s)),
        separation: (!clean_forces.is_empty())
            .then(|| separations(&departures, &periods, case.noise_n())),
    })
}

/// The separations by the deadline ([`Outcome::separation`]) of the best detector on
/// every sample and of the best one on the tooth periods' sums, from the true forces'
/// `departures` (sample, feed and tangential force [N]; every sample from the damage to the
/// deadline) and the records' `periods` (last sample, length) at one sample's noise
/// `noise_n` on each force. A period the deadline falls in counts with its samples up to
/// the deadline: a trip inside the period sees them.
fn separations(departures: &[(u64, [f64; 2])], periods: &[(u64, u32)], noise_n: f64) -> Separation {
    let every: f64 = departures.iter().map(|(_, [x, t])| x * x + t * t).sum();
    let (first, last) = match (departures.first(), departures.last()) {
        (Some(f), Some(l)) => (f.0, l.0),
        _ => (1, 0),
    };
    let mut summed = 0.0;
    for &(end, len) in periods {
        let start = (end + 1).saturating_sub(u64::from(len));
        if end < first || start > last {
            continue;
        }
        let (mut sx, mut st, mut n) = (0.0, 0.0, 0u32);
        for (_, [x, t]) in departures.iter().filter(|(i, _)| (start..=end).contains(i)) {
            sx += x;
            st += t;
            n += 1;
        }
        if n > 0 {
            summed += (sx * sx + st * st) / f64::from(n);
        }
    }
    Separation {
        samples: every.sqrt() / noise_n,
        periods: summed.sqrt() / noise_n,
    }
}

/// The exit that looks most like a sudden damage by its deadline ([`nearest_exit`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NearestExit {
    /// Where the exit that comes nearest on the samples begins: the first sample its
    /// forces leave the undamaged run's [s] (`None`: none of the exits tried comes nearer
    /// than the undamaged run itself).
    pub samples_from_s: Option<f64>,
    /// ... and the one nearest on the periods.
    pub periods_from_s: Option<f64>,
    /// The separations from those two, as [`Outcome::separation`] from the undamaged run.
    pub separation: Separation,
}

/// Exit faces tried per feed of travel in [`nearest_exit`].
const EXIT_FACES_PER_FEED: f64 = 16.0;

/// How far a sudden damage stands by its deadline (one revolution past the onset) from the
/// normal cut nearest to it: the same cut, the tool leaving the work through the far face
/// square to the feed (as every case's exit does) wherever that face lies, from two
/// revolutions before the onset to the deadline, and not at all. The exits a normal case
/// may hold are the alarms' nuisance: a rule that catches the damage raises a false alarm
/// on any exit whose forces, seen by the deadline, lie within the noise of the damage's.
/// The separations are those of the best detector told both in advance
/// ([`separations`], on the true forces' differences from the first sample either
/// departs to the deadline), the least over the faces, on the samples and on `records`'
/// periods each. `None` for other kinds, or where the damage changed no force.
pub fn nearest_exit(
    case: &Case,
    outcome: &Outcome,
    records: &[TracedRecord],
) -> Result<Option<NearestExit>> {
    let Some(onset) = outcome.onset_s.filter(|_| case.kind.sudden()) else {
        return Ok(None);
    };
    let mut clean = case.scenario.clone();
    clean.events.clear();
    let at = case.damage_s.unwrap_or(onset);
    let told = (case.noise_n(), at, onset, outcome.rev_s);
    nearest_exit_of(&case.scenario, &clean, told, records).map(Some)
}

/// [`nearest_exit`] of the run `sc` against the undamaged `clean` (the cut, its path and
/// faces), at one sample's noise `noise_n`, the damage at `at_s`, its onset `onset_s` and
/// a revolution `rev_s` long.
fn nearest_exit_of(
    sc: &Scenario,
    clean: &Scenario,
    (noise_n, at_s, onset, rev_s): (f64, f64, f64, f64),
    records: &[TracedRecord],
) -> Result<NearestExit> {
    let fs = sc.sample_rate_hz;
    let last = ((onset + rev_s) * fs).floor() as usize;
    let first = ((onset - 2.0 * rev_s) * fs).max(0.0) as usize;
    // The true forces up to the deadline (the simulation stopped there), and the path the
    // tool centre has travelled [mm] (the feed per tooth times the teeth passed).
    let truth = |sc: &Scenario| -> Result<(Vec<[f64; 2]>, Vec<f64>)> {
        let (mut forces, mut path) = (Vec::with_capacity(last + 1), Vec::new());
        let n = f64::from(sc.tool.flutes);
        let (mut p, mut done) = (0.0, false);
        let run = sim::simulate(sc, |row| {
            let t = &row.truth;
            forces.push([f64::from(t.fx_n), f64::from(t.ft_n)]);
            p += f64::from(t.tc_mm) * n * f64::from(t.rpm) / 60.0 / fs;
            path.push(p);
            // (Stopped at the deadline by an error the caller knows for that.)
            done = forces.len() > last;
            if done {
                bail!("the deadline");
            }
            Ok(())
        });
        match run {
            Err(e) if !done => Err(e),
            _ => Ok((forces, path)),
        }
    };
    let (damaged, _) = truth(sc)?;
    let (undamaged, path) = truth(clean)?;
    let periods: Vec<(u64, u32)> = records
        .iter()
        .map(|r| (r.record.end_sample, r.record.samples))
        .collect();
    let separation = |other: &[[f64; 2]]| {
        let departures: Vec<(u64, [f64; 2])> = (first..=last)
            .filter_map(|i| {
                let (d, o) = (damaged.get(i)?, other.get(i)?);
                Some((i as u64, [d[0] - o[0], d[1] - o[1]]))
            })
            .collect();
        separations(&departures, &periods, noise_n)
    };
    let mut best = NearestExit {
        samples_from_s: None,
        periods_from_s: None,
        separation: separation(&undamaged),
    };
    // The faces: the engaged arc reaches `reach` ahead of the centre, so an exit through a
    // face at `x` begins as the centre passes `x - reach`.
    let (Some(&p0), Some(&p1), Some((rr, _, tc))) =
        (path.get(first), path.get(last), engagement_at(sc, at_s))
    else {
        return Ok(best);
    };
    let reach = arc_reach_mm(sc.tool.radius_mm, rr);
    let step = tc / EXIT_FACES_PER_FEED;
    let faces = ((p1 - p0) / step).ceil().max(0.0) as usize;
    for k in 0..=faces {
        let face = p0 + reach + k as f64 * step;
        let mut exit = clean.clone();
        match exit.workpiece.as_mut().and_then(|w| w.spans_mm.last_mut()) {
            Some(s) => s[1] = s[1].min(face),
            None => break,
        }
        let (forces, _) = truth(&exit)?;
        let from = forces
            .iter()
            .zip(&undamaged)
            .position(|(a, b)| a != b)
            .map(|i| i as f64 / fs);
        let z = separation(&forces);
        if z.samples < best.separation.samples {
            (best.samples_from_s, best.separation.samples) = (from, z.samples);
        }
        if z.periods < best.separation.periods {
            (best.periods_from_s, best.separation.periods) = (from, z.periods);
        }
    }
    Ok(best)
}

/// [`nearest_exit`] of the case `o` came from, drawn again and run with `setup`, as the
/// goal's list appends it to the case's line (empty where there is none).
pub fn nearest_exit_note(o: &Outcome, setup: Setup) -> String {
    let found = draw_case(o.kind, o.index, o.seed).and_then(|mut case| {
        setup.apply(&mut case);
        let (outcome, records) = trace_case(&case)?;
        nearest_exit(&case, &outcome, &records)
    });
    match found {
        Ok(Some(e)) => format!("; {}", nearest_exit_text(&e, o)),
        Ok(None) => String::new(),
        Err(e) => format!("; no nearest exit: {e}"),
    }
}

/// A [`NearestExit`] in words, its times in revolutions from the onset of `o`'s damage.
pub fn nearest_exit_text(e: &NearestExit, o: &Outcome) -> String {
    let onset_s = o.onset_s.unwrap_or(0.0);
    let from = |t: Option<f64>| {
        t.map_or("no exit".to_string(), |t| {
            format!("an exit from {:+.2} revolutions", (t - onset_s) / o.rev_s)
        })
    };
    format!(
        "nearest normal cut by the deadline: {} on the samples, {:.1} sigma away; {} on the periods, {:.1} sigma",
        from(e.samples_from_s),
        e.separation.samples,
        from(e.periods_from_s),
        e.separation.periods
    )
}

/// How far a damage stands above the noise by the goal's deadline ([`Outcome::separation`]),
/// in sigma.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Separation {
    /// For the best detector on the samples.
    pub samples: f64,
    /// For the best detector on the tooth periods' sums (the records' windows).
    pub periods: f64,
}

/// One tooth record of a traced case ([`trace_case`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TracedRecord {
    /// The record, as the pipeline made it.
    pub record: ToothRecord,
    /// The simulator's noise-free feed force over the record's samples [N].
    pub true_fx_n: f64,
    /// The simulator's noise-free tangential force over the record's samples [N].
    pub true_ft_n: f64,
    /// Flutes intact at the record's last sample (bit i: flute i).
    pub intact: u32,
    /// The floor of the drop trip the alarms armed for the next period [N] (infinite: not
    /// armed).
    pub trip_floor_n: f32,
    /// That trip's share of the tooth's force.
    pub trip_share: f32,
    /// The hand-over stage's measure of the cut's span after the record
    /// (`AlarmState::span_share`, NaN: not known).
    pub span_share: f32,
    /// The alarm the record raised.
    pub event: Option<AlarmEvent>,
    /// The output latched after the record.
    pub latched: bool,
}

/// Runs `case` as [`run_case`] does (the same outcome) and keeps every tooth record, with
/// the truth over its samples: what to look at when a case is late or a false alarm.
pub fn trace_case(case: &Case) -> Result<(Outcome, Vec<TracedRecord>)> {
    let (mut fx, mut ft) = (Vec::new(), Vec::new());
    let mut records = Vec::new();
    let outcome = run_case_with(case, |row, out, alarms| {
        fx.push(f64::from(row.truth.fx_n));
        ft.push(f64::from(row.truth.ft_n));
        if let Some((record, out)) = out {
            records.push(TracedRecord {
                record: *record,
                true_fx_n: f64::NAN,
                true_ft_n: f64::NAN,
                intact: row.truth.flutes_intact,
                trip_floor_n: alarms.trip_floor_n(),
                trip_share: alarms.trip_share(),
                span_share: alarms.span_share(),
                event: out.event,
                latched: out.latched,
            });
        }
    })?;
    // A period is its `samples` samples up to and including `end_sample` (0 from the
    // first sample simulated).
    let mean = |v: &[f64], r: &ToothRecord| {
        let end = usize::try_from(r.end_sample).map_or(usize::MAX, |e| e.saturating_add(1));
        let start = end.saturating_sub(r.samples as usize);
        v.get(start..end)
            .filter(|p| !p.is_empty())
            .map_or(f64::NAN, |p| p.iter().sum::<f64>() / p.len() as f64)
    };
    for t in &mut records {
        t.true_fx_n = mean(&fx, &t.record);
        t.true_ft_n = mean(&ft, &t.record);
    }
    Ok((outcome, records))
}

/// The stretch of a traced case worth reading [s]: from `REVS_BEFORE` revolutions before
/// the damage or the first alarm, whichever came first, to a revolution past the first
/// alarm (or `REVS_AFTER` past the damage where none came after it). `None`: neither
/// damage nor alarm.
pub fn trace_window(outcome: &Outcome) -> Option<(f64, f64)> {
    const REVS_BEFORE: f64 = 3.0;
    const REVS_AFTER: f64 = 4.0;
    let rev = outcome.rev_s;
    let alarm = outcome.first_alarm.map(|(t, _)| t);
    let at = outcome.damage_s.or(alarm)?;
    let (start, end) = match alarm {
        Some(t) if t >= at => (at, t + rev),
        // (A false alarm before the damage: both shown.)
        Some(t) => (t, at + REVS_AFTER * rev),
        None => (at, at + REVS_AFTER * rev),
    };
    Some((start - REVS_BEFORE * rev, end))
}

/// A sudden damage's [`Outcome::separation`], in words (empty for other kinds).
fn separation_text(o: &Outcome) -> String {
    o.separation.map_or(String::new(), |z| {
        format!(
            "; separation by the deadline {:.1} sigma on the samples, {:.1} on the periods",
            z.samples, z.periods
        )
    })
}

/// What a traced case came to against its set's goal, in words.
fn verdict(o: &Outcome) -> String {
    let after = |l: f64| format!("{:.2} revolutions after", l / o.rev_s);
    if o.false_alarm() {
        return "a false alarm".into();
    }
    match (o.kind.expected(), o.detected_after_onset_s()) {
        (None, _) => "no alarm: right".into(),
        (Some(_), None) => "missed".into(),
        (Some(_), Some(l)) if o.kind.sudden() => {
            let late = if l > o.rev_s { "late" } else { "within one" };
            format!("{} the first changed force ({late})", after(l))
        }
        (Some(_), Some(l)) => format!("{:.3} s after the damage", l),
    }
}

/// The true immersion ratios and feed per tooth at the start of the segment that holds
/// `t_s` (each carried from the segment before where one leaves it out); `None` where no
/// segment gives them or the speed is 0.
fn engagement_at(sc: &Scenario, t_s: f64) -> Option<(f64, f64, f64)> {
    let (mut dr, mut da, mut rpm, mut feed) = (None, None, None, None);
    let mut start = 0.0;
    for seg in &sc.segments {
        let first = |p: &Option<crate::sim::scenario::Profile>| p.as_ref().map(|p| p.ends().0);
        dr = first(&seg.dr_mm).or(dr);
        da = first(&seg.da_mm).or(da);
        rpm = first(&seg.rpm).or(rpm);
        feed = first(&seg.feed_mm_min).or(feed);
        start += seg.duration_s;
        if start > t_s {
            break;
        }
    }
    let (r, n) = (sc.tool.radius_mm, f64::from(sc.tool.flutes));
    let (dr, da, rpm, feed) = (dr?, da?, rpm?, feed?);
    (rpm > 0.0 && r > 0.0).then(|| (dr / r, da / r, feed / (rpm * n)))
}

/// A traced case as text: what it is, its cut at the damage, what came of it (with its
/// nearest exit, `exit`, where given), and its records from `from_s` to `to_s`, a line each.
pub fn format_trace(
    case: &Case,
    outcome: &Outcome,
    records: &[TracedRecord],
    exit: Option<&NearestExit>,
    (from_s, to_s): (f64, f64),
) -> String {
    let sc = &case.scenario;
    let flutes = usize::from(sc.tool.flutes);
    let mut s = String::new();
    let at_damage = if case.damage_s.is_some() {
        " at the damage"
    } else {
        ""
    };
    let _ = writeln!(
        s,
        "seed {} {} {}: {} flutes, R {} mm, {} milling, {:.0} rpm{at_damage}, steady F_t {:.0} N",
        case.seed,
        case.kind.name(),
        case.index,
        flutes,
        sc.tool.radius_mm,
        format!("{:?}", sc.mode).to_lowercase(),
        case.rpm_at_damage,
        case.ft_n,
    );
    if let Some((rr, ra, tc)) = engagement_at(sc, case.damage_s.unwrap_or(0.0)) {
        let _ = writeln!(
            s,
            "cut{at_damage}: R_r {rr:.3}, R_a {ra:.3}, t_c {tc:.4} mm (true, at its segment's start)"
        );
    }
    let alarm = outcome
        .first_alarm
        .map_or("none".to_string(), |(at, cause)| {
            format!("{} at {at:.4} s", cause.name())
        });
    let damage = match (outcome.damage_s, outcome.onset_s) {
        (None, _) => "no damage".to_string(),
        (Some(d), None) => format!("damage at {d:.4} s"),
        (Some(d), Some(o)) => format!("damage at {d:.4} s, forces changed from {o:.4} s"),
    };
    let _ = writeln!(
        s,
        "{damage}, first alarm {alarm}: {}{}",
        verdict(outcome),
        separation_text(outcome)
    );
    if let Some(e) = exit {
        let _ = writeln!(s, "{}", nearest_exit_text(e, outcome));
    }
    let _ = writeln!(
        s,
        "\n{:>9} {:>5} {:>4} {:>8} {:>8} {:>8} {:>8} {:>6} {:>6} {:>7} {:>6} {:>8} {:>5} {:>5}  status, alarm",
        "time_s",
        "tooth",
        "len",
        "fx_n",
        "f2_n",
        "true_fx",
        "true_ft",
        "intact",
        "rr",
        "tc_mm",
        "ho_z",
        "trip_n",
        "share",
        "span",
    );
    let fs = f64::from(case.machine.monitor.sample_rate_hz);
    for r in records {
        let rec = &r.record;
        let time = rec.end_sample as f64 / fs;
        if time < from_s || time > to_s {
            continue;
        }
        let mut intact = String::new();
        for i in (0..flutes).rev() {
            intact.push(if r.intact >> i & 1 == 1 { '1' } else { '0' });
        }
        let event = r.event.map_or(String::new(), |e| {
            format!(
                ", {} ({:.1} against {:.1}), latched at {:.4} s",
                e.cause.name(),
                e.value,
                e.threshold,
                e.latched_sample as f64 / fs
            )
        });
        let _ = writeln!(
            s,
            "{time:>9.4} {:>5} {:>4} {:>8.1} {:>8.1} {:>8.1} {:>8.1} {intact:>6} {:>6.3} {:>7.4} {:>6.1} {:>8.1} {:>5.2} {:>5.2}  {}{event}{}",
            rec.tooth,
            rec.samples,
            rec.fx_n,
            rec.f2_n,
            r.true_fx_n,
            r.true_ft_n,
            rec.rr,
            rec.tc_mm,
            rec.handover_z,
            r.trip_floor_n,
            r.trip_share,
            r.span_share,
            rec.status,
            if r.latched && r.event.is_none() { ", latched" } else { "" },
        );
    }
    s
}

/// A case named `KIND:INDEX` (`break:16`), the index within the full set's cases of that
/// kind: what `evaluate-alarms --case` takes.
pub fn parse_case(text: &str) -> Result<(Kind, usize)> {
    let names = || KINDS.map(Kind::name).join(", ");
    let (name, index) = text
        .split_once(':')
        .ok_or_else(|| anyhow!("--case {text}: expected KIND:INDEX, e.g. break:16"))?;
    let kind = Kind::parse(name.trim())
        .ok_or_else(|| anyhow!("--case {text}: no set {name:?}; the sets are {}", names()))?;
    let index: usize = index
        .trim()
        .parse()
        .map_err(|_| anyhow!("--case {text}: the index {index:?} is not a whole number"))?;
    let count = KINDS
        .iter()
        .zip(SetSizes::FULL.counts)
        .find(|(k, _)| **k == kind)
        .map_or(0, |(_, n)| n);
    if index >= count {
        bail!(
            "--case {text}: the full set's {} cases are 0-{}",
            kind.name(),
            count.saturating_sub(1)
        );
    }
    Ok((kind, index))
}

/// How the monitor is set up, the same for every case of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setup {
    /// The monitor places the tooth windows ([`MonitorConfig::align_window`]).
    pub align: bool,
    /// The low end of the coefficients' fitted feed range [mm/tooth]; `None`: Table 2's
    /// (0.1042). The simulator's material follows Table 2's laws at every feed, so a
    /// calibration with cuts down to a lower feed finds the same laws and trusts them from
    /// there: the cuts drawn below 0.1042 (from 0.04) are then estimated, not flagged.
    pub tc_fit_from_mm: Option<f32>,
    /// The servo amplifiers' current-loop lag on every channel [s] (a first-order time
    /// constant); `None`: the cases' own, [`CURRENT_LAG_S`]. 0 measures what the lag costs
    /// the alarms.
    pub lag_s: Option<f64>,
    /// The spindle lag the monitor is told ([`MonitorConfig::spindle_lag_s`]); `None`: the
    /// one the case is drawn with, as a calibration measures it. 0: the lag not allowed
    /// for; another value measures what a mis-set one costs.
    pub monitor_lag_s: Option<f32>,
}

/// The current-loop lag every case is drawn with, feed and spindle channels alike [s].
pub const CURRENT_LAG_S: f64 = 0.0005;

impl Default for Setup {
    fn default() -> Self {
        Setup {
            align: true,
            tc_fit_from_mm: None,
            lag_s: None,
            monitor_lag_s: None,
        }
    }
}

impl Setup {
    /// `case` run with this setup.
    pub fn apply(&self, case: &mut Case) {
        case.machine.monitor.align_window = self.align;
        if let Some(lo) = self.tc_fit_from_mm {
            case.machine.monitor.estimator.coeffs.tc_fit_mm.0 = lo;
        }
        let sig = &mut case.scenario.signal;
        if let Some(lag) = self.lag_s {
            (sig.feed_lag_s, sig.spindle_lag_s) = (lag, lag);
        }
        case.machine.monitor.spindle_lag_s = self.monitor_lag_s.unwrap_or(sig.spindle_lag_s as f32);
    }
}

/// Runs every case of `sizes` at each draw seed of `seeds` on up to `threads` threads, and
/// returns the outcomes in order: by seed, then in [`KINDS`] order, then by index (the
/// same as the seeds run one at a time, one after the other).
pub fn evaluate(
    sizes: SetSizes,
    seeds: std::ops::Range<u64>,
    threads: usize,
    setup: Setup,
) -> Result<Vec<Outcome>> {
    let keys: Vec<(Kind, usize, u64)> = seeds
        .flat_map(|seed| {
            KINDS
                .iter()
                .zip(sizes.counts)
                .flat_map(move |(&kind, n)| (0..n).map(move |i| (kind, i, seed)))
        })
        .collect();
    // Each worker takes the next case when it is free: cases differ in length by a factor
    // of a few, and a fixed split leaves a core idle at the end of every seed.
    let next = std::sync::atomic::AtomicUsize::new(0);
    let run = |&(kind, index, seed): &(Kind, usize, u64)| -> Result<Outcome> {
        let mut case = draw_case(kind, index, seed)?;
        setup.apply(&mut case);
        run_case(&case)
    };
    let results: Vec<Result<Vec<(usize, Outcome)>>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads.clamp(1, 16))
            .map(|_| {
                s.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(key) = keys.get(k) else {
                            return Ok(done);
                        };
                        done.push((k, run(key)?));
                    }
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join()
                    .unwrap_or_else(|_| Err(anyhow!("an evaluation thread panicked")))
            })
            .collect()
    });
    let mut out = Vec::with_capacity(keys.len());
    for r in results {
        out.extend(r?);
    }
    out.sort_by_key(|&(k, _)| k);
    Ok(out.into_iter().map(|(_, o)| o).collect())
}

/// The cases behind the goal's shortfalls, a line each: every false alarm, and every full
/// breakage missed or caught later than one revolution of its first missed cut (with how
/// late), so that a run over many seeds names each case to trace (`draw_case(kind, index,
/// seed)` reproduces it), `nearest` appended to a breakage's line (the nearest exit,
/// where the caller can redraw the case: [`nearest_exit_note`]).
pub fn exceptions(outcomes: &[Outcome], nearest: impl Fn(&Outcome) -> String) -> String {
    let mut s = String::new();
    for o in outcomes {
        let case = format!("seed {} {} {}", o.seed, o.kind.name(), o.index);
        if o.false_alarm() {
            if let Some((t, cause)) = o.first_alarm {
                let when = match o.damage_s {
                    None => "no damage".to_string(),
                    Some(d) if t < d => {
                        format!("{:.2} revolutions before the damage", (d - t) / o.rev_s)
                    }
                    Some(_) => "not the expected cause".to_string(),
                };
                let _ = writeln!(s, "{case}: false alarm, {cause:?} at {t:.4} s ({when})");
            }
        } else if o.kind == Kind::Break {
            match o.detected_after_onset_s() {
                None => {
                    let _ = writeln!(s, "{case}: missed{}", nearest(o));
                }
                Some(l) if l > o.rev_s => {
                    let _ = writeln!(
                        s,
                        "{case}: late, {:.2} revolutions after the first missed cut{}{}",
                        l / o.rev_s,
                        separation_text(o),
                        nearest(o)
                    );
                }
                Some(_) => {}
            }
        }
    }
    s
}

/// Figures of one set.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SetFigures {
    /// Cases.
    pub cases: usize,
    /// Expected alarm raised after the damage.
    pub detected: usize,
    /// ... within one revolution of the damage's first effect on the forces (the broken
    /// flute's first missed cut).
    pub within_rev: usize,
    /// ... within one revolution of the damage itself.
    pub within_rev_of_damage: usize,
    /// Mean and largest latency from the first effect [ms].
    pub latency_ms: (f64, f64),
    /// Mean and largest latency from the first effect [tooth periods].
    pub latency_teeth: (f64, f64),
    /// False alarms (before the damage, or of another cause).
    pub false_alarms: usize,
    /// Cutting time [h].
    pub cutting_h: f64,
}

/// Figures per set, in [`KINDS`] order.
pub fn figures(outcomes: &[Outcome]) -> [SetFigures; 8] {
    KINDS.map(|kind| {
        let mut f = SetFigures::default();
        let mut lat = Vec::new();
        for o in outcomes.iter().filter(|o| o.kind == kind) {
            f.cases += 1;
            f.cutting_h += o.cutting_s / 3600.0;
            f.false_alarms += usize::from(o.false_alarm());
            if let (Some(from_damage), Some(l)) = (o.detected_after_s(), o.detected_after_onset_s())
            {
                f.detected += 1;
                // An overload and a taught-envelope excursion have no instant of damage: no
                // latency; wear's runs from the true multiplier's crossing of the warning
                // level (one revolution means nothing there).
                if kind.sudden() {
                    f.within_rev += usize::from(l <= o.rev_s);
                    f.within_rev_of_damage += usize::from(from_damage <= o.rev_s);
                }
                if kind.sudden() || kind == Kind::Wear {
                    lat.push((l * 1e3, l / o.tooth_s));
                }
            }
        }
        if !lat.is_empty() {
            let n = lat.len() as f64;
            f.latency_ms = (
                lat.iter().map(|l| l.0).sum::<f64>() / n,
                lat.iter().map(|l| l.0).fold(0.0, f64::max),
            );
            f.latency_teeth = (
                lat.iter().map(|l| l.1).sum::<f64>() / n,
                lat.iter().map(|l| l.1).fold(0.0, f64::max),
            );
        }
        f
    })
}

/// The report table (markdown).
pub fn report(fig: &[SetFigures; 8]) -> String {
    let mut s = String::from(
        "| set | cases | detected | within 1 rev of the first missed cut | within 1 rev of the damage | latency mean / max [teeth] | latency mean / max [ms] | false alarms | cutting [h] | false alarms per hour |\n\
         | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n",
    );
    for (kind, f) in KINDS.iter().zip(fig) {
        let det = if *kind == Kind::Wear {
            format!(
                "{} ({:.0} %) | - | - | {:.1} / {:.1} | {:.1} / {:.1}",
                f.detected,
                100.0 * f.detected as f64 / f.cases.max(1) as f64,
                f.latency_teeth.0,
                f.latency_teeth.1,
                f.latency_ms.0,
                f.latency_ms.1
            )
        } else if kind.expected().is_some() && !kind.sudden() {
            format!(
                "{} ({:.0} %) | - | - | - | -",
                f.detected,
                100.0 * f.detected as f64 / f.cases.max(1) as f64
            )
        } else if kind.expected().is_some() {
            format!(
                "{} ({:.0} %) | {} ({:.0} %) | {} ({:.0} %) | {:.1} / {:.1} | {:.1} / {:.1}",
                f.detected,
                100.0 * f.detected as f64 / f.cases.max(1) as f64,
                f.within_rev,
                100.0 * f.within_rev as f64 / f.cases.max(1) as f64,
                f.within_rev_of_damage,
                100.0 * f.within_rev_of_damage as f64 / f.cases.max(1) as f64,
                f.latency_teeth.0,
                f.latency_teeth.1,
                f.latency_ms.0,
                f.latency_ms.1
            )
        } else {
            "- | - | - | - | -".to_string()
        };
        let _ = writeln!(
            s,
            "| {} | {} | {det} | {} | {:.3} | {:.1} |",
            kind.name(),
            f.cases,
            f.false_alarms,
            f.cutting_h,
            f.false_alarms as f64 / f.cutting_h.max(1e-12)
        );
    }
    s
}

/// What CI holds the detectors to (`--check`): no false alarm in any set (a normal cut, or
/// before the damage, or of another cause), every overload and teach-in excursion raised,
/// [`MIN_WEAR_DETECTION`] of the wear warnings, at least
/// [`MIN_BREAK_DETECTION`] of full breakages caught and [`MIN_BREAK_WITHIN_REV`] of them
/// within one revolution. Below the product goal (every full breakage within one
/// revolution: BENCHMARKS.md gives the measured figures); a regression floor, so that a
/// change that loses ground fails.
pub fn check_goals(fig: &[SetFigures; 8]) -> Result<()> {
    for (kind, f) in KINDS.iter().zip(fig) {
        if f.false_alarms != 0 {
            bail!(
                "{} false alarms in the {} set (must be none)",
                f.false_alarms,
                kind.name()
            );
        }
    }
    let [_, brk, _, _, overload, _, teach, wear] = fig;
    let cases = brk.cases.max(1) as f64;
    if (brk.detected as f64) < MIN_BREAK_DETECTION * cases {
        bail!(
            "{} of {} full flute breakages caught (floor: {:.0} %)",
            brk.detected,
            brk.cases,
            100.0 * MIN_BREAK_DETECTION
        );
    }
    if (brk.within_rev as f64) < MIN_BREAK_WITHIN_REV * cases {
        bail!(
            "{} of {} full flute breakages caught within one revolution (floor: {:.0} %)",
            brk.within_rev,
            brk.cases,
            100.0 * MIN_BREAK_WITHIN_REV
        );
    }
    for (f, what) in [(overload, "overloads"), (teach, "teach-in excursions")] {
        if f.detected != f.cases {
            bail!("{} of {} {what} raised (must be all)", f.detected, f.cases);
        }
    }
    if (wear.detected as f64) < MIN_WEAR_DETECTION * wear.cases as f64 {
        bail!(
            "{} of {} wear warnings raised (floor: {:.0} %)",
            wear.detected,
            wear.cases,
            100.0 * MIN_WEAR_DETECTION
        );
    }
    Ok(())
}

/// Share of the wear set `--check` requires warned (the full set: 97-100 % at seeds 1-5;
/// a miss is a warning that comes after the job ends).
pub const MIN_WEAR_DETECTION: f64 = 0.9;

/// Share of full breakages `--check` requires caught (the small set: 10 of 10 at seed 1;
/// the full set 100 %).
pub const MIN_BREAK_DETECTION: f64 = 0.9;

/// Share of full breakages `--check` requires caught within one revolution of the first
/// missed cut (the small set: 10 of 10 at seeds 1-3; the full set 98-100 % at seeds 1-5).
pub const MIN_BREAK_WITHIN_REV: f64 = 0.9;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::scenario::Profile;

    /// A normal case whose feed change is a feed hold: in `ramp_s` down to `share` of the
    /// feed, held there for the rest of the job.
    fn feed_hold(index: usize, ramp_s: f64, share: f64) -> Case {
        let mut case = draw_case(Kind::Normal, index, 1).expect("a normal case");
        let feed = first_feed_mm_min(&case);
        let segs = &mut case.scenario.segments;
        segs[3].duration_s = ramp_s;
        segs[3].feed_mm_min = Some(Profile::Ramp(feed, share * feed));
        for s in segs.iter_mut().skip(4) {
            s.feed_mm_min = Some(Profile::Constant(share * feed));
        }
        case
    }

    /// A feed hold at a high-acceleration machine's rate (1.5 m/min to a fifth in 2 ms,
    /// about 10 m/s^2): the chip thins within a tooth period, every tooth at once, in the
    /// middle of a steady cut. Neither a breakage (the drop trip inside a period) nor a lost
    /// tool (the feed goes on).
    #[test]
    fn a_feed_hold_in_a_steady_cut_raises_nothing() {
        for i in 0..8 {
            let case = feed_hold(i, 0.002, 0.0);
            let out = run_case(&case).expect("the case runs");
            assert_eq!(out.first_alarm, None, "case {i}");
        }
    }

    /// A feed override turned down in one step (2 ms) to a tenth, a fifth or half: the
    /// force falls with the chip, to near the not-cutting floor at a tenth of a light cut's
    /// feed, while the feed goes on. Not a lost tool: the force still follows the feed.
    #[test]
    fn a_feed_override_step_raises_nothing() {
        let mut raised = Vec::new();
        for share in [0.1, 0.2, 0.5] {
            for i in 0..8 {
                let case = feed_hold(i, 0.002, share);
                let out = run_case(&case).expect("the case runs");
                if let Some(a) = out.first_alarm {
                    raised.push(format!("{share} case {i}: {a:?}"));
                }
            }
        }
        assert!(raised.is_empty(), "{raised:#?}");
    }

    /// From `LEGACY_SEEDS` on, no two cases share a draw: seeds 256 apart (which the legacy
    /// key `seed ^ index << 8` maps onto each other's cases) draw other tools and other
    /// noise, and every case's noise seed lies past the legacy ones.
    #[test]
    fn every_case_past_the_legacy_seeds_draws_its_own() {
        let mut tools = std::collections::HashSet::new();
        let mut noise = std::collections::HashSet::new();
        for seed in [LEGACY_SEEDS, LEGACY_SEEDS + 256, LEGACY_SEEDS + 512 + 1] {
            for index in 0..120 {
                let case = draw_case(Kind::Normal, index, seed).expect("a case");
                let t = &case.scenario.tool;
                let key: Vec<u64> = t.runout_mm.iter().map(|r| r.to_bits()).collect();
                assert!(
                    tools.insert(key),
                    "seed {seed} index {index}: a drawn tool again"
                );
                assert!(
                    noise.insert(case.scenario.seed),
                    "seed {seed} index {index}"
                );
                assert!(case.scenario.seed > LEGACY_SEEDS + 255 * 7919);
            }
        }
        // The legacy key's repeat, which the keys above avoid: seed 60's case 110 is seed
        // 6460's case 119.
        let tool = |index, seed| {
            draw_case(Kind::Break, index, seed)
                .expect("a case")
                .scenario
                .tool
        };
        assert_eq!(tool(110, 60).runout_mm, tool(119, 6460).runout_mm);
    }

    /// A run over consecutive seeds, on two threads taking cases as they come free, gives
    /// exactly the outcomes of each seed run alone on one thread, one seed after the other.
    #[test]
    fn a_run_over_seeds_is_each_seeds_run_in_turn() {
        let sizes = SetSizes {
            counts: [1, 2, 1, 0, 0, 0, 0, 0],
        };
        let pooled = evaluate(sizes, 11..14, 2, Setup::default()).expect("the run");
        let mut one_by_one = Vec::new();
        for seed in 11..14 {
            one_by_one
                .extend(evaluate(sizes, seed..seed + 1, 1, Setup::default()).expect("the run"));
        }
        assert_eq!(pooled.len(), 12);
        assert_eq!(pooled, one_by_one);
        let ids: Vec<_> = pooled.iter().map(|o| (o.seed, o.kind, o.index)).collect();
        assert_eq!(
            ids[4..8],
            [
                (12, Kind::Normal, 0),
                (12, Kind::Break, 0),
                (12, Kind::Break, 1),
                (12, Kind::Chip, 0)
            ]
        );
    }

    /// The exception list names each false alarm (in a normal cut, before the damage, of
    /// the wrong cause) and each full breakage missed or caught over a revolution after its
    /// first missed cut, and nothing else.
    #[test]
    fn the_exceptions_name_each_case_against_the_goal() {
        let base = Outcome {
            kind: Kind::Break,
            index: 0,
            seed: 7,
            cutting_s: 2.0,
            first_alarm: None,
            damage_s: Some(1.0),
            onset_s: Some(1.002),
            tooth_s: 0.005,
            rev_s: 0.02,
            first_rev_teeth: Some(1.0),
            separation: None,
        };
        let case = |kind, index, alarm: Option<(f64, Cause)>| Outcome {
            kind,
            index,
            first_alarm: alarm,
            damage_s: if kind == Kind::Normal {
                None
            } else {
                base.damage_s
            },
            ..base
        };
        let outcomes = [
            case(Kind::Normal, 3, None),
            case(Kind::Normal, 4, Some((0.5, Cause::Breakage))),
            // Within a revolution of the first missed cut (0.65 of one).
            case(Kind::Break, 5, Some((1.015, Cause::Breakage))),
            case(Kind::Break, 6, Some((1.032, Cause::Breakage))),
            case(Kind::Break, 7, None),
            case(Kind::Break, 8, Some((0.95, Cause::Breakage))),
            case(Kind::Break, 9, Some((1.01, Cause::ToolGone))),
            // Chips and lost tools late or missed are in the table, not the list.
            case(Kind::Chip, 10, None),
        ];
        assert_eq!(
            exceptions(&outcomes, |o| format!(" [{}]", o.index)),
            "seed 7 normal 4: false alarm, Breakage at 0.5000 s (no damage)\n\
             seed 7 break 6: late, 1.50 revolutions after the first missed cut [6]\n\
             seed 7 break 7: missed [7]\n\
             seed 7 break 8: false alarm, Breakage at 0.9500 s (2.50 revolutions before the damage)\n\
             seed 7 break 9: false alarm, ToolGone at 1.0100 s (not the expected cause)\n"
        );
    }

    /// The trace is the case's own run: the same outcome as `run_case`, the records a plain
    /// replay of its scenario gives, and each record's truth the mean of the simulator's
    /// forces over its samples (summed here as the samples stream by).
    #[test]
    fn a_traced_case_is_its_run_with_the_truth_over_each_record() {
        let case = draw_case(Kind::Break, 0, 1).expect("a break case");
        let (outcome, traced) = trace_case(&case).expect("traced");
        assert_eq!(outcome, run_case(&case).expect("run"));
        let pipeline = case.machine.clone().build().expect("the case's machine");
        let mut st = PipelineState::default();
        let (mut replayed, mut truth) = (Vec::new(), Vec::new());
        sim::simulate(&case.scenario, |row| {
            truth.push((row.truth.fx_n, row.truth.ft_n));
            if let Some((rec, out)) = pipeline.process(&mut st, &row.to_sample()) {
                replayed.push((rec, out.event));
            }
            Ok(())
        })
        .expect("simulated");
        assert_eq!(traced.len(), replayed.len());
        for (t, (rec, event)) in traced.iter().zip(&replayed) {
            assert_eq!((t.record, t.event), (*rec, *event));
            let (mut fx, mut ft, mut k) = (0.0f64, 0.0f64, 0u32);
            for (i, (x, y)) in truth.iter().enumerate() {
                if i as u64 <= rec.end_sample && i as u64 + u64::from(rec.samples) > rec.end_sample
                {
                    fx += f64::from(*x);
                    ft += f64::from(*y);
                    k += 1;
                }
            }
            assert_eq!(k, rec.samples);
            assert!((t.true_fx_n - fx / f64::from(k)).abs() < 1e-6 * (1.0 + fx.abs()));
            assert!((t.true_ft_n - ft / f64::from(k)).abs() < 1e-6 * (1.0 + ft.abs()));
        }
        assert!(
            traced.iter().any(|t| t.event.is_some()),
            "the break's alarm is traced"
        );
    }

    /// Without noise or current-loop lag a valid record's tangential force is its period's
    /// true force (to the spindle model's fit), where a period placed a sample or a tooth
    /// off would not be: under runout the teeth differ by far more.
    #[test]
    fn a_traced_records_truth_is_over_its_own_period() {
        let mut case = draw_case(Kind::Normal, 2, 1).expect("a normal case");
        let sig = &mut case.scenario.signal;
        (
            sig.feed_noise,
            sig.spindle_noise,
            sig.feed_lag_s,
            sig.spindle_lag_s,
        ) = (0.0, 0.0, 0.0, 0.0);
        let (_, traced) = trace_case(&case).expect("traced");
        let valid: Vec<_> = traced
            .iter()
            .filter(|t| t.record.status.is_valid())
            .collect();
        assert!(valid.len() > 100, "{} valid records", valid.len());
        for t in valid {
            let f = f64::from(t.record.f2_n);
            assert!(
                (f - t.true_ft_n).abs() < 0.01 * t.true_ft_n,
                "{f} against {}",
                t.true_ft_n
            );
        }
    }

    /// A case's sample noise is what its records' tangential forces scatter by about the
    /// truth (lag off): a tooth average of `N` samples by `noise_n / sqrt(N)`.
    #[test]
    fn a_cases_sample_noise_is_its_records_scatter() {
        let mut case = draw_case(Kind::Normal, 2, 1).expect("a normal case");
        let lag_off = Setup {
            lag_s: Some(0.0),
            ..Setup::default()
        };
        lag_off.apply(&mut case);
        let (_, traced) = trace_case(&case).expect("traced");
        let z: Vec<f64> = traced
            .iter()
            .filter(|t| t.record.status.is_valid())
            .map(|t| {
                let n = f64::from(t.record.samples);
                (f64::from(t.record.f2_n) - t.true_ft_n) * n.sqrt() / case.noise_n()
            })
            .collect();
        assert!(z.len() > 100, "{} valid records", z.len());
        let mean = z.iter().sum::<f64>() / z.len() as f64;
        let sd = (z.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (z.len() - 1) as f64).sqrt();
        assert!(
            (sd - 1.0).abs() < 0.15,
            "scatter {sd} of the sample noise's"
        );
    }

    /// The best detector's separation: on the samples, the departures' root sum of squares
    /// over the noise; on the periods, each period's summed departure over its own noise
    /// (`sqrt(n)` samples'), the deadline's period with its samples up to the deadline.
    #[test]
    fn a_damages_separation_is_its_departure_over_the_noise() {
        let noise = 2.0;
        // A step of 3 N on the feed force over samples 10-19, in the period 10-19.
        let step: Vec<_> = (10..20).map(|i| (i, [3.0, 0.0])).collect();
        let z = separations(&step, &[(9, 10), (19, 10), (29, 10)], noise);
        let want = 3.0 * 10f64.sqrt() / noise;
        assert!(
            (z.samples - want).abs() < 1e-12 && (z.periods - want).abs() < 1e-12,
            "{z:?}"
        );
        // Force moved inside the period, none lost over it: the periods see nothing.
        let moved: Vec<_> = (10..20)
            .map(|i| (i, [0.0, if i < 15 { 4.0 } else { -4.0 }]))
            .collect();
        let z = separations(&moved, &[(19, 10)], noise);
        assert!((z.samples - 4.0 * 10f64.sqrt() / noise).abs() < 1e-12 && z.periods.abs() < 1e-12);
        // The deadline at sample 19 inside a period of 10-29: its first ten samples count.
        let z = separations(&step, &[(29, 20)], noise);
        assert!((z.periods - want).abs() < 1e-12, "{z:?}");
        // Two periods, a loss of 3 N in one and 1 N in the next: their squares add.
        let two: Vec<_> = (0..20)
            .map(|i| (i, [0.0, if i < 10 { -3.0 } else { 1.0 }]))
            .collect();
        let z = separations(&two, &[(9, 10), (19, 10)], noise);
        assert!(
            (z.periods - (10.0 * (9.0 + 1.0) / 4.0f64).sqrt()).abs() < 1e-12,
            "{z:?}"
        );
    }

    /// A break's separation is known and a normal case has none; no detector on the periods
    /// sees more than one on every sample.
    #[test]
    fn a_breaks_separation_by_the_deadline_is_measured() {
        let case = draw_case(Kind::Break, 0, 1).expect("a break case");
        let o = run_case(&case).expect("ran");
        let z = o.separation.expect("a sudden damage's separation");
        assert!(
            z.periods > 0.0 && z.periods <= z.samples && z.samples.is_finite(),
            "{z:?}"
        );
        let normal = run_case(&draw_case(Kind::Normal, 0, 1).expect("a normal case")).expect("ran");
        assert_eq!(normal.separation, None);
    }

    /// The nearest exit is found where one is: a break case's cut, undamaged, leaving the
    /// work through a face placed (from the path the tool centre travels, by the feed per
    /// tooth at every sample) so that its exit begins at the damage's time, told as if
    /// that were a damage's onset. Among the faces tried is that one (two revolutions'
    /// travel at a constant feed is a whole number of the scan's steps), whose forces are
    /// the case's own: nothing separates them, and the exit found begins where the face
    /// was put, within a tooth. The undamaged cut told as if damaged is nearest to no exit.
    /// And a real break stands off every exit, no nearer than the undamaged run.
    #[test]
    fn the_nearest_exit_to_an_exit_is_itself() {
        let drawn = draw_case(Kind::Break, 0, 1).expect("a break case");
        let sc = &drawn.scenario;
        let t = drawn.damage_s.expect("a damage time");
        let fs = sc.sample_rate_hz;
        let (rr, _, tc) = engagement_at(sc, t).expect("a cut at the damage");
        let reach = arc_reach_mm(sc.tool.radius_mm, rr);
        // The path at `t` and two revolutions before, as `nearest_exit` integrates it.
        let mut clean = sc.clone();
        clean.events.clear();
        let rev_s = 60.0 / drawn.rpm_at_damage;
        let (at, before) = (
            (t * fs).floor() as usize,
            ((t - 2.0 * rev_s) * fs).max(0.0) as usize,
        );
        let n = f64::from(sc.tool.flutes);
        let (mut p, mut path) = (0.0, Vec::new());
        sim::simulate(&clean, |row| {
            p += f64::from(row.truth.tc_mm) * n * f64::from(row.truth.rpm) / 60.0 / fs;
            path.push(p);
            Ok(())
        })
        .expect("simulated");
        let travel = path[at] - path[before];
        assert!(
            (travel / (tc / EXIT_FACES_PER_FEED) - 2.0 * n * EXIT_FACES_PER_FEED).abs() < 0.05,
            "two revolutions at a constant feed: {travel} mm"
        );
        let mut exiting = Case {
            scenario: clean.clone(),
            ..drawn.clone()
        };
        if let Some(s) = exiting
            .scenario
            .workpiece
            .as_mut()
            .and_then(|w| w.spans_mm.last_mut())
        {
            s[1] = path[at] + reach;
        }
        let (mut told_o, records) = trace_case(&exiting).expect("traced");
        let onset = at as f64 / fs;
        (told_o.onset_s, told_o.rev_s) = (Some(onset), rev_s);
        let told = (drawn.noise_n(), t, onset, rev_s);
        let e = nearest_exit_of(&exiting.scenario, &clean, told, &records).expect("ran");
        assert!(
            e.separation.samples < 0.5 && e.separation.periods < 0.5,
            "{e:?}"
        );
        let begins = e.samples_from_s.expect("an exit found");
        let tooth_s = rev_s / n;
        assert!(
            begins > t - tooth_s && begins < t + tooth_s,
            "begins at {begins} s, the face put for {t} s"
        );
        // The undamaged cut told as if damaged: nothing nearer than itself, no exit.
        let same = nearest_exit_of(&clean, &clean, told, &records).expect("ran");
        assert_eq!(same.samples_from_s, None, "{same:?}");
        assert_eq!(same.separation.samples, 0.0, "{same:?}");
        let said = nearest_exit_text(&same, &told_o);
        assert!(
            said.contains("no exit on the samples, 0.0 sigma away"),
            "{said}"
        );
        let said = nearest_exit_text(&e, &told_o);
        assert!(said.contains(": an exit from "), "{said}");
        // A real break: no nearer than the undamaged run, and more than noise away; a
        // normal case has none.
        let (o, records) = trace_case(&drawn).expect("traced");
        let normal = Outcome {
            kind: Kind::Normal,
            ..o
        };
        let mut calm = drawn.clone();
        calm.kind = Kind::Normal;
        assert_eq!(nearest_exit(&calm, &normal, &records).expect("ran"), None);
        let z = o.separation.expect("a separation");
        let e = nearest_exit(&drawn, &o, &records)
            .expect("ran")
            .expect("an onset");
        assert!(
            e.separation.samples <= z.samples && e.separation.samples > 5.0,
            "{e:?} against {z:?}"
        );
    }

    /// The window shown: three revolutions before the damage to one past the first alarm;
    /// four past the damage without one; from before a false alarm that came before the
    /// damage; around the alarm without damage; none without either. And the text: the
    /// case, its verdict, and a line for each record in the window, the alarm's on the
    /// record that raised it.
    #[test]
    fn a_trace_shows_the_case_and_its_records_around_the_damage() {
        let o = Outcome {
            kind: Kind::Break,
            index: 3,
            seed: 7,
            cutting_s: 2.0,
            first_alarm: Some((1.03, Cause::Breakage)),
            damage_s: Some(1.0),
            onset_s: Some(1.01),
            tooth_s: 0.005,
            rev_s: 0.02,
            first_rev_teeth: Some(1.0),
            separation: None,
        };
        let near =
            |(a, b): (f64, f64), (c, d): (f64, f64)| (a - c).abs() < 1e-12 && (b - d).abs() < 1e-12;
        assert!(near(trace_window(&o).unwrap(), (0.94, 1.05)));
        let quiet = Outcome {
            first_alarm: None,
            ..o
        };
        assert!(near(trace_window(&quiet).unwrap(), (0.94, 1.08)));
        let early = Outcome {
            first_alarm: Some((0.9, Cause::Breakage)),
            ..o
        };
        assert!(near(trace_window(&early).unwrap(), (0.84, 1.08)));
        let normal = Outcome {
            kind: Kind::Normal,
            damage_s: None,
            onset_s: None,
            ..o
        };
        assert!(near(trace_window(&normal).unwrap(), (0.97, 1.05)));
        assert_eq!(
            trace_window(&Outcome {
                first_alarm: None,
                ..normal
            }),
            None
        );

        let case = draw_case(Kind::Break, 0, 1).expect("a break case");
        let (outcome, traced) = trace_case(&case).expect("traced");
        let window = trace_window(&outcome).expect("a damage");
        let text = format_trace(&case, &outcome, &traced, None, window);
        let fs = f64::from(case.machine.monitor.sample_rate_hz);
        let shown = traced
            .iter()
            .filter(|t| (window.0..=window.1).contains(&(t.record.end_sample as f64 / fs)))
            .count();
        assert!(shown > 8, "{shown} records");
        assert!(text.starts_with("seed 1 break 0: "), "{text}");
        let lines: Vec<&str> = text.lines().collect();
        // The cut at the damage, within the draw's ranges (R_r 0.2-1.6, R_a 0.3-1.5, t_c
        // 0.04-0.2 mm).
        let cut: Vec<f64> = lines[1]
            .strip_prefix("cut at the damage: ")
            .unwrap_or_else(|| panic!("{text}"))
            .split(", ")
            .take(3)
            .map(|f| {
                f.split(' ')
                    .nth(1)
                    .and_then(|v| v.parse().ok())
                    .expect("a number")
            })
            .collect();
        assert!(
            (0.2..=1.6).contains(&cut[0])
                && (0.3..=1.5).contains(&cut[1])
                && (0.04..=0.2).contains(&cut[2]),
            "{text}"
        );
        let told = format!("{}{}", verdict(&outcome), separation_text(&outcome));
        assert!(
            lines[2].ends_with(&told) && told.contains(" sigma on the samples"),
            "{text}"
        );
        assert_eq!(lines.len(), 5 + shown, "{text}");
        let raised = lines.iter().filter(|l| l.contains(", breakage (")).count();
        assert_eq!(raised, 1, "{text}");
    }

    #[test]
    fn a_case_is_named_by_its_set_and_index() {
        assert_eq!(parse_case("break:16").unwrap(), (Kind::Break, 16));
        assert_eq!(parse_case("normal:119").unwrap(), (Kind::Normal, 119));
        for (bad, says) in [
            ("brake:1", "the sets are normal, break, chip"),
            ("break", "expected KIND:INDEX"),
            ("break:x", "not a whole number"),
            ("break:120", "cases are 0-119"),
            ("wear:30", "cases are 0-29"),
        ] {
            let e = parse_case(bad).unwrap_err().to_string();
            assert!(e.contains(says), "{bad}: {e}");
        }
    }
}

/// The feed of a drawn case's first segment, up to its feed change [mm/min].
#[cfg(test)]
fn first_feed_mm_min(case: &Case) -> f64 {
    match case.scenario.segments[0].feed_mm_min {
        Some(sim::scenario::Profile::Constant(f)) => f,
        ref p => panic!("first segment's feed {p:?}"),
    }
}

/// Cases of held-out seeds that an earlier rule got wrong, each run over several noise
/// seeds (the one it was drawn with first).
#[cfg(test)]
mod held_out_tests {
    use super::*;

    /// No alarm on `kind` case `index` at draw seed `seed`, run with its own noise seed and
    /// the `seeds - 1` after it.
    fn no_alarm_over_noise(kind: Kind, index: usize, seed: u64, seeds: u64) {
        no_alarm_over_noise_in(Setup::default(), kind, index, seed, seeds);
    }

    /// ... with the monitor and the cases set up as `setup`.
    fn no_alarm_over_noise_in(setup: Setup, kind: Kind, index: usize, seed: u64, seeds: u64) {
        let raised: Vec<String> = outcomes_over_noise_in(setup, kind, index, seed, seeds)
            .into_iter()
            .filter_map(|(noise, out)| Some(format!("noise seed {noise}: {:?}", out.first_alarm?)))
            .collect();
        assert!(
            raised.is_empty(),
            "{kind:?} {index} at seed {seed}: {raised:#?}"
        );
    }

    /// `no_alarm_over_noise_in` over 16 noise seeds with no current-loop lag (`--lag-s 0`).
    fn no_alarm_without_lag(kind: Kind, index: usize, seed: u64) {
        no_alarm_over_noise_in(no_lag(), kind, index, seed, 16);
    }

    /// The cases and the monitor without the current-loop lag (`--lag-s 0`).
    fn no_lag() -> Setup {
        Setup {
            lag_s: Some(0.0),
            ..Setup::default()
        }
    }

    /// `kind` case `index` at draw seed `seed` over `seeds` noise seeds
    /// (`outcomes_over_noise`): each run's damage caught, and no alarm before it.
    fn caught_with_no_false_alarm(kind: Kind, index: usize, seed: u64, seeds: u64) {
        for (noise, out) in outcomes_over_noise(kind, index, seed, seeds) {
            assert!(
                !out.false_alarm() && out.detected_after_s().is_some(),
                "{kind:?} {index} at seed {seed}, noise seed {noise}: {:?}",
                out.first_alarm
            );
        }
    }

    /// The entry of a light cut (3 flutes, R_r 0.27, a feed of 0.8 % of the 8 mm radius,
    /// tooth averages of 20-50 N) whose force doubles over its 0.57 s, broken 1.4 s after
    /// it. `E`'s spread was learned early in the entry; the encoder jitter's share of the
    /// noise grows with the force, and a breakage was raised in the entry against the
    /// spread of half the force. With the spread scaled to the force, no alarm comes
    /// before the damage, and the break is caught.
    #[test]
    fn a_light_cut_entered_raises_nothing_before_its_break() {
        caught_with_no_false_alarm(Kind::Break, 2, 46, 8);
    }

    /// Light cuts whose short, steep chips begin inside the tooth period: seed 165's normal
    /// case 100 (2 flutes, `R_r` 0.2, tooth averages of 120 and 210 N) and seed 174's
    /// normal case 70 (4 flutes, 60-110 N, lightening). A hand-over pair in the noise (4.8
    /// sigma_R; 5 where the loss's record was flagged) armed the drop trip at 30 % of the
    /// tooth, and the sum over the period's first bins, which the encoder's jitter at the
    /// chip's edge swings by a spread of 19 N against 6 N of the whole period, passed it
    /// mid-period: a breakage raised in a normal cut. Found at seeds 145-192, after the
    /// rules had been set on seeds 1-120.
    #[test]
    fn the_jitter_at_a_light_cuts_edge_is_no_drop() {
        no_alarm_over_noise(Kind::Normal, 100, 165, 8);
        no_alarm_over_noise(Kind::Normal, 70, 174, 8);
    }

    /// A cut whose engagement changes from revolution to revolution (seed 200, normal case
    /// 44: 2 flutes, 1 267 rpm, most records flagged transient): one tooth lost 44 N in a
    /// flagged record and the next gained 53 N, a pair of 5.1 sigma_R that passed as the
    /// evidence of a hand-over; the losing tooth's next period tripped at 0.3 of the tooth
    /// on the cut's change of shape. A flagged loss is evidence only out of a cut steady for
    /// the 2N records before it. Found at seeds 193-240.
    #[test]
    fn a_pair_in_a_cut_that_keeps_changing_is_no_evidence() {
        no_alarm_over_noise(Kind::Normal, 44, 200, 8);
    }

    /// An exit (4 flutes, 2 162 rpm, up milling) flagged transient for its first
    /// revolutions, then fading on unflagged: one tooth lost 136 N (a third) in a transient
    /// record, the next gained 27 N, past the 5 sigma_R a flagged loss asks, and the 2N
    /// records before were unflagged. The trip armed at 0.3 of the tooth passed on the
    /// exit's next tooth. The revolution before the loss had lost 297 N against three
    /// revolutions earlier (4.7 sigma of that change): a flagged loss is evidence only where
    /// the force held. (Asking the 2N records before to be neither transient nor settling
    /// instead made seed 20's break case 0 late in 1 of its 8 noise seeds: a cut settling
    /// after its entry.)
    #[test]
    fn a_flagged_pair_as_an_exit_fades_is_no_evidence() {
        no_alarm_over_noise(Kind::Normal, 52, 276, 8);
    }

    /// A light steady cut (4 flutes, 2 794 rpm, tooth averages of 135-180 N): one tooth
    /// 10 N over its level and, a revolution later, 14 N under it. `E` swung -40 N and
    /// +37.7 N at once, a breakage's pattern, against a threshold of 35.8 N (4.5 of E's
    /// spread, 9.0 N over the whole cut). At 5 spreads it is noise.
    #[test]
    fn one_teeths_excursion_in_a_light_cut_is_no_breakage() {
        no_alarm_over_noise(Kind::Normal, 84, 250, 8);
    }

    /// Two-flute cuts after a speed change (seed 31 taught case 21, 1 823 rpm, up milling;
    /// seed 91 break case 65 before its damage, 1 375 rpm): for five revolutions one
    /// tooth's force rose about 10 N a revolution and the other's fell, the total steady.
    /// The means of two revolutions against two three revolutions earlier, tried with 2
    /// flutes too, raised a breakage on both. With 2 flutes that rule is off.
    #[test]
    fn a_two_flute_split_drifting_after_a_speed_change_is_no_breakage() {
        no_alarm_over_noise(Kind::Taught, 21, 31, 8);
        for (noise, out) in breaks_over_noise(65, 91, 8) {
            assert!(
                !out.false_alarm(),
                "noise seed {noise}: {:?}",
                out.first_alarm
            );
        }
    }

    /// An exit of a 2-flute tool at 3 645 rpm (tooth averages from 355 N down to 100 N
    /// over ten revolutions, flagged transient and settling): one revolution held inside
    /// its noise (sigma_R 12 N), the plain drop trip was armed at half the tooth, and the
    /// exit's next tooth lost 72 N of its 115 N. The newest two revolutions had lost 132 N
    /// against the two three revolutions earlier, 5.5 of that change's noise: past 4 the
    /// plain trip is not armed. Found at seeds 289-336, the first run past the seeds the
    /// rules were set on.
    #[test]
    fn an_exit_that_pauses_for_a_revolution_arms_no_trip() {
        no_alarm_over_noise(Kind::Normal, 4, 299, 8);
    }

    /// A 2-flute tool under strong runout (80 and 40 N a tooth, 1 640 rpm) as the spindle
    /// sped up by 1-2 % a tooth: the current loop's lag, a time, moved force across the
    /// hand-over stage's bins, and the light flute's period showed a hand-over of 12 N at
    /// 4.4 sigma: a breakage raised 0.7 s before the damage. The hand-over decides only
    /// where the newest two revolutions are as long as the two before (to 1 % and two
    /// samples; here 807 samples against 834). Found at seeds 289-336.
    #[test]
    fn a_speed_ramp_under_runout_is_no_hand_over() {
        caught_with_no_false_alarm(Kind::Break, 105, 306, 8);
    }

    /// A wide arc (3 flutes, `R_r` 1.5, 3 134 rpm, tooth averages of 230-270 N): in one
    /// revolution tooth 2 was 15 N over its level and tooth 0, the next, 15 N under (the
    /// encoder's jitter moves force between adjacent windows). Both returned on the next
    /// pass: against that revolution a loss and the next tooth's gain, 50 N (4.8 sigma_R),
    /// which passed as a hand-over's evidence; the trip armed at 0.3 of the tooth fired on
    /// an exit's first tooth. Against two revolutions earlier the pair was 18.5 N (1.8):
    /// it must stand there too. Found at seeds 337-384, the first run past seeds 1-336.
    #[test]
    fn a_pair_of_excursions_returning_is_no_evidence() {
        no_alarm_over_noise(Kind::Taught, 14, 382, 8);
    }

    /// An exit's tail (4 flutes, up milling, `R_r` 1.17, 1 670 rpm: seed 1723, normal case
    /// 113): 150-200 N a tooth for revolutions, its records flagged transient on and off,
    /// ending inside one period. The plain trip, armed on a settling record two after two
    /// transient ones, passed at the end: a breakage. Not armed with two of the last N
    /// records flagged. Found at seeds 1633-1728.
    #[test]
    fn an_exits_flagged_tail_arms_no_plain_trip() {
        no_alarm_over_noise(Kind::Normal, 113, 1723, 8);
    }

    /// An exit's slow tail (2 flutes under runout, 2 229 rpm, down milling, a revolution's
    /// two teeth 500 N together, then 360 N three revolutions later): two revolutions
    /// unflagged, then a pair in the noise, one tooth 43 N down and the next 50 N up (4.6
    /// sigma_R), passed as a hand-over's evidence and armed the trip at 0.3; the exit's
    /// next period lost 48 N. The revolution before the pair had fallen 138 N against
    /// three earlier, 4.8 of that change's noise: a cut that fell before the loss (past 4
    /// of it, 2 where the loss's record is flagged) gives no evidence. Found at seeds
    /// 1729-1824.
    #[test]
    fn an_exits_unflagged_tail_gives_no_evidence() {
        no_alarm_over_noise(Kind::Normal, 30, 1786, 8);
    }

    /// An exit through a face under runout (4 flutes, `R_r` 1.27, down milling, 0.2 mm a
    /// tooth, tooth averages of 1 250-1 710 N, the heaviest 18 % over the revolution's
    /// mean): the newest tooth lost 6 % (in the noise), the plain trip was armed at 0.59 of
    /// the next, and that one lost past it. The next flute's reach is its own chip ahead of
    /// the newest one's, not a feed: under runout the heavy flute's chip is thicker by about
    /// its force's excess over the mean. Found at seeds 1825-1920 (seed 1900 normal 32).
    #[test]
    fn a_heavy_flute_at_an_exit_is_a_chip_ahead() {
        no_alarm_over_noise(Kind::Normal, 32, 1900, 8);
    }

    /// An exit through a face (4 flutes, `R_r` 1.18, `R_a` 1.07, 30 deg helix, down milling,
    /// 0.23 mm a tooth, 900-1 300 N a tooth): a window lost 57 % of its tangential force
    /// after the one before lost nothing, against a trip at 0.58. The cut's span, its arc
    /// and the helix's lag, is 2.36 rad against a pitch of 1.57: each window holds the
    /// start of the next flute's cut too, a feed further on, and loses with it. Found at
    /// seeds 1921-2016 (seed 1981 normal 10; the code before raised it too).
    #[test]
    fn a_window_holding_two_flutes_cuts_loses_a_feed_further_on() {
        no_alarm_over_noise(Kind::Normal, 10, 1981, 8);
    }

    /// An exit's tail (4 flutes, `R_r` 1.5, 0.026 mm a tooth, 50 N a tooth, its records
    /// flagged transient): the two revolutions' means against three earlier, two
    /// neighbouring teeth up 17 and 14 N and one down 33 N, passed as a gain split over two
    /// windows. The split gain counts only out of unflagged records. Found at seeds
    /// 2017-2112 (seed 2101 normal 90; raised since the split gain came in).
    #[test]
    fn an_exits_flagged_tail_is_no_split_gain() {
        no_alarm_over_noise(Kind::Normal, 90, 2101, 8);
    }

    /// An exit that holds and steps (4 flutes, `R_r` 0.81, 0.034 mm a tooth): the
    /// revolutions' sums flat at 590-630 N for three revolutions, one tooth 2.3 sigma_R up
    /// on the last (206 N against 160 and 108 around it), then a fall of 29 % in one
    /// revolution: against that high reference its next period lost 63 %, past the plain
    /// trip at 0.55 and 118 N. The floor rises by the reference tooth's gain a revolution
    /// ago. Found at seeds 2161-2256 (seed 2256 normal 48; 938293f raised it too).
    #[test]
    fn a_reference_tooths_excursion_raises_the_trip() {
        no_alarm_over_noise(Kind::Normal, 48, 2256, 8);
    }

    /// Wide arcs in down milling (3-4 flutes, `R_r` 1.22-1.39, tooth averages of 450-1 400
    /// N): a pair in the noise that passed as a hand-over's evidence (a tooth down, the
    /// next up, past 4.5 sigma_R together), and an exit whose first period was one the
    /// pair armed at 0.3 of the tooth: it lost 30-37 %. The pair tells nothing of the
    /// period to come; the share now covers what an exit beginning there could take (one
    /// feed's travel past what the newest tooth allows: 0.40-0.49 here). Seed 417 normal
    /// 98, seed 489 normal 21, seed 537 normal 70, seed 627 normal 60: found at seeds
    /// 385-432, 481-576 and 577-672.
    #[test]
    fn an_exit_right_after_a_pair_trips_no_lower_than_its_share() {
        for (index, seed) in [(98, 417), (21, 489), (70, 537), (60, 627)] {
            no_alarm_over_noise(Kind::Normal, index, seed, 8);
        }
    }

    /// A hand-over inside the period past 4 sigma in cuts with no break: seed 746 normal
    /// 37 (2 flutes, 3 083 rpm, up milling, every record ambiguous: 8.5 N at 4.02 sigma
    /// against the share's 4.6 N), seed 848 normal 97 (3 flutes, 1 871 rpm, down milling,
    /// `R_r` 0.8: 21.5 N at 4.12 against 10.4 N), seed 699 chip 26 before its damage (4
    /// flutes, up milling: 41 N at 4.05 against 26 N). Found at seeds 673-864, the first
    /// runs past seeds 1-672; the hand-over now decides past 4.5 sigma.
    #[test]
    fn a_hand_over_just_past_four_sigma_is_noise() {
        no_alarm_over_noise(Kind::Normal, 37, 746, 8);
        no_alarm_over_noise(Kind::Normal, 97, 848, 8);
        for (noise, out) in outcomes_over_noise(Kind::Chip, 26, 699, 8) {
            assert!(
                !out.false_alarm(),
                "noise seed {noise}: {:?}",
                out.first_alarm
            );
        }
    }

    /// A 2-flute tool under runout (200 and 75 N a tooth, 2 267 rpm) as the spindle sped
    /// up by 10 % over 8 teeth: a pair in the noise passed as a hand-over's evidence and
    /// armed the drop trip at 0.3 of the tooth; the period lost 33 % (the current loop's
    /// lag, a time, moving force across the windows' boundaries): a breakage 0.25 s
    /// before the tool was lost. The evidence counts only with the newest revolution as
    /// long as the one before. Found at seeds 673-768.
    #[test]
    fn a_pair_in_a_speed_ramp_is_no_evidence() {
        caught_with_no_false_alarm(Kind::Gone, 8, 678, 8);
    }

    /// An exit fading over five revolutions (3 flutes under runout, 200, 60 and 140 N a
    /// tooth, 1 457 rpm, down milling, `R_r` 0.66): its first teeth lost 2.7 and 5.4
    /// sigma_R, the light flute after them gained 1.4 by noise, and the pair (6.9 sigma_R,
    /// a strong one) passed as a hand-over's evidence; the trip armed at 0.3 on the first
    /// tooth's window passed as it lost its next 23 %. Where the tooth before the loss lost
    /// too, a pair is evidence only if its gain takes half of both losses (a flute broken in
    /// the window before hands both on: `a_flute_whose_cut_begins_in_the_window_before_the_loss_trips_there`).
    /// Seed 908 normal 79, found at seeds 865-960 (their first run, with the hand-over at
    /// 4.5 sigma).
    #[test]
    fn an_exits_first_teeth_and_a_noise_gain_are_no_evidence() {
        no_alarm_over_noise(Kind::Normal, 79, 908, 8);
    }

    /// An exit's first tooth and a light flute after it (3 flutes under runout, 485, 130
    /// and 300 N a tooth, 1 886 rpm, down milling, `R_r` 1.27 at a feed of 0.04 mm): the
    /// heavy flute's tooth lost 5 sigma_R as the exit began, the light one gained 0.4 by
    /// noise where the exit's share of its force was a loss of 1.3, and the pair passed as
    /// a hand-over's evidence; the window before armed at 0.3 lost 33 % in the exit. A
    /// pair's gain must stand 2.5 sigma_R above the exit's share. Seed 968 normal 32,
    /// found at seeds 961-1056 (their first run).
    #[test]
    fn a_light_flutes_noise_gain_after_an_exits_first_tooth_is_no_evidence() {
        no_alarm_over_noise(Kind::Normal, 32, 968, 8);
    }

    /// The window's move out of a cut into the gap between cuts (2 flutes, 1 930 rpm, down
    /// milling, `R_r` 0.39: a cut of 76 degrees of the 180 a tooth, its thick entry in the
    /// last bin before the pulse): the odd period, 1.66 periods long, was judged whole at
    /// its close against the trip armed at half the tooth, and its last bin, which had
    /// taken the excess into the gap, lost half the tooth against the same bin a
    /// revolution earlier (the entry's peak). Raised as a breakage in an overload case,
    /// before the overload. The move's realignment now drops a trip the close raised.
    /// Seed 1175 overload 6, found at seeds 1153-1248 (their first run).
    #[test]
    fn a_moved_windows_odd_period_raises_nothing() {
        caught_with_no_false_alarm(Kind::Overload, 6, 1175, 8);
    }

    /// An exit whose tail fades for dozens of revolutions near the not-cutting floor (2
    /// flutes, down milling, 150 N a tooth in the cut, 10-40 N in the tail, noise 4.5 N a
    /// tooth). E's spread was learned with each value clipped at `k F`, 6 N in the tail,
    /// under the noise itself: the spread, and the drop trip's floor with it, fell with the
    /// force (sigma_R 4.6 N), and a tooth 10 N up then 17 N down tripped at 6 of it. Seed
    /// 3642 normal 103, found at seeds 3553-3648 (their first run).
    #[test]
    fn an_exits_tail_in_the_noise_keeps_its_noise_figure() {
        no_alarm_over_noise(Kind::Normal, 103, 3642, 8);
    }

    /// An exit's tail (4 flutes, up milling, R 8 mm, 50-110 N a tooth, noise 16 N a tooth on
    /// each channel): the plain trip, armed at a floor of 6 sigma_R of the resultant (15.8
    /// N, learned over the tail's last revolutions), passed on the tangential channel's
    /// pair, a tooth 39 N up then 48 N down, 3.8 of that channel's own sigma_R (23 N). The
    /// trip's floor now widens by its channel's noise over the resultant's. Seed 3723
    /// normal 34, found at seeds 3649-3744 (their first run).
    #[test]
    fn the_trips_floor_is_in_its_own_channels_noise() {
        no_alarm_over_noise(Kind::Normal, 34, 3723, 8);
    }

    /// An exit right after a noise pair (3 flutes, down milling, 8 mm, `R_r` 1.0, 0.18 mm a
    /// tooth, 1 000-1 500 N a tooth): a tooth 92 N down (1.6 sigma_R) and the next 168 N
    /// up passed as a hand-over's evidence; the exit began in the period after, its first
    /// tooth 117 N down (hidden under 2 sigma_R), and the handed tooth's period, the
    /// heaviest flute (17 % over the revolution's mean), armed at 0.30 (the two-feed
    /// exit's 0.299, under the evidence's least), lost 30 %. Its reach asks 0.32. Seed
    /// 3804 normal 11, found at seeds 3745-3840 (their first run).
    #[test]
    fn an_exit_after_a_pair_is_covered_at_a_heavy_flutes_reach() {
        no_alarm_over_noise(Kind::Normal, 11, 3804, 8);
    }

    /// One tooth's excursion in a steady cut (4 flutes, down milling, R 6 mm, 2 500 rpm,
    /// 310-640 N a tooth): `R` -44, +92 (5.3 sigma_R), -41 N, so `E` +136 and -133 N
    /// against a floor of 123 N (5 sigma_E), two exceedances of both signs. The second was
    /// the first's mirror (the teeth on either side 41 and 44 N); it now counts only where
    /// one of them carries half the threshold, or the shared tooth passes it alone. Seed
    /// 4002 normal 35, found at seeds 3937-4032 (their first run).
    #[test]
    fn one_tooths_excursion_is_one_exceedance() {
        no_alarm_over_noise(Kind::Normal, 35, 4002, 8);
    }

    /// An exit under heavy runout (2 flutes, down milling, R 5 mm, 3 100 rpm, flute 0 out
    /// by 65 um: 715 and 186 N a tooth): the heavy tooth lost 306 N of a revolution's
    /// change of 146 N, an exceedance of `E`, and its mirror counted because the shared
    /// tooth alone passed the threshold. It counts now only past that tooth's share of the
    /// revolution's change too. Seed 4712 normal 100, found at seeds 4705-4800 (their
    /// first run; raised with the window's boundary at the pulse too).
    #[test]
    fn an_exit_under_heavy_runout_is_no_mirror() {
        no_alarm_over_noise(Kind::Normal, 100, 4712, 8);
    }

    /// A break whose next flute's gain the current loop's lag carried mostly into the
    /// window after (2 flutes, 3 136 rpm: the broken tooth 214 -> 136 N, the next 207 ->
    /// 237 N against 273 N true). Its gain alone is under half the threshold, but the loss
    /// alone passes it (8 sigma_R): the pair counts. With its drawn noise, caught 0.59
    /// revolutions after the damage (1.01 without: 1.00 after the first missed cut); over
    /// the 8 noise seeds 0.59-1.01. Seed 3981 break 28, at seeds 3937-4032.
    #[test]
    fn a_loss_past_the_threshold_alone_counts_with_a_lagged_gain() {
        let got = latencies_over_noise(28, 3981, 8);
        let within = |r: &Option<f64>, revs: f64| r.is_some_and(|r| r < revs);
        assert!(
            within(&got[0], 0.8) && got.iter().all(|r| within(r, 1.2)),
            "{got:?}"
        );
    }

    /// A speed change coming to its end (2 flutes under runout, down milling, 4 mm, 40-60 N
    /// a tooth, 1 546 -> 1 695 rpm over 8 teeth): the window's boundary, which follows the
    /// pulses' tracked times, still lagged while the last revolutions were as long, and
    /// moved force from one window into the other (55 -> 29 N and 36 -> 60 N). A pair of
    /// that passed as a hand-over's evidence, and the handed tooth's period, armed at 0.3,
    /// lost 35 %: a breakage 14 revolutions before the damage. The evidence now asks the
    /// speed settled over 16 teeth as the rules that compare revolutions do. Seed 3890
    /// break 103, found at seeds 3841-3936 (their first run).
    #[test]
    fn a_pair_as_a_speed_change_settles_is_no_evidence() {
        caught_with_no_false_alarm(Kind::Break, 103, 3890, 8);
    }

    /// A tool lost late in a period (4 flutes, down milling, 1 100 / 590 / 880 / 820 N a
    /// tooth, in the revolutions after the window moved): the drop trip latched 3 ms after
    /// the loss; the tripped period kept 31 % of its force, the next one 1 %, and the rule
    /// for a resumed cut named a breakage on that first empty tooth, before the second
    /// told a lost tool. A collapsed tooth is now left to the trip's naming. Seed 3731 gone
    /// 23, found at seeds 3649-3744 (their first run).
    #[test]
    fn a_tool_lost_late_in_a_tripped_period_is_named_a_lost_tool() {
        caught_with_no_false_alarm(Kind::Gone, 23, 3731, 8);
    }

    /// A speed change under runout (2 flutes, 0.063 mm out against a chip of 0.19 mm,
    /// 1 977 -> 2 267 rpm in 0.15 s, the speed overshooting to 2 344 rpm and settling
    /// back): the placed boundary, which follows the pulses' tracked times, lagged through
    /// the ramp and its settling, and at the heavy flute's steep chip edge that moved force
    /// from its window into the light flute's, 58 -> 122 N and 184 -> 128 N: `E` past the
    /// threshold both ways, then, in the settling, the redistribution against three
    /// revolutions earlier. A breakage was raised before the tool was lost. The rules that
    /// compare revolutions now decide only with the newest two revolutions as long as the
    /// two 16 teeth earlier. Seed 1190 gone 14, found at seeds 1153-1248 (their first run).
    #[test]
    fn a_speed_change_under_runout_is_no_breakage() {
        caught_with_no_false_alarm(Kind::Gone, 14, 1190, 8);
    }

    /// A light cut with the window at the pulse (2 flutes, 3 884 rpm, 77 samples a tooth,
    /// `R_r` 0.2, tooth averages of 70 and 90 N; the window's review left the boundary
    /// there): a hand-over pair in the noise armed the drop trip at 0.3 of the tooth, and
    /// the next period's boundary, a pulse 1.4 samples early against the pulses' tracked
    /// times, its reference's 1.2 late, moved the chip's steep rising edge by 2.6 samples
    /// inside the period: 30 % of the tooth lost there mid-period, none over the period. The
    /// trip allowed for a shift of one sample; it now allows for how far the two pulses lay
    /// off their tracked times.
    /// Seed 1301 normal 41, found at seeds 1249-1344 (their first run).
    #[test]
    fn a_pulses_jitter_at_a_light_cuts_edge_is_no_drop() {
        no_alarm_over_noise(Kind::Normal, 41, 1301, 8);
    }

    /// A flute broken a revolution after the window's one move of the cut (4 flutes, 3 712
    /// rpm, `R_r` 1.1, tooth averages of 800-900 N): the history was forgotten at the move,
    /// and the missing-flute watch ran for 2N+2 records. The flute broke early in its
    /// period, whose window still held 399 N (46 % of the mean, over the 0.45 share); its
    /// first empty pass (163 N against 900) came on the watch's last record, where it was
    /// the newest tooth, which the watch leaves out. Caught 91.66 revolutions late, at the
    /// exit. The watch now runs 3N+2 records. Found at seeds 385-432.
    #[test]
    fn a_flute_broken_in_the_revolution_after_a_move_is_caught() {
        all_caught_within(72, 414, 2.0);
    }

    /// A flute of a 4-flute tool broken in a wide arc (down milling, 3 529 rpm, tooth
    /// averages of 950-1 550 N, sigma_R 72 N: the encoder's jitter moves the steep edges
    /// inside the cut across the boundaries): its tooth lost 280 N in the first revolution
    /// and 80 more in the second, the next two teeth gained it over two passes. No
    /// revolution's change, against one revolution or three earlier, passed 4.5 sigma_R
    /// with both signs, and the loss was under the trip's half: never detected. Over 8
    /// noise seeds the rules caught 4; with the means of two revolutions against two
    /// three revolutions earlier (the noise over sqrt 2), 6, each within 2.5 revolutions.
    /// Two stay missed: the loss is about 5 sigma_R over two revolutions' means.
    #[test]
    fn a_loss_in_a_wide_arc_under_single_teeths_noise_is_caught() {
        let revs = latencies_over_noise(98, 263, 8);
        let caught = revs.iter().filter(|r| r.is_some()).count();
        assert!(
            caught >= 6 && revs.iter().flatten().all(|&r| r < 2.5),
            "{revs:?}"
        );
    }

    /// An exit through a face at `R_r` 1.37 and a feed of 3 % of the radius, 3 925 rpm, 4
    /// flutes, one out by 37 % of the chip. The arc holds `pi/2`: the thickest chip leaves
    /// first, as the square root of the travel, and the exit's second tooth loses about
    /// 45 % of its force (more with noise) while its first lost 11 %, inside the noise.
    /// The drop trip (half the tooth) raised a breakage on it.
    #[test]
    fn an_exit_whose_second_tooth_loses_half_is_not_a_breakage() {
        no_alarm_over_noise(Kind::Normal, 13, 14, 32);
    }

    /// An exit through a face at a feed of 7 % of the radius, one flute out by 40 % of
    /// the chip: 3.7 revolutions from the first tooth's loss to air, the revolution mean
    /// under the not-cutting floor two revolutions after the last steady record, while the
    /// teeth between faded (not a lost tool's one partial tooth).
    #[test]
    fn an_exit_that_fades_over_revolutions_is_not_a_lost_tool() {
        no_alarm_over_noise(Kind::Taught, 28, 11, 8);
    }

    /// A flute of a 2-flute tool broken 7 revolutions into the steady cut (R_r 1.47, a feed
    /// of 5 % of the radius, 2 913 rpm): E's spread then had fewer than 32 values (16
    /// revolutions of a 2-flute tool), and the breakage rules, which waited for them, saw
    /// the broken flute only once it was the steady pattern: the alarm came at the exit, 93
    /// revolutions later.
    #[test]
    fn a_flute_broken_early_in_the_cut_is_caught_within_a_revolution() {
        all_within_a_revolution(&[(1, 23)]);
    }

    /// Break case `index` at draw seed `seed`, run with its own noise seed and the
    /// `seeds - 1` after it: each run's noise seed and outcome.
    fn breaks_over_noise(index: usize, seed: u64, seeds: u64) -> Vec<(u64, Outcome)> {
        outcomes_over_noise(Kind::Break, index, seed, seeds)
    }

    /// `kind` case `index` at draw seed `seed`, run with its own noise seed and the
    /// `seeds - 1` after it: each noise seed and its outcome.
    fn outcomes_over_noise(kind: Kind, index: usize, seed: u64, seeds: u64) -> Vec<(u64, Outcome)> {
        outcomes_over_noise_in(Setup::default(), kind, index, seed, seeds)
    }

    /// ... with the monitor set up as `setup`.
    fn outcomes_over_noise_in(
        setup: Setup,
        kind: Kind,
        index: usize,
        seed: u64,
        seeds: u64,
    ) -> Vec<(u64, Outcome)> {
        let drawn = draw_case(kind, index, seed).expect("a case").scenario.seed;
        (0..seeds)
            .map(|k| {
                let mut case = draw_case(kind, index, seed).expect("a case");
                setup.apply(&mut case);
                case.scenario.seed = drawn.wrapping_add(k);
                (case.scenario.seed, run_case(&case).expect("the case runs"))
            })
            .collect()
    }

    /// ... each run's latency from the damage in revolutions (`None`: not detected).
    fn latencies_over_noise(index: usize, seed: u64, seeds: u64) -> Vec<Option<f64>> {
        breaks_over_noise(index, seed, seeds)
            .iter()
            .map(|(_, out)| out.detected_after_s().map(|l| l / out.rev_s))
            .collect()
    }

    /// Break case `index` at draw seed `seed`, over 8 noise seeds: every run caught within
    /// `revs` revolutions of the damage.
    fn all_caught_within(index: usize, seed: u64, revs: f64) {
        let got = latencies_over_noise(index, seed, 8);
        assert!(
            got.iter().all(|r| r.is_some_and(|r| r < revs)),
            "case {index} at seed {seed}: {got:?}"
        );
    }

    /// Two breaks whose chips settle over revolutions (4 flutes under runout: each chip is
    /// cut from the surface every flute before left, so the other flutes' chips change
    /// over a few passes after a break), each revolution's change under every threshold:
    /// seed 99, case 59 (3 263 rpm, down milling), never detected; seed 113, case 102
    /// (3 760 rpm, up milling), 11 revolutions late. Judged against three revolutions
    /// earlier too, each within 2 revolutions in all 8 noise seeds.
    #[test]
    fn a_break_whose_chips_settle_over_revolutions_is_caught() {
        for (index, seed) in [(59, 99), (102, 113)] {
            all_caught_within(index, seed, 2.0);
        }
    }

    /// Break case `index` at draw seed `seed` over noise seeds (`breaks_over_noise`): the
    /// runs whose alarm was not within a revolution of the damage.
    fn late_over_noise(index: usize, seed: u64, seeds: u64) -> Vec<String> {
        late_of_kind_over_noise(Kind::Break, index, seed, seeds)
    }

    /// ... of `kind` (a break, a chip or a lost tool).
    fn late_of_kind_over_noise(kind: Kind, index: usize, seed: u64, seeds: u64) -> Vec<String> {
        outcomes_over_noise(kind, index, seed, seeds)
            .into_iter()
            .filter(|(_, out)| !out.detected_after_s().is_some_and(|l| l <= out.rev_s))
            .map(|(noise, out)| format!("noise seed {noise}: {:?}", out.first_alarm))
            .collect()
    }

    /// Break cases `(index, draw seed)`, each over 8 noise seeds (its own first): every
    /// run's alarm within a revolution of the damage.
    fn all_within_a_revolution(cases: &[(usize, u64)]) {
        for &(index, seed) in cases {
            let late = late_over_noise(index, seed, 8);
            assert!(late.is_empty(), "case {index} at seed {seed}: {late:#?}");
        }
    }

    /// Break cases `(index, draw seed)`, each at its own noise seed alone: caught within a
    /// revolution of the first missed cut.
    fn each_drawn_within_a_revolution(cases: &[(usize, u64)]) {
        for &(index, seed) in cases {
            let out =
                run_case(&draw_case(Kind::Break, index, seed).expect("a case")).expect("runs");
            let l = out.detected_after_onset_s().expect("caught");
            assert!(
                l <= out.rev_s,
                "seed {seed} break {index}: {:.2} revolutions",
                l / out.rev_s
            );
        }
    }

    /// An exit (3 flutes, R_r 1.02, 3 009 rpm) right after a noise pair that passed as the
    /// evidence of a hand-over (one tooth 52 N down, the next 40 N up, 5.4 sigma_R
    /// together): the exit's first tooth, the one after the pair, lost 2.8 sigma_R, under
    /// the armed walk's 3, and the trip of the losing tooth's next period, armed at 0.3,
    /// passed on the exit's loss. After a pair the trip is armed lower only if the newest
    /// tooth lost under 2 sigma_R.
    #[test]
    fn an_exit_right_after_a_noise_pair_is_not_a_breakage() {
        no_alarm_over_noise(Kind::Taught, 12, 68, 8);
    }

    /// A hand-over pair far past the noise, decided at once (`alarm::PAIR_RAISE_SIGMAS`):
    /// seed 9069 break 56 (4 flutes, 4 167 rpm: a pair of 9.5 sigma_R, the alarm 0.2 ms
    /// past the revolution) and seed 9138 break 42 (2 flutes, a light cut: 12 sigma_R after
    /// a flagged record, the alarm a record later). Late in 1 and 2 of 16 noise seeds from
    /// the first missed cut before; within a revolution of the damage in all 8 here when
    /// the pair raised past 9 sigma_R. Past 9.5 (a steady cut's noise pair reached 9.04,
    /// seed 13805 chip 29), seed 9069's pair at noise seed 2321720, 9.46 sigma_R, arms the
    /// drop trip as evidence instead, which passed 0.4 ms past the damage's revolution
    /// (1.01 revolutions after the first missed cut): at most that one run of its 8, and
    /// within 1.05 revolutions of the damage.
    #[test]
    fn a_pair_far_past_the_noise_is_decided_on_its_gain() {
        all_within_a_revolution(&[(42, 9138)]);
        let late: Vec<_> = outcomes_over_noise(Kind::Break, 56, 9069, 8)
            .into_iter()
            .filter(|(_, o)| !o.detected_after_s().is_some_and(|l| l <= o.rev_s))
            .collect();
        assert!(
            late.len() <= 1
                && late
                    .iter()
                    .all(|(_, o)| o.detected_after_s().is_some_and(|l| l <= 1.05 * o.rev_s)),
            "{late:#?}"
        );
    }

    /// A 4-flute tool in a wide arc (seed 9527 break 33: up milling, `R_r` 1.49, 2 990
    /// rpm), a flute broken in its cut: its next cut begins in the window before its own,
    /// which lost 9 % (past the plain walk's 3 sigma_R), its own window 70 %. That loss
    /// kept the trip of the broken flute's window from being armed, and the alarm came on
    /// the next flute's gain, a period past the revolution. Where the cut spans more than
    /// a pitch the trip is armed after such a loss, at the share of the exit it would
    /// show. Late in 5 of these 8 noise seeds before, none now. (Seed 9446 break 57, the
    /// same pattern: late from the first missed cut in 3 of 8 before, none now, one of
    /// them 0.01 revolutions past the damage's.)
    #[test]
    fn a_wide_cuts_loss_in_the_window_before_arms_the_trip() {
        all_within_a_revolution(&[(33, 9527)]);
    }

    /// Exits of 4-flute tools in wide arcs (seed 8770 normal 2: down milling, `R_r` 1.59;
    /// seed 8783 normal 7: `R_r` 1.1, one flute 0.03 mm out), whose windows lost 24-29 %,
    /// then 21-22 %, then 54-57 %: the trip armed on the second loss alone, at the share of
    /// the exit it would show, passed on the third (both in their first noise seed). After
    /// a loss in a wide cut the trip is armed only where the teeth before it held.
    #[test]
    fn an_exit_whose_windows_all_lose_does_not_arm_on_the_newest_loss() {
        no_alarm_over_noise(Kind::Normal, 2, 8770, 8);
        no_alarm_over_noise(Kind::Normal, 7, 8783, 8);
    }

    /// An exit of a 3-flute tool (up milling, `R_r` 1.16, `R_a` 1.5): its first window lost
    /// 5.5 sigma_R, the trip was armed at 0.5 on the exit that loss shows (a reach of 0.41
    /// plus the resultant's noise), and the next window's period, 0.395 lost in the truth,
    /// lost 0.507 on the trip channel at its close (that channel's noise 3.4 sigma over
    /// it, against a share that took the resultant's). The close asks past the trip
    /// channel's noise in wide cuts too (alarm's
    /// `a_wide_cuts_close_asks_past_the_trip_channels_noise`). One noise seed in 16 alarmed.
    #[test]
    fn an_exits_close_is_judged_past_the_trip_channels_noise() {
        no_alarm_over_noise(Kind::Taught, 7, 9690, 16);
    }

    /// An exit of a 4-flute tool in a narrow arc (down milling, `R_r` 0.61, 200 N a tooth):
    /// a pair of 6.1 sigma_R by noise (19 N lost, 37 N gained; 3 N in the truth) just
    /// before it, strong, so the exit's first teeth (the newest 3 sigma_R down) did not
    /// void the evidence, and the handed tooth's period, armed at 0.3, lost 30 % (24 % in
    /// the truth). A strong pair keeps the evidence past the newest tooth's loss only where
    /// no estimate tells the span (alarm's
    /// `after_a_strong_pair_the_newest_tooths_loss_disarms_a_known_narrow_arc`).
    #[test]
    fn a_strong_noise_pair_before_an_exit_in_a_narrow_arc_is_no_evidence() {
        no_alarm_over_noise(Kind::Normal, 9, 9859, 8);
    }

    /// An exit of a 3-flute tool in a wide cut (down milling, `R_r` 1.26, 744 N a tooth,
    /// one flute 0.035 mm out): the exit's second period lost 0.475 in the truth, over the
    /// exit's share at the estimate's `R_r` (0.471, the estimate 0.02 low), and the trip,
    /// at 3 sigma_R of noise over it (0.548), passed inside the period (0.54 at the
    /// close). One noise seed in 16 alarmed; the share is asked past
    /// `alarm::TRIP_NOISE_SIGMAS` now.
    #[test]
    fn an_exits_second_period_in_a_wide_cut_is_asked_past_the_noise_of_its_loss() {
        no_alarm_over_noise(Kind::Normal, 6, 10264, 16);
    }

    /// An exit right after a noise pair, in a wide cut (3 flutes, down milling, `R_r` 1.26,
    /// 345 N): one tooth 28 N down and the next 31 N up (4.9 sigma_R together, 3 N in the
    /// truth), then the exit's first tooth 22 % down, which in a cut wider than a pitch
    /// does not void the pair's evidence; the handed tooth's period lost 44 % in the truth,
    /// 57 % measured, against the exit's reach, 0.47, with no noise over it. The share is
    /// asked past `alarm::EVIDENCE_UNDER_WAY_SIGMAS` of noise over the reach now.
    #[test]
    fn an_exit_right_after_a_noise_pair_is_asked_past_the_noise_of_its_reach() {
        no_alarm_over_noise(Kind::Taught, 16, 11206, 16);
    }

    /// Flutes broken late in their cut (4 flutes, wide arcs: seed 11288 break 103 and
    /// seed 11357 break 99, 1.02 and 1.26 revolutions after the first missed cut before):
    /// the break's revolution handed a little of the chip to the next flute, a hand-over
    /// inside the period past 2.5 sigma, and the broken flute's next period is asked past
    /// `alarm::HANDED_NOISE_SIGMAS` of noise over the exit's share, not 4: it trips before
    /// the flute reaches its break angle again.
    #[test]
    fn a_flute_that_handed_over_trips_on_its_next_pass() {
        each_drawn_within_a_revolution(&[(103, 11288), (99, 11357)]);
    }

    /// A flute broken 12 pulses after the spindle slowed by 14 % (seed 11513 break 89: 2 flutes,
    /// heavy runout, 1.77 revolutions after the first missed cut before). The placed
    /// boundaries still swung with the tracker's settling, the newest revolution 7 samples
    /// longer than the one before, past `same_speed`'s 1 % and two, and the plain trip was
    /// not armed for the broken flute's next pass, 90 % down. A revolution as long as the
    /// one two back is no ramp (`alarm::Alarms::steady_speed`): caught within a revolution
    /// over 8 noise seeds (the swing is the draw's own: late at the case's noise seed
    /// alone before), with no false alarm.
    #[test]
    fn a_flute_broken_as_the_boundaries_settle_after_a_ramp_trips_on_its_next_pass() {
        all_within_a_revolution(&[(89, 11513)]);
        caught_with_no_false_alarm(Kind::Break, 89, 11513, 8);
    }

    /// Flutes broken right after two teeth that lost to noise (seed 12791 break 118: 3
    /// flutes at `R_r` 1.49, the newest two -54 and -33 N measured, -29 and +19 N in the
    /// truth; seed 12794 break 3: 3 flutes at `R_r` 1.52). The plain trip was not armed
    /// after the run (an exit may be under way), and the alarm waited for the next flute's
    /// gain, 1.35 revolutions after the first missed cut; armed at the share of the exit
    /// the run's loss shows, the broken flute's empty window trips it.
    #[test]
    fn a_flute_broken_after_teeth_lost_to_noise_trips_its_empty_window() {
        // (An alarm before the damage is late too: no false alarm at those 8 either.)
        all_within_a_revolution(&[(118, 12791), (3, 12794)]);
    }

    /// A window moved in the middle of a speed ramp (seed 12813 normal 115: 2 flutes, 39 N a
    /// tooth, the spindle 18 % slower over 10 teeth). The one period since the move was as
    /// long as the one before the odd period (107 and 106 samples), and its change from the
    /// profile re-cut at the move, off by the ramp, passed as a hand-over's evidence: the
    /// drop trip armed at 0.30 fired on the next period. The period since must be as long
    /// as the one a revolution before that too: no alarm over 16 noise seeds.
    #[test]
    fn a_window_moved_in_a_speed_ramp_gives_no_evidence_across_the_move() {
        no_alarm_over_noise(Kind::Normal, 115, 12813, 16);
    }

    /// An exit right after a noise pair, with no current-loop lag (seed 13070 normal 28: 3
    /// flutes, `R_r` 1.2, a cut within a pitch but for 9 % of its span; one tooth 111 N down
    /// and the next 60 N up, the loss 3.2 sigma_R, true forces unchanged). The exit began
    /// at the next tooth, 7 % down, and the handed tooth's window lost 42 % in the truth
    /// against the evidence's share, the exit's reach, 0.43, with no noise over it: 47 %
    /// measured, it tripped inside the period. A pair whose loss could be noise, in a cut
    /// within a pitch, asks the reach past `alarm::EVIDENCE_NOISY_SIGMAS` of noise: no alarm
    /// over 16 noise seeds.
    #[test]
    fn an_exit_after_a_noise_pair_without_lag_is_asked_past_the_noise_of_its_reach() {
        no_alarm_without_lag(Kind::Normal, 28, 13070);
    }

    /// A light cut slowing down (seed 13208 taught 9 with no current-loop lag, found by
    /// the first run of 13185-13280 so: 2 flutes, `R_r` 0.23, 54 N, down milling; pulses
    /// 80, 81, 83, 83 samples apart after 78-79). The pulses' tracked times fell behind
    /// them, the placed boundary with them, 2.4 then 6.3 samples, and the light tooth's
    /// short chip came a bin and more later in its period than a revolution earlier: the
    /// drop trip, armed at half the tooth, fired in the middle of a period that lost
    /// nothing in all. The tracked times' lag that far past the jitter is the ramp's, and
    /// its change is allowed for whole (`handover::Handover::period_start`).
    #[test]
    fn a_light_cut_slowing_down_raises_no_drop_when_its_chip_comes_late() {
        no_alarm_without_lag(Kind::Taught, 9, 13208);
    }

    /// Flutes broken 13 and 9 teeth after a speed ramp (seed 12739 break 29 and seed 12793
    /// break 37: 2 flutes, boundaries in the cut's quiet stretch, 1.00 revolution after the
    /// first missed cut before). The next flute's gain raised `E` at 3.3 and 4.3 times its
    /// threshold, and the speed test took it back: the tracked boundaries still moved, but
    /// where nothing is cut, 12 N of the 264 and 162 N; the trip came on the broken
    /// flute's next pass. `E` past its threshold by what the boundaries moved stands
    /// (`handover::Handover::boundary_moved_n`): within a revolution over 8 noise seeds.
    #[test]
    fn a_flute_broken_after_a_ramp_is_raised_past_what_the_boundaries_moved() {
        all_within_a_revolution(&[(29, 12739), (37, 12793)]);
    }

    /// Flutes broken in wide cuts after a hand-over's evidence (seed 11755 break 118: 4
    /// flutes, `R_r` 1.6; seeds 11843 break 72 and 11922 break 103; 1.16, 1.22 and 1.10
    /// revolutions after the first missed cut before). The broken flute's first whole
    /// window lost about the exit's reach the trip was armed at: that reach took the
    /// newest tooth as having lost the 2 sigma_R the evidence's `kept` allows, though it
    /// had gained. Its own loss, as the plain trip takes it, puts the exit 2 sigma_R of its
    /// force nearer: the reach 0.46 -> 0.42 at 11755, whose window lost 0.457.
    #[test]
    fn a_wide_cuts_handed_flute_is_asked_only_the_exit_its_newest_tooth_shows() {
        each_drawn_within_a_revolution(&[(118, 11755), (72, 11843), (103, 11922)]);
    }

    /// A 3-flute tool lost inside a tooth's cut (seed 12018 gone 0, found by the first run
    /// of 11937-12032): that window kept 45 %, and the rule on two revolutions' means
    /// found the loss's pair of gains in two teeth whose means three revolutions back lay
    /// in the noise under their level, and named a breakage on the window itself. A drop
    /// alone, the teeth before it unchanged from one revolution earlier, is left to the
    /// next record: a lost tool, on its empty windows, over 8 noise seeds.
    #[test]
    fn a_tool_lost_inside_a_cut_of_three_flutes_is_no_breakage() {
        caught_with_no_false_alarm(Kind::Gone, 0, 12018, 8);
    }

    /// 2-flute tools lost inside a tooth's cut (seeds 10018 gone 3 and 28: that window
    /// kept 49 % and 59 %, flagged transient, so no drop trip was armed for the next),
    /// named on the first empty window after it, within a revolution of the damage (1.24
    /// and 1.20 revolutions after the first missed cut before, on the second); and a
    /// flute of 2 broken at its cut's start (seed 10123 break 48: its window empty after
    /// the other flute's, 10 % down by noise) named a breakage, not a lost tool.
    #[test]
    fn a_two_flute_tool_lost_inside_a_cut_is_named_on_its_first_empty_window() {
        for index in [3, 28] {
            let late = late_of_kind_over_noise(Kind::Gone, index, 10018, 8);
            assert!(late.is_empty(), "gone {index}: {late:#?}");
        }
        caught_with_no_false_alarm(Kind::Break, 48, 10123, 8);
    }

    /// 2-flute tools lost late in a tooth's cut (seeds 13378 gone 7, 13381 gone 15 and
    /// 13387 gone 16: 2 flutes, that window 4.4, 3.2 and 3.4 sigma_R down, under
    /// `GONE_BEFORE_SIGMAS`): the first empty window latches the output, the second names
    /// the lost tool, within a revolution of the damage (1.16-1.23 revolutions after the
    /// first missed cut before, on the second empty window). Over 8 noise seeds each.
    /// Found at seeds 13377-13388, after the rules had been set.
    #[test]
    fn a_two_flute_tool_lost_late_in_a_cut_latches_on_its_first_empty_window() {
        for (index, seed) in [(7, 13378), (15, 13381), (16, 13387)] {
            let late = late_of_kind_over_noise(Kind::Gone, index, seed, 8);
            assert!(late.is_empty(), "gone {index} at seed {seed}: {late:#?}");
        }
    }

    /// Light flutes under heavy runout broken at their cut's start, whose first missed
    /// cut took too little to arm the drop trip on the next pass (seed 13291 break 117: 2
    /// flutes, 70 N beside 253 N, 1.22 revolutions late; seed 13076 break 107: 3 flutes,
    /// 38 N beside 126 and 185 N, 1.19): the empty window latches the output, within a
    /// revolution of the first missed cut; the next flute's gain names the breakage. Over
    /// 8 noise seeds each: before, 3 and 2 of them late or missed; now all of 13291's
    /// within, and all of 13076's but noise seed 3347570. There the break's window kept 15
    /// N (7 in the truth), then 8, so that no window was empty at the steady feed and no
    /// revolution's change passed its floor: missed, until the 3-flute hand-over pair on
    /// two revolutions' means caught it 1.51 revolutions after the first missed cut (the
    /// unit test `a_light_flute_of_three_broken_inside_its_cut_is_a_pair_on_the_means`
    /// takes its records). Found at seeds 13281-13376 and 12993-13088.
    #[test]
    fn a_light_flutes_empty_window_latches_within_the_revolution() {
        for (index, seed, most) in [(117, 13291, 0), (107, 13076, 1)] {
            let late = late_runs_after_onset_in(Setup::default(), index, seed, 8);
            assert!(
                late.len() <= most,
                "break {index} at seed {seed}: {late:#?}"
            );
            let missed: Vec<_> = late
                .iter()
                .filter(|(_, o)| o.first_alarm.is_none())
                .collect();
            assert!(
                missed.is_empty(),
                "break {index} at seed {seed}: {missed:#?}"
            );
        }
    }

    /// A pair of tooth averages in a steady cut's noise, the one record's hand-over past
    /// 9 sigma_R (seed 13805 chip 29, 10.6 revolutions before the damage: 4 flutes, `R_r`
    /// 1.02, no estimate; a tooth 53 N down and the next 69 N up against sigma_R 13.5 N,
    /// 9.04 together). `PAIR_RAISE_SIGMAS` at 9.5: over 8 noise seeds, no alarm before the
    /// damage (at 9 the case's own raised a breakage).
    #[test]
    fn a_noise_pair_past_9_sigma_in_a_steady_cut_is_no_breakage() {
        let outs = outcomes_over_noise(Kind::Chip, 29, 13805, 8);
        let early: Vec<_> = outs.iter().filter(|(_, o)| o.false_alarm()).collect();
        assert!(early.is_empty(), "{early:#?}");
    }

    /// Wide 4-flute cuts (`R_r` 1.55-1.57; seed 13542 with no estimate, `t_c` under the
    /// laws' fitted range) whose flute broke inside its cut and handed a little over inside
    /// the period (2.6-3.8 sigma): the broken flute's next cut begins in the window before
    /// the handed tooth's, which lost 0.54-0.58 of its force in the truth against an exit's
    /// reach of 0.42 and 4 sigma_R. That window's trip is armed with the handed tooth's 2
    /// sigma_R too. Over 8 noise seeds each, late before: 2 and 1 (seed 13467 break 88,
    /// found at seeds 13377-13472; 13542 break 14 at 13473-13568).
    #[test]
    fn a_wide_cuts_window_before_the_handed_one_trips_with_less_noise() {
        for (index, seed, most) in [(88, 13467, 1), (14, 13542, 0)] {
            let late = late_after_onset_in(Setup::default(), index, seed, 8);
            assert!(
                late.len() <= most,
                "break {index} at seed {seed}: {late:#?}"
            );
        }
    }

    /// Light flutes of 2-flute tools under runout broken inside their cuts (seed 10573
    /// break 21: 64 N beside 285 N after a feed cut, `t_c` 0.09 mm; seed 8798 break 110):
    /// the loss and the other flute's gain each split over two revolutions, no
    /// revolution's change past its floor, and the cut flagged as changing after. Against
    /// three revolutions earlier they are a hand-over pair. Over 8 noise seeds each,
    /// missed in 1 and 4 before, 0 and 2 now; no alarm before the damage.
    #[test]
    fn a_light_flute_broken_inside_its_cut_is_caught_as_a_pair_against_revolutions_earlier() {
        for (index, seed, most) in [(21, 10573, 0), (110, 8798, 2)] {
            let outs = outcomes_over_noise(Kind::Break, index, seed, 8);
            let early: Vec<_> = outs.iter().filter(|(_, o)| o.false_alarm()).collect();
            assert!(early.is_empty(), "break {index} at seed {seed}: {early:#?}");
            let missed: Vec<u64> = outs
                .iter()
                .filter(|(_, o)| o.first_alarm.is_none())
                .map(|(noise, _)| *noise)
                .collect();
            assert!(
                missed.len() <= most,
                "break {index} at seed {seed}: missed at {missed:?}"
            );
        }
    }

    /// 4-flute cuts under the paper's feed range (`t_c` 0.078 and 0.074 mm, 0.75 of that
    /// range's low end): flagged out of range, so no estimate, and the drop trip's exit
    /// share at the worst `R_r`, 0.69-0.73 of the tooth; a flute broken at the end of its
    /// cut was caught 1.00 and 1.01 revolutions after its first missed cut, at its next
    /// window's end. With the laws trusted down to 0.04 mm (a calibration that reached
    /// those feeds: the simulator's material is Table 2's at every feed) the cuts are
    /// estimated, and each break caught within the revolution over 8 noise seeds.
    #[test]
    fn a_feed_under_the_papers_range_is_judged_on_its_estimate_where_calibrated() {
        let setup = Setup {
            tc_fit_from_mm: Some(0.04),
            ..Setup::default()
        };
        for (index, seed) in [(57, 10320), (109, 10360)] {
            let late = late_after_onset_in(setup, index, seed, 8);
            assert!(late.is_empty(), "break {index} at seed {seed}: {late:#?}");
        }
    }

    /// Break case `index` at draw seed `seed` over `seeds` noise seeds with the monitor set
    /// up as `setup`: the runs whose alarm was not within a revolution of the first missed
    /// cut (the goal's measure).
    fn late_after_onset_in(setup: Setup, index: usize, seed: u64, seeds: u64) -> Vec<String> {
        late_runs_after_onset_in(setup, index, seed, seeds)
            .into_iter()
            .map(|(noise, out)| format!("noise seed {noise}: {:?}", out.first_alarm))
            .collect()
    }

    /// ... those runs' outcomes.
    fn late_runs_after_onset_in(
        setup: Setup,
        index: usize,
        seed: u64,
        seeds: u64,
    ) -> Vec<(u64, Outcome)> {
        outcomes_over_noise_in(setup, Kind::Break, index, seed, seeds)
            .into_iter()
            .filter(|(_, out)| !out.detected_after_onset_s().is_some_and(|l| l <= out.rev_s))
            .collect()
    }

    /// Wide 4-flute cuts in down milling (`R_r` about 1.5 where estimated, seed 12288
    /// under the laws' fitted feed; 38-45 samples a tooth), a flute broken late in its
    /// cut, whose next pass the spindle current loop's 0.5 ms lag (4.5 samples) kept from
    /// tripping before the flute came back to its break: the heavy window before bled into
    /// the reference period the trip's share is of (seed 12405 break 11: 1 442 N measured
    /// against 1 278 N true). 1.23-1.29 revolutions after the first missed cut with the lag
    /// unmodelled. Over 8 noise seeds each, the lag allowed for (the monitor told the
    /// cases' own, as a calibration measures it) leaves at most two thirds as many runs
    /// late (6 against 11 when measured; 7 against 16, half, before the plain trip's
    /// shares were taken from two revolutions back, which catches some of the unmodelled
    /// runs too). Not every late break gains: over the 15 late breaks of seeds
    /// 12225-12416, 40 of their 120 runs late against 51, seed 12257 break 39 6 against 5
    /// (BENCHMARKS.md).
    #[test]
    fn a_break_behind_the_current_loops_lag_is_caught_within_the_revolution() {
        let unmodelled = Setup {
            monitor_lag_s: Some(0.0),
            ..Setup::default()
        };
        let cases = [
            (11, 12405),
            (61, 12322),
            (76, 12328),
            (109, 12240),
            (73, 12288),
        ];
        let late = |setup: Setup| -> Vec<String> {
            cases
                .iter()
                .flat_map(|&(index, seed)| {
                    late_after_onset_in(setup, index, seed, 8)
                        .into_iter()
                        .map(move |run| format!("break {index} at seed {seed}, {run}"))
                })
                .collect()
        };
        let (allowed, unallowed) = (late(Setup::default()), late(unmodelled));
        assert!(
            3 * allowed.len() <= 2 * unallowed.len(),
            "the lag allowed for: {allowed:#?}\nunmodelled: {unallowed:#?}"
        );
    }

    /// 2-flute light cuts (`F_t` about 40 N, short steep chips; seed 12307 taught 3 in a
    /// speed change, seed 12320 wear 5), where the lag's term on the running sum inside the
    /// period (tried, not landed: `handover`'s "Current-loop lag") tripped mid-period: one
    /// bin's change at a steep chip edge swings with the jitter by 20 times its noise, and
    /// where the chip is short two bins' do too. With the monitor told a half, one and one
    /// and a half times the true lag, they raise nothing over 8 noise seeds.
    #[test]
    fn a_lag_set_half_off_raises_no_drop_at_a_light_cuts_edge() {
        for mis in [0.5, 1.0, 1.5] {
            let setup = Setup {
                monitor_lag_s: Some((mis * CURRENT_LAG_S) as f32),
                ..Setup::default()
            };
            for (kind, index, seed) in [(Kind::Taught, 3, 12307), (Kind::Wear, 5, 12320)] {
                let raised: Vec<String> = outcomes_over_noise_in(setup, kind, index, seed, 8)
                    .into_iter()
                    .filter(|(_, out)| out.false_alarm())
                    .map(|(noise, out)| format!("noise seed {noise}: {:?}", out.first_alarm))
                    .collect();
                assert!(
                    raised.is_empty(),
                    "{kind:?} {index} at seed {seed}, {mis} of the lag: {raised:#?}"
                );
            }
        }
    }

    /// A flute of a 3-flute tool broken 32 % into its period (down milling, 2 904 rpm): its
    /// period lost 52 N (4.2 sigma_R) and the next gained 67 N. The trip of its next
    /// period, at 4 sigma_R, against a reference that had already lost those 52 N, passed
    /// 2 samples past the revolution. The loss counts toward the floor now (at least 2
    /// sigma_R).
    #[test]
    fn a_flute_broken_inside_its_period_has_its_loss_counted_toward_the_trip() {
        all_within_a_revolution(&[(61, 26)]);
    }

    /// A 4-flute tool in a wide arc (down milling, R_r 1.5, 2 554 rpm), a flute broken at
    /// the end of its period: its next period lost 54 % of the tooth, and the trip was
    /// armed at 0.64, the exit through a face at two feeds' travel (the first tooth's loss
    /// hidden in the noise). But the newest tooth did not lose: an exit under way has
    /// travelled at most as far as takes 6 sigma_R of it. Late in 6 of these 8 noise
    /// seeds before, in 2 after, 3 since the trip inside the period allows for a sample's
    /// jitter (`handover::JITTER_SAMPLES`, `the_jitter_at_a_light_cuts_edge_is_no_drop`).
    /// Over 32 noise seeds: 9 late with the boundary at the pulse, 7 with it on the
    /// pulses' tracked times (`window::TRACK_DELAY_SAMPLES`; 4 of the first 8), 8 with it
    /// between samples. Over 64, 13 rounded to whole samples, 14 between them (over 96, 25
    /// and 28: the scatter of a marginal case); 15 with each tooth's reference in the
    /// hand-over stage blended over its periods (`handover`'s "Reference": another noise
    /// in the reference, the same scatter), and late from the first missed cut in 3 of
    /// the 64 against 5. 19 since the plain trip asks 4 sigma_R of the loss's noise over
    /// the exit's share, not 3 (`alarm::TRIP_NOISE_SIGMAS`; seed 10264 normal 6).
    #[test]
    fn a_flute_broken_in_a_wide_arc_trips_under_the_exits_share() {
        let late = late_over_noise(46, 4, 64);
        assert!(late.len() <= 19, "{late:#?}");
    }

    /// 4-flute tools in wide arcs, up milling (`R_r` 1.38 and 1.41, the cut's span, its arc
    /// and the helix's lag, 2.7 and 2.2 rad against a pitch of 1.57), a flute broken late
    /// in its cut: its next cut begins in the window before its own. A pair (the broken
    /// period down, the next up) armed the trip of that window at 0.3; it lost 14-25 %,
    /// and that loss, which an exit's first tooth after a pair in the noise makes too,
    /// disarmed the handed tooth's trip, whose window then lost 50-59 %. Where the cut
    /// spans more than a pitch the evidence holds through it, at the share the exit that
    /// loss shows would take. Seed 2298 break 58 and seed 2352 break 45, found at seeds
    /// 2257-2352: 4 of their 16 runs were late before, 2 after. Over 32 noise seeds each:
    /// 17 of 64 late with the boundary at the pulse, 14 with it on the pulses' tracked
    /// times (3 of the first 16).
    #[test]
    fn a_wide_cuts_break_begins_in_the_window_before_its_own() {
        let late: Vec<String> = [(58, 2298), (45, 2352)]
            .into_iter()
            .flat_map(|(index, seed)| late_over_noise(index, seed, 32))
            .collect();
        assert!(late.len() <= 14, "{late:#?}");
    }

    /// An exit fading over revolutions (4 flutes, `R_r` 0.29, an axial depth of 11 mm whose
    /// helix's lag makes the cut wider than a pitch, no estimate), its records flagged
    /// transient on and off: a pair in it (88 N down, 55 up, 5.6 sigma_R) armed the trip
    /// at 0.3, and the next window, whose first bins lost, passed it. A pair out of 2N
    /// records (4N since seed 2969 normal 119, below) more than one of them flagged is no
    /// hand-over. Found at seeds 2737-2832 (seed 2743 normal 75; eeec131 raises it too).
    #[test]
    fn a_pair_in_an_exit_flagged_on_and_off_is_no_evidence() {
        no_alarm_over_noise(Kind::Normal, 75, 2743, 8);
    }

    /// A deep exit fading over 55 revolutions (3 flutes, `R_a` 1.1, the helix's lag 37
    /// degrees, no estimate) whose teeth swing by a third from one revolution to the next:
    /// a pair in it (43 N down, 29 up) out of 6 records one of them flagged, 6 of the 12,
    /// armed the trip at 0.3, and the next window lost 65 %. A pair out of 4N records more
    /// than one of them flagged is no hand-over. Found at seeds 2881-2976 (seed 2969
    /// normal 119).
    #[test]
    fn a_pair_in_a_deep_exit_swinging_by_revolutions_is_no_evidence() {
        no_alarm_over_noise(Kind::Normal, 119, 2969, 8);
    }

    /// A slow exit (3 flutes, a feed of 0.4 % of the radius, one flute out by 14 um and
    /// another 0.4 um in, no estimate): over three revolutions the heavy flute lost 16 N of
    /// 58 while the light one gained 14 N of 10, past the two revolutions' means floor. The
    /// means' two earlier revolutions held a flagged transient; with any there, the means
    /// do not decide. Found at seeds 2881-2976 (seed 2906 normal 57).
    #[test]
    fn a_slow_exits_shares_moving_between_flutes_are_no_loss() {
        no_alarm_over_noise(Kind::Normal, 57, 2906, 8);
    }

    /// A noise pair (52 N down, 53 up, 5.3 sigma_R) on the revolution an exit through a face
    /// began (4 flutes, `R_r` 0.6, a feed of 0.18 mm a tooth, the exit 5 revolutions long):
    /// the two teeth after the gain lost 1.5 sigma_R each, and the handed tooth's period,
    /// armed at 0.3, lost 32 %. Where every tooth since the gain lost, the share covers an
    /// exit begun right after it. Found at seeds 3169-3264 (seed 3213 normal 99).
    #[test]
    fn an_exit_begun_after_a_noise_pair_is_no_hand_over() {
        no_alarm_over_noise(Kind::Normal, 99, 3213, 8);
    }

    /// Flutes broken in a moved window's odd period (the period in which the boundary
    /// moved, of mixed alignment, unusable to the rules on the records, which forget their
    /// history there): the next flute's first period after the move gained 29-83 % on its
    /// re-cut profile. Without that evidence the broken flute's next period was armed at
    /// the plain share and 6 sigma_R, and tripped past its revolution. Seeds 2459 break 73
    /// (4 flutes), 2526 break 79 and 2541 break 118 (3 flutes, an 83 % gain, now raised
    /// at it) and 2456 break 38 (4 flutes, broken in the first period after the move: its
    /// loss and the next flute's gain on their re-cut profiles): found at seeds 2449-2544,
    /// 13 of their 32 runs were late before, 6 after.
    #[test]
    fn a_flute_broken_in_a_moved_windows_odd_period_is_handed_on() {
        let late: Vec<String> = [(73, 2459), (79, 2526), (118, 2541), (38, 2456)]
            .into_iter()
            .flat_map(|(index, seed)| late_over_noise(index, seed, 8))
            .collect();
        assert!(late.len() <= 6, "{late:#?}");
    }

    /// An exit in a cut wider than a pitch (4 flutes, `R_r` 0.71, `R_a` 0.87, down
    /// milling, 480 N a tooth): a pair in the noise (67 N down, 57 up), then the window
    /// before the handed tooth's lost 19 %, the exit's first tooth. Armed at the two feeds'
    /// exit (0.3), the handed tooth's window passed it; the exit that loss shows takes
    /// 0.44 a feed on. Seed 41 normal 111 (an earlier form of the rule above raised it).
    #[test]
    fn an_exit_after_a_pair_in_a_wide_cut_is_as_far_as_its_loss() {
        no_alarm_over_noise(Kind::Normal, 111, 41, 8);
    }

    /// An exit (4 flutes, down milling, runout of 27 um on one flute, 0.074 mm a tooth,
    /// no estimate: the feed per tooth outside the coefficients' range): a pair in its
    /// noise (115 N down, 61 up), then the next tooth 24 % down, which kept the window
    /// before the handed tooth's from being armed lower, then one 1 sigma_R down; the
    /// handed tooth's period, armed at 0.3 on the pair, lost 29 %. The loss voids the
    /// evidence for the periods after it too. Found at seeds 2449-2544 (seed 2452 normal
    /// 65; 8397e51 raised it too).
    #[test]
    fn an_exits_loss_after_a_pair_spends_the_evidence() {
        no_alarm_over_noise(Kind::Normal, 65, 2452, 8);
    }

    /// A flute of a 2-flute tool broken inside its period (down milling, R_r 1.53, a feed
    /// of 3.4 % of the radius, 3 712 rpm): its period lost part of its force and the next
    /// flute gained it, under every rule on the records. When it came round, the drop trip
    /// at 6 sigma and half the tooth passed only past a revolution of the damage, in 6 of
    /// these 8 noise seeds. With that loss and gain behind it, the trip of its next period
    /// is armed at 4 sigma and 0.3 of the tooth.
    #[test]
    fn a_flute_broken_inside_its_period_trips_before_its_break_angle() {
        all_within_a_revolution(&[(54, 22)]);
    }

    /// A flute of a 2-flute tool broken a fifth from the end of its period (down milling,
    /// R_r 1.27, 3 680 rpm): its period lost 84 N (6 sigma_R), the next flute, whose arc
    /// overlaps, gained only 16 N in its own. The loss was more than the armed walk
    /// allows, and the gain under the 1.5 sigma_R a hand-over asked of it: no trip was
    /// armed, and the records' rules caught it 1.6 revolutions on (in 1 of these 8 noise
    /// seeds, its own; the others gained more). A hand-over's gain need only be one now.
    #[test]
    fn a_loss_whose_gain_spread_over_two_periods_arms_the_trip() {
        all_within_a_revolution(&[(117, 24)]);
    }

    /// Two 4-flute tools in up milling with arcs wider than a pitch (R_r 1.30 and 1.17,
    /// 2 617 and 2 520 rpm): seed 20, case 0 and seed 69, case 57. The broken flute's
    /// period lost 184 and 121 N and the next gained 134 and 106 N (7-8 sigma_R
    /// together); when it came round its cut began in the window before, which lost 4.3
    /// and 2.4 sigma_R, and a hand-over's trip is not armed lower after a newest tooth
    /// that lost 2 sigma_R (an exit begun after a noise pair): caught 1.35 and 1.01
    /// revolutions on. A pair past 6 sigma_R is no noise an exit could follow.
    #[test]
    fn a_strong_hand_over_arms_the_trip_though_the_window_before_lost() {
        all_within_a_revolution(&[(0, 20), (57, 69)]);
    }

    /// A 4-flute tool in down milling, R_r 1.54, under runout (0.05 mm on one flute against
    /// a 0.13 mm feed per tooth): seed 1543, case 101. The broken flute's window lost 430 N
    /// for good and the next flute's cut, two windows wide, took the chip, 230 and 200 N in
    /// each: no rule decided it in the 70 revolutions to the exit. Two neighbouring teeth's
    /// gains together complete the redistribution: caught within 3 revolutions in all 8
    /// noise seeds.
    #[test]
    fn a_gain_split_between_two_windows_completes_the_loss() {
        all_caught_within(101, 1543, 3.0);
    }

    /// A 2-flute tool in down milling, R_r 0.1, 3 739 rpm, 50 N: seed 1199, case 111. The
    /// window was still at the pulse, halving each flute's cut between two windows: the
    /// broken flute's loss and the next flute's gain fell in the same averages. The break's
    /// own transient records restarted the window's profile, which moved the boundary 14
    /// revolutions later, and the break was caught then. A profile half learned goes on
    /// through a few transient records: caught within a revolution in 7 of 8 noise seeds,
    /// and 5.7 revolutions on in the other (there the profile, restarted by a transient
    /// record before it was half learned, began 5.5 revolutions before the break and moved
    /// the boundary 8.5 after it).
    #[test]
    fn a_breaks_own_transients_do_not_restart_the_windows_profile() {
        let revs = latencies_over_noise(111, 1199, 8);
        let within = revs.iter().filter(|r| r.is_some_and(|r| r <= 1.0)).count();
        assert!(
            within >= 7 && revs.iter().all(|r| r.is_some_and(|r| r < 8.0)),
            "{revs:?}"
        );
    }

    /// Flutes of 2-flute tools broken 13 to 17 revolutions after the cut began, while the
    /// window was still at the pulse, where the boundary cut a flute's arc in two: seed
    /// 8301 break 53 (3 702 rpm, true tooth averages 113 and 35 N after the break in the
    /// pulse's windows, 80 and 70 N measured through the drives' 0.5 ms lag, so the
    /// redistribution hid in the records), seed 8571 break 115, seed 8551 break 119 and
    /// seed 8647 break 27 (2 290 rpm). With the profile reviewed after 8 revolutions the
    /// window moved after the damage, the records forgot their history there, and the
    /// breaks came 7.87, 4.72, 4.70 and 3.77 revolutions late. Reviewed after
    /// `window::REVIEW_REVS` (4), the window is placed before the damage: every run
    /// within a revolution.
    #[test]
    fn a_window_placed_early_in_the_cut_catches_an_early_break() {
        all_within_a_revolution(&[(53, 8301), (115, 8571), (119, 8551), (27, 8647)]);
    }

    /// Late runs over the cases' 8 noise seeds each.
    fn late_runs(cases: &[(usize, u64)]) -> usize {
        cases
            .iter()
            .map(|&(i, s)| late_over_noise(i, s, 8).len())
            .sum()
    }

    /// The weakest flute under runout, broken inside its period: seed 101, case 15 (2
    /// flutes, teeth of 116 and 37 N, 6 sigma_R 28 N) and seed 40, case 102. The damage's
    /// period lost 9 N, and on the next pass the trip's floor of 6 sigma_R was more than
    /// the reference (the period that had lost) held. That loss now counts toward the
    /// floor. Late in 10 of the 16 runs before, 5 after (the rest are the share and the
    /// noise), 6 with the allowance for a sample's jitter inside the period (7, and seed 38
    /// case 52 late at one noise seed, with the bin before's level allowed for too within
    /// the jitter's reach of a bin's start, which was tried for the loss a shift leaves
    /// past a steep falling edge and not kept). And seed 38,
    /// case 52 (2 flutes, 190 and 400 N): the same credit lets the trip pass a few samples
    /// sooner, at the break angle (late in 1 of 8 before).
    #[test]
    fn the_loss_a_weak_flute_took_counts_toward_its_next_trip() {
        let late = late_runs(&[(15, 101), (102, 40)]);
        assert!(late <= 6, "{late} of 16 late");
        all_within_a_revolution(&[(52, 38)]);
    }

    /// The exits that the rejected variants of the two rules above raised false alarms on,
    /// each over 16 noise seeds: the floor's credit through exits fading over revolutions
    /// (seed 6 normal 71, seed 16 normal 74, seed 36 normal 22), the share credited too (seed
    /// 113 normal 63 and seed 72 taught 22, within 2-6 N of the plain trip), the evidence at
    /// 4.5 sigma_R with the loss's record flagged (seed 110 normal 81).
    #[test]
    fn exits_near_the_trip_raise_nothing() {
        for (kind, index, seed) in [
            (Kind::Normal, 71, 6),
            (Kind::Normal, 74, 16),
            (Kind::Normal, 22, 36),
            (Kind::Normal, 63, 113),
            (Kind::Taught, 22, 72),
            (Kind::Normal, 81, 110),
        ] {
            no_alarm_over_noise(kind, index, seed, 16);
        }
    }

    /// Hand-overs of 4.5-7 sigma_R: seed 45, case 34 (a pair of 6.3 sigma_R: strong now,
    /// the window before may lose), seed 46, case 61 and seed 99, case 59 (pairs of 4.6-5.2
    /// sigma_R, the evidence now from 4.5 where the loss's own record is not transient).
    /// Late in 16 of their 24 runs before, 9 after, 10 with the allowance for a sample's
    /// jitter inside the period, 11 since the evidence asks the newest revolution to be
    /// as long as the one before (seed 99 case 59, noise seed 467323: 4 flutes at 3 263
    /// rpm, a revolution of 184 samples, the allowance 3 of them against the pulses'
    /// jitter).
    #[test]
    fn hand_overs_under_the_old_evidence_arm_the_trip() {
        let late = late_runs(&[(34, 45), (61, 46), (59, 99)]);
        assert!(late <= 11, "{late} of 24 late");
    }

    /// Flutes whose next pass lost past the trip's limit only with the period's last bin
    /// (left out inside the period: it takes a longer period's excess): seed 96, case 100
    /// (2 flutes, 1 234 rpm, 52 % of the tooth lost against 0.5), seed 43, case 29 (4
    /// flutes, R_r 1.46, 72 % against 0.69) and seed 49, case 32. The rules on the records
    /// leave a drop alone undecided until the next flute's gain, a revolution past the
    /// damage. The period's close judges the whole period against the trip's limit. (Seed
    /// 43 case 29 is late in 1 of the 8 noise seeds since the trip asks 4 sigma_R of noise
    /// over the exit's share, not 3: `alarm::TRIP_NOISE_SIGMAS`, seed 10264 normal 6.)
    #[test]
    fn a_loss_past_the_trip_with_the_last_bin_trips_at_the_close() {
        all_within_a_revolution(&[(100, 96), (32, 49)]);
        let late = late_over_noise(29, 43, 8);
        assert!(late.len() <= 1, "{late:#?}");
    }

    /// An exit fading over revolutions in a light cut (3 flutes, tooth averages of 30-80
    /// N, 1 835 rpm; seed 84, normal case 95): with the records flagged transient, one
    /// tooth lost and the next gained (5.3 sigma_R, flutes of unequal runout leaving at
    /// unequal times), and the exit's end emptied the losing tooth's next period, which
    /// passed the trip armed lower after that pair once the period's close judged its
    /// last bin too. A pair after a transient record is no hand-over.
    #[test]
    fn a_fading_exit_is_no_hand_over() {
        no_alarm_over_noise(Kind::Normal, 95, 84, 8);
    }

    /// Flutes broken within two revolutions after the window moved (the history
    /// forgotten), in arcs wider than a pitch: seed 30, case 80 (2 flutes, R_r 0.86, 2 570
    /// rpm) and seed 118, case 62 (4 flutes, R_r 0.56, 1 363 rpm). The broken flute's
    /// window keeps the end of the cut before it, 35-39 % of the revolution mean, over
    /// the 30 % the rule for a resumed cut asked: the trip caught them 1-2 samples past
    /// the revolution. It asks 45 % now.
    #[test]
    fn a_flute_broken_after_a_move_whose_window_keeps_a_cut_is_caught() {
        all_within_a_revolution(&[(80, 30), (62, 118)]);
    }

    /// Three 3-flute tools in down milling whose window moved in the revolution a flute
    /// broke in: seed 46, case 3 (2 796 rpm), seed 72, case 102 (2 131 rpm), seed 74, case
    /// 59 (1 815 rpm). The move forgot the tooth history, and the broken flute's first
    /// period after it, nearly empty, had no reference: caught 1.07-1.42 revolutions on,
    /// by the rules on the records, late in 15 of the 24 runs over their noise seeds. The
    /// hand-over stage re-cuts its profiles at the new boundary now, and the trip is armed
    /// from the first record after the move; and the monitor's revolution means hold each
    /// tooth once across the move, so that the records after it are not flagged transient
    /// (seed 46's case at its fifth noise seed: the move 0.4 revolutions before the damage,
    /// the record before the broken flute's window flagged, caught 1.41 revolutions on).
    /// Of the two runs still late, in one the broken flute's window is the first after the
    /// move, which no record arms; the other is caught 1.005 revolutions on. Three since
    /// the boundaries fall between samples (over 64 noise seeds each, 16 late against 13
    /// rounded to whole samples; over 96, 19 against 18).
    #[test]
    fn a_flute_broken_in_the_revolution_of_a_move_trips_within_it() {
        let late = late_runs(&[(3, 46), (102, 72), (59, 74)]);
        assert!(late <= 3, "{late} of 24 late");
    }

    /// Normal case `index` at draw seed `seed` whose exit through the far face begins
    /// `teeth` tooth periods after the record that closed the window's move (at the
    /// first feed, which the move always comes in: `window::REVIEW_REVS` revolutions into
    /// the cut): its first alarm.
    fn exit_at_the_move(index: usize, seed: u64, teeth: i32) -> Option<(f64, Cause)> {
        let case = draw_case(Kind::Normal, index, seed).expect("a case");
        let pipeline = case.machine.clone().build().expect("a machine");
        let fs = f64::from(case.machine.monitor.sample_rate_hz);
        let mut st = PipelineState::default();
        let mut moved = None;
        sim::simulate(&case.scenario, |row| {
            if let Some((r, _)) = pipeline.process(&mut st, &row.to_sample()) {
                if moved.is_none() && r.status.contains(estimator_core::Status::WINDOW_MOVED) {
                    moved = Some(r.end_sample as f64 / fs);
                }
            }
            Ok(())
        })
        .expect("the case runs");
        let moved = moved.expect("the window moves");
        let tooth_s = 60.0 / (case.rpm_at_damage * f64::from(case.scenario.tool.flutes));
        let feed_mm_s = first_feed_mm_min(&case) / 60.0;
        let mut case = case;
        let work = &mut case.scenario.workpiece.as_mut().expect("faces").spans_mm[0];
        // The entry face lies the arc's reach past the path at the end of the first air
        // move; the exit begins where the arc's reach meets the far face.
        let reach_mm = work[0] - feed_mm_s * case.scenario.segments[0].duration_s;
        work[1] = feed_mm_s * (moved + f64::from(teeth) * tooth_s) + reach_mm;
        run_case(&case).expect("the case runs").first_alarm
    }

    /// Exits through a face beginning from two tooth periods before a window's move to two
    /// after its first revolution (5 cases at seed 1, 2-4 flutes): the first revolution
    /// after the move, where the trip is armed on the hand-over stage's re-cut profiles
    /// (the records have no tooth a revolution earlier), raises nothing. Armed there on
    /// the exit's share alone, without the stage's check that no period since the move
    /// lost, 14 of these 43 exits raised a breakage (those from two teeth before the move
    /// to one after).
    #[test]
    fn an_exit_at_a_move_raises_nothing() {
        let mut raised = Vec::new();
        for index in [1, 13, 17, 30, 34] {
            let flutes = i32::from(
                draw_case(Kind::Normal, index, 1)
                    .expect("a case")
                    .scenario
                    .tool
                    .flutes,
            );
            for teeth in -2..=flutes + 2 {
                if let Some(a) = exit_at_the_move(index, 1, teeth) {
                    raised.push(format!("case {index}, {teeth} teeth after the move: {a:?}"));
                }
            }
        }
        assert!(raised.is_empty(), "{raised:#?}");
    }

    /// Two 4-flute tools in down milling whose arcs are wider than a pitch (no boundary
    /// falls between cuts): seed 94, case 119 (3 116 rpm), a flute broken a sixth from the
    /// end of its window, its cut going on into the next: that window lost 150 N, the one
    /// after gained 163 N; seed 89, case 40 (R_r 1.58, 3 251 rpm), the loss over two
    /// windows and the gain in the third. The hand-over arms the losing tooth's trip, but
    /// the flute's next cut begins in the window before, and at the exit's share (0.6)
    /// that window's trip passed just past the revolution. The window before the losing
    /// one is armed at the evidence's share too. Seed 89's case over 32 noise seeds: one
    /// late, with the boundaries rounded to whole samples or between them (over 96, 4 late
    /// between them against 7 rounded).
    #[test]
    fn a_flute_whose_cut_begins_in_the_window_before_the_loss_trips_there() {
        all_within_a_revolution(&[(119, 94)]);
        let late = late_over_noise(40, 89, 32);
        assert!(late.len() <= 1, "{late:#?}");
    }

    /// An up-milling exit's first period on a cut within a pitch (seed 8808, normal case
    /// 14: 2 flutes, `R_r` 1.37): the light tooth lost 48 % as the arc's far reach, the
    /// thickest chip, left the work, all of it at the window's far end. The trip's share,
    /// 0.58, is the exit's 0.49 and 3 sigma_R of the resultant, but it measures the
    /// tangential channel, whose noise was 12 % of its force: the whole period at its close
    /// measured 58.6 % and tripped. The close asks the exit's share with that channel's
    /// noise (inside the period a broken flute loses from its first angles and is judged
    /// at the resultant's). Found at seeds 8769-8864, after the rules had been set.
    #[test]
    fn an_exits_first_period_judged_whole_allows_for_the_trip_channels_noise() {
        no_alarm_over_noise(Kind::Normal, 14, 8808, 8);
    }

    /// An entry into a face that takes seconds (seed 38, taught case 1: 3 flutes, up
    /// milling, `R_r` 1.35): the window's profile was reviewed 0.2 s in, its arc a third of
    /// the period, and the boundary went to the middle of the quiet stretch; the arc went
    /// on widening over it, and at 280 N the boundary stood on the cut's steep edge, where
    /// the pulses' jitter moved force from one window into the next: a hand-over raised in
    /// a normal cut. The profile is reviewed again once the cut has grown
    /// (`window::REGROWN`). Found at seeds 1-96 after the profile's 1-2-1 smoothing.
    #[test]
    fn a_boundary_placed_early_in_a_long_entry_is_reviewed_as_the_cut_grows() {
        no_alarm_over_noise(Kind::Taught, 1, 38, 8);
    }

    /// The heavy flute of a 2-flute tool broken (seed 8800, break case 22: the flutes 82
    /// and 18 % of the load): the window placed on its whole cut emptied, the revolution's
    /// mean fell under the not-cutting floor (23.9 N against 24) before the light flute
    /// took the chip, and the tool-gone rule named the drop trip a lost tool. One empty
    /// tooth is left to the trip's naming (the window was placed there by the review as
    /// the entry's cut grew, `window::REGROWN`).
    #[test]
    fn a_heavy_flutes_empty_window_is_a_breakage_not_a_lost_tool() {
        caught_with_no_false_alarm(Kind::Break, 22, 8800, 8);
    }

    /// Flutes broken inside the window their next pass is judged against (seed 12998
    /// break 2: 4 flutes, `R_r` 1.57, down milling, 3 978 rpm; seed 13285 break 26 with no
    /// current-loop lag: 4 flutes, `R_r` 1.50, down milling, 3 824 rpm): that window, the
    /// trip's reference, lost the rest of the flute's chip, and the next pass lost the
    /// trip's share of the force two revolutions back but not of the lighter reference:
    /// 1.32 and 1.23 revolutions after the first missed cut. The plain trip's shares are
    /// now of the force before that loss. Each at its own noise seed within a revolution,
    /// and 12998's over 16 noise seeds at most 1 late (3 before). Found at seeds
    /// 12993-13088 and 13281-13376, after the rules had been set.
    #[test]
    fn a_trip_whose_reference_lost_the_rest_of_the_chip_counts_from_before_it() {
        each_drawn_within_a_revolution(&[(2, 12998)]);
        let late = late_after_onset_in(Setup::default(), 2, 12998, 16);
        assert!(late.len() <= 1, "{late:#?}");
        let late = late_after_onset_in(no_lag(), 26, 13285, 1);
        assert!(late.is_empty(), "{late:#?}");
    }

    /// A noise pair, then an exit (seed 13203, normal case 51, with no current-loop lag: 3
    /// flutes, `R_r` 1.12, 515 N): one tooth 93 N down, 41 N of it its period two
    /// revolutions back standing high by noise, the next 26 N up; the evidence armed the
    /// handed tooth's trip, and the exit's first period there lost 81 N. Taken from two
    /// revolutions back, as the plain trip's shares are, the evidence's share was 0.20 of
    /// the reference and tripped; it stays the share of the reference (0.34). Over 16
    /// noise seeds. Found at seeds 13185-13280 with the shares from two back everywhere.
    #[test]
    fn a_noise_pairs_evidence_keeps_its_share_of_the_reference() {
        no_alarm_without_lag(Kind::Normal, 51, 13203);
    }

    /// A flute broken 5 teeth after the window moved (seed 13375, break case 9: 4 flutes,
    /// up milling, `R_r` 0.99, 2 661 rpm): its period lost 43 % (flagged transient) and the
    /// next gained 46 %, a pair of about 20 sigma_R. A flagged loss counts only out of a
    /// cut whose revolutions before it held, which were not armed yet after the move, and
    /// the trip on the broken flute's next pass came 1.04 revolutions after the first
    /// missed cut. Such a pair now raises at once where it is as far past the noise as
    /// `pair_raises` asks. Found at seeds 13281-13376, after the rules had been set.
    #[test]
    fn a_pair_far_past_the_noise_just_after_a_moved_window_raises() {
        all_within_a_revolution(&[(9, 13375)]);
    }
}

/// The hand-over stage's measure of a cut's span (`AlarmState::span_share`) against the
/// truth, on the break cases of seeds 12225-12240 without an estimate (684: the feed under
/// the calibrated range, where the monitor measures it): each cut's arc and the helix's lag
/// over its depth (`acos(1 - R_r) + R_a tan 30 deg`) as a share of the pitch, against the
/// median of the measure over the last 0.3 s before the damage. Every cut within 0.95 of a
/// pitch measures under `alarm::SPAN_SHARE` (0.1), every one past 1.15 over it. `cargo
/// test --release -p host-sim --lib -- --ignored the_span_share_measures` (about a minute
/// and a half).
#[cfg(test)]
mod span_scan {
    use super::*;

    #[test]
    #[ignore = "about a minute in release: a calibration of SPAN_SHARE, run by hand"]
    fn the_span_share_measures_the_span_of_the_cut() {
        use estimator_core::alarm::SPAN_SHARE;
        let (mut narrow, mut wide, mut cuts) = (0, 0, 0);
        let mut table = [[0usize; 4]; 6];
        for seed in 12225..12241u64 {
            for i in 0..120 {
                let case = draw_case(Kind::Break, i, seed).expect("a case");
                let fs = f64::from(case.machine.monitor.sample_rate_hz);
                let damage = case.damage_s.expect("a damage");
                let mut seen = Vec::new();
                run_case_with(&case, |_, out, alarms| {
                    if let Some((r, _)) = out {
                        let t = r.end_sample as f64 / fs;
                        // (Only a cut without an estimate: the monitor measures the
                        // span there alone.)
                        let usable = r.status == estimator_core::Status::TC_OUT_OF_RANGE;
                        if usable && t < damage && t > damage - 0.3 {
                            seen.push(alarms.span_share());
                        }
                    }
                })
                .expect("runs");
                seen.retain(|x| x.is_finite());
                if seen.is_empty() {
                    continue;
                }
                seen.sort_by(f32::total_cmp);
                let median = seen[seen.len() / 2];
                let (rr, ra, _) = engagement_at(&case.scenario, damage).expect("a cut");
                let pitch = 2.0 * std::f64::consts::PI / f64::from(case.scenario.tool.flutes);
                let span = ((1.0 - rr).acos() + ra * 30f64.to_radians().tan()) / pitch;
                cuts += 1;
                let row = [0.8, 0.95, 1.0, 1.05, 1.15]
                    .iter()
                    .filter(|&&b| span >= b)
                    .count();
                for (c, t) in table[row].iter_mut().zip([-1.0, 0.1, 0.2, 0.3]) {
                    *c += usize::from(median > t);
                }
                if span < 0.95 {
                    narrow += 1;
                    assert!(
                        median < SPAN_SHARE,
                        "seed {seed} break {i}: {span} {median}"
                    );
                } else if span > 1.15 {
                    wide += 1;
                    assert!(
                        median > SPAN_SHARE,
                        "seed {seed} break {i}: {span} {median}"
                    );
                }
            }
        }
        eprintln!("{cuts} cuts: {narrow} within 0.95 of a pitch, {wide} past 1.15");
        eprintln!("by span over the pitch (0.8, 0.95, 1, 1.05, 1.15): cuts, median over 0.1, 0.2, 0.3: {table:?}");
        assert!(narrow > 150 && wide > 100, "{narrow} {wide}");
    }
}
