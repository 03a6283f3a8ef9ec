//! Instruction-count bench: statistics the `icount-bench` program gathers in SysTick ticks,
//! the lines it prints, and (host) their reading and conversion to instructions.
//!
//! # Design
//!
//! Under `qemu-system-arm -icount shift=0` every guest instruction advances virtual time by
//! exactly 1 ns, and SysTick, clocked from the core clock, counts virtual time: the
//! netduinoplus2 model clocks the core at 168 MHz, so one tick is `1e9 / 168e6 = 5.95`
//! instructions. The program does not trust that figure: it times loops of a known
//! instruction count (`subs; bne`, two instructions per turn) and prints the ticks, and the
//! host derives instructions per tick from them ([`BenchReport::instructions_per_tick`]) and
//! checks it against 168 MHz. DWT CYCCNT is not modelled (reads 0).
//!
//! Each timed call is bracketed by two SysTick reads; the reads' own cost is measured the
//! same way around nothing (`overhead`) and subtracted. A single call is resolved to one
//! tick (about 6 instructions): min and max carry that granularity, means over many calls
//! do not. The figures are instructions, not cycles: a Cortex-M4 takes one cycle for most,
//! more for loads, branches taken, divides and flash wait states.
//!
//! Report lines (inside the usual `target-check begin` / `end N` frame):
//!
//! ```text
//! calib {loop turns} {instructions} {ticks}
//! stat {name} {count} {min ticks} {max ticks} {sum of ticks}
//! info {key} {value}
//! ```

use core::fmt::{self, Write};

/// SysTick is a 24-bit down-counter.
pub const SYST_MASK: u32 = 0x00FF_FFFF;

/// Running statistics of one measured operation, in SysTick ticks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stat {
    /// Calls timed.
    pub count: u32,
    /// Fewest ticks of one call.
    pub min: u32,
    /// Most ticks of one call.
    pub max: u32,
    /// Ticks of all calls.
    pub sum: u64,
}

impl Default for Stat {
    fn default() -> Self {
        Stat {
            count: 0,
            min: u32::MAX,
            max: 0,
            sum: 0,
        }
    }
}

impl Stat {
    /// Adds one call of `ticks`.
    pub fn add(&mut self, ticks: u32) {
        self.count = self.count.saturating_add(1);
        self.min = self.min.min(ticks);
        self.max = self.max.max(ticks);
        self.sum = self.sum.saturating_add(ticks as u64);
    }

    /// Writes the `stat` line.
    pub fn write(&self, w: &mut impl Write, name: &str) -> fmt::Result {
        let min = if self.count == 0 { 0 } else { self.min };
        writeln!(
            w,
            "stat {name} {} {min} {} {}",
            self.count, self.max, self.sum
        )
    }
}

/// Ticks between two reads of the down-counting SysTick (`start` read first); correct
/// across one wrap of the 24-bit counter when the reload value is [`SYST_MASK`].
#[inline(always)]
pub fn ticks_between(start: u32, end: u32) -> u32 {
    start.wrapping_sub(end) & SYST_MASK
}

#[cfg(not(target_os = "none"))]
pub use self::host::*;

#[cfg(not(target_os = "none"))]
mod host {
    use super::Stat;
    use std::format;
    use std::string::{String, ToString};
    use std::vec::Vec;

    /// The nominal core clock of QEMU's netduinoplus2 (and of the STM32F405 at full speed).
    pub const CORE_HZ: f64 = 168e6;

    /// A parsed bench report.
    #[derive(Debug, Clone, Default)]
    pub struct BenchReport {
        /// `(loop turns, instructions, ticks)` of each calibration loop.
        pub calib: Vec<(u64, u64, u64)>,
        /// Statistics by name, in report order.
        pub stats: Vec<(String, Stat)>,
        /// Other figures by key, in report order.
        pub info: Vec<(String, String)>,
    }

    /// One statistic converted to instructions (overhead of the SysTick reads removed).
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct Instructions {
        /// Calls.
        pub count: u32,
        /// Fewest instructions of one call (+- one tick).
        pub min: f64,
        /// Mean.
        pub mean: f64,
        /// Most instructions of one call (+- one tick).
        pub max: f64,
    }

    impl BenchReport {
        /// Reads the case lines of a report (see the module docs).
        pub fn parse<'a>(lines: impl IntoIterator<Item = &'a str>) -> Result<Self, String> {
            let mut r = BenchReport::default();
            for line in lines {
                let f: Vec<&str> = line.split_whitespace().collect();
                let num = |i: usize| -> Result<u64, String> {
                    f.get(i)
                        .and_then(|s| s.parse().ok())
                        .ok_or_else(|| format!("bad field {i} in `{line}`"))
                };
                match f.first().copied() {
                    Some("calib") if f.len() == 4 => r.calib.push((num(1)?, num(2)?, num(3)?)),
                    Some("stat") if f.len() == 6 => {
                        let n32 =
                            |i| num(i).and_then(|v| u32::try_from(v).map_err(|e| e.to_string()));
                        let s = Stat {
                            count: n32(2)?,
                            min: n32(3)?,
                            max: n32(4)?,
                            sum: num(5)?,
                        };
                        r.stats.push((f[1].to_string(), s));
                    }
                    Some("info") if f.len() >= 3 => {
                        r.info.push((f[1].to_string(), f[2..].join(" ")));
                    }
                    _ => return Err(format!("unknown bench line `{line}`")),
                }
            }
            if r.calib.is_empty() {
                return Err("no calibration lines".into());
            }
            Ok(r)
        }

        /// A statistic by name.
        pub fn stat(&self, name: &str) -> Option<Stat> {
            self.stats.iter().find(|(n, _)| n == name).map(|(_, s)| *s)
        }

        /// An info value by key.
        pub fn info(&self, key: &str) -> Option<&str> {
            self.info
                .iter()
                .find(|(k, _)| k == key)
                .map(|(_, v)| v.as_str())
        }

        /// Instructions per SysTick tick, from the longest calibration loop (the others
        /// only show that the relation is linear).
        pub fn instructions_per_tick(&self) -> f64 {
            self.calib
                .iter()
                .max_by_key(|c| c.1)
                .map(|&(_, insns, ticks)| insns as f64 / ticks.max(1) as f64)
                .unwrap_or(f64::NAN)
        }

        /// SysTick frequency in virtual time [Hz] implied by the calibration (1 instruction
        /// = 1 ns under `-icount shift=0`).
        pub fn systick_hz(&self) -> f64 {
            1e9 / self.instructions_per_tick()
        }

        /// Mean ticks of the empty measurement (the two SysTick reads and the fences).
        pub fn overhead_ticks(&self) -> f64 {
            self.stat("overhead")
                .filter(|s| s.count > 0)
                .map(|s| s.sum as f64 / s.count as f64)
                .unwrap_or(0.0)
        }

        /// A statistic in instructions, the measuring overhead subtracted.
        pub fn instructions(&self, name: &str) -> Option<Instructions> {
            let s = self.stat(name).filter(|s| s.count > 0)?;
            let k = self.instructions_per_tick();
            let o = self.overhead_ticks();
            let conv = |t: f64| ((t - o) * k).max(0.0);
            Some(Instructions {
                count: s.count,
                min: conv(s.min as f64),
                mean: conv(s.sum as f64 / s.count as f64),
                max: conv(s.max as f64),
            })
        }
    }
}
