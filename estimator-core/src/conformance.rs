//! A fixed set of cases run through the forward model and the estimators, so that host
//! (x86_64) and target (thumbv7em, under QEMU) can be compared bit for bit: both call
//! [`run`] and print the same lines, `tests/target-check` diffs them.
//!
//! The hand-over stage's drop trip runs here too, through a current loop's lag with the
//! lag allowed for, not, and half (the lag's terms: `Handover::lagged`'s `expf`, each
//! close's plateau, the trip's share corrected and the span measured with the lag undone).
//!
//! Why it can differ at all: f32 arithmetic is IEEE on both, and `libm` is pure Rust, but a
//! compiler that fused a multiply-add or a target that used a different `sqrt` would change
//! the last bits. This is the check that it does not.

use crate::estimator::{Estimate, EstimatorConfig, Measured, Solver};
use crate::{average_forces, Engagement, MillingMode, Tool, TABLE2};

const FEEDS_MM: [f32; 5] = [0.02, 0.1042, 0.2083, 0.4167, 0.6];
const IMMERSIONS: [f32; 8] = [0.05, 0.125, 0.3, 0.7, 1.0, 1.5, 1.95, 2.0];

fn push_estimate(buf: &mut [u32; 32], n: &mut usize, e: &Estimate) {
    for v in [
        e.rr.to_bits(),
        e.ra.to_bits(),
        e.dr_mm.to_bits(),
        e.da_mm.to_bits(),
        e.t_a_mm.to_bits(),
        e.status.0 as u32,
        e.method as u32,
    ] {
        if let Some(slot) = buf.get_mut(*n) {
            *slot = v;
            *n += 1;
        }
    }
}

/// Flutes, samples a period (before the jitter), and periods of the hand-over cases.
const HAND_TEETH: u8 = 3;
const HAND_LEN: u32 = 48;
const HAND_PERIODS: u32 = 150;
/// The period in which flute 1 breaks, and the sample of its period it breaks at: near its
/// chip's end (its next pass loses most), or before its chip (that pass loses all).
const HAND_BREAK: u32 = 121;
const HAND_BREAK_AT: [u32; 2] = [30, 0];

/// The drop trip with the current loop's lag allowed for ([`crate::handover`], "Current-loop
/// lag"), where the trip's share, the lag's terms at each close and the whole period's
/// judgement meet: a 3-flute cut (flute 0 heavier, runout), periods of 47 to 49 samples, a
/// little deterministic noise, through a first-order lag of `tau` samples told as `told`;
/// flute 1 breaks inside period [`HAND_BREAK`]. Each flute's chip is a half sine over the
/// first two thirds of its period, the trip armed at 0.4 of the tooth (it trips inside
/// the period); or, `up`, a ramp over the period's second half to its end (up milling's
/// thickest chip last), the trip armed at 0.9, which the period's bins before its last
/// never lose: it trips on the whole period at its close, the lag's plateau terms in it.
/// Each period's close hands the measured hand-over, the noise figure and the span measured
/// ([`crate::handover::Handover::measure_span`]); a trip its loss, its limit and the sample
/// it came at.
fn handover_case(tau: f32, told: f32, up: bool, out: &mut impl FnMut(&[u32])) {
    use crate::handover::{Handover, HandoverState, Period, BINS};
    let h = Handover::new(HAND_TEETH, true, true, true).lagged(told);
    let mut st = HandoverState::default();
    let a = libm::expf(-1.0 / tau);
    let (mut y, mut noise) = (0.0f32, 0x2545_f491u32);
    let (mut last_len, mut last_mean, mut sum) = (HAND_LEN, 0.0f32, 0.0f32);
    for k in 0..HAND_PERIODS {
        let len = HAND_LEN + k % 3 - 1;
        let tooth = (k % HAND_TEETH as u32) as u8;
        let step = crate::window::bin_step(last_len);
        let mut buf = [0u32; 8];
        let mut n = 0usize;
        for pos in 0..len {
            let closed = (pos == 0 && k > 0).then(|| ((k - 1) % HAND_TEETH as u32) as u8);
            let at = HAND_BREAK_AT[usize::from(up)];
            let broken = tooth == 1 && (k > HAND_BREAK || k == HAND_BREAK && pos >= at);
            let gain = if tooth == 0 { 1.3 } else { 1.0 };
            let (cut, half) = (2 * len / 3, len / 2);
            let chip = if up {
                pos.saturating_sub(half) as f32 / (len - half) as f32
            } else if pos < cut {
                libm::sinf(core::f32::consts::PI * pos as f32 / cut as f32)
            } else {
                0.0
            };
            let x = if broken { 0.0 } else { gain * 100.0 * chip };
            noise = noise.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let x = x + 2.0 * ((noise >> 8) as f32 / (1u32 << 24) as f32 - 0.5);
            y = a * y + (1.0 - a) * x;
            let bin = (((pos as u64 * step as u64) >> 16) as usize).min(BINS - 1);
            h.sample(&mut st, closed, bin, y);
            sum += y;
            if let Some(t) = closed {
                h.period_start(&mut st, 0.0, 0.0);
                h.period_len(&mut st, last_len);
                let (z, amount) = h.measure(&mut st, t, Period::Cut { steady: true }, 1.0);
                let share = if up { 0.9 } else { 0.4 };
                // (The closed period's tangential force: its mean, nothing cut being 0.)
                h.arm_trip(&mut st, t, last_mean, share, 0.0, f32::INFINITY, share);
                h.measure_span(&mut st, t, last_mean);
                for v in [z, amount, st.change_var_n2(), st.span_share()] {
                    if let Some(slot) = buf.get_mut(n) {
                        *slot = v.to_bits();
                        n += 1;
                    }
                }
            }
            if let Some((lost, limit)) = h.take_trip(&mut st) {
                for v in [lost.to_bits(), limit.to_bits(), pos] {
                    if let Some(slot) = buf.get_mut(n) {
                        *slot = v;
                        n += 1;
                    }
                }
            }
        }
        (last_len, last_mean, sum) = (len, sum / len as f32, 0.0);
        out(buf.get(..n).unwrap_or(&[]));
    }
}

