//! The streaming monitor: raw samples and encoder pulses in, one [`ToothRecord`] per tooth
//! period out. The firmware and host-sim both run exactly this.
//!
//! # Design
//! `samples -> tooth means -> forces -> filtered forces -> immersion`, per tooth:
//! 1. [`crate::tooth`] averages the raw channels over each tooth period (per sample: a few
//!    additions; everything below runs once per tooth), from a boundary that
//!    [`crate::window`] places where no flute cuts (the encoder pulse, delayed). Per
//!    sample too, [`crate::handover`] bins the spindle channel over the period: the chip a
//!    flute broken inside its cut hands to the next one (`handover_z`, `handover_n`).
//! 2. The means become forces ([`crate::drive`]): the feed force `F_ax` from the feed-axis
//!    currents, projected on the feed direction, and the tangential force `F_at` from the
//!    spindle current or load; or, from a dynamometer, `F_ax` and `F_ay` directly. All
//!    conversions are linear in the signal at constant speed, so converting the mean is the
//!    same as averaging converted samples, at a fraction of the cost.
//! 3. Runout makes the flutes cut unequally; any `N` consecutive teeth hold each flute once,
//!    so means over whole revolutions remove it. The filter is the mean of the last
//!    `filter_revs * N` valid teeth; its uncertainty is the scatter of its per-revolution
//!    block means (standard error), propagated through the estimator.
//! 4. Validity: the immersion is reported only when the whole window is steady. Entry,
//!    exit and engagement steps show as a change between the last revolution and the one
//!    before (`TRANSIENT`), feed or speed changes as a change of `t_c` (`FEED_CHANGE`);
//!    either, like an invalid period or an air cut, restarts a settling count that keeps
//!    the immersion flagged until the window holds only data from after it. (Not a moved
//!    tooth window's odd period: it stands in the window as its teeth a revolution
//!    earlier, and a steady cut's revolution holds the same force at any boundary.)

use crate::drive::{FeedDrive, SpindleModel};
use crate::estimator::{Estimate, Estimator, EstimatorConfig, Measured, Method};
use crate::fmath;
use crate::handover::{self, Handover, HandoverState};
use crate::probe::{NoProbe, Probe, Stage};
use crate::status::Status;
use crate::tooth::{Period, SyncMode, Timing, ToothState, CHANNELS, LENGTH_CHANGE_SAMPLES};
use crate::window::{Window, WindowState};
use crate::ConfigError;

/// Most teeth the filter window may hold (`filter_revs * flutes`, and at least two
/// revolutions): 64 teeth of three floats, under 1 KiB of state.
pub const MAX_WINDOW: usize = 64;
const _: () = assert!(MAX_WINDOW.is_power_of_two());
/// Most flutes the not-cutting decision averages over.
const MAX_REV_TEETH: usize = 32;

/// Cosine of the largest turn of the feed direction between two teeth that is not a
/// feed change (about 3 degrees: an arc of 20 mm radius at 250 mm/min turns 0.3 degrees
/// per tooth at 600 rpm, 4 flutes).
const MAX_TURN_COS: f32 = 0.9986;

/// Weight of a new tooth in the running noise variance (memory of about 64 teeth).
const NOISE_ALPHA: f32 = 1.0 / 64.0;
/// A change of the revolution mean counts as a transient beyond this many standard
/// deviations of its noise.
const NOISE_SIGMAS: f32 = 4.0;
/// Largest change of the revolution mean, relative to the force, that noise may excuse.
const NOISE_CAP_REL: f32 = 0.15;

/// What the analog inputs carry.
// No heap to box the large variant into, and there is one of these per monitor.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Input {
    /// Servo-amplifier check terminals: feed-axis currents [A] and the spindle signal.
    Motor {
        /// Feed drive model (one or two axes).
        feed: FeedDrive,
        /// Spindle model (current or load %).
        spindle: SpindleModel,
    },
    /// Forces [N] in the feed frame from a dynamometer: `feed[0] = F_ax`, `feed[1] = F_ay`.
    Dynamometer,
}

/// Where the feed velocity comes from.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum FeedVelocity {
    /// From the samples (feed-axis encoders).
    #[default]
    Measured,
    /// A fixed programmed feed [mm/min] per axis, when no encoder is wired.
    Nominal([f32; 2]),
}

/// Monitor configuration, checked once by [`build`](Self::build).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MonitorConfig {
    /// ADC sample rate [Hz].
    pub sample_rate_hz: f32,
    /// Analog inputs.
    pub input: Input,
    /// Feed velocity source.
    pub feed_velocity: FeedVelocity,
    /// Tool, coefficients, mode, solver.
    pub estimator: EstimatorConfig,
    /// Encoder pulses per tooth or per revolution.
    pub sync: SyncMode,
    /// Slowest spindle speed monitored [rpm]; a longer period means the spindle stopped.
    pub min_rpm: f32,
    /// Fastest spindle speed [rpm]; a shorter period is a glitch.
    pub max_rpm: f32,
    /// Largest relative change of the tooth period from one tooth to the next, on top of
    /// the [`LENGTH_CHANGE_SAMPLES`] that timing pulses to whole samples makes.
    pub max_period_jump: f32,
    /// Filter length in revolutions.
    pub filter_revs: u8,
    /// Relative change of the revolution-mean force between consecutive revolutions that
    /// counts as entry, exit or an engagement step.
    pub transient_rel: f32,
    /// Relative change of the feed per tooth that counts as a feed or speed change (of a
    /// revolution's mean, on top of [`LENGTH_CHANGE_SAMPLES`] of its length).
    pub feed_change_rel: f32,
    /// Clipping levels of the feed X, feed Y and spindle inputs (same units as the
    /// samples); a sample at or beyond is saturated.
    pub clip: [f32; 3],
    /// Learn where in the tooth period no flute cuts and begin the averaging windows there
    /// ([`crate::window`]); off: they begin at the encoder pulse.
    pub align_window: bool,
    /// Time constant of the spindle amplifier's current loop, first order [s], from 0 to
    /// [`MAX_SPINDLE_LAG_S`]; 0: none allowed for. The drop trip allows for it in the
    /// reference it takes its share of and in the whole period at its close
    /// ([`crate::handover`], "Current-loop lag"); measured on the machine, it is the
    /// current's response to a step of torque (63 %); a setting half or one and a half
    /// times the true one raised no false alarm where the evaluation's cases were run so
    /// (BENCHMARKS.md).
    pub spindle_lag_s: f32,
}

