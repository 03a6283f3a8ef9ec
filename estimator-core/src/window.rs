//! Where each tooth period's averaging window begins: at the encoder pulse, delayed by a
//! share of the period learned so that the boundary falls where no flute cuts.
//!
//! # Design
//! The tooth-sync pulse sits at whatever angle to the flutes the tool was clamped at. With
//! the boundary inside a flute's cut (down milling with a helix: the upper edge still
//! cuts after the tip leaves), every tooth average holds the end of one flute's cut and
//! the start of the next one's: a flute that breaks changes two averages by part of its
//! loss each, and the chip it hands to the next flute partly lands in the same average.
//! The breakage signature shrinks, up to halving. Windows that begin where no flute cuts
//! keep each flute's cut in one average.
//!
//! The boundary is the pulse delayed by `phase` of a tooth period (a share in 1/65536;
//! the delay in samples from the last interval between pulses, divided by the teeth per
//! pulse). Every boundary, at `phase` 0 too, follows the pulses' tracked times rather
//! than each pulse: an alpha-beta tracker (gains [`TRACK_ALPHA`] and the interval's
//! weight) takes a quarter of each pulse's timing error, and the boundary comes
//! [`TRACK_DELAY_SAMPLES`] after the tracked time, so that a tracked time before its
//! pulse is still a boundary. An encoder pulse a sample early or late moves a boundary
//! inside a flute's cut and with it force from one tooth average to the next, a
//! breakage's pattern in small; tracked, the boundaries scatter by a fifth of the pulses'
//! mean square. At the pulse, where a cut's steep edge lay at the boundary, the jitter
//! alone made more of the noise of a tooth's change from one revolution to the next than
//! the sensors' (seed 4682 break 8, boundary at the pulse: its spread 15.5 N with the
//! jitter and no sensor noise, 8.5 N the other way round). The boundary falls between
//! samples: the tooth stage splits the sample it falls in between the two periods.
//! Rounded to whole samples, its error of up to half a sample moved force between the
//! averages as the jitter did (seed 46 break 45, no sensor noise: the spread 18.1 N
//! rounded, 5.1 N split). A speed ramp is followed about a sample behind (5 % of the
//! speed in 0.2 s at 140 samples a tooth: the interval's weight over the ramp's change
//! per pulse squared, 1.6 samples of error, three quarters of it kept). With
//! [`Window::align`] off the window begins at the pulse itself.
//!
//! Learning: per sample, the raw feed and spindle channels are summed into
//! [`PROFILE_BINS`] bins of the open tooth period. After [`REVIEW_REVS`] revolutions of
//! steady cutting, once a cut and again where the records' force has grown past
//! [`REGROWN`] of the profile's it was placed on (the monitor calls [`Window::review`]
//! with every record and its force), the monitor converts the bins to forces, and the boundary moves to the middle of the bin of least
//! resultant force, smoothed 1-2-1 with its neighbours (the middle of a quiet stretch, not
//! the noise's pick in it), if the current boundary's two bins are above that bin's by
//! more than [`MOVE_SHARE`] of the profile's mean (squared resultants; hysteresis: a flat profile,
//! flutes always engaged, never moves it). Any record that is not a steady cut restarts
//! the profile, but for a few transient records (up to [`PAUSE_REVS`]) once half of it
//! is learned, at the speed it began at, which it goes on through. The period in which
//! the new delay takes over has an odd length: longer (past one and a half periods it
//! counts as two teeth, as after a lost pulse) or, where
//! the new boundary comes less than half a period after the last, a glitch merged into
//! the next period; [`crate::tooth::Timing`] flags both. The period in which the boundary moved
//! is flagged [`Status::WINDOW_MOVED`]: it mixes two alignments, and the rules on the tooth
//! records forget their history there, as at a lost pulse; the hand-over stage re-cuts its
//! per-tooth profiles at the new boundary ([`crate::handover::Handover::realign`]), so that
//! the drop trip keeps a reference. The period after it is judged against the length before
//! the move, not against the odd one (`Timing::odd_period`).

use crate::fmath;
use crate::status::Status;
use crate::tooth::CHANNELS;

