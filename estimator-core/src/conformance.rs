//! A fixed set of cases run through the forward model and the estimators, so that host
//! (x86_64) and target (thumbv7em, under QEMU) can be compared bit for bit: both call
//! [`run`] and print the same lines, `tests/target-check` diffs them.
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

/// Runs every case and hands `out(case_index, bit patterns of all its outputs)`.
pub fn run(out: &mut impl FnMut(u32, &[u32])) {
    let mut case = 0u32;
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
