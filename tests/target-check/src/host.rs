//! Host-side helpers for target tests: build a thumbv7em ELF of a workspace package and run it
//! in QEMU with a timeout.
//!
//! # Design
//!
//! The nested `cargo build` uses its own target directory (`target/qemu`, or
//! `$CARGO_TARGET_DIR/qemu`): the outer `cargo test` still holds the lock on the main one, and
//! sharing it would deadlock. QEMU runs the STM32F405 map of `memory.x` as the netduinoplus2
//! machine; it does not model the RCC, so programs run here must not touch embassy-stm32.
//!
//! With [`QemuConfig::icount`] QEMU runs with `-icount shift=0`: one guest instruction is
//! one nanosecond of virtual time, so SysTick read before and after a piece of code gives its
//! instruction count (not cycles; DWT CYCCNT reads 0 in QEMU).
//!
//! These are test helpers: they panic with a message that says what to do (install QEMU,
//! fix the build) rather than returning errors, so a missing tool fails the test loudly.

// Note: the crate is `no_std` (for the target), so std's prelude items are imported by name.
use std::env;
use std::ffi::{OsStr, OsString};
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::string::String;
use std::thread::{self, JoinHandle};
use std::time::{Duration, Instant};
use std::vec::Vec;

/// The cross target the firmware and the QEMU programs are built for.
pub const TARGET: &str = "thumbv7em-none-eabihf";

/// The workspace root (two levels above this crate).
pub fn workspace_root() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    // Canonical for readable messages; the joined path works as well if that fails.
    std::fs::canonicalize(&root).unwrap_or(root)
}

/// Target directory for the nested cross builds (see the module docs).
pub fn qemu_target_dir() -> PathBuf {
    let base = env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace_root().join("target"));
    base.join("qemu")
}

/// Builds `bin` of `package` for [`TARGET`] in release and returns the ELF's path.
///
/// # Panics
/// If cargo cannot be started or the build fails (its output goes to the terminal).
pub fn build_elf(package: &str, bin: &str) -> PathBuf {
    build_elfs(package, &[bin], &[])
        .pop()
        .expect("one path per bin")
}

/// Builds `bins` of `package` for [`TARGET`] in release, in one cargo run with extra
/// environment variables (e.g. `TRACE_BIN`, read by this crate's build.rs), and returns
/// the ELF paths in the order of `bins`.
///
/// Note: every build of the crate rewrites all its ELFs in [`qemu_target_dir`]. Tests that
/// build with different environments must not run at the same time: keep them in
/// different test files (cargo runs test binaries one after the other).
///
/// # Panics
/// If cargo cannot be started or the build fails (its output goes to the terminal).
pub fn build_elfs(package: &str, bins: &[&str], envs: &[(&str, &OsStr)]) -> Vec<PathBuf> {
    // `$CARGO` is the cargo running this test: same toolchain as the outer build.
    let cargo = env::var_os("CARGO").unwrap_or_else(|| OsString::from("cargo"));
    let target_dir = qemu_target_dir();
    let mut cmd = Command::new(&cargo);
    cmd.current_dir(workspace_root())
        .args(["build", "--release", "--target", TARGET])
        .args(["-p", package]);
    for bin in bins {
        cmd.args(["--bin", bin]);
    }
    for (k, v) in envs {
        cmd.env(k, v);
    }
    let status = cmd
        .env("CARGO_TARGET_DIR", &target_dir)
        .stdin(Stdio::null())
        .status()
        .unwrap_or_else(|e| panic!("cannot start {cargo:?}: {e}"));
    assert!(
        status.success(),
        "cross build of {package} {bins:?} for {TARGET} failed ({status})"
    );
    bins.iter()
        .map(|bin| {
            let elf = target_dir.join(TARGET).join("release").join(bin);
            assert!(elf.is_file(), "built, but {} is missing", elf.display());
            elf
        })
        .collect()
}

/// `llvm-size` of an ELF (Berkeley format: text, data, bss), or `None` if the tool is
/// missing or fails. `$LLVM_SIZE` overrides the binary.
pub fn llvm_size(elf: &Path) -> Option<ElfSize> {
    let tool = env::var_os("LLVM_SIZE").unwrap_or_else(|| OsString::from("llvm-size"));
    let out = Command::new(tool).arg(elf).output().ok()?;
    if !out.status.success() {
        return None;
    }
    let text = String::from_utf8_lossy(&out.stdout);
    // Second line: "text data bss dec hex filename".
    let mut f = text.lines().nth(1)?.split_whitespace();
    let mut next = || f.next()?.parse::<u64>().ok();
    Some(ElfSize {
        text: next()?,
        data: next()?,
        bss: next()?,
    })
}

