//! Firmware for the STM32F405RG tool monitor (embassy).
//!
//! # Design
//!
//! For now a skeleton that proves the pieces link together on the target: it boots embassy on
//! the default clock tree (16 MHz HSI), runs the estimator-core conformance grid once so the
//! core's `no_std` code is linked and exercised on the MCU, logs the result over defmt-RTT, and
//! blinks a status LED from its own task. Every decision belongs in `estimator-core`, where host
//! tests reach it; this binary only wires peripherals to it.
//!
//! On the host (any target with an OS) the binary is an empty `main`, so workspace-wide
//! `cargo test` / `cargo clippy` stay green without a cross toolchain; build it for real with
//! `cargo fw` (alias for `cargo build -p firmware --target thumbv7em-none-eabihf --release`).
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod target {
    use defmt::{error, info};
    use embassy_executor::Spawner;
    use embassy_stm32::gpio::{Level, Output, Speed};
    use embassy_time::Timer;
    // Linked for their side effects: the RTT logger, the panic handler, the critical-section
    // implementation (cortex-m) and the vector table / reset handler (cortex-m-rt).
    use {cortex_m as _, cortex_m_rt as _, defmt_rtt as _, panic_probe as _};

    /// Half period of the status blink: a steady 1 Hz blink means the executor is alive.
    const BLINK_HALF_PERIOD_MS: u64 = 500;

    /// Result of one pass over the conformance grid: proves the core runs on the MCU.
    struct ConformanceSummary {
        cases: u32,
        words: u32,
        /// FNV-1a over every output word, to compare with the host at a glance.
        hash: u32,
    }

    fn run_conformance() -> ConformanceSummary {
        let mut s = ConformanceSummary {
            cases: 0,
            words: 0,
            hash: 0x811c_9dc5,
        };
        estimator_core::conformance::run(&mut |_idx, bits| {
            s.cases = s.cases.wrapping_add(1);
            for &w in bits {
                s.words = s.words.wrapping_add(1);
                s.hash = (s.hash ^ w).wrapping_mul(0x0100_0193);
            }
        });
        s
    }

    #[embassy_executor::task]
    async fn blink(mut led: Output<'static>) {
        loop {
            led.toggle();
            Timer::after_millis(BLINK_HALF_PERIOD_MS).await;
        }
    }

    #[embassy_executor::main]
    async fn main(spawner: Spawner) {
        let p = embassy_stm32::init(Default::default());
        info!("tool monitor firmware {}", env!("CARGO_PKG_VERSION"));

        let c = run_conformance();
        info!(
            "estimator-core conformance: {} cases, {} words, hash {=u32:08x}",
            c.cases, c.words, c.hash
        );

        // Note: PC1 is the user LED of the Adafruit Feather STM32F405; move it to the board
        // constants file once the real board is fixed.
        let led = Output::new(p.PC1, Level::Low, Speed::Low);
        match blink(led) {
            Ok(token) => spawner.spawn(token),
            // Only possible if the task pool is exhausted: a build mistake, not a runtime one.
            Err(e) => error!("status LED task not spawned: {}", e),
        }
    }
}

#[cfg(not(target_os = "none"))]
fn main() {}
