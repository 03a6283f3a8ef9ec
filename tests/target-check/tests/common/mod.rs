//! The synthetic raw trace the QEMU replay and the bench run: deterministic, motor route,
//! built from the core's own forward model under `MonitorConfig::default()`'s drive models.
//!
//! 5 kS/s, 600 rpm, 4 flutes (125 samples per tooth, one sync pulse per tooth), feed along
//! +X at `t_c * N * rpm`. On top of the per-tooth averages of `average_forces`: a
//! within-tooth ripple (zero mean over a tooth), runout (flute factors with unit mean over a
//! revolution) and uniform noise from a fixed-seed xorshift. Events, so that most status
//! paths show up: air cut (not cutting), entry (transient, settling), a rise of radial
//! engagement over 3 revolutions, a NaN spindle sample (input fault), a lost sync pulse (period invalid), a
//! feed override (feed change), exit into an air cut.
//!
//! Length: 5.2 s = 26 000 samples = 624 KB as a TMS1 blob (24 bytes per sample), well
//! inside the 1 MiB flash of the QEMU image beside about 70 KB of code.

#![allow(dead_code)] // each test binary uses part of it

use estimator_core::monitor::Input;
use estimator_core::{
    average_forces, Engagement, MillingMode, MonitorConfig, Sample, Tool, TABLE2,
};

/// Sample rate [Hz].
pub const SAMPLE_RATE_HZ: f32 = 5000.0;
/// Spindle speed [rpm].
pub const RPM: f32 = 600.0;
/// Samples per tooth period.
pub const PER_TOOTH: u32 = 125;
/// Trace length [samples].
pub const SAMPLES: u32 = 26_000;

/// One row: time, what the board sees, and the truth behind it.
#[derive(Clone, Copy, Debug)]
pub struct SynthRow {
    /// [s].
    pub time_s: f64,
    /// Inputs.
    pub sample: Sample,
    /// Radial, axial depth [mm] (0 in air).
    pub dr_mm: f32,
    /// Axial depth [mm].
    pub da_mm: f32,
    /// Feed per tooth [mm].
    pub tc_mm: f32,
    /// Per-tooth average forces behind the signals: F_ax, F_ay, F_at [N].
    pub forces_n: [f32; 3],
}

/// Engagement at sample `i`: `(rr, ra, tc_mm)`, `rr = 0` in air.
fn schedule(i: u32) -> (f32, f32, f32) {
    let t = i as f32 / SAMPLE_RATE_HZ;
    let tc = if t < 3.6 { 0.15 } else { 0.18 };
    // The radial engagement grows over 3 revolutions, as a wall entered over travel does:
    // a step inside one tooth period is what a flute taking a broken one's chip looks
    // like to the breakage rules' first tooth.
    let rr = match t {
        t if t < 0.3 => 0.0,
        t if t < 1.4 => 0.5,
        t if t < 1.7 => 0.5 + 0.7 * (t - 1.4) / 0.3,
        t if t < 4.6 => 1.2,
        _ => 0.0,
    };
    (rr, 1.0, tc)
}

/// Sample of the NaN spindle reading.
const NAN_AT: u32 = 12_060; // 2.412 s
/// Tooth boundary whose pulse is lost.
const LOST_PULSE_AT: u32 = 120 * PER_TOOTH; // 3.0 s

/// Fixed-seed xorshift32, uniform in [-1, 1).
struct Noise(u32);

impl Noise {
    fn next(&mut self) -> f32 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.0 = x;
        (x >> 8) as f32 / (1u32 << 23) as f32 - 1.0
    }
}