/// Runs every case and hands `out(case_index, bit patterns of all its outputs)`.
pub fn run(out: &mut impl FnMut(u32, &[u32])) {
    let mut case = 0u32;
    // The hand-over stage through a lag: told it, told none, and told half of it.
    for up in [false, true] {
        for (tau, told) in [(4.5, 4.5), (4.5, 0.0), (4.5, 2.25)] {
            handover_case(tau, told, up, &mut |bits| {
                out(case, bits);
                case += 1;
            });
        }
    }
    for mode in [MillingMode::Down, MillingMode::Up] {
        let configs = [Solver::Auto, Solver::Inversion, Solver::Table3].map(|solver| {
            EstimatorConfig {
                mode,
                solver,
                ..Default::default()
            }
            .build()
            .ok()
        });
        for tc in FEEDS_MM {
            for rr in IMMERSIONS {
                let f = average_forces(
                    &Tool::PAPER,
                    &TABLE2,
                    mode,
                    Engagement {
                        rr,
                        ra: 1.5,
                        tc_mm: tc,
                    },
                );
                let mut buf = [0u32; 32];
                let mut n = 0;
                for v in [f.ft_n, f.fx_n, f.fy_n, f.fz_n] {
                    buf[n] = v.to_bits();
                    n += 1;
                }
                let motor = Measured::Motor {
                    fx_n: f.fx_n,
                    ft_n: f.ft_n,
                };
                let dyn_ = Measured::Dynamometer {
                    fx_n: f.fx_n,
                    fy_n: f.fy_n,
                };
                for (cfg, m) in [
                    (&configs[0], motor),
                    (&configs[1], motor),
                    (&configs[0], dyn_),
                    (&configs[2], dyn_),
                ] {
                    // Table 3 does not apply to up milling: its slot stays empty.
                    if let Some(est) = cfg {
                        push_estimate(&mut buf, &mut n, &est.estimate(tc, m));
                    }
                }
                out(case, &buf[..n]);
                case += 1;
            }
        }
    }
    // Inputs a broken signal chain can produce.
    if let Ok(est) = EstimatorConfig::default().build() {
        for (tc, fx, ft) in [
            (f32::NAN, -10.0, 100.0),
            (0.1, f32::INFINITY, 100.0),
            (0.1, -10.0, 0.5),
            (0.1, -150.0, 100.0),
            (0.1, 90.0, 100.0),
            (1e-30, 1e30, 1e-30),
            (3e4, -1e-3, 1e20),
        ] {
            let mut buf = [0u32; 32];
            let mut n = 0;
            push_estimate(
                &mut buf,
                &mut n,
                &est.estimate(tc, Measured::Motor { fx_n: fx, ft_n: ft }),
            );
            out(case, &buf[..n]);
            case += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::vec::Vec;

    /// Each period's outputs of a hand-over case, and the periods in which a trip came
    /// with the sample it came at (a trip on the whole period at its close: the next
    /// period's sample 0).
    fn periods(tau: f32, told: f32, up: bool) -> (Vec<Vec<u32>>, Vec<(usize, u32)>) {
        let mut all = Vec::new();
        handover_case(tau, told, up, &mut |bits| all.push(bits.to_vec()));
        let trips = all
            .iter()
            .enumerate()
            .filter(|(k, b)| b.len() == if *k > 0 { 7 } else { 3 })
            .map(|(k, b)| (k, b[b.len() - 1]))
            .collect();
        (all, trips)
    }

    /// The hand-over cases reach what they are there for: told the lag, the broken flute's
    /// pass trips the drop trip (nothing before the break), inside the period for the half
    /// sine and at the period's close for the ramp; and the lag's terms change the bits the
    /// grid compares (told none, the ramp's close does not trip at all).
    #[test]
    fn the_hand_over_cases_trip_at_the_break_and_the_lag_terms_count() {
        for up in [false, true] {
            let (told, trips) = periods(4.5, 4.5, up);
            let (untold, untold_trips) = periods(4.5, 0.0, up);
            let (half, _) = periods(4.5, 2.25, up);
            assert_eq!(told.len(), HAND_PERIODS as usize);
            // Inside the broken flute's next pass, or at the close of its first pass
            // without a chip (the next period's first sample).
            let pass = (HAND_BREAK + if up { 0 } else { u32::from(HAND_TEETH) }) as usize;
            let first = trips.first().copied();
            let right = if up {
                first == Some((pass + 1, 0))
            } else {
                first.is_some_and(|(k, p)| k == pass && p > 0)
            };
            assert!(right, "up {up}: trips {trips:?}");
            assert!(
                !up || untold_trips.is_empty(),
                "told none: {untold_trips:?}"
            );
            assert_ne!(told, untold, "up {up}");
            assert_ne!(told, half, "up {up}");
        }
    }
}
