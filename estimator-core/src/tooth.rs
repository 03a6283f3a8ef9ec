//! Tooth-synchronous averaging: raw samples and encoder pulses in, one mean per tooth
//! period out (method.md section 2: the estimator works on per-tooth averages).
//!
//! # Design
//! The mean of every channel over each period between two tooth boundaries; a boundary
//! that falls inside a sample (the window stage's, on the pulses' tracked times) splits
//! the sample between the two periods by its share of the sample's time. Boundaries
//! come from the spindle encoder, either one pulse per tooth or one pulse per revolution
//! with the revolution split into `N` equal parts using the previous revolution's length.
//! A period is closed, flagged and still emitted when it cannot be trusted:
//! - too short or too long for the configured speed range, or its length jumped from the
//!   previous one by more than `max_jump` and [`LENGTH_CHANGE_SAMPLES`] (speed change, a
//!   lost pulse: a lost pulse also
//!   advances the tooth index by the number of teeth it swallowed);
//! - a pulse closer than half a period to the previous one is a glitch: ignored, and the
//!   period that contains it flagged;
//! - no pulse for longer than the longest period: one `NO_SYNC` period is emitted and
//!   averaging waits for the next pulse (spindle stopped, encoder unplugged);
//! - a sample that is not finite or sits at the ADC's clipping level is left out of the
//!   sums and the period flagged `INPUT_FAULT`.
//!
//! Per sample this is a handful of additions and compares; the per-tooth work lives in
//! [`crate::monitor`].

use crate::status::Status;

/// Raw channels averaged per tooth: feed-axis signals X and Y, feed velocities X and Y
/// [mm/min], spindle signal.
pub const CHANNELS: usize = 5;

/// Where tooth boundaries come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum SyncMode {
    /// One pulse per tooth.
    #[default]
    PerTooth,
    /// One pulse per revolution; teeth are equal fractions of the revolution.
    PerRevolution,
}

/// Change of a period's length from the last one that timing alone makes: the three
/// pulses that bound the two periods are each timed to a sample (and jitter by about one),
/// and the change is `b2 - 2 b1 + b0` of their times.
pub const LENGTH_CHANGE_SAMPLES: f32 = 4.0;

/// Timing limits, in samples, derived once from the monitor's configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timing {
    /// Sync source.
    pub mode: SyncMode,
    /// Teeth per revolution.
    pub teeth: u8,
    /// Shortest acceptable tooth period [samples].
    pub min_period: u32,
    /// Longest acceptable tooth period [samples]; beyond it, `NO_SYNC`.
    pub max_period: u32,
    /// Largest relative change of the period from one tooth to the next.
    pub max_jump: f32,
    /// Absolute level at or beyond which a sample of channels 0, 1, 4 counts as clipped.
    pub clip: [f32; 3],
}

/// One closed tooth period.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Period {
    /// Index of the last sample in the period.
    pub end_sample: u64,
    /// Length [samples].
    pub samples: u32,
    /// Tooth index in the revolution (0-based; arbitrary phase with one pulse per tooth).
    pub tooth: u8,
    /// Channel means over the good samples.
    pub mean: [f32; CHANNELS],
    /// Samples left out (not finite or clipped).
    pub bad_samples: u32,
    /// `PERIOD_INVALID`, `NO_SYNC`, `INPUT_FAULT`, or valid.
    pub status: Status,
}

/// Running state.
#[derive(Clone, Copy, Debug, Default)]
pub struct ToothState {
    /// Index of the current sample (0-based).
    sample: u64,
    sum: [f32; CHANNELS],
    good: u32,
    /// The share of the boundary samples that opened and closed the period counted in
    /// `sum`, less the samples' count in `good` (a boundary splits its sample).
    split: f32,
    bad: u32,
    /// Samples since the current period started.
    len: u32,
    /// Samples since the last revolution pulse (per-revolution mode).
    since_rev: u32,
    /// Whether a period is open (a boundary has been seen since start or the last timeout).
    open: bool,
    glitch: bool,
    tooth: u8,
    /// Previous period length [samples] (0: none yet).
    last_len: u32,
    /// Length of the period before that one [samples] (0: none).
    before_len: u32,
    /// Previous revolution length [samples] (per-revolution mode; 0: none yet).
    rev_len: u32,
}

