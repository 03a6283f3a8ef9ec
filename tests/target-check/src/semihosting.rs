//! Target side, shared by the thumbv7em programs: buffered semihosting output, exit, and a
//! HardFault handler that fails the QEMU run.

use core::fmt;
use cortex_m_semihosting::{debug, hio};

/// Bytes gathered before one semihosting write: each write is a trap into QEMU, and one
/// per `write_str` fragment would dominate the run time.
const BUF_LEN: usize = 2048;

/// `fmt::Write` into a buffer flushed to the host's stdout when full and on `flush`.
pub struct Buffered {
    out: hio::HostStream,
    buf: [u8; BUF_LEN],
    len: usize,
}

impl Buffered {
    /// A writer to the host's stdout; `Err` if semihosting cannot open it.
    pub fn stdout() -> Result<Self, fmt::Error> {
        Ok(Buffered {
            out: hio::hstdout().map_err(|()| fmt::Error)?,
            buf: [0; BUF_LEN],
            len: 0,
        })
    }

    /// Writes out what is buffered.
    pub fn flush(&mut self) -> fmt::Result {
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

/// Best-effort message on the host's stderr (unbuffered: for errors just before an exit).
pub fn eprint(args: fmt::Arguments<'_>) {
    if let Ok(mut err) = hio::hstderr() {
        // Nothing to do if even this fails: the exit status carries the failure.
        let _ = fmt::Write::write_fmt(&mut err, args);
    }
}

/// Ends the QEMU run with success or failure.
pub fn exit(ok: bool) -> ! {
    debug::exit(if ok {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    // Only reached if the host lets the program continue after the exit request.
    loop {
        cortex_m::asm::wfi();
    }
}

/// Defines the HardFault handler of a program: report the PC on stderr and exit with
/// failure, so a fault fails the QEMU run at once instead of spinning until the timeout.
/// Use once, at the top level of a thumbv7em bin.
#[macro_export]
macro_rules! hardfault_exits {
    () => {
        // Note(unsafe): cortex-m-rt requires `unsafe fn` for a HardFault handler (it runs in
        // exception context on whatever stack is left). It only reports and exits.
        #[allow(unsafe_code)]
        #[cortex_m_rt::exception]
        unsafe fn HardFault(frame: &cortex_m_rt::ExceptionFrame) -> ! {
            $crate::semihosting::eprint(format_args!("HardFault at pc {:#010x}\n", frame.pc()));
            $crate::semihosting::exit(false)
        }
    };
}