/// Bins of the in-period force profile.
pub const PROFILE_BINS: usize = 16;
/// Revolutions of steady cutting a profile is reviewed after.
///
/// Until the review the boundary is at the pulse, and a flute that breaks there can have
/// its loss and the next flute's gain in the same averages. At 8, in 19 of the 106 late
/// breaks at seeds 8193-8768 the window moved after the damage (the break came within 8
/// revolutions of the entry settling), up to 7.9 revolutions late (seed 8301 break 53);
/// at 4, 46 of the 106 came within a revolution and one was later. Four revolutions of
/// 2 to 4 flutes are 8 to 16 periods a bin: the least-force bin stands out of 3 % noise.
/// 2 caught 4 more of the 106 and was not taken further: a shorter profile is more of
/// an entry's last settling.
pub const REVIEW_REVS: u32 = 4;
/// A placed boundary is reviewed again where its profile's records' mean squared
/// resultant has grown past this multiple of the one it was placed on (about 10 % more
/// force).
///
/// An entry into a face can take seconds (the tool crosses its diameter at the feed), its
/// arc still widening when the first profile is reviewed: the quiet stretch chosen then
/// shrinks from one side, and the boundary ends up on the cut's steep edge, where the
/// pulses' jitter moves force between the windows (seed 38 taught 1: 3 flutes, up milling,
/// placed at 190 N, the cut grown to 280 N over the next 2 s around a boundary then at 360
/// N of the profile's 650 N; a hand-over raised in the jitter). A broken flute hands its
/// chip to the next one and leaves the revolution's force as it was: it never asks a
/// review.
pub const REGROWN: f32 = 1.2;
/// Revolutions of transient records a profile goes on through.
pub const PAUSE_REVS: u32 = 2;
/// The boundary moves when its squared resultant exceeds the least bin's by this share of
/// the profile's mean square.
pub const MOVE_SHARE: f32 = 0.3;
/// Weight of a new interval between pulses in their running mean.
const LEN_WEIGHT: f32 = 0.0625;
/// Share of a pulse's timing error (against the time predicted from the last pulse's
/// tracked time and the interval) taken into its tracked time.
const TRACK_ALPHA: f32 = 0.25;
/// Every aligned boundary comes this many samples after the pulses' tracked time, so that
/// a tracked time before its pulse can still be one (the tracker keeps three quarters of
/// a pulse's error, about a sample at the encoder's jitter). Each record closes that much
/// later: kept to one sample, a tenth of a millisecond at 10 kHz.
pub const TRACK_DELAY_SAMPLES: f32 = 1.0;

/// Records that end a profile: no cut, bad data, or a cut that is changing.
const NOT_STEADY: Status = Status(
    Status::NOT_CUTTING.0
        | Status::NON_FINITE.0
        | Status::PERIOD_INVALID.0
        | Status::NO_SYNC.0
        | Status::INPUT_FAULT.0
        | Status::TRANSIENT.0
        | Status::FEED_CHANGE.0
        | Status::WINDOW_MOVED.0,
);

/// Bins per sample of a period binned as `len` samples (16.16 fixed point): a sample `p`
/// of the period falls in bin `(p step) >> 16`, the last bin taking any excess.
#[inline(always)]
pub fn bin_step(len: u32) -> u32 {
    ((PROFILE_BINS as u32) << 16) / len.max(1)
}

/// The window stage, derived once from the monitor's configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window {
    /// Learn the boundary (off: the window begins at the pulse).
    pub align: bool,
    /// Teeth between two pulses (1 per tooth, `N` per revolution).
    pub teeth_per_pulse: u8,
    /// Teeth per revolution.
    pub teeth: u8,
}

/// Running state.
#[derive(Clone, Copy, Debug, Default)]
pub struct WindowState {
    /// Boundary delay, share of a tooth period in 1/65536.
    phase: u16,
    /// Moves so far (wrapping), and the move each pending pulse was delayed under.
    epoch: u8,
    /// Delayed pulses to come: samples left (0: slot free), epoch, the boundary's share
    /// of the sample it falls in that comes before it.
    pending: [(u32, u8, f32); 2],
    /// Epoch of the last delayed pulse fired.
    fired_epoch: u8,
    /// The boundary moved: flag the next period that closes.
    moved: bool,
    /// Samples since the last pulse, and the interval between pulses, averaged.
    since_pulse: u32,
    pulse_len: f32,
    /// The tracked time of the last pulse less its time [samples].
    offset: f32,
    /// Position in the open period [samples], and bins per sample (16.16 fixed point).
    pos: u32,
    bin_step: u32,
    /// Per bin: sums of raw feed X, feed Y, spindle, and the samples summed.
    prof: [[f32; 3]; PROFILE_BINS],
    prof_n: [u32; PROFILE_BINS],
    /// Steady periods in the profile.
    periods: u32,
    /// The last record was a steady cut: samples go into the profile.
    learning: bool,
    /// The boundary was reviewed in this cut, on records of this mean squared resultant
    /// [N^2] (again only once the cut has grown past [`REGROWN`] of it).
    placed: bool,
    placed_force2: f32,
    /// Sum of the profile's records' squared resultants [N^2].
    force2_sum: f32,
    /// Transient records the profile went on through.
    transients: u16,
    /// The interval between pulses when the profile started.
    prof_len: f32,
}