/// Longest [`MonitorConfig::spindle_lag_s`] [s]: the shortest tooth periods monitored are a
/// few ms, and a lag near them smears each tooth's force into the next.
pub const MAX_SPINDLE_LAG_S: f32 = 0.01;

impl Default for MonitorConfig {
    /// The paper's tool on a one-axis feed with a current-sensed spindle, 20 kS/s.
    fn default() -> Self {
        MonitorConfig {
            sample_rate_hz: 20_000.0,
            input: Input::Motor {
                feed: FeedDrive::default(),
                spindle: SpindleModel::default(),
            },
            feed_velocity: FeedVelocity::Measured,
            estimator: EstimatorConfig::default(),
            sync: SyncMode::PerTooth,
            min_rpm: 60.0,
            max_rpm: 24_000.0,
            max_period_jump: 0.1,
            filter_revs: 4,
            transient_rel: 0.02,
            feed_change_rel: 0.03,
            clip: [f32::INFINITY; 3],
            align_window: true,
            spindle_lag_s: 0.0,
        }
    }
}

impl MonitorConfig {
    /// Validates everything and derives the sample-count limits.
    pub fn build(self) -> Result<Monitor, ConfigError> {
        use ConfigError::*;
        let est = self.estimator.build()?;
        if let Input::Motor { feed, spindle } = &self.input {
            feed.validate()?;
            spindle.validate()?;
        }
        let fs = self.sample_rate_hz;
        if !fs.is_finite() || fs <= 0.0 {
            return Err(OutOfRange("sample_rate_hz"));
        }
        if let FeedVelocity::Nominal(v) = self.feed_velocity {
            if !(v[0].is_finite() && v[1].is_finite()) {
                return Err(NonFinite("feed_velocity"));
            }
        }
        if !(self.min_rpm.is_finite() && self.min_rpm > 0.0) {
            return Err(OutOfRange("min_rpm"));
        }
        if !(self.max_rpm.is_finite() && self.max_rpm > self.min_rpm) {
            return Err(OutOfRange("max_rpm"));
        }
        for (v, name) in [
            (self.max_period_jump, "max_period_jump"),
            (self.transient_rel, "transient_rel"),
            (self.feed_change_rel, "feed_change_rel"),
        ] {
            if !(v.is_finite() && v > 0.0 && v < 1.0) {
                return Err(OutOfRange(name));
            }
        }
        if self.clip.iter().any(|c| c.is_nan() || *c <= 0.0) {
            return Err(OutOfRange("clip"));
        }
        if !(self.spindle_lag_s >= 0.0 && self.spindle_lag_s <= MAX_SPINDLE_LAG_S) {
            return Err(OutOfRange("spindle_lag_s"));
        }
        let n = self.estimator.tool.flutes as usize;
        let window = self.filter_revs as usize * n;
        if self.filter_revs == 0 || window.max(2 * n) > MAX_WINDOW {
            return Err(OutOfRange("filter_revs"));
        }
        let per_tooth = |rpm: f32| fs * 60.0 / (rpm * n as f32);
        let timing = Timing {
            mode: self.sync,
            teeth: n as u8,
            min_period: per_tooth(self.max_rpm) as u32,
            max_period: per_tooth(self.min_rpm) as u32,
            max_jump: self.max_period_jump,
            clip: self.clip,
        };
        if timing.min_period < 2 {
            return Err(OutOfRange("max_rpm"));
        }
        let handover = Handover::new(
            n as u8,
            matches!(self.input, Input::Motor { .. }),
            self.align_window,
            self.sync == SyncMode::PerTooth,
        )
        .lagged(self.spindle_lag_s * fs);
        let boundary = Window {
            align: self.align_window,
            teeth_per_pulse: match self.sync {
                SyncMode::PerTooth => 1,
                SyncMode::PerRevolution => n as u8,
            },
            teeth: n as u8,
        };
        Ok(Monitor {
            est,
            timing,
            boundary,
            handover,
            window,
            settle: window.max(2 * n),
            clip_any: self.clip.iter().any(|c| *c < f32::INFINITY),
            inv_flutes: 1.0 / n as f32,
            inv_revs: 1.0 / self.filter_revs as f32,
            cfg: self,
        })
    }
}

/// One sample of every input.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Sample {
    /// Feed-axis currents X, Y [A] (motor input) or feed-frame forces `F_ax`, `F_ay` [N]
    /// (dynamometer input).
    pub feed: [f32; 2],
    /// Feed velocity X, Y [mm/min], signed (ignored with a nominal feed).
    pub feed_velocity_mm_min: [f32; 2],
    /// Spindle current [A] or load [%], per the spindle model (unused for a dynamometer).
    pub spindle: f32,
    /// A tooth-sync (or revolution) pulse arrived at this sample.
    pub sync: bool,
}

