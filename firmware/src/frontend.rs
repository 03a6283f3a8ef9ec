//! The analog and encoder front end, in numbers: ADC codes to signal units, quadrature counts
//! to feed velocity.
//!
//! # Design
//!
//! Raw codes on the hot path, units once per sample: [`Scale`] folds the divider, the level
//! shift, the ADC reference and the drive's scaling of [`AnalogInput`] into one
//! `units = per_lsb * code + offset` (a multiply-add per channel and sample). A code at
//! either rail (0 or 4095) is a clipped input: it becomes `+inf`, which the core's tooth
//! averager leaves out of the sums and flags (`input_fault`), as it does with a NaN.
//!
//! The feed velocity comes from TIM4 in encoder mode, read once per block: [`FeedVelocity`]
//! unwraps the 16-bit counter (any travel below 32 768 counts per block, 20 m/s at
//! 1 000 counts/mm and 20 kS/s) and returns the travel over the last `window_blocks` blocks
//! divided by their duration, in mm/min. Every sample of a block gets the same velocity;
//! the core averages it per tooth anyway. A window of many blocks trades lag (about half
//! the window, 50 ms at 64 blocks of 1.6 ms) for resolution: the core flags a change of
//! the feed per tooth above 3 % (`feed_change`), and a single-block window would quantise
//! a 360 mm/min feed to 37.5 mm/min steps at 1 000 counts/mm.
//!
//! [`AnalogInput`] and the encoder's [`FeedEncoder`](estimator_core::FeedEncoder) are the
//! core's types (`MachineConfig::front_end`, what host-sim reads from the machine file's
//! `[front_end]` table); this module holds the arithmetic that uses them.

use crate::config::{ADC_MAX_CODE, ADC_VREF_V};
use estimator_core::AnalogInput;

/// A raw 12-bit ADC reading.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct AdcCode(pub u16);

/// `units = per_lsb * code + offset`, from an [`AnalogInput`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scale {
    /// Signal units per LSB.
    pub per_lsb: f32,
    /// Signal at code 0 (by extrapolation: code 0 itself is the rail).
    pub offset: f32,
}

impl Scale {
    /// Folds the chain of `input` (see [`AnalogInput`]).
    pub fn new(input: &AnalogInput) -> Scale {
        let volts_per_lsb = ADC_VREF_V / ADC_MAX_CODE as f32;
        // v_terminal = (v_pin - offset) / gain; units = upv * v_terminal + u0.
        let per_lsb = volts_per_lsb / input.front_end_gain * input.units_per_volt;
        let offset = input.units_at_zero_v
            - input.front_end_offset_v / input.front_end_gain * input.units_per_volt;
        Scale { per_lsb, offset }
    }

    /// The signal of one reading; `+inf` at either rail (clipped).
    #[inline]
    pub fn apply(&self, code: AdcCode) -> f32 {
        if code.0 == 0 || code.0 >= ADC_MAX_CODE {
            f32::INFINITY
        } else {
            self.per_lsb * code.0 as f32 + self.offset
        }
    }
}

/// Longest velocity window [blocks] (the ring is 4 bytes a block, in the sampling task):
/// the core's limit on `FeedEncoder::window_blocks`.
pub use estimator_core::frontend::MAX_WINDOW_BLOCKS;

/// Feed velocity from the encoder counter, one reading per block.
#[derive(Clone, Debug)]
pub struct FeedVelocity {
    /// Unwrapped positions at the ends of the last blocks, oldest overwritten first.
    ring: [i32; MAX_WINDOW_BLOCKS + 1],
    head: usize,
    filled: usize,
    window: usize,
    last_raw: u16,
    position: i32,
    /// mm/min per count per block.
    mm_min_per_count_block: f32,
}

impl FeedVelocity {
    /// For an encoder of `counts_per_mm`, a window of `window_blocks` (clamped to
    /// `1..=MAX_WINDOW_BLOCKS`), blocks of `block_s` seconds; `first_raw` is the counter
    /// at the start.
    pub fn new(counts_per_mm: f32, window_blocks: u16, block_s: f32, first_raw: u16) -> Self {
        let window = (window_blocks as usize).clamp(1, MAX_WINDOW_BLOCKS);
        FeedVelocity {
            ring: [0; MAX_WINDOW_BLOCKS + 1],
            head: 1,
            filled: 1,
            window,
            last_raw: first_raw,
            position: 0,
            mm_min_per_count_block: 60.0 / (counts_per_mm * block_s),
        }
    }

    /// Takes the counter at the end of a block; returns the velocity [mm/min] over the
    /// window (what is there of it during the first blocks; 0 before the first).
    pub fn push(&mut self, raw: u16) -> f32 {
        // Note: wrapping difference as i16: the counter runs both ways through 0 and 65535.
        self.position = self
            .position
            .wrapping_add(raw.wrapping_sub(self.last_raw) as i16 as i32);
        self.last_raw = raw;
        let cap = self.ring.len();
        if let Some(slot) = self.ring.get_mut(self.head) {
            *slot = self.position;
        }
        self.head = (self.head + 1) % cap;
        self.filled = (self.filled + 1).min(cap);
        let span = self.window.min(self.filled - 1);
        if span == 0 {
            return 0.0;
        }
        // The entry `span` blocks before the newest.
        let old = (self.head + cap - 1 - span) % cap;
        let travel = self
            .position
            .wrapping_sub(self.ring.get(old).copied().unwrap_or(0));
        travel as f32 * self.mm_min_per_count_block / span as f32
    }
}