impl WindowState {
    /// Boundary delay, share of a tooth period.
    pub fn phase(&self) -> f32 {
        self.phase as f32 / 65536.0
    }
}

impl Window {
    /// The sync line as the tooth stage sees it: `sync` delayed by the boundary's phase.
    /// `Some(w)` where a boundary falls in this sample, `w` the share of the sample before
    /// it (the sample at index `j` stands for the times `j - 1/2` to `j + 1/2`).
    #[inline(always)]
    pub fn delay(&self, st: &mut WindowState, sync: bool) -> Option<f32> {
        let mut fire = None;
        if st.pending[0].0 | st.pending[1].0 != 0 {
            for (left, epoch, w) in st.pending.iter_mut() {
                if *left != 0 {
                    *left -= 1;
                    if *left == 0 {
                        fire = Some(*w);
                        if *epoch != st.fired_epoch {
                            st.fired_epoch = *epoch;
                            st.moved = true;
                        }
                    }
                }
            }
        }
        st.since_pulse = st.since_pulse.saturating_add(1);
        if sync {
            // The delay from the interval averaged over about 16 pulses: from the last
            // interval alone, a pulse that comes late (encoder jitter) would be delayed
            // the more for it, doubling the jitter of the boundaries. A jump of more than a
            // quarter (a lost pulse, a new cut) starts the average again.
            let len = st.since_pulse as f32;
            st.since_pulse = 0;
            if libm::fabsf(len - st.pulse_len) > 0.25 * st.pulse_len {
                st.pulse_len = len;
                st.offset = 0.0;
            } else {
                // An alpha-beta tracker of the pulse times: `e` is this pulse against the
                // time predicted from the last one's tracked time and the interval.
                let e = len - st.pulse_len - st.offset;
                st.pulse_len += e * LEN_WEIGHT;
                st.offset = -(1.0 - TRACK_ALPHA) * e;
            }
            let tooth_len = self.tracked_len(st);
            // An aligned boundary follows the pulses' tracked times, to a fraction of a
            // sample: the sample it falls in is split between the two periods. `as u32`
            // saturates (and takes NaN and a negative delay to 0).
            let (d, w) = if self.align {
                let t = st.phase as f32 * (1.0 / 65536.0) * tooth_len
                    + st.offset
                    + TRACK_DELAY_SAMPLES
                    + 0.5;
                let d = t as u32;
                (d, fmath::min(fmath::max(t - d as f32, 0.0), 1.0))
            } else {
                (0, 0.0)
            };
            if d == 0 {
                fire = Some(w);
                if st.epoch != st.fired_epoch {
                    st.fired_epoch = st.epoch;
                    st.moved = true;
                }
            } else if let Some(slot) = st.pending.iter_mut().find(|p| p.0 == 0) {
                *slot = (d, st.epoch, w);
            } else {
                // Pulses closer than the delay twice over: a burst of glitches. This one
                // goes through undelayed; the tooth stage flags it as a glitch.
                fire = Some(0.0);
            }
        }
        fire
    }

    /// Adds a sample to the profile, after the tooth stage has seen it (`closed`: the
    /// sample opened a new period, of which `last_len` is the previous one's length).
    /// Returns the sample's bin in the open period (bins of the previous period's length;
    /// the last bin takes a longer period's excess).
    #[inline(always)]
    pub fn profile(&self, st: &mut WindowState, x: &[f32; CHANNELS], closed: Option<u32>) -> usize {
        if let Some(len) = closed {
            st.pos = 0;
            self.rebin(st, len);
        }
        let pos = st.pos;
        st.pos = pos.saturating_add(1);
        let bin = (((pos as u64 * st.bin_step as u64) >> 16) as usize).min(PROFILE_BINS - 1);
        if !st.learning {
            return bin;
        }
        let v = [x[0], x[1], x[4]];
        if (v[0] + v[1] + v[2]).is_finite() {
            if let (Some(p), Some(n)) = (st.prof.get_mut(bin), st.prof_n.get_mut(bin)) {
                p[0] += v[0];
                p[1] += v[1];
                p[2] += v[2];
                *n += 1;
            }
        }
        bin
    }

    /// Bins of the open period from a period of `len` samples.
    #[inline(always)]
    pub fn rebin(&self, st: &mut WindowState, len: u32) {
        st.bin_step = bin_step(len);
    }

