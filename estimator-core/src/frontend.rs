//! The board's front end in configuration: how the analog inputs scale to signal units and
//! how the feed encoder scales to travel.
//!
//! These are part of [`crate::MachineConfig`] so that a machine is one type everywhere:
//! host-sim reads them from the machine file's `[front_end]` table (and ignores them in
//! replay: a trace is already in signal units), the firmware turns them into its
//! code-to-units scaling at start-up. The arithmetic that uses them lives in the firmware
//! (`firmware/src/frontend.rs`); here are the numbers and their checks.

use crate::ConfigError;

/// Longest feed-velocity window, in blocks ([`FeedEncoder::window_blocks`]); the firmware's
/// ring holds this many blocks.
pub const MAX_WINDOW_BLOCKS: usize = 64;

/// One analog input: check terminal -> front end -> ADC pin.
///
/// `v_pin = front_end_gain * v_terminal + front_end_offset_v`, and the drive's check
/// terminal reads `signal = units_per_volt * v_terminal + units_at_zero_v` (amperes for a
/// current input, % for a spindle load).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AnalogInput {
    /// Volts at the ADC pin per volt at the check terminal (the divider), > 0.
    pub front_end_gain: f32,
    /// Volts at the ADC pin for 0 V at the terminal (the level shift), >= 0 (the firmware
    /// also requires it within the ADC reference).
    pub front_end_offset_v: f32,
    /// Signal units per volt at the terminal (the drive's scaling, e.g. 3 A/V for a drive
    /// whose check terminal gives 10 V at 30 A), not 0.
    pub units_per_volt: f32,
    /// Signal at 0 V at the terminal (the drive's offset).
    pub units_at_zero_v: f32,
}

impl AnalogInput {
    /// A bipolar ±10 V check terminal on the reference front end (gain 0.15, offset 1.65 V:
    /// -10 V -> 0.15 V, +10 V -> 3.15 V at the pin) at `units_per_volt`.
    pub const fn bipolar_10v(units_per_volt: f32) -> Self {
        AnalogInput {
            front_end_gain: 0.15,
            front_end_offset_v: 1.65,
            units_per_volt,
            units_at_zero_v: 0.0,
        }
    }

    /// Checks the input; `names` are the parameter names of its four fields, in order.
    fn validate_as(&self, names: [&'static str; 4]) -> Result<(), ConfigError> {
        let [gain, offset, upv, u0] = names;
        let fields = [
            (self.front_end_gain, gain),
            (self.front_end_offset_v, offset),
            (self.units_per_volt, upv),
            (self.units_at_zero_v, u0),
        ];
        for (v, name) in fields {
            if !v.is_finite() {
                return Err(ConfigError::NonFinite(name));
            }
        }
        if self.front_end_gain <= 0.0 {
            return Err(ConfigError::OutOfRange(gain));
        }
        if self.front_end_offset_v < 0.0 {
            return Err(ConfigError::OutOfRange(offset));
        }
        if self.units_per_volt == 0.0 {
            return Err(ConfigError::OutOfRange(upv));
        }
        Ok(())
    }
}

/// The feed-axis quadrature encoder.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FeedEncoder {
    /// Counts per mm of axis travel (x4 decoding included), signed: negative flips the
    /// direction; not 0.
    pub counts_per_mm: f32,
    /// Velocity window in blocks, `1..=MAX_WINDOW_BLOCKS`: the velocity is the travel over
    /// the last `window_blocks` blocks. 1 count over 64 blocks of 1.6 ms is 0.6 mm/min at
    /// 1 000 counts/mm.
    pub window_blocks: u16,
}

impl Default for FeedEncoder {
    /// 1 000 counts/mm, a window of 64 blocks.
    fn default() -> Self {
        FeedEncoder {
            counts_per_mm: 1000.0,
            window_blocks: 64,
        }
    }
}

impl FeedEncoder {
    /// Checks the encoder; errors name `front_end.feed_encoder.*`.
    pub fn validate(&self) -> Result<(), ConfigError> {
        if !self.counts_per_mm.is_finite() {
            return Err(ConfigError::NonFinite(
                "front_end.feed_encoder.counts_per_mm",
            ));
        }
        if self.counts_per_mm == 0.0 {
            return Err(ConfigError::OutOfRange(
                "front_end.feed_encoder.counts_per_mm",
            ));
        }
        if self.window_blocks == 0 || usize::from(self.window_blocks) > MAX_WINDOW_BLOCKS {
            return Err(ConfigError::OutOfRange(
                "front_end.feed_encoder.window_blocks",
            ));
        }
        Ok(())
    }
}

/// The front end of a board: the two analog inputs and the feed encoder.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FrontEnd {
    /// Feed-axis current input.
    pub feed: AnalogInput,
    /// Spindle current (or load) input.
    pub spindle: AnalogInput,
    /// Feed-axis encoder (used when the monitor measures the feed velocity).
    pub feed_encoder: FeedEncoder,
}

impl Default for FrontEnd {
    /// ±10 V check terminals scaled 3 A/V (feed) and 5 A/V (spindle), a 1 000 counts/mm
    /// feed encoder with a 64-block window.
    fn default() -> Self {
        FrontEnd {
            feed: AnalogInput::bipolar_10v(3.0),
            spindle: AnalogInput::bipolar_10v(5.0),
            feed_encoder: FeedEncoder::default(),
        }
    }
}

impl FrontEnd {
    /// Checks all three parts; errors name the parameter (`front_end.feed.units_per_volt`).
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.feed.validate_as([
            "front_end.feed.front_end_gain",
            "front_end.feed.front_end_offset_v",
            "front_end.feed.units_per_volt",
            "front_end.feed.units_at_zero_v",
        ])?;
        self.spindle.validate_as([
            "front_end.spindle.front_end_gain",
            "front_end.spindle.front_end_offset_v",
            "front_end.spindle.units_per_volt",
            "front_end.spindle.units_at_zero_v",
        ])?;
        self.feed_encoder.validate()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_front_end_is_valid() {
        assert_eq!(FrontEnd::default().validate(), Ok(()));
    }

    #[test]
    fn errors_name_the_parameter() {
        let mut f = FrontEnd::default();
        f.feed.units_per_volt = 0.0;
        assert_eq!(
            f.validate(),
            Err(ConfigError::OutOfRange("front_end.feed.units_per_volt"))
        );
        let mut f = FrontEnd::default();
        f.spindle.front_end_gain = f32::NAN;
        assert_eq!(
            f.validate(),
            Err(ConfigError::NonFinite("front_end.spindle.front_end_gain"))
        );
        let mut f = FrontEnd::default();
        f.spindle.front_end_offset_v = -0.1;
        assert_eq!(
            f.validate(),
            Err(ConfigError::OutOfRange(
                "front_end.spindle.front_end_offset_v"
            ))
        );
        let mut f = FrontEnd::default();
        f.feed_encoder.window_blocks = MAX_WINDOW_BLOCKS as u16 + 1;
        assert_eq!(
            f.validate(),
            Err(ConfigError::OutOfRange(
                "front_end.feed_encoder.window_blocks"
            ))
        );
        let mut f = FrontEnd::default();
        f.feed_encoder.counts_per_mm = 0.0;
        assert_eq!(
            f.validate(),
            Err(ConfigError::OutOfRange(
                "front_end.feed_encoder.counts_per_mm"
            ))
        );
    }
}