impl ToothState {
    /// The length the open period is judged against [samples]: the last period's, or
    /// after an odd one ([`Timing::odd_period`]) the one before it.
    #[inline(always)]
    pub(crate) fn reference_len(&self) -> u32 {
        self.last_len
    }

    /// The open period's tooth index.
    #[inline(always)]
    pub(crate) fn open_tooth(&self) -> u8 {
        self.tooth
    }

    /// Index of the last sample fed (0-based; wraps only after 2^64 samples).
    pub fn last_sample(&self) -> u64 {
        self.sample.wrapping_sub(1)
    }
}

impl Timing {
    /// Feeds one sample; returns a period when one closes.
    ///
    /// `x`: the raw channels; `sync`: an encoder pulse at this sample.
    ///
    /// Per sample this is the inline fast path (no pulse, one pulse per tooth, the period
    /// not over-long): the sample is added and nothing else happens. Everything else, the
    /// closing of a period above all, is out of line.
    #[inline(always)]
    pub fn push(&self, st: &mut ToothState, x: &[f32; CHANNELS], sync: bool) -> Option<Period> {
        self.push_checked(st, x, sync.then_some(0.0), true)
    }

    /// [`Self::push`], with a boundary (`sync`) that may fall inside the sample: `Some(w)`,
    /// `w` the share of the sample that ends the period it closes (0: the sample opens the
    /// next one, as at a pulse). And with the clip test left out when `check_clip` is
    /// false: for a caller that knows every clip level is infinite, where the test can only
    /// catch an infinite sample, which the finiteness test catches anyway.
    #[inline(always)]
    pub(crate) fn push_checked(
        &self,
        st: &mut ToothState,
        x: &[f32; CHANNELS],
        sync: Option<f32>,
        check_clip: bool,
    ) -> Option<Period> {
        // `timeout` fires when the period, with this sample, outgrows `max_period`.
        let quiet = sync.is_none()
            && self.mode == SyncMode::PerTooth
            && !(st.open && st.len.saturating_add(1) > self.max_period);
        if quiet {
            // What `push_slow` does when there is no boundary and no timeout.
            self.accumulate(st, x, check_clip);
            st.sample = st.sample.wrapping_add(1);
            return None;
        }
        // By value: the sample is spilled for the call only on this path.
        self.push_slow(st, *x, sync, check_clip)
    }

    /// [`Self::push`] in full: boundaries, accumulation, timeout.
    #[inline(never)]
    fn push_slow(
        &self,
        st: &mut ToothState,
        x: [f32; CHANNELS],
        sync: Option<f32>,
        check_clip: bool,
    ) -> Option<Period> {
        // A boundary inside the sample (its share `w` before the boundary): that share
        // joins the open period, and leaves the one open after the boundary's test, which
        // `accumulate` then adds the whole sample to. Where the boundary closed a period,
        // the new one holds the rest of the sample; where it did not (a glitch), the two
        // cancel. A bad sample is not split.
        let good = self.good(&x, check_clip);
        let w = match sync {
            Some(w) if w > 0.0 && good => w,
            _ => 0.0,
        };
        if w > 0.0 {
            Self::add_share(st, &x, w);
        }
        let out = match self.mode {
            SyncMode::PerTooth => self.boundary_per_tooth(st, sync.is_some()),
            SyncMode::PerRevolution => self.boundary_per_rev(st, sync.is_some()),
        };
        if w > 0.0 {
            Self::add_share(st, &x, -w);
        }
        // The sample that carries the pulse belongs to the new period.
        self.add(st, &x, good);
        let out = out.or_else(|| self.timeout(st));
        st.sample = st.sample.wrapping_add(1);
        out
    }