    /// How far the boundary that opened the open period lies from the pulses' tracked
    /// times [samples]: unaligned, at the pulse, its jitter, which the tracker takes only a
    /// quarter of; an aligned boundary follows the tracked times (0).
    #[inline(always)]
    pub fn boundary_off(&self, st: &WindowState) -> f32 {
        if self.align {
            0.0
        } else {
            -st.offset
        }
    }

    /// How far the pulses' tracked times, which an aligned boundary follows, lag the last
    /// pulse [samples]: the encoder's jitter, and after a speed ramp the tracker's lag
    /// (the drop trip allows for its change, [`crate::handover::Handover::period_start`]).
    /// At the pulse, 0: the boundary is the pulse.
    #[inline(always)]
    pub fn boundary_lag(&self, st: &WindowState) -> f32 {
        if self.align {
            st.offset
        } else {
            0.0
        }
    }

    /// The tooth period the pulses' tracked interval gives [samples] (0 before a pulse).
    #[inline(always)]
    pub fn tracked_len(&self, st: &WindowState) -> f32 {
        st.pulse_len / self.teeth_per_pulse.max(1) as f32
    }

    /// Whether the period closing now is the first under a moved boundary (then cleared).
    #[inline(always)]
    pub fn take_moved(&self, st: &mut WindowState) -> bool {
        core::mem::take(&mut st.moved)
    }

    /// Once per record, with its status: counts steady periods and, after the first
    /// [`REVIEW_REVS`] revolutions of them in a cut (and of each such profile once the cut
    /// has grown, [`REGROWN`]), moves the boundary to the least-force bin of the profile.
    /// `force2_n2`: the record's squared resultant force [N^2]; `force2` converts a bin's
    /// raw means `[feed X, feed Y, spindle]` to the squared resultant force. Returns
    /// whether the boundary moved.
    ///
    /// Out of line: it runs once a tooth, and its profile conversion is long.
    #[inline(never)]
    pub fn review(
        &self,
        st: &mut WindowState,
        status: Status,
        force2_n2: f32,
        force2: impl Fn([f32; 3]) -> f32,
    ) -> bool {
        if !self.align {
            return false;
        }
        if status.contains(Status::NOT_CUTTING) {
            st.placed = false;
        }
        if status.intersects(Status(NOT_STEADY.0 & !Status::TRANSIENT.0)) {
            st.learning = false;
            return false;
        }
        let teeth = self.teeth.max(1) as u32;
        if status.contains(Status::TRANSIENT) {
            // A flute breaking makes a few transient records. Restarted there, the profile
            // of a cut whose window is still at the pulse waits `REVIEW_REVS` more, and
            // where that boundary halves each flute's cut between two windows (2 flutes:
            // the loss and the next flute's gain in one average) the break is seen only
            // after the move (seed 1199 break 111: 15.85 revolutions late; 1623 break 15,
            // 12.74). A profile half learned goes on through up to PAUSE_REVS of them, not
            // counting them, at the speed it began at (a speed ramp moves the cuts in the
            // period); an entry's or exit's run of them restarts it. (Through any number
            // from the profile's start, an entry's shape placed the boundary for the
            // steady cut after it: seed 1509 break 111 never caught.)
            if st.learning
                && st.periods >= REVIEW_REVS * teeth / 2
                && (st.transients as u32) < PAUSE_REVS * teeth
                && libm::fabsf(st.pulse_len - st.prof_len) <= 0.01 * st.prof_len
            {
                st.transients += 1;
            } else {
                st.learning = false;
            }
            return false;
        }
        if !st.learning {
            // The profile starts with the period that opens now.
            st.learning = true;
            self.restart(st);
            return false;
        }
        st.periods += 1;
        st.force2_sum += force2_n2;
        if st.periods < REVIEW_REVS * teeth {
            return false;
        }
        // One review a cut, and again only where the cut has grown (`REGROWN`): a
        // boundary that passes stays. Reviewed on every profile, one near the move's
        // margin would tip over on any change of a few per cent (a flute breaking inside
        // its period), and the move would make the detectors forget their history just
        // when it is needed. The growth is the records' (converted already), so that a
        // placed boundary's profile is converted only where it grew: 16 bins through the
        // drive models are about 6 000 instructions. (Not `<=`: a NaN mean reviews
        // nothing.)
        let grown = st.force2_sum / st.periods as f32;
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if st.placed && !(grown > REGROWN * st.placed_force2) {
            self.restart(st);
            return false;
        }
        st.placed = true;
        st.placed_force2 = grown;
        let mut r2 = [0.0f32; PROFILE_BINS];
        let mut mean = 0.0f32;
        for ((r, p), &n) in r2.iter_mut().zip(&st.prof).zip(&st.prof_n) {
            let inv = 1.0 / n.max(1) as f32;
            *r = force2([p[0] * inv, p[1] * inv, p[2] * inv]);
            mean += *r;
        }
        self.restart(st);
        let mean = mean / PROFILE_BINS as f32;
        // The bin of least force with half its two neighbours' (a 1-2-1 smoothing): across
        // a stretch of bins at the noise, the least bin alone is the noise's pick, and may
        // lie next to a cut's edge, where the drives' lag and the pulses' jitter move force
        // across the boundary (seed 8697 break 104: idle bins 7-15, the least bin 14 after
        // 4 revolutions, 13 after 8). With its neighbours, nearer the middle of the quiet
        // stretch; a single quiet bin is still its own pick.
        let at = |k: usize| r2.get(k % PROFILE_BINS).copied().unwrap_or(0.0);
        let (mut j, mut least3) = (0usize, f32::INFINITY);
        // (From `PROFILE_BINS` on, so that the bin before the first is `k - 1`.)
        for k in PROFILE_BINS..2 * PROFILE_BINS {
            let r = at(k - 1) + 2.0 * at(k) + at(k + 1);
            if r < least3 {
                (j, least3) = (k - PROFILE_BINS, r);
            }
        }
        let least = at(j);
        let boundary = 0.5 * (at(0) + at(PROFILE_BINS - 1));
        // Not `<=`: a NaN profile (absurd conversion) moves nothing.
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(boundary - least > MOVE_SHARE * mean) {
            return false;
        }
        // The middle of bin `j`, as a share of the period in 1/65536.
        let shift = ((2 * j as u32 + 1) << 16) / (2 * PROFILE_BINS as u32);
        st.phase = st.phase.wrapping_add(shift as u16);
        st.epoch = st.epoch.wrapping_add(1);
        true
    }