/// The sampling task's arithmetic: a block of raw readings and an encoder reading into a
/// block of samples (one feed axis: the second feed channel and velocity are 0).
#[derive(Clone, Debug)]
pub struct Frontend {
    /// Feed input.
    pub feed: Scale,
    /// Spindle input.
    pub spindle: Scale,
    /// Feed velocity from the encoder.
    pub velocity: FeedVelocity,
}

impl Frontend {
    /// The samples of `codes` (`(feed, spindle)` per sample), first index `first`, with the
    /// encoder counter `encoder_raw` read at the block's end.
    pub fn block(
        &mut self,
        first: u64,
        codes: &[(AdcCode, AdcCode)],
        encoder_raw: u16,
    ) -> crate::stage::SampleBlock {
        let v = self.velocity.push(encoder_raw);
        let mut b = crate::stage::SampleBlock::empty(first);
        for (dst, (f, s)) in b.samples.iter_mut().zip(codes) {
            *dst = estimator_core::Sample {
                feed: [self.feed.apply(*f), 0.0],
                feed_velocity_mm_min: [v, 0.0],
                spindle: self.spindle.apply(*s),
                sync: false,
            };
            b.len += 1;
        }
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_maps_the_terminal_range_onto_the_codes() {
        // ±10 V at 3 A/V: 0 V at the terminal is 1.65 V at the pin, code 2047.5.
        let s = Scale::new(&AnalogInput::bipolar_10v(3.0));
        let at = |v_pin: f32| s.apply(AdcCode((v_pin / 3.3 * 4095.0).round() as u16));
        assert!(at(1.65).abs() < 3.0 * 10.0 / 2048.0, "{}", at(1.65));
        // +10 V at the terminal: 3.15 V at the pin, 30 A.
        assert!((at(3.15) - 30.0).abs() < 0.02, "{}", at(3.15));
        assert!((at(0.15) + 30.0).abs() < 0.02, "{}", at(0.15));
        assert_eq!(s.apply(AdcCode(0)), f32::INFINITY);
        assert_eq!(s.apply(AdcCode(4095)), f32::INFINITY);
        assert!(s.apply(AdcCode(1)).is_finite());
    }

    #[test]
    fn velocity_is_travel_over_the_window_through_counter_wraps() {
        // 1 000 counts/mm, blocks of 1.6 ms: 10 counts per block is 375 mm/min.
        let mut v = FeedVelocity::new(1000.0, 8, 0.0016, 65_530);
        let mut raw: u16 = 65_530;
        let mut out = 0.0;
        for _ in 0..20 {
            raw = raw.wrapping_add(10);
            out = v.push(raw);
        }
        assert!((out - 375.0).abs() < 1e-3, "{out}");
        // Reversal through zero: -10 counts per block.
        for _ in 0..20 {
            raw = raw.wrapping_sub(10);
            out = v.push(raw);
        }
        assert!((out + 375.0).abs() < 1e-3, "{out}");
    }

    #[test]
    fn a_block_of_codes_becomes_samples() {
        let mut fe = Frontend {
            feed: Scale::new(&AnalogInput::bipolar_10v(3.0)),
            spindle: Scale::new(&AnalogInput::bipolar_10v(5.0)),
            velocity: FeedVelocity::new(1000.0, 4, 0.0016, 0),
        };
        let codes = [(AdcCode(2048), AdcCode(3000)), (AdcCode(4095), AdcCode(1))];
        let b = fe.block(64, &codes, 10);
        assert_eq!((b.first, b.len), (64, 2));
        let s = b.samples();
        assert!(s[0].feed[0].abs() < 0.02 && s[0].spindle > 10.0);
        assert_eq!(s[1].feed[0], f32::INFINITY, "clipped");
        assert!((s[0].feed_velocity_mm_min[0] - 375.0).abs() < 1e-3);
        assert!(s.iter().all(|x| !x.sync && x.feed[1] == 0.0));
    }

    #[test]
    fn velocity_warms_up_with_what_it_has() {
        let mut v = FeedVelocity::new(1000.0, 64, 0.0016, 0);
        assert!((v.push(10) - 375.0).abs() < 1e-3);
        assert!((v.push(20) - 375.0).abs() < 1e-3);
        // A quantised feed averages out over the window: 10.5 counts per block.
        let mut v = FeedVelocity::new(1000.0, 64, 0.0016, 0);
        let mut out = 0.0;
        for k in 1..=200u32 {
            out = v.push((k * 21 / 2) as u16);
        }
        assert!((out - 393.75).abs() < 393.75 * 0.002, "{out}");
    }
}
