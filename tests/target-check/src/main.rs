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
    use cortex_m_rt::{entry, exception, ExceptionFrame};
    use cortex_m_semihosting::{debug, hio};
    // Linked for their side effects: critical-section implementation and panic handler.
    use {cortex_m as _, panic_semihosting as _};

    /// Bytes gathered before one semihosting write: each write is a trap into QEMU, and one
    /// per `write_str` fragment would dominate the run time.
    const BUF_LEN: usize = 2048;

    /// `fmt::Write` into a buffer flushed to the host's stdout when full and on `flush`.
    struct Buffered {
        out: hio::HostStream,
        buf: [u8; BUF_LEN],
        len: usize,
    }

    impl Buffered {
        fn flush(&mut self) -> fmt::Result {
            let pending = self.buf.get(..self.len).ok_or(fmt::Error)?;
            self.out.write_all(pending).map_err(|()| fmt::Error)?;
            self.len = 0;
            Ok(())
        }
    }

    impl fmt::Write for Buffered {
        fn write_str(&mut self, s: &str) -> fmt::Result {
            let bytes = s.as_bytes();
            if self.len + bytes.len() > BUF_LEN {
                self.flush()?;
            }
            if bytes.len() > BUF_LEN {
                // Larger than the whole buffer: pass it straight through.
                return self.out.write_all(bytes).map_err(|()| fmt::Error);
            }
            let end = self.len + bytes.len();
            self.buf
                .get_mut(self.len..end)
                .ok_or(fmt::Error)?
                .copy_from_slice(bytes);
            self.len = end;
            Ok(())
        }
    }

    fn report() -> fmt::Result {
        let out = hio::hstdout().map_err(|()| fmt::Error)?;
        let mut w = Buffered {
            out,
            buf: [0; BUF_LEN],
            len: 0,
        };
        target_check::write_report(&mut w)?;
        w.flush()
    }

    #[entry]
    fn main() -> ! {
        let status = match report() {
            Ok(()) => debug::EXIT_SUCCESS,
            Err(fmt::Error) => debug::EXIT_FAILURE,
        };
        debug::exit(status);
        // Only reached if the host lets the program continue after the exit request.
        loop {
            cortex_m::asm::wfi();
        }
    }

    // Note(unsafe): cortex-m-rt requires `unsafe fn` for a HardFault handler (it runs in
    // exception context on whatever stack is left). It only reports and exits, so that a fault
    // fails the QEMU run at once instead of spinning until the host-side timeout.
    #[allow(unsafe_code)]
    #[exception]
    unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
        if let Ok(mut err) = hio::hstderr() {
            // Best effort: the exit below is what the host test relies on.
            let _ = fmt::Write::write_fmt(
                &mut err,
                format_args!("HardFault at pc {:#010x}\n", frame.pc()),
            );
        }
        debug::exit(debug::EXIT_FAILURE);
        loop {
            cortex_m::asm::wfi();
        }
    }
}

#[cfg(not(target_os = "none"))]
fn main() {}