    /// Whether a sample goes into the sums: finite and not clipped.
    #[inline(always)]
    fn good(&self, x: &[f32; CHANNELS], check_clip: bool) -> bool {
        let clipped = check_clip
            && (x[0].abs() >= self.clip[0]
                || x[1].abs() >= self.clip[1]
                || x[4].abs() >= self.clip[2]);
        // `is_finite` on the sum of all channels catches any NaN/inf with one test.
        (x[0] + x[1] + x[2] + x[3] + x[4]).is_finite() && !clipped
    }

    #[inline(always)]
    fn accumulate(&self, st: &mut ToothState, x: &[f32; CHANNELS], check_clip: bool) {
        // (The sample's tests only for an open period: the common path.)
        if st.open {
            self.add(st, x, self.good(x, check_clip));
        }
    }

    /// Adds the sample `x` to the open period: to its sums if it is `good`, else to its
    /// count of bad samples.
    #[inline(always)]
    fn add(&self, st: &mut ToothState, x: &[f32; CHANNELS], good: bool) {
        if !st.open {
            return;
        }
        st.len = st.len.saturating_add(1);
        st.since_rev = st.since_rev.saturating_add(1);
        if good {
            for (s, v) in st.sum.iter_mut().zip(x) {
                *s += v;
            }
            st.good += 1;
        } else {
            st.bad = st.bad.saturating_add(1);
        }
    }

    /// Adds `w` of the sample `x` to the open period's sums. (Out of line: it runs only at
    /// a boundary, and inlined twice it cost half a kilobyte of flash.)
    #[inline(never)]
    fn add_share(st: &mut ToothState, x: &[f32; CHANNELS], w: f32) {
        for (s, v) in st.sum.iter_mut().zip(x) {
            *s += w * v;
        }
        st.split += w;
    }

    #[inline(always)]
    fn boundary_per_tooth(&self, st: &mut ToothState, sync: bool) -> Option<Period> {
        if !sync {
            return None;
        }
        if !st.open {
            self.start(st, 0);
            return None;
        }
        // A pulse within half a period of the last one is noise on the encoder line.
        if st.last_len > 0 && st.len < st.last_len / 2 {
            st.glitch = true;
            return None;
        }
        let advance = self.teeth_swallowed(st.len, st.last_len);
        let p = self.close(st, st.sample.wrapping_sub(1), advance);
        Some(p)
    }

    #[inline(always)]
    fn boundary_per_rev(&self, st: &mut ToothState, sync: bool) -> Option<Period> {
        let n = self.teeth as u32;
        if sync {
            if !st.open {
                self.start(st, 0);
                st.since_rev = 0;
                return None;
            }
            if st.rev_len > 0 && st.since_rev < st.rev_len / 2 {
                st.glitch = true;
                return None;
            }
            // The pulse ends the last tooth of the revolution, whatever the count says.
            let measured = st.since_rev;
            let was_last = st.tooth as u32 + 1 == n;
            let mut p = self.close(st, st.sample.wrapping_sub(1), 0);
            if !was_last || st.rev_len == 0 {
                p.status |= Status::PERIOD_INVALID;
            }
            st.rev_len = measured;
            st.since_rev = 0;
            st.tooth = 0;
            return Some(p);
        }
        if st.open && st.rev_len > 0 && (st.tooth as u32 + 1) < n {
            let k = st.tooth as u32 + 1;
            // Boundary k of the revolution, rounded to the nearest sample.
            let boundary = ((k as u64 * st.rev_len as u64 + n as u64 / 2) / n as u64) as u32;
            if st.since_rev >= boundary {
                return Some(self.close(st, st.sample.wrapping_sub(1), 1));
            }
        }
        None
    }