/// What the monitor says about one tooth period. Immersion fields are 0 unless
/// `status.is_valid()`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ToothRecord {
    /// Index of the period's last sample (time = `end_sample / sample_rate_hz`).
    pub end_sample: u64,
    /// Tooth index in the revolution.
    pub tooth: u8,
    /// Period length [samples].
    pub samples: u32,
    /// Spindle speed from the period [rpm].
    pub rpm: f32,
    /// Feed per tooth of this period [mm/tooth].
    pub tc_mm: f32,
    /// Tooth-average feed force `F_ax` [N].
    pub fx_n: f32,
    /// Tooth-average tangential force `F_at` (motor) or normal force `F_ay`
    /// (dynamometer) [N].
    pub f2_n: f32,
    /// `F_ax` filtered over the window [N].
    pub fx_filt_n: f32,
    /// Second force filtered [N].
    pub f2_filt_n: f32,
    /// Feed per tooth filtered [mm/tooth].
    pub tc_filt_mm: f32,
    /// Radial immersion ratio.
    pub rr: f32,
    /// Axial immersion ratio.
    pub ra: f32,
    /// Radial depth [mm].
    pub dr_mm: f32,
    /// Axial depth [mm].
    pub da_mm: f32,
    /// 1-sigma of `dr_mm` [mm].
    pub dr_sigma_mm: f32,
    /// 1-sigma of `da_mm` [mm].
    pub da_sigma_mm: f32,
    /// Flags; empty means the immersion can be trusted.
    pub status: Status,
    /// What produced `R_r`.
    pub method: Method,
    /// The chip this tooth took over from the one before inside the period (a flute that
    /// broke in its cut, see [`crate::handover`]), in standard deviations of its noise;
    /// 0 where not measured.
    pub handover_z: f32,
    /// That hand-over as a change of the tooth-average tangential force [N].
    pub handover_n: f32,
}

impl ToothRecord {
    /// End time of the period [s].
    pub fn time_s(&self, sample_rate_hz: f32) -> f64 {
        self.end_sample as f64 / sample_rate_hz as f64
    }

    /// Every field as raw bits, in declaration order: what host and target compare.
    pub fn to_words(&self) -> [u32; RECORD_WORDS] {
        [
            self.end_sample as u32,
            (self.end_sample >> 32) as u32,
            self.tooth as u32,
            self.samples,
            self.rpm.to_bits(),
            self.tc_mm.to_bits(),
            self.fx_n.to_bits(),
            self.f2_n.to_bits(),
            self.fx_filt_n.to_bits(),
            self.f2_filt_n.to_bits(),
            self.tc_filt_mm.to_bits(),
            self.rr.to_bits(),
            self.ra.to_bits(),
            self.dr_mm.to_bits(),
            self.da_mm.to_bits(),
            self.dr_sigma_mm.to_bits(),
            self.da_sigma_mm.to_bits(),
            self.status.0 as u32,
            self.method as u32,
            self.handover_z.to_bits(),
            self.handover_n.to_bits(),
        ]
    }
}

/// Length of [`ToothRecord::to_words`].
pub const RECORD_WORDS: usize = 21;

/// The drop trip passes only with the feed speed at least this share of the last
/// period's (see `Monitor::take_trip`).
pub const TRIP_FEED_SHARE: f32 = 0.8;

/// Periods the hand-over stage does not compare across: the tooth alignment or the
/// forces' level may have moved (an air cut or a moved window restarts it altogether).
const NO_HANDOVER: Status = Status(
    Status::NON_FINITE.0
        | Status::PERIOD_INVALID.0
        | Status::NO_SYNC.0
        | Status::INPUT_FAULT.0
        | Status::FEED_CHANGE.0,
);

/// What one pass over the window gives (see [`Monitor::blocks`]).
#[derive(Clone, Copy, Debug, Default)]
struct Blocks {
    /// Whole revolutions available (at most `max(filter_revs, 2)`).
    count: usize,
    newest: Entry,
    before: Entry,
    filter: Entry,
    /// Variance of the filter's `F_ax`, second force (squared standard error) [N^2].
    var: [f32; 2],
}

/// A tooth's means converted, for [`Monitor::judge`].
struct Means {
    tc_mm: f32,
    fx_n: f32,
    f2_n: f32,
    /// All four above are finite.
    all_finite: bool,
    /// Feed speed [mm/min] and velocity.
    speed: f32,
    /// Period length [samples].
    samples: u32,
    v: [f32; 2],
    moving: bool,
}

/// One valid tooth in the filter window.
#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    fx_n: f32,
    f2_n: f32,
    tc_mm: f32,
}

/// Running state of a [`Monitor`]: about 1.6 KiB, no heap.
#[derive(Clone, Debug)]
pub struct MonitorState {
    tooth: ToothState,
    win: WindowState,
    hand: HandoverState,
    /// Feed speed of the last period [mm/min] (the drop trip's feed test).
    speed_mm_min: f32,
    ring: [Entry; MAX_WINDOW],
    /// `rev[i]`: mean of the revolution (`flutes` entries) ending at `ring[i]`, newest
    /// first, made when `ring[i]` was stored. A revolution that reaches back before the
    /// last reset holds stale entries; `blocks` reads only revolutions that do not.
    rev: [Entry; MAX_WINDOW],
    /// Next write position.
    head: usize,
    /// Valid entries (saturates at MAX_WINDOW).
    len: usize,
    /// Teeth still to come before the window is steady again.
    settle: usize,
    /// Feed direction (unit vector) of the last valid tooth.
    dir: [f32; 2],
    /// The last revolution's per-tooth force magnitudes (cutting or not), for the
    /// not-cutting decision.
    mags: [f32; MAX_REV_TEETH],
    mag_head: usize,
    /// Running variance of same-flute force differences less their common part [N^2].
    noise_var: f32,
    /// Eq. 7's `[F_ax, F_at]` at the last estimate (see `Estimator::estimate_with_model`).
    model_n: [f32; 2],
    /// Last filtered output (kept through invalid periods, for display).
    fx_filt_n: f32,
    f2_filt_n: f32,
    tc_filt_mm: f32,
}

impl Default for MonitorState {
    fn default() -> Self {
        MonitorState {
            tooth: ToothState::default(),
            win: WindowState::default(),
            hand: HandoverState::default(),
            speed_mm_min: 0.0,
            ring: [Entry::default(); MAX_WINDOW],
            rev: [Entry::default(); MAX_WINDOW],
            head: 0,
            len: 0,
            settle: 0,
            dir: [0.0; 2],
            mags: [0.0; MAX_REV_TEETH],
            mag_head: 0,
            noise_var: 0.0,
            model_n: [0.0; 2],
            fx_filt_n: 0.0,
            f2_filt_n: 0.0,
            tc_filt_mm: 0.0,
        }
    }
}