    fn restart(&self, st: &mut WindowState) {
        st.prof = [[0.0; 3]; PROFILE_BINS];
        st.prof_n = [0; PROFILE_BINS];
        st.periods = 0;
        st.force2_sum = 0.0;
        st.transients = 0;
        st.prof_len = st.pulse_len;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::vec::Vec;

    fn window(teeth_per_pulse: u8) -> Window {
        Window {
            align: true,
            teeth_per_pulse,
            teeth: 4,
        }
    }

    /// Samples at which `delay` fires, for pulses at `pulses` (sorted) over `len` samples.
    fn fired(w: &Window, st: &mut WindowState, pulses: &[usize], len: usize) -> Vec<usize> {
        (0..len)
            .filter(|i| w.delay(st, pulses.contains(i)).is_some())
            .collect()
    }

    /// Unaligned, the window begins at each pulse, sample for sample.
    #[test]
    fn an_unaligned_window_passes_the_pulses_through() {
        let w = Window {
            align: false,
            ..window(1)
        };
        let mut st = WindowState::default();
        let pulses: Vec<usize> = (0..50).map(|k| 13 + k * 97 + (k * 7) % 3).collect();
        assert_eq!(fired(&w, &mut st, &pulses, 5000), pulses);
        assert!(!w.take_moved(&mut st));
    }

    /// The mean square of `got`'s boundaries about the grid `13 + 79 k + delay`, past the
    /// first 20 (the interval's average settles), and each within 2 samples of it.
    fn scatter_about_grid(got: &[usize], delay: i64) -> f64 {
        let dev: Vec<i64> = got
            .iter()
            .map(|&b| b as i64 - delay - 13)
            .map(|d| d - (d as f64 / 79.0).round() as i64 * 79)
            .skip(20)
            .collect();
        assert!(dev.len() > 350, "{}", dev.len());
        assert!(dev.iter().all(|d| d.abs() <= 2), "{dev:?}");
        dev.iter().map(|d| (d * d) as f64).sum::<f64>() / dev.len() as f64
    }

    /// Pulses off a grid of `period` samples by -1, 0 or +1 sample (a fixed pseudo-random
    /// pattern), each rounded to its sample, and their mean square off the grid
    /// [samples^2].
    fn jittered(period: f64) -> (Vec<usize>, f64) {
        let mut x = 12345u32;
        let mut jitter = || {
            x = x.wrapping_mul(1_103_515_245).wrapping_add(12_345);
            ((x >> 16) % 3) as f64 - 1.0
        };
        let pulses: Vec<usize> = (0..400)
            .map(|k| (13.0 + k as f64 * period + jitter()).round() as usize)
            .collect();
        let pulse_ms = pulses
            .iter()
            .enumerate()
            .map(|(k, &p)| (p as f64 - 13.0 - k as f64 * period).powi(2))
            .sum::<f64>()
            / pulses.len() as f64;
        (pulses, pulse_ms)
    }

    /// At phase 0 too the boundaries follow the pulses' tracked times, `TRACK_DELAY_SAMPLES`
    /// after them: on a regular grid exactly that much after each pulse; under the
    /// encoder's jitter they scatter by less than half the pulses' mean square.
    #[test]
    fn phase_zero_follows_the_tracked_pulse_times() {
        let w = window(1);
        let delay = (TRACK_DELAY_SAMPLES + 0.5) as usize;
        let mut st = WindowState::default();
        let pulses: Vec<usize> = (0..50).map(|k| 13 + k * 97).collect();
        let got = fired(&w, &mut st, &pulses, 5000);
        let expect: Vec<usize> = pulses.iter().map(|p| p + delay).collect();
        assert_eq!(got, expect);
        assert!(!w.take_moved(&mut st));

        let mut st = WindowState::default();
        let (pulses, pulse_ms) = jittered(79.0);
        let got = fired(&w, &mut st, &pulses, 400 * 79);
        let ms = scatter_about_grid(&got, delay as i64);
        assert!(
            ms < 0.5 * pulse_ms,
            "boundaries {ms} against pulses {pulse_ms} (samples^2)"
        );
    }

    /// On a grid of pulses a fraction of a sample long (79.37 samples, each pulse rounded to
    /// its sample and jittered by a sample either way), the boundaries fall between samples
    /// on the tracked times: as times (`j - 1/2 + w`) they scatter about the grid, delayed by
    /// `TRACK_DELAY_SAMPLES`, by less than the same boundaries rounded to whole samples do:
    /// rounding adds a uniform error of a sample's width, 1/12 samples^2 (0.158 against
    /// 0.234 here).
    #[test]
    fn boundaries_fall_between_samples_on_the_tracked_times() {
        let w = window(1);
        let mut st = WindowState::default();
        let period = 79.37;
        let (pulses, _) = jittered(period);
        let times: Vec<(usize, f32)> = (0..400 * 80)
            .filter_map(|i| w.delay(&mut st, pulses.contains(&i)).map(|w| (i, w)))
            .collect();
        // Mean square about the grid, past the first 20 (the interval's average settles).
        let scatter = |t: &dyn Fn(&(usize, f32)) -> f64| {
            let dev: Vec<f64> = times
                .iter()
                .map(|b| t(b) - 13.0 - f64::from(TRACK_DELAY_SAMPLES))
                .map(|d| d - (d / period).round() * period)
                .skip(20)
                .collect();
            assert!(dev.len() > 350, "{}", dev.len());
            dev.iter().map(|d| d * d).sum::<f64>() / dev.len() as f64
        };
        let split = scatter(&|&(j, w)| j as f64 - 0.5 + f64::from(w));
        let whole = scatter(&|&(j, _)| j as f64);
        assert!(whole - split > 0.06, "{split} against {whole} samples^2");
    }

    /// Unaligned, the boundary at the pulse lies off the pulses' tracked times by the part
    /// of a pulse's lateness the tracker does not take (`1 - TRACK_ALPHA` of it, once the
    /// interval has settled); an aligned boundary follows the tracked times.
    #[test]
    fn the_boundary_at_the_pulse_reports_how_far_it_lies_off_the_track() {
        for (align, late) in [(false, 3usize), (false, 0), (true, 3)] {
            let w = Window { align, ..window(1) };
            let mut st = WindowState::default();
            let mut pulses: Vec<usize> = (0..60).map(|k| 10 + k * 90).collect();
            if let Some(p) = pulses.last_mut() {
                *p += late;
            }
            fired(&w, &mut st, &pulses, 60 * 90 + 10);
            let want = if align {
                0.0
            } else {
                late as f32 * (1.0 - TRACK_ALPHA)
            };
            assert!(
                (w.boundary_off(&st) - want).abs() < 1e-3,
                "{align} {late}: {}",
                w.boundary_off(&st)
            );
        }
    }

    /// The record at which `profile` (squared resultants per bin) moves the boundary, and
    /// the phase it moves to, under `status(record)`, the pulses' interval `len(record)`.
    fn moves_with(
        profile: [f32; PROFILE_BINS],
        status: impl Fn(u32) -> Status,
        len: impl Fn(u32) -> f32,
    ) -> Option<(u32, u16)> {
        let w = window(1);
        let mut st = WindowState::default();
        let r = (0..400).find(|&r| {
            st.pulse_len = len(r);
            set_profile(&mut st, &profile);
            w.review(&mut st, status(r), 1.0, |[_, _, c]| c)
        })?;
        Some((r, st.phase))
    }

    /// The profile's bins as one period of `profile` on the spindle channel (the review's
    /// `force2` here takes that channel as the force).
    fn set_profile(st: &mut WindowState, profile: &[f32; PROFILE_BINS]) {
        for ((p, n), &c) in st.prof.iter_mut().zip(&mut st.prof_n).zip(profile) {
            *p = [0.0, 0.0, c];
            *n = 1;
        }
    }

    /// ... a profile with one quiet bin (5 of 16): the record it moves at.
    fn moves_at(status: impl Fn(u32) -> Status, len: impl Fn(u32) -> f32) -> Option<u32> {
        let profile = core::array::from_fn(|k| if k == 5 { 0.0 } else { 1.0 });
        moves_with(profile, status, len).map(|(r, _)| r)
    }

    /// A quiet stretch of bins at the noise (7-15 here, the cut in 0-6): the boundary goes
    /// to its middle, not to its least bin where that lies next to a cut's edge (bin 14,
    /// next to the cut's start); a lone quiet bin is still picked (`moves_at`).
    #[test]
    fn the_boundary_goes_to_the_middle_of_a_quiet_stretch() {
        let quiet = [0.05, 0.04, 0.03, 0.04, 0.05, 0.06, 0.04, 0.02, 0.3];
        let profile = core::array::from_fn(|k| if k < 7 { 1.0 } else { quiet[k - 7] });
        let (_, phase) = moves_with(profile, |_| Status::VALID, |_| 100.0).expect("moves");
        // The middle of bin 9 (0.04, between 0.03 and 0.05).
        assert_eq!(
            phase,
            (((2 * 9 + 1) << 16) / (2 * PROFILE_BINS as u32)) as u16
        );
    }

    /// A placed boundary is reviewed again only once the cut has grown (`REGROWN`), on
    /// the records' force: a profile whose shape changed at the same force (a broken
    /// flute's chip taken by the next, or any redistribution) leaves it, however loaded
    /// its bins have become; the same shape with 30 % more squared force (an entry's arc
    /// still widening over the boundary) moves it to the new quiet bin. The profile's own
    /// level does not ask a review.
    #[test]
    fn a_placed_boundary_is_reviewed_again_only_where_the_cut_grew() {
        let w = window(1);
        let mut st = WindowState {
            pulse_len: 100.0,
            ..Default::default()
        };
        let quiet_at = |k: usize, scale: f32| -> [f32; PROFILE_BINS] {
            core::array::from_fn(|b| if b == k { 0.0 } else { scale })
        };
        // The records until the boundary moves on `profile` (relative to the boundary),
        // each record's squared force `force2`, at most `records`.
        let moved_after =
            |st: &mut WindowState, profile: [f32; PROFILE_BINS], force2: f32, records: u32| {
                (1..=records).find(|_| {
                    set_profile(st, &profile);
                    w.review(st, Status::VALID, force2, |[_, _, c]| c)
                })
            };
        let rev = REVIEW_REVS * w.teeth as u32;
        // Placed (the first record starts the profile).
        assert_eq!(
            moved_after(&mut st, quiet_at(5, 1.0), 100.0, 10 * rev),
            Some(rev + 1)
        );
        // The quiet bin now at 10, the boundary's bins loaded, the force as it was; nor
        // does the profile's level alone ask a review.
        assert_eq!(
            moved_after(&mut st, quiet_at(10, 1.0), 100.0, 10 * rev),
            None
        );
        assert_eq!(
            moved_after(&mut st, quiet_at(10, 1.3), 110.0, 10 * rev),
            None
        );
        // The records grown by 30 %: reviewed at the end of the profile under way.
        assert_eq!(
            moved_after(&mut st, quiet_at(10, 1.3), 130.0, 10 * rev),
            Some(rev)
        );
        let bins = |k: u32| ((2 * k + 1) << 16) / (2 * PROFILE_BINS as u32);
        assert_eq!(st.phase, (bins(5) + bins(10)) as u16);
        // Grown 10 % more since (under `REGROWN`): not reviewed.
        assert_eq!(
            moved_after(&mut st, quiet_at(3, 1.43), 143.0, 10 * rev),
            None
        );
        // Grown past it: reviewed, on the profile of the records since the last review.
        assert_eq!(
            moved_after(&mut st, quiet_at(3, 1.6), 160.0, 10 * rev),
            Some(rev)
        );
        assert_eq!(st.phase, (bins(5) + bins(10) + bins(3)) as u16);
    }

    /// Record 0 starts the profile; it moves on its `REVIEW_REVS`-th revolution of steady
    /// records. Transient records once half of it is learned are passed over, up to
    /// `PAUSE_REVS` of them; before that, past that, or at another speed they restart it
    /// (from the next steady record).
    #[test]
    fn a_profile_half_learned_goes_on_through_a_few_transients() {
        let n = window(1).teeth as u32;
        let (whole, half, pause) = (REVIEW_REVS * n, REVIEW_REVS * n / 2, PAUSE_REVS * n);
        let steady = |_| 100.0;
        let transient_at = |from: u32, count: u32| {
            move |r: u32| {
                if (from..from + count).contains(&r) {
                    Status::TRANSIENT
                } else {
                    Status::VALID
                }
            }
        };
        assert_eq!(moves_at(|_| Status::VALID, steady), Some(whole));
        // Half learned: passed over.
        assert_eq!(moves_at(transient_at(half + 1, 1), steady), Some(whole + 1));
        assert_eq!(
            moves_at(transient_at(half + 1, pause), steady),
            Some(whole + pause)
        );
        // Before half: restarted; the next record starts the profile again.
        let at = half - 1;
        assert_eq!(moves_at(transient_at(at, 1), steady), Some(at + 1 + whole));
        // One more than the pause: restarted at the last.
        let last = half + 1 + pause;
        assert_eq!(
            moves_at(transient_at(half + 1, pause + 1), steady),
            Some(last + 1 + whole)
        );
        // At another speed: restarted.
        let faster = |r: u32| if r > half { 98.0 } else { 100.0 };
        assert_eq!(
            moves_at(transient_at(half + 1, 1), faster),
            Some(half + 2 + whole)
        );
        // Any other break in the cut restarts it as before.
        let feed = |r: u32| {
            if r == half + 1 {
                Status::FEED_CHANGE
            } else {
                Status::VALID
            }
        };
        assert_eq!(moves_at(feed, steady), Some(half + 2 + whole));
    }

    #[test]
    fn a_phase_delays_each_pulse_by_its_share_of_the_interval() {
        let w = window(1);
        let mut st = WindowState {
            phase: 0xA800, // 0.65625
            ..WindowState::default()
        };
        // Regular pulses: each boundary is round(0.65625 * 79 + TRACK_DELAY_SAMPLES)
        // samples after its pulse (the first pulse has no interval before it).
        let pulses: Vec<usize> = (0..50).map(|k| 13 + k * 79).collect();
        let got = fired(&w, &mut st, &pulses, 5000);
        let delay = (0.65625 * 79.0 + TRACK_DELAY_SAMPLES + 0.5) as usize;
        let expect: Vec<usize> = pulses[1..].iter().map(|p| p + delay).collect();
        assert_eq!(got[1..], expect[..]);
    }

    /// Pulses off a 79-sample grid by -1, 0 or +1 sample: the placed boundaries scatter
    /// about their own grid (the pulse grid plus the delay) by less than half the pulses'
    /// mean square, rounding to whole samples included.
    #[test]
    fn a_placed_boundary_follows_the_tracked_pulse_times() {
        let w = window(1);
        let mut st = WindowState {
            phase: 0xA800,
            ..WindowState::default()
        };
        let (pulses, pulse_ms) = jittered(79.0);
        let got = fired(&w, &mut st, &pulses, 400 * 79);
        let delay = (0.65625 * 79.0 + TRACK_DELAY_SAMPLES + 0.5) as i64;
        let ms = scatter_about_grid(&got, delay);
        assert!(
            ms < 0.5 * pulse_ms,
            "boundaries {ms} against pulses {pulse_ms} (samples^2)"
        );
    }

    #[test]
    fn encoder_jitter_is_not_doubled_by_the_delay() {
        let w = window(1);
        let mut st = WindowState {
            phase: 0xA800,
            ..WindowState::default()
        };
        // Pulses +-2 samples off a 79-sample grid: intervals 75..=83.
        let jitter = [0i64, 2, -2, 1, -1, 2, 0, -2, 1];
        let pulses: Vec<usize> = (0..60)
            .map(|k| (13 + k as i64 * 79 + jitter[k % jitter.len()]) as usize)
            .collect();
        let got = fired(&w, &mut st, &pulses, 5000);
        let intervals =
            |v: &[usize]| -> Vec<i64> { v.windows(2).map(|p| p[1] as i64 - p[0] as i64).collect() };
        let raw = intervals(&pulses);
        let out = intervals(&got[10..]);
        let spread = |v: &[i64]| v.iter().max().unwrap() - v.iter().min().unwrap();
        // One sample more than the pulses' own spread at most (the delay's rounding).
        assert!(spread(&out) <= spread(&raw) + 1, "{out:?} against {raw:?}");
    }
}
