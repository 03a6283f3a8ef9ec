//! The independent watchdog.
//!
//! # Design
//!
//! IWDG from the 32 kHz LSI, timeout `firmware::config::WATCHDOG_TIMEOUT_US` (100 ms),
//! started once the configuration has built and the graph is spawned (a board whose
//! configuration does not build stays up, relay de-energised, to say why over defmt and
//! the LED). The watchdog task checks the monitor's heartbeat every
//! `WATCHDOG_CHECK_MS` (20 ms) and feeds the IWDG only if it moved
//! (`firmware::alarm_out::Liveness`): a stalled monitor, sampling chain or executor resets
//! the board, and the reset drops the relay.

use embassy_stm32::peripherals::IWDG;
use embassy_stm32::wdg::IndependentWatchdog;
use embassy_stm32::Peri;
use firmware::config::WATCHDOG_TIMEOUT_US;

/// The watchdog peripheral.
pub struct Parts {
    /// IWDG.
    pub iwdg: Peri<'static, IWDG>,
}

/// Starts the IWDG; from here on it must be fed.
pub fn start(p: Parts) -> IndependentWatchdog<'static, IWDG> {
    let mut wdg = IndependentWatchdog::new(p.iwdg, WATCHDOG_TIMEOUT_US);
    wdg.unleash();
    wdg
}