impl MonitorState {
    /// Index of the last sample fed (0-based).
    pub fn last_sample(&self) -> u64 {
        self.tooth.last_sample()
    }

    /// Eq. 7's `[F_ax, F_at]` at the estimate of the last record that has one.
    #[inline(always)]
    pub(crate) fn model_n(&self) -> [f32; 2] {
        self.model_n
    }

    /// The last record's change from its tooth's profile re-cut at a moved window, as a
    /// tangential force [N] ([`HandoverState::recut_change_n`]); NaN where it had none.
    #[inline(always)]
    pub(crate) fn recut_change_n(&self) -> f32 {
        self.hand.recut_change_n()
    }

    /// Boundaries in a row that lie where their tooth's did a revolution earlier
    /// ([`HandoverState::lag_quiet`]).
    #[inline(always)]
    pub(crate) fn lag_quiet(&self) -> u8 {
        self.hand.lag_quiet()
    }

    /// The least bin's share of the tooth's force ([`HandoverState::span_share`]).
    #[inline(always)]
    pub(crate) fn span_share(&self) -> f32 {
        self.hand.span_share()
    }

    /// The drop trip's channel's noise ([`HandoverState::change_var_n2`]).
    #[inline(always)]
    pub(crate) fn change_var_n2(&self) -> f32 {
        self.hand.change_var_n2()
    }

    /// The `k`-th most recent entry (0 = newest); `k < len`.
    fn back(&self, k: usize) -> Entry {
        // MAX_WINDOW is a power of two: the wrap is a mask.
        let i = self.head.wrapping_sub(1).wrapping_sub(k) & (MAX_WINDOW - 1);
        self.ring.get(i).copied().unwrap_or_default()
    }

    /// Mean of entries `from..from + count` back from the newest.
    fn mean(&self, from: usize, count: usize) -> Entry {
        let mut m = Entry::default();
        for k in from..from + count {
            let e = self.back(k);
            m.fx_n += e.fx_n;
            m.f2_n += e.f2_n;
            m.tc_mm += e.tc_mm;
        }
        let inv = 1.0 / count.max(1) as f32;
        Entry {
            fx_n: m.fx_n * inv,
            f2_n: m.f2_n * inv,
            tc_mm: m.tc_mm * inv,
        }
    }
}

/// A validated monitor. `process` is the whole signal chain and cannot fail.
#[derive(Clone, Debug)]
pub struct Monitor {
    cfg: MonitorConfig,
    est: Estimator,
    timing: Timing,
    /// Where the tooth windows begin.
    boundary: Window,
    /// The chip handed from flute to flute inside the period.
    handover: Handover,
    window: usize,
    /// Derived once: `settle_teeth()`, `1 / flutes`, `1 / filter_revs`, whether any clip
    /// level is finite (with none, the per-sample clip test is left out).
    settle: usize,
    clip_any: bool,
    inv_flutes: f32,
    inv_revs: f32,
}

impl Monitor {
    /// The configuration.
    pub fn config(&self) -> &MonitorConfig {
        &self.cfg
    }

    /// The estimator the monitor runs.
    pub fn estimator(&self) -> &Estimator {
        &self.est
    }

    /// Feeds one sample; returns a record when a tooth period closes.
    ///
    /// Not inlined, so that the record (72 bytes) is built straight into the caller's
    /// variable (see `Pipeline::process`).
    #[inline(never)]
    pub fn process(&self, st: &mut MonitorState, s: &Sample) -> Option<ToothRecord> {
        self.process_with(st, s, &mut NoProbe)
    }

    /// [`Self::process`], telling `probe` where each stage of a tooth update ends (for the
    /// instruction-count bench; see [`crate::probe`]).
    #[cfg(feature = "probe")]
    #[inline(never)]
    pub fn process_probed<P: Probe>(
        &self,
        st: &mut MonitorState,
        s: &Sample,
        probe: &mut P,
    ) -> Option<ToothRecord> {
        self.process_with(st, s, probe)
    }

    #[inline(always)]
    pub(crate) fn process_with<P: Probe>(
        &self,
        st: &mut MonitorState,
        s: &Sample,
        probe: &mut P,
    ) -> Option<ToothRecord> {
        match self.period(st, s) {
            None => None,
            Some(p) => {
                probe.mark(Stage::Period);
                Some(self.tooth(st, &p, probe))
            }
        }
    }

    /// The per-sample part: the sample into the tooth averages; the period when one closes.
    #[inline(always)]
    pub(crate) fn period(&self, st: &mut MonitorState, s: &Sample) -> Option<Period> {
        let v = match self.cfg.feed_velocity {
            FeedVelocity::Measured => s.feed_velocity_mm_min,
            FeedVelocity::Nominal(v) => v,
        };
        let x: [f32; CHANNELS] = [s.feed[0], s.feed[1], v[0], v[1], s.spindle];
        let sync = self.boundary.delay(&mut st.win, s.sync);
        let mut p = self
            .timing
            .push_checked(&mut st.tooth, &x, sync, self.clip_any);
        let bin = self
            .boundary
            .profile(&mut st.win, &x, p.as_ref().map(|p| p.samples));
        self.handover
            .sample(&mut st.hand, p.as_ref().map(|p| p.tooth), bin, x[4]);
        if let Some(p) = p.as_mut() {
            // (The move first: the re-cut needs the odd period's start offset, which the
            // open period's start replaces.)
            let len = if self.boundary.take_moved(&mut st.win) {
                self.moved(st, p)
            } else {
                p.samples
            };
            let off = self.boundary.boundary_off(&st.win);
            let lag = self.boundary.boundary_lag(&st.win);
            self.handover.period_start(&mut st.hand, off, lag);
            self.handover.period_len(&mut st.hand, len);
        }
        p
    }