    /// How many teeth a period of `len` samples spans, judged against the previous one;
    /// 1 unless pulses were lost.
    #[inline(always)]
    fn teeth_swallowed(&self, len: u32, last: u32) -> u8 {
        // Below one and a half periods (`2 len < 3 last`) the rounded ratio is 1: no
        // division needed. (Exact for `last < 2^23`: `len / last` is then at least
        // `1 / (2 last)` below 1.5, more than the rounding of the f32 quotient.)
        if last == 0 || (last < 1 << 23 && len <= (3 * last - 1) / 2) {
            return 1;
        }
        let k = (len as f32 / last as f32 + 0.5) as u32;
        if (2..=self.teeth as u32).contains(&k) {
            k as u8
        } else {
            1
        }
    }

    #[inline(always)]
    fn start(&self, st: &mut ToothState, tooth: u8) {
        st.open = true;
        st.sum = [0.0; CHANNELS];
        st.good = 0;
        st.split = 0.0;
        st.bad = 0;
        st.len = 0;
        st.glitch = false;
        st.tooth = tooth;
    }

    /// Closes the open period, whose last sample is `end`, and opens the next one,
    /// `advance` teeth later. (Inlined into `push_slow`'s few call sites: it runs once per
    /// tooth, and out of line its `Period` is built aside and copied.)
    #[inline(always)]
    fn close(&self, st: &mut ToothState, end: u64, advance: u8) -> Period {
        let mut status = Status::VALID;
        let len = st.len;
        status.set_if(
            len < self.min_period || len > self.max_period || st.glitch,
            Status::PERIOD_INVALID,
        );
        if st.last_len > 0 && self.mode == SyncMode::PerTooth {
            // Against the relative limit plus what timing pulses to whole samples allows
            // (at 40 samples a tooth a jitter of one sample on each of the three pulses
            // moves the length by 10 %: every period would be a jump).
            let jump = (len as f32 - st.last_len as f32).abs();
            let allowed = self.max_jump * st.last_len as f32 + LENGTH_CHANGE_SAMPLES;
            status.set_if(jump > allowed, Status::PERIOD_INVALID);
        }
        status.set_if(st.bad > 0, Status::INPUT_FAULT);
        let weight = st.good as f32 + st.split;
        let inv = if weight > 0.0 { 1.0 / weight } else { 0.0 };
        let p = Period {
            end_sample: end,
            samples: len,
            tooth: st.tooth,
            mean: st.sum.map(|s| s * inv),
            bad_samples: st.bad,
            status,
        };
        st.before_len = st.last_len;
        st.last_len = len;
        let teeth = self.teeth.max(1) as u32;
        let next = st.tooth as u32 + advance.max(1) as u32;
        // `tooth < teeth` and `advance <= teeth`: one subtraction wraps it (the division
        // only for a state not made by this `Timing`).
        let next = if next < teeth {
            next
        } else if next < 2 * teeth {
            next - teeth
        } else {
            next % teeth
        } as u8;
        let since_rev = st.since_rev;
        self.start(st, next);
        st.since_rev = since_rev;
        p
    }

    /// The period just closed is odd by design (the window stage moved the boundary inside
    /// it): the next one's length is judged against the period before it, so that a good
    /// period is not flagged for the jump back (the detectors would forget their history a
    /// second time, a revolution after the first).
    #[inline(always)]
    pub(crate) fn odd_period(&self, st: &mut ToothState) {
        if st.before_len > 0 {
            st.last_len = st.before_len;
        }
    }

