//! Board constants and the configuration the board runs, in one file.
//!
//! # Design
//!
//! Two kinds of numbers live here:
//!
//! - **Constants of the build** (`const`): clocks, block and queue sizes, the UART rate, the
//!   watchdog timeout. Each carries its derivation. Pins are in the board module
//!   (`src/board/mod.rs`), the only place that names peripherals.
//! - **The configuration** ([`BoardConfig`]): the core's [`MachineConfig`] (tool,
//!   coefficients, drive models, thresholds, and the analog front end of each input and
//!   the feed encoder in `machine.front_end`: the same type host-sim reads from
//!   `machine.toml`) plus what only a board has: the telemetry decimation. [`BoardConfig::board_default`] is what the
//!   firmware is built with; [`BoardConfig::build`] checks it once at start-up, with errors
//!   that name the parameter, and the per-sample path cannot fail afterwards.
//!
//! To run another tool or machine, build with its machine file (the one `host-sim replay`
//! reads and `host-sim calibrate` writes) turned into Rust:
//! `host-sim machine-rs --config machine.toml --output machine.rs`, then
//! `FIRMWARE_MACHINE_RS=machine.rs cargo build -p firmware ...` ([`machine_file`]; the
//! polynomial of calibrated coefficients comes in through `ESTIMATOR_FXT_POLY`, see
//! estimator-core's build.rs). Without it the board runs the core's defaults. The board refuses to
//! start its alarm output on a configuration that does not build (the relay stays
//! de-energised, the LED blinks the error, defmt logs the parameter).
//!
//! ## Sample clock
//! TIM3 runs from the APB1 timer clock, [`TIMER_CLOCK_HZ`] = 84 MHz (HSI 16 MHz / 8 x 168
//! / 2 = 168 MHz SYSCLK, APB1 = SYSCLK / 4 = 42 MHz, timers x 2), and its update event
//! (TRGO) triggers one ADC scan per sample: the sample rate is `84 MHz / n` for an integer
//! `n`; 20 kS/s is `n = 4200`. TIM2 counts those update events, so the tooth-sync capture
//! reads the sample index directly (see `board/tooth_capture.rs`).

use estimator_core::monitor::Input;
pub use estimator_core::{AnalogInput, FeedEncoder, FrontEnd};
use estimator_core::{ConfigError, MachineConfig, Pipeline};

/// The machine configuration compiled in: `OUT_DIR/machine.rs`, from `FIRMWARE_MACHINE_RS`
/// (see build.rs) or the core's default.
pub mod machine_file {
    include!(concat!(env!("OUT_DIR"), "/machine.rs"));
}

/// APB1 timer clock [Hz]: the sample trigger (TIM3) and the sample counter (TIM2).
pub const TIMER_CLOCK_HZ: u32 = 84_000_000;

/// Samples per block: one half of the ADC's circular DMA buffer. 32 samples are 1.6 ms at
/// 20 kS/s: a record is at most one block (plus the queue) late, and the per-block
/// overhead (channel, wake-up) is small against the per-sample work. A block may close
/// several tooth periods (at 24 000 rpm, 4 flutes, a tooth is 12.5 samples).
pub const SAMPLE_BLOCK: usize = 32;

/// Blocks the sampling task may run ahead of the monitor (4 x 1.6 ms at 20 kS/s).
pub const SAMPLE_QUEUE: usize = 4;

/// Tooth-sync edges waiting to be merged into the samples (a block of 32 samples holds at
/// most 3 edges at the shortest tooth period the default configuration allows).
pub const EDGE_QUEUE: usize = 16;

/// Telemetry messages waiting for the UART. A full queue drops the newest message and
/// counts it (`frames_dropped`); the host sees the gap in the sequence numbers too.
pub const MESSAGE_QUEUE: usize = 8;

/// Telemetry UART rate [baud]: a record frame is 144 bytes, 1 440 bits with start and stop
/// bits, so 921 600 baud carries about 640 frames per second (every tooth up to 640
/// teeth/s; above, set [`TelemetryConfig::record_every`]).
pub const UART_BAUD: u32 = 921_600;

/// Independent watchdog timeout [us]. The watchdog is fed only while the monitor task
/// keeps consuming blocks (one every 1.6 ms at 20 kS/s), so 100 ms is a stalled graph.
pub const WATCHDOG_TIMEOUT_US: u32 = 100_000;

/// How often the watchdog task checks the monitor's heartbeat [ms].
pub const WATCHDOG_CHECK_MS: u64 = 20;