/// The whole trace.
pub fn rows() -> Vec<SynthRow> {
    let cfg = MonitorConfig::default();
    let Input::Motor { feed, spindle } = cfg.input else {
        panic!("MonitorConfig::default() is expected to be the motor route");
    };
    let tool = Tool::PAPER;
    let flutes = tool.flutes as u32;
    let mut noise = Noise(0x1234_5678);
    let mut out = Vec::with_capacity(SAMPLES as usize);
    for i in 0..SAMPLES {
        let (rr, ra, tc) = schedule(i);
        let v = tc * flutes as f32 * RPM; // mm/min
        let f = if rr > 0.0 {
            average_forces(
                &tool,
                &TABLE2,
                MillingMode::Down,
                Engagement { rr, ra, tc_mm: tc },
            )
        } else {
            Default::default()
        };
        // Within the tooth: ripple of zero mean; across flutes: runout of unit mean.
        let j = i % PER_TOOTH;
        let flute = (i / PER_TOOTH) % flutes;
        let phase = 2.0 * std::f32::consts::PI * j as f32 / PER_TOOTH as f32;
        let shape = (1.0 + 0.4 * phase.sin() + 0.15 * (2.0 * phase).cos())
            * (1.0 + 0.03 * (std::f32::consts::FRAC_PI_2 * flute as f32).cos());
        let vel = [v + 0.5 * noise.next(), 0.0];
        let fx = f.fx_n * shape + 0.5 * noise.next();
        let ft = f.ft_n * shape + 0.5 * noise.next();
        // One-axis drive: the Y channel is not written to the CSV and reads back as 0.
        let currents = [feed.currents_for_loads_a([fx, 0.0], vel)[0], 0.0];
        let mut spindle_a = spindle.signal_for_force(ft, RPM, tool.radius_mm);
        if i == NAN_AT {
            spindle_a = f32::NAN;
        }
        let sync = j == 0 && i != LOST_PULSE_AT;
        out.push(SynthRow {
            time_s: i as f64 / SAMPLE_RATE_HZ as f64,
            sample: Sample {
                feed: currents,
                feed_velocity_mm_min: vel,
                spindle: spindle_a,
                sync,
            },
            dr_mm: rr * tool.radius_mm,
            da_mm: ra * tool.radius_mm,
            tc_mm: tc,
            forces_n: [f.fx_n, f.fy_n, f.ft_n],
        });
    }
    out
}

/// The trace as a TMS1 blob, by target-check's own encoder (host-sim's is the reference;
/// the QEMU test uses that one).
pub fn blob(rows: &[SynthRow]) -> Vec<u8> {
    let samples: Vec<Sample> = rows.iter().map(|r| r.sample).collect();
    let mut out = vec![0u8; target_check::tms1::HEADER_LEN + 24 * samples.len()];
    let n = target_check::tms1::encode_into(SAMPLE_RATE_HZ, &samples, &mut out)
        .expect("buffer sized for the samples");
    out.truncate(n);
    out
}

/// What a list of record lines holds: total, valid, and how often each status flag is set.
#[derive(Debug, Default)]
pub struct Summary {
    /// Records.
    pub records: usize,
    /// Records with an empty status.
    pub valid: usize,
    /// Per flag name (in `Status::NAMES` order), records carrying it.
    pub flags: Vec<(&'static str, usize)>,
}

impl Summary {
    /// From `"{idx} {w0:08x} ..."` lines (`ToothRecord::to_words`: status is word 17).
    pub fn of(lines: &[String]) -> Summary {
        use estimator_core::Status;
        let mut s = Summary {
            flags: Status::NAMES.iter().map(|(_, n)| (*n, 0)).collect(),
            ..Summary::default()
        };
        for l in lines {
            let w: Vec<&str> = l.split_whitespace().collect();
            let status = w
                .get(1 + 17)
                .and_then(|h| u32::from_str_radix(h, 16).ok())
                .unwrap_or_else(|| panic!("no status word in `{l}`"));
            let status = Status(status as u16);
            s.records += 1;
            s.valid += status.is_valid() as usize;
            for ((flag, _), (_, n)) in Status::NAMES.iter().zip(&mut s.flags) {
                *n += status.contains(*flag) as usize;
            }
        }
        s
    }
}

impl std::fmt::Display for Summary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} records, {} valid", self.records, self.valid)?;
        for (name, n) in &self.flags {
            if *n > 0 {
                write!(f, ", {n} {name}")?;
            }
        }
        Ok(())
    }
}

/// The case lines of a framed report, failing the test with the raw output if malformed.
pub fn case_lines(side: &str, output: &str) -> Vec<String> {
    let mut lines = Vec::new();
    if let Err(e) = target_check::parse_report(output, |l| lines.push(l.to_owned())) {
        panic!("{side} report unreadable: {e}\n--- {side} output ---\n{output}");
    }
    lines
}
