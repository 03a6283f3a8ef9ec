//! Tooth timing: the spindle encoder's sync pulse, captured as a sample index.
//!
//! # Design
//!
//! TIM2 (32 bit) does not count the timer clock: in external clock mode 1 with trigger
//! ITR2 it counts TIM3's TRGO, i.e. one per ADC trigger. Its counter is therefore the
//! number of samples triggered, and channel 1's input capture on PA0 (rising edge) latches
//! that count at the pulse: capture `c` is sample `c`, the first after the pulse (see
//! `firmware::sync`). No conversion between clocks, nothing to drift.
//!
//! The capture uses embassy-stm32's `InputCapture` (interrupt and waker); three things are
//! set through the PAC afterwards because the HAL has no call for them: the slave mode
//! (`SMCR`: external clock from ITR2), prescaler 0, and the full 32-bit capture value
//! (the HAL reads CCR through a 16-bit view). Overcapture (`CCxOF`: a second pulse before
//! the first was read) is a lost edge: counted, like an edge that finds the queue full.
//!
//! Note: `InputCapture` sets the input filter to none on every wait; the pulse must reach
//! PA0 clean (the front end's RC and Schmitt trigger, see README "Input ranges").

use embassy_stm32::peripherals::{PA0, TIM2};
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::input_capture::{CapturePin, InputCapture};
use embassy_stm32::timer::low_level::CountingMode;
use embassy_stm32::timer::Channel;
use embassy_stm32::{gpio::Pull, pac, Peri};
use firmware::config::TIMER_CLOCK_HZ;
use firmware::sync::CaptureClock;

use super::Irqs;

/// The peripherals of tooth timing.
pub struct Parts {
    /// Sample counter and capture.
    pub tim: Peri<'static, TIM2>,
    /// Sync pulse input.
    pub pin: Peri<'static, PA0>,
}

/// Samples triggered so far (TIM2's counter), modulo 2^32.
pub fn sample_count() -> u32 {
    pac::TIM2.cnt().read()
}

/// The running capture.
pub struct ToothCapture {
    ic: InputCapture<'static, TIM2>,
    clock: CaptureClock,
}

/// What a wait gave.
pub enum Event {
    /// A pulse at this sample index; `lost` edges were overwritten before it.
    Edge {
        /// Sample index.
        index: u64,
        /// Overcaptures seen with it.
        lost: u32,
    },
    /// No pulse within the wait: the counter was read to keep the 64-bit extension fresh.
    Tick,
}

impl ToothCapture {
    /// Sets TIM2 up as the sample counter with capture on CH1. Call before sampling
    /// starts, so that the counter sees TIM3's first update.
    pub fn new(p: Parts) -> Self {
        let pin = CapturePin::new(p.pin, Pull::None);
        let ic = InputCapture::new(
            p.tim,
            Some(pin),
            None,
            None,
            None,
            Irqs,
            Hertz(TIMER_CLOCK_HZ),
            CountingMode::EdgeAlignedUp,
        );
        let r = pac::TIM2;
        r.cr1().modify(|w| w.set_cen(false));
        r.psc().write_value(0);
        r.arr().write_value(u32::MAX);
        r.smcr().modify(|w| {
            w.set_ts(pac::timer::vals::Ts::ITR2);
            w.set_sms(pac::timer::vals::Sms::EXT_CLOCK_MODE);
        });
        // Load the prescaler, zero the counter, then count TIM3's updates.
        r.egr().write(|w| w.set_ug(true));
        r.cnt().write_value(0);
        r.sr().write_value(pac::timer::regs::SrGp16(0));
        r.cr1().modify(|w| w.set_cen(true));
        ToothCapture {
            ic,
            clock: CaptureClock::default(),
        }
    }

    /// Waits for a pulse, or `timeout_ms` (then reads the counter: [`Event::Tick`]).
    pub async fn next(&mut self, timeout_ms: u64) -> Event {
        use embassy_futures::select::{select, Either};
        let wait = self.ic.wait_for_rising_edge(Channel::Ch1);
        match select(wait, embassy_time::Timer::after_millis(timeout_ms)).await {
            Either::First(_low16) => {
                let r = pac::TIM2;
                // The HAL's value is CCR1's low half; the register holds all 32 bits.
                let captured = r.ccr(0).read();
                let sr = r.sr().read();
                let lost = sr.ccof(0) as u32;
                if lost != 0 {
                    r.sr().modify(|w| w.set_ccof(0, false));
                }
                Event::Edge {
                    index: self.clock.extend(captured),
                    lost,
                }
            }
            Either::Second(()) => {
                self.clock.extend(sample_count());
                Event::Tick
            }
        }
    }
}
