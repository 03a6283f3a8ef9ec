//! thumbv7em program: the streaming `Monitor` over a raw trace embedded in flash.
//!
//! The trace is a TMS1 blob (`target_check::tms1`) chosen at build time: `TRACE_BIN=path`
//! (see build.rs), else a tiny built-in one. The program runs `MonitorConfig::default()` at
//! the blob's sample rate over every sample and prints one framed case line per tooth record
//! (`ToothRecord::to_words`) over semihosting; `tests/monitor_replay.rs` compares them with
//! host-sim's replay of the same trace.
//!
//! Exit status: success after a complete report; failure, with the reason on stderr, for a
//! malformed blob, a refused configuration, a write error, a panic or a HardFault.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod target {
    use cortex_m_rt::entry;
    use target_check::semihosting::{eprint, exit, Buffered};
    use target_check::{write_replay_report, ReplayError};
    // Linked for their side effects: critical-section implementation and panic handler.
    use {cortex_m as _, panic_semihosting as _};

    /// The trace, copied to OUT_DIR by build.rs.
    static TRACE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/trace.bin"));

    fn run() -> Result<u32, ReplayError> {
        let mut w = Buffered::stdout()?;
        let n = write_replay_report(&mut w, TRACE)?;
        w.flush()?;
        Ok(n)
    }

    #[entry]
    fn main() -> ! {
        match run() {
            Ok(_) => exit(true),
            Err(e) => {
                eprint(format_args!("monitor-replay: {e}\n"));
                exit(false)
            }
        }
    }

    target_check::hardfault_exits!();
}

#[cfg(not(target_os = "none"))]
fn main() {}