    /// The period `p` closed is the first under a moved window boundary (once a cut); the
    /// length the open period's bins take.
    #[cold]
    #[inline(never)]
    fn moved(&self, st: &mut MonitorState, p: &mut Period) -> u32 {
        p.status |= Status::WINDOW_MOVED;
        // The next period is judged against the length before the move; its bins are not
        // the odd period's.
        self.timing.odd_period(&mut st.tooth);
        // The re-cut, and the open period's bins, from the pulses' tracked interval: one
        // period's length jitters with the encoder (seed 2856 chip 22: 49 samples against
        // 51.4 tracked, each re-cut profile 1-2 bins off the periods after the move, 6-16 %
        // of a tooth).
        let tracked = self.boundary.tracked_len(&st.win);
        let tracked = if (1.0..1.0e6).contains(&tracked) {
            tracked
        } else {
            st.tooth.reference_len() as f32
        };
        // (`as` saturates: a period of 0 is 1 sample's bins.)
        let len = (tracked + 0.5) as u32;
        self.boundary.rebin(&mut st.win, len);
        // The teeth the tooth stage counted the odd period as: up to the open period's.
        let n = self.cfg.estimator.tool.flutes as usize;
        let teeth = (st.tooth.open_tooth() as usize + n - p.tooth as usize % n.max(1)) % n.max(1);
        self.handover
            .realign(&mut st.hand, p.tooth, teeth, p.samples, tracked);
        // Not stored in the filter window (its length is flagged), the odd period's teeth
        // are stored as they were a revolution earlier. Left out, each revolution mean over
        // it would hold one tooth twice and miss one, off by the runout, and the transient
        // test would flag the revolutions after a move as a change of the cut. (A mean that
        // holds teeth of both alignments is still off by the runout's share of the
        // boundary's shift, less.) Only where its length is all that is wrong with it.
        if Self::stands_in(st, p.status, n) {
            for _ in 0..teeth {
                let e = st.back(n - 1);
                self.push(st, e, n);
            }
        }
        len
    }

    /// Whether a closed period of `status` is a moved window's odd period that `moved`
    /// stands in for with its teeth a revolution earlier: flagged for its length alone,
    /// with a revolution in the ring to copy.
    #[inline(always)]
    fn stands_in(st: &MonitorState, status: Status, n: usize) -> bool {
        status == Status(Status::WINDOW_MOVED.0 | Status::PERIOD_INVALID.0) && st.len >= n
    }

    /// Feed force and second force [N] from a period's raw channel means (feed X, feed Y,
    /// velocity X, Y, spindle) at `rpm`, and whether the feed moves.
    ///
    /// Out of line: the two drive models are about 2 KiB of Cortex-M code, and the window
    /// stage's review converts its profile with them too; inlined at both places they
    /// took the firmware over 64 KiB of flash. A call per tooth is the price.
    ///
    /// Also the tangential force of one unit of the spindle signal (0 for a dynamometer).
    #[inline(never)]
    fn forces(&self, m: [f32; CHANNELS], rpm: f32) -> (f32, f32, bool, f32) {
        let [m0, m1, v0, v1, sp] = m;
        match &self.cfg.input {
            Input::Motor { feed, spindle } => {
                let (fx_n, moving) = feed.feed_force_and_moving([m0, m1], [v0, v1]);
                let (ft_n, per_unit_n) = spindle.tangential_force_and_slope_n(
                    sp,
                    rpm,
                    self.cfg.estimator.tool.radius_mm,
                );
                (fx_n, ft_n, moving, per_unit_n)
            }
            Input::Dynamometer => (m0, m1, fmath::hypot(v0, v1) > 0.0, 0.0),
        }
    }

    /// The hand-over into the closed period of `tooth` (see [`crate::handover`]), judged
    /// `status`: `(z, newtons)`; `per_unit_n`: the tangential force of one unit of the
    /// spindle signal.
    #[inline(always)]
    fn handover(
        &self,
        st: &mut MonitorState,
        tooth: u8,
        status: Status,
        per_unit_n: f32,
    ) -> (f32, f32) {
        let period = if status.intersects(Status(Status::NOT_CUTTING.0 | Status::WINDOW_MOVED.0)) {
            // A moved window's odd period is flagged for its length: nothing else about
            // it stops the re-cut profiles from being kept.
            let moved = status.contains(Status::WINDOW_MOVED)
                && !status.intersects(Status(
                    NO_HANDOVER.0 & !Status::PERIOD_INVALID.0 | Status::NOT_CUTTING.0,
                ));
            if moved {
                handover::Period::Moved
            } else {
                handover::Period::Restart
            }
        } else if status.intersects(NO_HANDOVER) {
            handover::Period::Unusable
        } else {
            handover::Period::Cut {
                steady: !status.contains(Status::TRANSIENT),
            }
        };
        let (z, amount) = self
            .handover
            .measure(&mut st.hand, tooth, period, per_unit_n);
        let n = amount * per_unit_n;
        if n.is_finite() {
            (z, n)
        } else {
            (0.0, 0.0)
        }
    }

    /// Arms the hand-over stage's drop trip for the open period after `rec` (see
    /// [`Handover::arm_trip`]).
    pub(crate) fn arm_trip(
        &self,
        st: &mut MonitorState,
        rec: &ToothRecord,
        share: f32,
        floor_n: f32,
        quiet_n: f32,
        whole_share: f32,
    ) {
        self.handover.arm_trip(
            &mut st.hand,
            rec.tooth,
            rec.f2_n,
            share,
            floor_n,
            quiet_n,
            whole_share,
        );
        // (The alarms ask the span measured only without an estimate.)
        if !rec.status.is_valid() {
            self.handover
                .measure_span(&mut st.hand, rec.tooth, rec.f2_n);
        }
    }