/// Most samples [`crate::stage::MonitorStage`] feeds as NaN to bridge a gap (an ADC ring
/// overrun): enough for any tooth period the default configuration allows (5 000 samples
/// at 60 rpm and 20 kS/s), so that sample indices stay aligned with the capture; a longer
/// gap is counted but bridged only this far.
pub const GAP_FILL_MAX: u64 = 8192;

/// Full-scale code of the 12-bit ADC.
pub const ADC_MAX_CODE: u16 = 4095;

/// ADC reference [V] (VDDA on the board).
pub const ADC_VREF_V: f32 = 3.3;

/// Telemetry stream.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TelemetryConfig {
    /// Send every n-th record (1: all). Records that raise an alarm, and the first after
    /// the latch changes, are always sent.
    pub record_every: u16,
}

/// Everything the board is configured with.
#[derive(Clone, Debug, PartialEq)]
pub struct BoardConfig {
    /// The core's configuration: monitor, alarms and front end (host-sim's
    /// `machine.toml`). `machine.front_end.feed` is wired to ADC1 IN4, `.spindle` to
    /// ADC1 IN5, `.feed_encoder` to TIM4.
    pub machine: MachineConfig,
    /// Telemetry.
    pub telemetry: TelemetryConfig,
}

impl BoardConfig {
    /// What the firmware is built with: the machine file of `FIRMWARE_MACHINE_RS`, else
    /// `MachineConfig::default()` (the paper's tool, one feed axis, current-sensed spindle,
    /// 20 kS/s, default alarms, and the default [`FrontEnd`]: ±10 V check terminals scaled
    /// 3 A/V (feed) and 5 A/V (spindle), a 1 000 counts/mm feed encoder over 64 blocks),
    /// every record sent (see the module docs).
    pub fn board_default() -> Self {
        BoardConfig {
            machine: machine_file::machine(),
            telemetry: TelemetryConfig { record_every: 1 },
        }
    }

    /// Checks everything the board needs on top of the core's own checks; errors name the
    /// parameter.
    pub fn build(self) -> Result<BuiltConfig, BoardConfigError> {
        use BoardConfigError::*;
        let fs = self.machine.monitor.sample_rate_hz;
        let trigger_period = trigger_period_ticks(TIMER_CLOCK_HZ, fs)
            .ok_or(Board("machine.monitor.sample_rate_hz"))?;
        if let Input::Motor { feed, .. } = &self.machine.monitor.input {
            // One feed current input is wired (ADC1 IN4): a two-axis drive needs another.
            if feed.two_axis {
                return Err(Board("machine.monitor.input.motor.feed.two_axis"));
            }
        }
        let fe = self.machine.front_end;
        // The core checks the front end (MachineConfig::build, below); the board adds that
        // the level shift lies within its ADC reference.
        for (input, name) in [
            (&fe.feed, "machine.front_end.feed.front_end_offset_v"),
            (&fe.spindle, "machine.front_end.spindle.front_end_offset_v"),
        ] {
            if input.front_end_offset_v > ADC_VREF_V {
                return Err(Board(name));
            }
        }
        if self.telemetry.record_every == 0 {
            return Err(Board("telemetry.record_every"));
        }
        let pipeline = self.machine.build().map_err(Core)?;
        let feed_scale = crate::frontend::Scale::new(&fe.feed);
        let spindle_scale = crate::frontend::Scale::new(&fe.spindle);
        Ok(BuiltConfig {
            pipeline,
            trigger_period_ticks: trigger_period,
            sample_rate_hz: fs,
            feed_scale,
            spindle_scale,
            feed_encoder: fe.feed_encoder,
            telemetry: self.telemetry,
        })
    }
}

/// A checked [`BoardConfig`], in the form the tasks use.
#[derive(Clone, Debug)]
pub struct BuiltConfig {
    /// The core's validated pipeline.
    pub pipeline: Pipeline,
    /// TIM3 period in timer clocks (`TIMER_CLOCK_HZ / sample_rate_hz`).
    pub trigger_period_ticks: u32,
    /// Sample rate [Hz].
    pub sample_rate_hz: f32,
    /// Feed input, code to amperes.
    pub feed_scale: crate::frontend::Scale,
    /// Spindle input, code to its unit.
    pub spindle_scale: crate::frontend::Scale,
    /// Feed encoder.
    pub feed_encoder: FeedEncoder,
    /// Telemetry.
    pub telemetry: TelemetryConfig,
}

/// Why a configuration cannot run on the board.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoardConfigError {
    /// The core refused it.
    Core(ConfigError),
    /// A board parameter, named, is out of range.
    Board(&'static str),
}