    /// Emits one `NO_SYNC` period when the open one outgrows every speed allowed.
    #[inline(always)]
    fn timeout(&self, st: &mut ToothState) -> Option<Period> {
        let limit = match self.mode {
            SyncMode::PerTooth => st.len,
            SyncMode::PerRevolution => st.since_rev / self.teeth.max(1) as u32,
        };
        if !st.open || limit <= self.max_period {
            return None;
        }
        // The current sample is already in the period: it is the last one.
        let mut p = self.close(st, st.sample, 1);
        p.status |= Status::NO_SYNC | Status::PERIOD_INVALID;
        // Wait for a fresh pulse; lengths before the gap say nothing about those after it.
        st.open = false;
        st.last_len = 0;
        st.before_len = 0;
        st.rev_len = 0;
        Some(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::{vec, vec::Vec};

    fn timing(mode: SyncMode) -> Timing {
        Timing {
            mode,
            teeth: 4,
            min_period: 50,
            max_period: 400,
            max_jump: 0.1,
            clip: [10.0, 10.0, 10.0],
        }
    }

    /// Runs `n` samples with a pulse every `period` samples (per tooth) and channel 0 equal
    /// to the tooth's index, returns the periods.
    fn run(
        t: &Timing,
        pulses: &[u32],
        total: u32,
        f: impl Fn(u32) -> [f32; CHANNELS],
    ) -> Vec<Period> {
        let mut st = ToothState::default();
        let mut out = Vec::new();
        for i in 0..total {
            if let Some(p) = t.push(&mut st, &f(i), pulses.contains(&i)) {
                out.push(p);
            }
        }
        out
    }

    /// A boundary inside a sample (at time `j - 1/2 + w` of the sample `j`, which stands
    /// for `j - 1/2` to `j + 1/2`) splits it: each period's mean is the signal's mean
    /// between its two boundary times, against a brute-force integral of the held samples.
    /// Per tooth and, at the revolution's pulse, per revolution; a bad sample at a boundary
    /// is not split (the new period leaves it out).
    #[test]
    fn a_boundary_inside_a_sample_splits_it_between_the_periods() {
        let value = |i: u32| ((i * 37 + 11) % 23) as f32 * 0.1 + (i / 97) as f32 * 0.5;
        // (sample, share before the boundary): the first opens the first period.
        let bounds: Vec<(u32, f32)> = (0..9)
            .map(|k| (7 + k * 97 + k % 3, [0.25, 0.0, 0.8, 0.5][k as usize % 4]))
            .collect();
        let time = |(j, w): (u32, f32)| j as f64 - 0.5 + w as f64;
        let integral = |a: f64, b: f64| {
            let steps = ((b - a) * 1000.0) as usize;
            let h = (b - a) / steps as f64;
            (0..steps)
                .map(|s| value((a + (s as f64 + 0.5) * h + 0.5).floor() as u32) as f64 * h)
                .sum::<f64>()
                / (b - a)
        };
        for mode in [SyncMode::PerTooth, SyncMode::PerRevolution] {
            let t = Timing {
                teeth: 1,
                ..timing(mode)
            };
            let mut st = ToothState::default();
            let mut got = Vec::new();
            for i in 0..bounds.last().map_or(0, |b| b.0 + 1) {
                let sync = bounds.iter().find(|b| b.0 == i).map(|b| b.1);
                let mut x = [value(i), 0.0, 0.0, 0.0, 0.0];
                if i == bounds[5].0 {
                    x[1] = f32::NAN;
                }
                if let Some(p) = t.push_checked(&mut st, &x, sync, true) {
                    got.push(p);
                }
            }
            assert_eq!(got.len(), bounds.len() - 1, "{mode:?}");
            for (k, p) in got.iter().enumerate() {
                let (a, b) = (bounds[k], bounds[k + 1]);
                // Around the bad sample: left out whole, by the period it opens.
                let (ta, tb) = match k {
                    4 => (time(a), b.0 as f64 - 0.5),
                    5 => (a.0 as f64 + 0.5, time(b)),
                    _ => (time(a), time(b)),
                };
                let want = integral(ta, tb);
                assert!(
                    (p.mean[0] as f64 - want).abs() < 1e-4 * want.abs().max(1.0),
                    "{mode:?} period {k}: {} against {want}",
                    p.mean[0]
                );
                assert_eq!(p.samples, b.0 - a.0, "{mode:?} period {k}");
            }
        }
    }

    #[test]
    fn averages_each_tooth_period_exactly() {
        let t = timing(SyncMode::PerTooth);
        let pulses: Vec<u32> = (0..10).map(|k| k * 100).collect();
        // Channel 0 ramps with the sample index: the mean of a period is its midpoint.
        let ps = run(&t, &pulses, 950, |i| [i as f32 / 100.0, 1.0, 2.0, 3.0, 4.0]);
        assert_eq!(ps.len(), 9);
        for (k, p) in ps.iter().enumerate() {
            assert_eq!(p.samples, 100);
            // The pulse at 100 (k + 1) opens the next period: this one ends just before.
            assert_eq!(p.end_sample, (k as u64 + 1) * 100 - 1);
            assert!(p.status.is_valid(), "{}", p.status);
            let mid = (k as f32 * 100.0 + 49.5) / 100.0;
            assert!((p.mean[0] - mid).abs() < 1e-5, "{} vs {mid}", p.mean[0]);
            assert_eq!(p.mean[4], 4.0);
            assert_eq!(p.tooth as usize, k % 4);
        }
    }

    #[test]
    fn lost_pulse_is_flagged_and_the_tooth_index_keeps_count() {
        let t = timing(SyncMode::PerTooth);
        let pulses: Vec<u32> = (0..12).map(|k| k * 100).filter(|&p| p != 500).collect();
        let ps = run(&t, &pulses, 1150, |_| [1.0; CHANNELS]);
        let teeth: Vec<u8> = ps.iter().map(|p| p.tooth).collect();
        // Period 4 (400-600) swallowed tooth 5: index jumps 4 -> 6 (mod 4: 0 -> 2).
        assert_eq!(teeth, vec![0, 1, 2, 3, 0, 2, 3, 0, 1, 2]);
        assert!(ps[4].status.contains(Status::PERIOD_INVALID));
        assert!(
            ps[5].status.contains(Status::PERIOD_INVALID),
            "jump back from 200 to 100"
        );
        assert!(ps[6].status.is_valid());
    }

    /// The window stage moves the boundary 40 samples later: one period of 140. Marked odd,
    /// the next period (100) is judged against the 100 before it and the bins of the open
    /// period follow it; unmarked, it is a jump back, as after a lost pulse.
    #[test]
    fn the_period_after_an_odd_one_is_judged_against_the_one_before() {
        let t = timing(SyncMode::PerTooth);
        let pulses = [0, 100, 200, 340, 440, 540];
        for marked in [true, false] {
            let mut st = ToothState::default();
            let mut ps = Vec::new();
            for i in 0..600 {
                if let Some(p) = t.push(&mut st, &[1.0; CHANNELS], pulses.contains(&i)) {
                    if marked && p.samples == 140 {
                        t.odd_period(&mut st);
                    }
                    ps.push((p, st.reference_len()));
                }
            }
            let lens: Vec<(u32, bool, u32)> = ps
                .iter()
                .map(|(p, r)| (p.samples, p.status.contains(Status::PERIOD_INVALID), *r))
                .collect();
            // The odd period itself is a jump (flagged); the one after it only unmarked.
            assert_eq!(
                lens,
                vec![
                    (100, false, 100),
                    (100, false, 100),
                    (140, true, if marked { 100 } else { 140 }),
                    (100, !marked, 100),
                    (100, false, 100)
                ],
                "marked {marked}"
            );
        }
    }

    #[test]
    fn pulses_a_sample_off_at_short_periods_are_no_jump() {
        // 38.9 samples a tooth, pulses a sample early and late in turn: lengths 37 and 41,
        // a change of 10.8 % a tooth; a lost pulse there still doubles the period.
        let t = Timing {
            min_period: 10,
            ..timing(SyncMode::PerTooth)
        };
        let pulses: Vec<u32> = (0..40)
            .map(|k| (k as f32 * 38.9).round() as u32 + 1)
            .map(|p| if p % 2 == 0 { p - 1 } else { p + 1 })
            .filter(|&p| p != 895)
            .collect();
        assert_eq!(pulses.len(), 39, "the pulse at 895 is the lost one");
        let ps = run(&t, &pulses, 1540, |_| [1.0; CHANNELS]);
        let widest = ps.windows(2).map(|w| w[0].samples.abs_diff(w[1].samples));
        assert!(widest.max() >= Some(4));
        for p in &ps {
            // The double period, and the few after it (a jump back; a pulse a little under
            // half the double period after the last is a glitch, and the jump from the
            // merged period).
            let flagged = p.status.contains(Status::PERIOD_INVALID);
            match p.end_sample {
                935 => assert!(flagged && p.samples == 78, "{p:?}"),
                936..=1100 => {}
                _ => assert!(!flagged, "{p:?}"),
            }
        }
    }

    #[test]
    fn doubled_pulse_is_a_glitch_not_a_tooth() {
        let t = timing(SyncMode::PerTooth);
        let mut pulses: Vec<u32> = (0..8).map(|k| k * 100).collect();
        pulses.push(330);
        let ps = run(&t, &pulses, 750, |_| [1.0; CHANNELS]);
        assert_eq!(ps.len(), 7);
        assert!(ps[3].status.contains(Status::PERIOD_INVALID));
        assert_eq!(ps[3].samples, 100);
        assert!(ps[4].status.is_valid());
    }

    #[test]
    fn bad_samples_are_left_out_and_flagged() {
        let t = timing(SyncMode::PerTooth);
        let pulses: Vec<u32> = (0..5).map(|k| k * 100).collect();
        let ps = run(&t, &pulses, 450, |i| match i {
            150 => [f32::NAN, 0.0, 0.0, 0.0, 0.0],
            250 => [10.0, 0.0, 0.0, 0.0, 2.0],
            _ => [2.0, 0.0, 0.0, 0.0, 2.0],
        });
        assert!(ps[0].status.is_valid());
        assert_eq!(ps[1].status, Status::INPUT_FAULT);
        assert_eq!((ps[1].bad_samples, ps[1].mean[0]), (1, 2.0));
        assert_eq!(ps[2].status, Status::INPUT_FAULT, "clipped");
        assert!(ps[3].status.is_valid(), "recovers");
    }

    #[test]
    fn stopped_spindle_gives_one_no_sync_period_then_recovers() {
        let t = timing(SyncMode::PerTooth);
        let mut pulses: Vec<u32> = (0..4).map(|k| k * 100).collect();
        pulses.extend((0..5).map(|k| 2000 + k * 120));
        let ps = run(&t, &pulses, 2500, |_| [1.0; CHANNELS]);
        let no_sync: Vec<_> = ps
            .iter()
            .filter(|p| p.status.contains(Status::NO_SYNC))
            .collect();
        assert_eq!(no_sync.len(), 1);
        let after: Vec<_> = ps.iter().filter(|p| p.end_sample > 2000).collect();
        assert_eq!(after.len(), 4);
        assert!(after
            .iter()
            .all(|p| p.status.is_valid() && p.samples == 120));
    }

    #[test]
    fn one_pulse_per_revolution_splits_into_teeth() {
        let t = timing(SyncMode::PerRevolution);
        let pulses: Vec<u32> = (0..6).map(|k| k * 400).collect();
        let ps = run(&t, &pulses, 2001, |i| {
            [(i % 400 / 100) as f32, 0.0, 0.0, 0.0, 0.0]
        });
        // First revolution only measures the revolution; then 4 teeth per revolution.
        let after: Vec<_> = ps.iter().skip(1).collect();
        assert_eq!(after.len(), 16);
        for p in &after {
            assert_eq!(p.samples, 100);
            assert!(p.status.is_valid(), "{}", p.status);
            assert_eq!(
                p.mean[0], p.tooth as f32,
                "tooth {} gets its own quarter",
                p.tooth
            );
        }
    }

    #[test]
    fn nothing_before_the_first_pulse() {
        let t = timing(SyncMode::PerTooth);
        assert!(run(&t, &[], 5000, |_| [1.0; CHANNELS]).is_empty());
    }
}