    /// The drop trip passed in the open period at sample `s`: `(lost, limit)` [N]. Not
    /// while the feed slows: a feed hold or override thins every chip at once, the tooth
    /// in its period first (the feed speed at the trip under [`TRIP_FEED_SHARE`] of the
    /// last period's; with a nominal feed velocity the monitor cannot see it).
    #[inline(always)]
    pub(crate) fn take_trip(&self, st: &mut MonitorState, s: &Sample) -> Option<(f32, f32)> {
        let trip = self.handover.take_trip(&mut st.hand)?;
        let v = match self.cfg.feed_velocity {
            FeedVelocity::Measured => s.feed_velocity_mm_min,
            FeedVelocity::Nominal(v) => v,
        };
        (fmath::hypot(v[0], v[1]) >= TRIP_FEED_SHARE * st.speed_mm_min).then_some(trip)
    }

    /// Where the window's boundary is in the tooth period (share of a period after the
    /// encoder pulse).
    pub fn window_phase(&self, st: &MonitorState) -> f32 {
        st.win.phase()
    }

    /// Everything that happens once per tooth period.
    ///
    /// Never inlined: it runs once per tooth, and keeping it out of line keeps the
    /// per-sample code around `process` small and the same in every program that links it.
    /// The record is built by one struct expression at the end, straight into the caller's
    /// place (a `ToothRecord` built in a local and then returned is copied by a `memcpy`
    /// call, about a hundred instructions on the Cortex-M4).
    #[inline(never)]
    pub(crate) fn tooth<P: Probe>(
        &self,
        st: &mut MonitorState,
        p: &Period,
        probe: &mut P,
    ) -> ToothRecord {
        self.tooth_record(st, p, None, probe)
    }

    /// How much force the boundaries of the period closed `back` records before the last
    /// may have moved against its tooth's a revolution earlier
    /// ([`Handover::boundary_moved_n`]).
    pub(crate) fn boundary_moved_n(&self, st: &MonitorState, back: usize) -> f32 {
        self.handover.boundary_moved_n(&st.hand, back)
    }

    /// [`Self::tooth`], also writing the record into `copy`: from the registers it is
    /// computed in, the second copy costs a store per field, where copying the record
    /// afterwards is a `memcpy` call (see `Pipeline::tooth_update`).
    #[inline(never)]
    pub(crate) fn tooth_and_copy<P: Probe>(
        &self,
        st: &mut MonitorState,
        p: &Period,
        copy: &mut ToothRecord,
        probe: &mut P,
    ) -> ToothRecord {
        self.tooth_record(st, p, Some(copy), probe)
    }

    /// The body of [`Self::tooth`] and [`Self::tooth_and_copy`].
    #[inline(always)]
    fn tooth_record<P: Probe>(
        &self,
        st: &mut MonitorState,
        p: &Period,
        copy: Option<&mut ToothRecord>,
        probe: &mut P,
    ) -> ToothRecord {
        let n = self.cfg.estimator.tool.flutes as usize;
        let fs = self.cfg.sample_rate_hz;
        let rpm = if p.samples > 0 {
            fs * 60.0 / (p.samples as f32 * n as f32)
        } else {
            0.0
        };
        let [_, _, v0, v1, _] = p.mean;
        let speed = crate::fmath::hypot(v0, v1);
        st.speed_mm_min = speed;
        let tc_mm = speed / (n as f32 * rpm);
        let (fx_n, f2_n, moving, per_unit_n) = self.forces(p.mean, rpm);
        probe.mark(Stage::Forces);
        let finite = [
            rpm.is_finite(),
            tc_mm.is_finite(),
            fx_n.is_finite(),
            f2_n.is_finite(),
        ];
        let means = Means {
            tc_mm,
            fx_n,
            f2_n,
            all_finite: finite == [true; 4],
            speed,
            samples: p.samples,
            v: [v0, v1],
            moving,
        };
        let (status, e) = self.judge(st, p.status, &means, probe);
        let (handover_z, handover_n) = self.handover(st, p.tooth, status, per_unit_n);
        let force2_n2 = fx_n * fx_n + f2_n * f2_n;
        self.boundary
            .review(&mut st.win, status, force2_n2, |[a, b, c]| {
                let (fx, f2, _, _) = self.forces([a, b, v0, v1, c], rpm);
                fx * fx + f2 * f2
            });
        // The immersion fields are 0 unless the record is valid.
        let valid = status.is_valid() && e.method != Method::None;
        let r = self.cfg.estimator.tool.radius_mm;
        let pick = |v: f32| if valid { v } else { 0.0 };
        let zero_unless = |ok: bool, v: f32| if ok { v } else { 0.0 };
        let (rpm, tc_mm, fx_n, f2_n) = (
            zero_unless(finite[0], rpm),
            zero_unless(finite[1], tc_mm),
            zero_unless(finite[2], fx_n),
            zero_unless(finite[3], f2_n),
        );
        let (filt, method) = ([st.fx_filt_n, st.f2_filt_n, st.tc_filt_mm], e.method);
        let imm = [
            pick(e.rr),
            pick(e.ra),
            pick(e.dr_mm),
            pick(e.da_mm),
            pick(e.rr_sigma * r),
            pick(e.ra_sigma * r),
        ];
        // Written out for each destination: from the same registers, not copied.
        macro_rules! record {
            () => {
                ToothRecord {
                    end_sample: p.end_sample,
                    tooth: p.tooth,
                    samples: p.samples,
                    rpm,
                    tc_mm,
                    fx_n,
                    f2_n,
                    fx_filt_n: filt[0],
                    f2_filt_n: filt[1],
                    tc_filt_mm: filt[2],
                    rr: imm[0],
                    ra: imm[1],
                    dr_mm: imm[2],
                    da_mm: imm[3],
                    dr_sigma_mm: imm[4],
                    da_sigma_mm: imm[5],
                    status,
                    method,
                    handover_z,
                    handover_n,
                }
            };
        }
        if let Some(copy) = copy {
            *copy = record!();
        }
        // (Before the returned record is written, which goes straight to the caller's
        // place; a mark after it would make that a copy in the probed build.)
        probe.mark(Stage::Record);
        record!()
    }