impl BoardConfigError {
    /// The parameter it names (for a log line without `core::fmt`).
    pub fn parameter(&self) -> &'static str {
        match self {
            Self::Core(ConfigError::NonFinite(p) | ConfigError::OutOfRange(p)) => p,
            Self::Core(ConfigError::NoPolynomial) => "estimator.solver (no polynomial)",
            Self::Core(ConfigError::Table3NotApplicable) => "estimator.solver (table3)",
            Self::Board(p) => p,
        }
    }
}

impl core::fmt::Display for BoardConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Core(e) => write!(f, "{e}"),
            Self::Board(p) => write!(f, "parameter `{p}` cannot run on this board"),
        }
    }
}

/// Timer clocks per sample for `sample_rate_hz` from `clock_hz`, if the rate is an exact
/// divisor of the clock (within 1 ppm) and the period fits TIM3's 16 bits; `None` else.
pub fn trigger_period_ticks(clock_hz: u32, sample_rate_hz: f32) -> Option<u32> {
    if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
        return None;
    }
    let exact = clock_hz as f64 / sample_rate_hz as f64;
    let n = (exact + 0.5) as u64;
    let exact_enough = (n as f64 - exact).abs() <= 1e-6 * exact;
    (exact_enough && (2..=65_536).contains(&n)).then_some(n as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A machine file compiled in is the configuration host-sim loaded from it, field for
    /// field (f32 Debug prints the shortest round-trip digits, so equal text is equal bits).
    #[test]
    fn machine_file_is_what_host_sim_loaded() {
        if let Some(want) = machine_file::MACHINE_DEBUG {
            assert_eq!(std::format!("{:?}", machine_file::machine()), want);
            machine_file::machine()
                .build()
                .expect("the machine file builds");
        }
    }

    #[test]
    fn default_board_builds_at_20_ks() {
        let b = BoardConfig::board_default().build().expect("builds");
        assert_eq!(b.trigger_period_ticks, 4200);
    }

    #[test]
    fn sample_rate_must_divide_the_timer_clock() {
        assert_eq!(trigger_period_ticks(84_000_000, 20_000.0), Some(4200));
        assert_eq!(trigger_period_ticks(84_000_000, 5_000.0), Some(16_800));
        assert_eq!(
            trigger_period_ticks(84_000_000, 1_000.0),
            None,
            "84 000 > 65 536"
        );
        assert_eq!(trigger_period_ticks(84_000_000, 30_001.0), None);
        assert_eq!(trigger_period_ticks(84_000_000, f32::NAN), None);
        let mut c = BoardConfig::board_default();
        c.machine.monitor.sample_rate_hz = 30_001.0;
        assert_eq!(
            c.build().err(),
            Some(BoardConfigError::Board("machine.monitor.sample_rate_hz"))
        );
    }

    #[test]
    fn errors_name_the_parameter() {
        let mut c = BoardConfig::board_default();
        c.telemetry.record_every = 0;
        assert_eq!(
            c.build().err(),
            Some(BoardConfigError::Board("telemetry.record_every"))
        );
        let mut c = BoardConfig::board_default();
        c.machine.front_end.spindle.front_end_gain = 0.0;
        let e = c.build().err();
        assert_eq!(
            e,
            Some(BoardConfigError::Core(ConfigError::OutOfRange(
                "front_end.spindle.front_end_gain"
            )))
        );
        assert_eq!(
            e.map(|e| e.parameter()),
            Some("front_end.spindle.front_end_gain")
        );
        let mut c = BoardConfig::board_default();
        c.machine.front_end.feed.front_end_offset_v = ADC_VREF_V + 0.1;
        assert_eq!(
            c.build().err(),
            Some(BoardConfigError::Board(
                "machine.front_end.feed.front_end_offset_v"
            ))
        );
        let mut c = BoardConfig::board_default();
        c.machine.front_end.feed_encoder.window_blocks = 0;
        assert_eq!(
            c.build().err(),
            Some(BoardConfigError::Core(ConfigError::OutOfRange(
                "front_end.feed_encoder.window_blocks"
            )))
        );
        let mut c = BoardConfig::board_default();
        if let Input::Motor { feed, .. } = &mut c.machine.monitor.input {
            feed.two_axis = true;
        }
        assert_eq!(
            c.build().err(),
            Some(BoardConfigError::Board(
                "machine.monitor.input.motor.feed.two_axis"
            ))
        );
        let mut c = BoardConfig::board_default();
        c.machine.monitor.filter_revs = 0;
        let e = c.build().err();
        assert_eq!(
            e,
            Some(BoardConfigError::Core(ConfigError::OutOfRange(
                "filter_revs"
            )))
        );
        assert_eq!(e.map(|e| e.parameter()), Some("filter_revs"));
    }
}
