//! The thumbv7em half of target-check: runs the estimator-core conformance grid on a
//! Cortex-M4F (QEMU's netduinoplus2, an STM32F405) and prints the report over semihosting.
//!
//! Exit status is QEMU's: success after a complete report, failure on a write error, panic
//! (panic-semihosting `exit`) or HardFault. On the host this is an empty `main`; see
//! `tests/host_vs_target.rs` for the test that builds, runs and compares it.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod target {
    use core::fmt;
    use cortex_m_rt::entry;
    use target_check::semihosting::{exit, Buffered};
    // Linked for their side effects: critical-section implementation and panic handler.
    use {cortex_m as _, panic_semihosting as _};

    fn report() -> fmt::Result {
        let mut w = Buffered::stdout()?;
        target_check::write_report(&mut w)?;
        w.flush()
    }

    #[entry]
    fn main() -> ! {
        exit(report().is_ok())
    }

    target_check::hardfault_exits!();
}

#[cfg(not(target_os = "none"))]
fn main() {}