    /// The checks, the filter and the estimator for one tooth: the record's status, and
    /// the estimate (`Method::None` and zeros when the tooth is flagged before the
    /// estimator). Updates the state, including the filter output the record shows.
    #[inline(always)]
    fn judge<P: Probe>(
        &self,
        st: &mut MonitorState,
        period_status: Status,
        t: &Means,
        probe: &mut P,
    ) -> (Status, Estimate) {
        let n = self.cfg.estimator.tool.flutes as usize;
        let none = Estimate::default();
        let mut status = period_status;
        let usable = status.is_valid() && t.all_finite;
        if !usable {
            status.set_if(status.is_valid(), Status::NON_FINITE);
            // A moved window's odd period, wrong in its length alone, stands in the ring
            // as its teeth a revolution earlier (`moved`): the filter's revolutions stay
            // whole (a steady cut's revolution holds the same force at any boundary), and
            // the estimates go on.
            if !(Self::stands_in(st, status, n) && t.all_finite) {
                st.settle = self.settle_teeth();
            }
            return (status, none);
        }
        // Air cut or stopped feed: nothing to estimate, and the cut that follows starts
        // with an entry.
        // Judged on the mean over the last revolution, not on this tooth: with a flute
        // broken (or gross runout) in a light cut, one tooth period in N carries no chip
        // while the cut goes on.
        let magnitude = match self.cfg.input {
            Input::Motor { .. } => t.f2_n,
            Input::Dynamometer => crate::fmath::hypot(t.fx_n, t.f2_n),
        };
        let nm = n.clamp(1, MAX_REV_TEETH);
        // `mag_head < nm` always: the wrap is a compare, the division a fallback.
        let slot = if st.mag_head < nm {
            st.mag_head
        } else {
            st.mag_head % nm
        };
        if let Some(m) = st.mags.get_mut(slot) {
            *m = magnitude;
        }
        st.mag_head = if slot + 1 < nm { slot + 1 } else { 0 };
        // In index order from -0, as `Iterator::sum`.
        let mut rev_mag = -0.0f32;
        for &m in st.mags.get(..nm).unwrap_or(&[]) {
            rev_mag += m;
        }
        let rev_mag = rev_mag / n.max(1) as f32;
        let cutting = t.moving && rev_mag > self.cfg.estimator.force_floor_n;
        if !cutting {
            status |= Status::NOT_CUTTING;
            st.settle = self.settle_teeth();
            st.len = 0;
            return (status, none);
        }
        // Feed direction against the last tooth's (reversal, corner, tight arc).
        let dir = [t.v[0] / t.speed, t.v[1] / t.speed];
        if st.len >= n && dir[0] * st.dir[0] + dir[1] * st.dir[1] < MAX_TURN_COS {
            status |= Status::FEED_CHANGE;
            st.settle = self.settle_teeth();
        }
        st.dir = dir;
        self.push(
            st,
            Entry {
                fx_n: t.fx_n,
                f2_n: t.f2_n,
                tc_mm: t.tc_mm,
            },
            n,
        );
        probe.mark(Stage::Checks);
        let b = self.blocks(st, n);
        // Feed change: the newest revolution's mean t_c against the one before. A single
        // tooth's t_c jitters by a sample of period length (3 % at 35 samples a tooth); a
        // revolution's sum of periods by less, but its change from the last revolution by
        // the timing of three pulses, as a period's length does: allowed on top (2.6 % at
        // 40 samples a tooth and 4 flutes), without a division.
        if b.count >= 2 {
            let (now, before) = (b.newest.tc_mm, b.before.tc_mm);
            let rev_samples = (t.samples as usize * n) as f32;
            if (now - before).abs() * rev_samples
                > (self.cfg.feed_change_rel * rev_samples + LENGTH_CHANGE_SAMPLES) * before
            {
                status |= Status::FEED_CHANGE;
                st.settle = self.settle_teeth();
            }
        }
        probe.mark(Stage::Blocks);
        // Transient: the newest revolution against the one before (both runout-free).
        if b.count >= 2 && self.transient(st, n, &b) {
            status |= Status::TRANSIENT;
            st.settle = self.settle_teeth();
        }
        probe.mark(Stage::Transient);
        // The window is whole revolutions once the monitor has warmed up; until then, what
        // there is (the record is flagged then anyway).
        let revs = self.cfg.filter_revs as usize;
        let filt = if b.count >= revs {
            b.filter
        } else {
            st.mean(0, self.window.min(st.len))
        };
        st.fx_filt_n = filt.fx_n;
        st.f2_filt_n = filt.f2_n;
        st.tc_filt_mm = filt.tc_mm;
        if st.settle > 0 || st.len < self.settle_teeth() {
            status |= Status::SETTLING;
            st.settle = st.settle.saturating_sub(1);
            return (status, none);
        }
        probe.mark(Stage::Filter);
        let m = match self.cfg.input {
            Input::Motor { .. } => Measured::Motor {
                fx_n: filt.fx_n,
                ft_n: filt.f2_n,
            },
            Input::Dynamometer => Measured::Dynamometer {
                fx_n: filt.fx_n,
                fy_n: filt.f2_n,
            },
        };
        let (e, model) = self.est.estimate_with_model(filt.tc_mm, m, b.var);
        st.model_n = model;
        probe.mark(Stage::Estimate);
        (status | e.status, e)
    }