/// Section sizes of an ELF [bytes].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ElfSize {
    /// Code and constants (flash).
    pub text: u64,
    /// Initialised statics (flash and RAM).
    pub data: u64,
    /// Zeroed statics (RAM).
    pub bss: u64,
}

impl ElfSize {
    /// Flash used: text and the initial values of data.
    pub fn flash(&self) -> u64 {
        self.text + self.data
    }

    /// Static RAM: data and bss (the stack comes on top).
    pub fn static_ram(&self) -> u64 {
        self.data + self.bss
    }
}

/// How to run QEMU.
#[derive(Debug, Clone)]
pub struct QemuConfig {
    /// Add `-icount shift=0` (deterministic virtual time: 1 instruction = 1 ns).
    pub icount: bool,
    /// Kill QEMU after this long; the run then counts as failed.
    pub timeout: Duration,
}

impl Default for QemuConfig {
    fn default() -> Self {
        Self {
            icount: false,
            timeout: Duration::from_secs(120),
        }
    }
}

/// What a QEMU run produced.
#[derive(Debug, Clone)]
pub struct QemuRun {
    /// QEMU's exit code (the program's semihosting exit status); `None` if killed.
    pub code: Option<i32>,
    /// The timeout expired and QEMU was killed.
    pub timed_out: bool,
    /// Wall-clock time of the run.
    pub elapsed: Duration,
    /// Semihosting stdout (and anything else QEMU printed there).
    pub stdout: String,
    /// QEMU's stderr: its own warnings, and the program's `hstderr` (HardFault report).
    pub stderr: String,
}

impl QemuRun {
    /// The program exited with success, within the timeout.
    pub fn success(&self) -> bool {
        !self.timed_out && self.code == Some(0)
    }
}

/// The QEMU binary: `$QEMU_SYSTEM_ARM` if set, else `qemu-system-arm` from `PATH`.
pub fn qemu_binary() -> OsString {
    env::var_os("QEMU_SYSTEM_ARM").unwrap_or_else(|| OsString::from("qemu-system-arm"))
}

/// The QEMU command line for `elf` (also written out in `run-qemu.sh`).
pub fn qemu_command(elf: &Path, config: &QemuConfig) -> Command {
    let mut cmd = Command::new(qemu_binary());
    cmd.args(["-cpu", "cortex-m4", "-machine", "netduinoplus2"])
        .args([
            "-nographic",
            "-semihosting-config",
            "enable=on,target=native",
        ]);
    if config.icount {
        cmd.args(["-icount", "shift=0"]);
    }
    cmd.arg("-kernel").arg(elf);
    cmd
}

/// Runs `elf` in QEMU, capturing its output, and kills it after `config.timeout`.
///
/// # Panics
/// If QEMU cannot be started (not installed: `apt-get install -y qemu-system-arm`, or run
/// `bash tests/all.sh`, which installs it).
pub fn run_qemu(elf: &Path, config: &QemuConfig) -> QemuRun {
    let mut child = qemu_command(elf, config)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| {
            panic!(
                "cannot start {:?}: {e}. Install QEMU (`apt-get install -y qemu-system-arm`) \
                 or run `bash tests/all.sh`, which does",
                qemu_binary()
            )
        });
    let start = Instant::now();
    // Drain both pipes on their own threads so a chatty program cannot block on a full pipe
    // while we wait for it.
    let out = drain(child.stdout.take());
    let err = drain(child.stderr.take());

    let mut timed_out = false;
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break Some(status),
            Ok(None) if start.elapsed() >= config.timeout => {
                timed_out = true;
                // Kill can only fail if it already exited; wait() below reaps it either way.
                let _ = child.kill();
                break child.wait().ok();
            }
            Ok(None) => thread::sleep(Duration::from_millis(20)),
            Err(e) => panic!("waiting for QEMU failed: {e}"),
        }
    };
    let elapsed = start.elapsed();
    QemuRun {
        code: status.and_then(|s| s.code()),
        timed_out,
        elapsed,
        stdout: out.join().unwrap_or_else(|_| "<reader panicked>".into()),
        stderr: err.join().unwrap_or_else(|_| "<reader panicked>".into()),
    }
}

/// Reads a child's pipe to the end on a thread of its own, as lossy UTF-8.
fn drain<R: Read + Send + 'static>(pipe: Option<R>) -> JoinHandle<String> {
    thread::spawn(move || {
        let mut bytes = Vec::new();
        if let Some(mut p) = pipe {
            // A read error only truncates the capture; the report framing catches that.
            let _ = p.read_to_end(&mut bytes);
        }
        String::from_utf8_lossy(&bytes).into_owned()
    })
}
