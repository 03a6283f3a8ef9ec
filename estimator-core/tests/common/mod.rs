//! Synthetic cuts for the monitor tests: instantaneous forces from the closed-form
//! per-flute integrals of paper 000 eq. 4 (helical flute, coefficients at `t_a`), turned
//! into what the board sees (drive currents with lag and noise, encoder pulses).
//!
//! Independent of the code under test: it never calls eq. 7 or the tooth averager; the
//! per-tooth averages the monitor computes have to come out of the time signal.
#![allow(dead_code)]

use estimator_core::geometry::{average_chip_thickness_mm, engaged_arc_rad, entry_exit_rad};
use estimator_core::{CuttingCoefficients, MillingMode, Tool};
use std::f64::consts::PI;

/// Instantaneous total forces on the cutter `(F_t-sum, F_x, F_y)` [N] at rotation angle
/// `theta` of flute 0, for chip loads `tc_per_flute` (runout makes them unequal) and the
/// coefficients held at the nominal `t_a`.
#[allow(clippy::too_many_arguments)]
pub fn instantaneous(
    tool: &Tool,
    coeffs: &CuttingCoefficients,
    mode: MillingMode,
    rr: f64,
    ra: f64,
    tc_nominal: f64,
    tc_per_flute: &[f64],
    theta: f64,
) -> (f64, f64, f64) {
    let r = tool.radius_mm as f64;
    let tan_b = (tool.helix_deg as f64).to_radians().tan();
    let (st, ex) = entry_exit_rad(mode, rr as f32);
    let (st, ex) = (st as f64, ex as f64);
    let t_a = average_chip_thickness_mm(tc_nominal as f32, rr as f32, engaged_arc_rad(rr as f32));
    let ks = coeffs.ks.at(t_a) as f64;
    let r1 = coeffs.r1.at(t_a) as f64;
    let da = ra * r;
    let phi_a = da * tan_b / r;
    let n = tool.flutes as usize;
    let (mut ft, mut fx, mut fy) = (0.0, 0.0, 0.0);
    for j in 0..n {
        let tc = tc_per_flute.get(j).copied().unwrap_or(tc_nominal).max(0.0);
        let phi = (theta + j as f64 * 2.0 * PI / n as f64).rem_euclid(2.0 * PI);
        if tan_b == 0.0 {
            if phi >= st && phi <= ex {
                let dft = ks * tc * phi.sin() * da;
                ft += dft;
                fx += dft * (phi.cos() + r1 * phi.sin());
                fy += dft * (-phi.sin() + r1 * phi.cos());
            }
            continue;
        }
        // Engaged heights map to angles [phi - phi_a, phi] (mod 2 pi); with phi in
        // [0, 2 pi) and the arc inside [0, pi], only shifts 0..=(phi_a + pi) / 2 pi meet it.
        let k = ks * tc * r / tan_b;
        let m_max = ((phi_a + PI) / (2.0 * PI)).ceil() as i64;
        for m in 0..=m_max {
            let hi = (phi + 2.0 * PI * m as f64).min(ex);
            let lo = (phi + 2.0 * PI * m as f64 - phi_a).max(st);
            if hi > lo {
                // Antiderivatives of sin, sin cos, sin^2.
                let c = lo.cos() - hi.cos();
                let a = 0.5 * (hi.sin().powi(2) - lo.sin().powi(2));
                let b = 0.5 * (hi - lo) - 0.25 * ((2.0 * hi).sin() - (2.0 * lo).sin());
                ft += k * c;
                fx += k * (a + r1 * b);
                fy += k * (-b + r1 * a);
            }
        }
    }
    (ft, fx, fy)
}

/// Deterministic xorshift + Box-Muller, so failures reproduce.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed.max(1))
    }
    pub fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    pub fn gauss(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
    }
}