    /// The transient test on the newest revolution against the one before, and the update
    /// of the running noise variance it is judged against.
    #[inline(always)]
    fn transient(&self, st: &mut MonitorState, n: usize, b: &Blocks) -> bool {
        let (now, before) = (b.newest, b.before);
        let mag = |e: &Entry| match self.cfg.input {
            Input::Motor { .. } => e.f2_n,
            Input::Dynamometer => crate::fmath::hypot(e.fx_n, e.f2_n),
        };
        let (a, c) = (mag(&now), mag(&before));
        // Noise floor: the same flute one revolution apart, less the common change of
        // the two revolutions, is noise (and runout drift) alone; its running variance
        // sets how large a change of the revolution mean is more than noise.
        let (new, old) = (st.back(0), st.back(n));
        let r_mag = (mag(&new) - mag(&old)) - (a - c);
        let r_fx = (new.fx_n - old.fx_n) - (now.fx_n - before.fx_n);
        // The noise term may widen the limit up to NOISE_CAP_REL of the force and no
        // further, and one tooth's residual enters the variance at most at that size:
        // a breakage (a large same-flute change) or a heavy cut before a light one must
        // not leave the detector blind to the next exit.
        let m = fmath::max(a.abs(), c.abs());
        let cap = NOISE_CAP_REL * m;
        let r2 = fmath::min(fmath::max(r_mag * r_mag, r_fx * r_fx), cap * cap);
        if r2.is_finite() {
            st.noise_var += NOISE_ALPHA * (r2 - st.noise_var);
        }
        // The limit is `max(transient_rel m, min(noise, cap))`, never below `transient_rel
        // m`: changes within that are no transient whatever the noise, and the square root
        // behind the noise is taken only for the rare changes beyond it.
        let (d_mag, d_fx) = ((a - c).abs(), (now.fx_n - before.fx_n).abs());
        let floor = self.cfg.transient_rel * m;
        if !(d_mag > floor || d_fx > floor) {
            return false;
        }
        let noise = NOISE_SIGMAS * libm::sqrtf(st.noise_var / fmath::max(n as f32 - 1.0, 1.0));
        // The feed force is held to the same scale: it can change alone (a reversal
        // turns down milling into up milling at the same tangential force).
        let limit = fmath::max(floor, fmath::min(noise, cap));
        d_mag > limit || d_fx > limit
    }

    /// The window in whole revolutions (blocks of `n` teeth, newest first): the newest two
    /// block means (transient test), the mean of the first `filter_revs` (the filter), and
    /// the variance of that mean from the scatter of the block means (at least two blocks,
    /// so one-revolution filters still get a figure). The block means were made when their
    /// newest tooth was stored ([`Self::push`]): the same sums in the same order as summing
    /// the window here, without going over it every tooth.
    #[inline(always)]
    fn blocks(&self, st: &MonitorState, n: usize) -> Blocks {
        let revs = self.cfg.filter_revs as usize;
        // Only revolutions whose teeth all came after the last reset (`len` counts them).
        let count = revs.max(2).min(st.len / n.max(1));
        let mut out = Blocks {
            count,
            ..Blocks::default()
        };
        let (mut sum, mut sum2) = ([0.0f32; 2], [0.0f32; 2]);
        let mut i = st.head.wrapping_sub(1) & (MAX_WINDOW - 1);
        let rev = |i: usize| st.rev.get(i).copied().unwrap_or_default();
        if count >= 1 {
            out.newest = rev(i);
        }
        if count >= 2 {
            out.before = rev(i.wrapping_sub(n) & (MAX_WINDOW - 1));
        }
        // The blocks of the filter, then any beyond it (`count > revs` only with a
        // one-revolution filter, whose scatter still takes two blocks).
        let in_filter = count.min(revs);
        for _ in 0..in_filter {
            let m = rev(i);
            i = i.wrapping_sub(n) & (MAX_WINDOW - 1);
            out.filter.fx_n += m.fx_n;
            out.filter.f2_n += m.f2_n;
            out.filter.tc_mm += m.tc_mm;
            sum[0] += m.fx_n;
            sum2[0] += m.fx_n * m.fx_n;
            sum[1] += m.f2_n;
            sum2[1] += m.f2_n * m.f2_n;
        }
        for _ in in_filter..count {
            let m = rev(i);
            i = i.wrapping_sub(n) & (MAX_WINDOW - 1);
            sum[0] += m.fx_n;
            sum2[0] += m.fx_n * m.fx_n;
            sum[1] += m.f2_n;
            sum2[1] += m.f2_n * m.f2_n;
        }
        let inv = self.inv_revs;
        out.filter = Entry {
            fx_n: out.filter.fx_n * inv,
            f2_n: out.filter.f2_n * inv,
            tc_mm: out.filter.tc_mm * inv,
        };
        if count >= 2 {
            let nb = count as f32;
            out.var = [0, 1].map(|k| {
                let mean = sum[k] / nb;
                let var = (sum2[k] - nb * mean * mean) / (nb - 1.0);
                // `max(var, 0)`, NaN to 0.
                (if var > 0.0 { var } else { 0.0 }) * inv
            });
        }
        out
    }

    /// Stores a tooth in the window, and the mean of the revolution it completes: the `n`
    /// newest entries summed newest first, times `1 / n` (the value `1.0 / n as f32`).
    #[inline(always)]
    fn push(&self, st: &mut MonitorState, e: Entry, n: usize) {
        let head = st.head & (MAX_WINDOW - 1);
        if let Some(slot) = st.ring.get_mut(head) {
            *slot = e;
        }
        // From 0, the new entry first (from registers), then the `n - 1` before it.
        let mut m = Entry {
            fx_n: 0.0 + e.fx_n,
            f2_n: 0.0 + e.f2_n,
            tc_mm: 0.0 + e.tc_mm,
        };
        let mut i = head;
        for _ in 1..n {
            i = i.wrapping_sub(1) & (MAX_WINDOW - 1);
            let e = st.ring.get(i).copied().unwrap_or_default();
            m.fx_n += e.fx_n;
            m.f2_n += e.f2_n;
            m.tc_mm += e.tc_mm;
        }
        if let Some(slot) = st.rev.get_mut(head) {
            *slot = Entry {
                fx_n: m.fx_n * self.inv_flutes,
                f2_n: m.f2_n * self.inv_flutes,
                tc_mm: m.tc_mm * self.inv_flutes,
            };
        }
        st.head = (head + 1) & (MAX_WINDOW - 1);
        st.len = (st.len + 1).min(MAX_WINDOW);
    }

    /// Teeth a disturbance keeps the immersion flagged: the window, and at least the two
    /// revolutions the transient test compares.
    #[inline(always)]
    fn settle_teeth(&self) -> usize {
        self.settle
    }
}
