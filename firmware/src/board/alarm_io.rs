//! The alarm output to the CNC, the status LED and the reset input.
//!
//! # Design
//!
//! - **Alarm output**, PB12, push-pull, driving a relay (or an opto-coupler) through a
//!   low-side driver (ULN2003 channel, or an N-MOSFET with a flyback diode): high =
//!   energised = all well. It starts low at reset and stays low until the monitor runs, so
//!   a board that is dead, resetting, unconfigured or hung (the watchdog resets it) holds
//!   the CNC's input in the alarm state. Wire the CNC's feed-hold / alarm input to the
//!   relay's normally-open contact (closed = OK).
//! - **LED**, PC1 (the Feather's red LED), high = on; patterns in `firmware::alarm_out`.
//! - **Reset**, PB13 with the internal pull-up, EXTI line 13: a button or the CNC's reset
//!   output pulling it to GND clears a latched alarm. Debounced: the line must still be low
//!   20 ms after the falling edge, and must go high again before the next reset counts.
//!
//! What the output shows is decided in `firmware::alarm_out` and `firmware::graph`
//! (`alarm_output_task`); this file only owns the pins.

use embassy_stm32::exti::ExtiInput;
use embassy_stm32::gpio::{Level, Output, Pull, Speed};
use embassy_stm32::mode::Async;
use embassy_stm32::peripherals::{EXTI13, PB12, PB13, PC1};
use embassy_stm32::Peri;
use firmware::graph::AlarmPins;

use super::Irqs;

/// Debounce time of the reset input [ms].
pub const RESET_DEBOUNCE_MS: u64 = 20;

/// The pins.
pub struct Parts {
    /// Relay driver.
    pub relay: Peri<'static, PB12>,
    /// Status LED.
    pub led: Peri<'static, PC1>,
    /// Reset input.
    pub reset: Peri<'static, PB13>,
    /// Its EXTI line.
    pub reset_exti: Peri<'static, EXTI13>,
}

/// Relay and LED.
pub struct Outputs {
    relay: Output<'static>,
    led: Output<'static>,
}

/// Sets the pins up: relay de-energised, LED off; the reset input with its EXTI line.
pub fn split(p: Parts) -> (Outputs, ExtiInput<'static, Async>) {
    let outputs = Outputs {
        relay: Output::new(p.relay, Level::Low, Speed::Low),
        led: Output::new(p.led, Level::Low, Speed::Low),
    };
    let reset = ExtiInput::new(p.reset, p.reset_exti, Pull::Up, Irqs);
    (outputs, reset)
}

impl AlarmPins for Outputs {
    fn set_relay(&mut self, energised: bool) {
        self.relay.set_level(Level::from(energised));
    }

    fn set_led(&mut self, on: bool) {
        self.led.set_level(Level::from(on));
    }
}
