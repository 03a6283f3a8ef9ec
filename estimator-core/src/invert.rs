//! Exact inversion of the force ratios for `R_r`: the reference for the polynomial and its
//! fallback outside the fitted range.
//!
//! The unknown is the engaged arc `u = acos(1 - R_r)` in `(0, pi]` rather than `R_r`:
//! near the slot `dR_r/du -> 0` where `d f / d R_r -> infinity`, so a root finder in `u`
//! sees a well-behaved function. On the branch that contains the slot each ratio is
//! monotonic in `u`; `f_xt` in down milling is monotonic on the whole range (method.md,
//! tested), the others turn over at light cuts (`r1` grows without bound as `t_a -> 0`),
//! so their branch ends at the extremum, found by golden-section search. Roots: Illinois
//! (regula falsi with the stale end halved), bracketed, so it cannot leave the interval.

use crate::coefficients::CuttingCoefficients;
use crate::forward::Operating;
use crate::geometry::{ArcIntegrals, MillingMode, RR_MIN};
use crate::status::Status;
use core::f32::consts::PI;

/// Which measured ratio is being inverted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ratio {
    /// `f_xt = F_ax / F_at` (feed motor + spindle motor).
    Fxt,
    /// `f_x = F_ax / |(F_ax, F_ay)|` (dynamometer).
    Fx,
}

/// The ratio as a function of the engaged arc `u`.
pub fn ratio_at_arc(
    coeffs: &CuttingCoefficients,
    mode: MillingMode,
    ratio: Ratio,
    u: f32,
    tc_mm: f32,
) -> f32 {
    let rr = 1.0 - libm::cosf(u);
    let op = Operating::from_integrals(coeffs, ArcIntegrals::from_arc(mode, rr, u), tc_mm);
    match ratio {
        Ratio::Fxt => op.ratio_fxt(),
        Ratio::Fx => op.ratio_fx(),
    }
}

/// Whether the ratio rises with `R_r` on the slot-side branch.
fn rises(mode: MillingMode, ratio: Ratio) -> bool {
    matches!(
        (ratio, mode),
        (Ratio::Fxt, MillingMode::Down) | (Ratio::Fx, MillingMode::Down)
    )
}

/// Smallest arc searched: `R_r = RR_MIN`.
fn arc_min() -> f32 {
    libm::acosf(1.0 - RR_MIN)
}

/// Result of an inversion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inverted {
    /// Radial immersion ratio, always in `[RR_MIN, 2]`.
    pub rr: f32,
    /// `RR_CLAMPED` and/or `AMBIGUOUS`, else valid.
    pub status: Status,
}

/// Solves `ratio(R_r, t_c) = target` for `R_r` on the branch that contains the slot.
///
/// `target` and `tc_mm` must be finite and `tc_mm > 0` (the estimator checks).
pub fn invert(
    coeffs: &CuttingCoefficients,
    mode: MillingMode,
    ratio: Ratio,
    target: f32,
    tc_mm: f32,
) -> Inverted {
    // Work with g(u) = s * (ratio(u) - target), increasing in u on the branch.
    let s = if rises(mode, ratio) { 1.0 } else { -1.0 };
    let g = |u: f32| s * ratio_at_arc(coeffs, mode, ratio, u, tc_mm);
    let u_min = arc_min();
    let u_lo = if ratio == Ratio::Fxt && mode == MillingMode::Down {
        u_min
    } else {
        argmin(&g, u_min, PI)
    };
    let t = s * target;
    let (g_lo, g_hi) = (g(u_lo), g(PI));
    let mut status = Status::VALID;
    let u = if t <= g_lo {
        status |= Status::RR_CLAMPED;
        u_lo
    } else if t >= g_hi {
        status |= Status::RR_CLAMPED;
        PI
    } else {
        // Any part of the other branch (u < u_lo) reaching the same value makes the
        // answer ambiguous; g on that branch lies between g(u_min) and g(u_lo).
        status.set_if(
            u_lo > u_min && t >= g_lo && t <= g(u_min),
            Status::AMBIGUOUS,
        );
        illinois(&g, t, u_lo, PI, g_lo, g_hi)
    };
    if u_lo > u_min && status.contains(Status::RR_CLAMPED) && u == u_lo {
        // Below the turning point the ratio is insensitive to R_r.
        status |= Status::AMBIGUOUS;
    }
    Inverted {
        rr: (1.0 - libm::cosf(u)).clamp(RR_MIN, 2.0),
        status,
    }
}

/// Golden-section search for the minimum of a unimodal `g` on `[a, b]`.
fn argmin(g: &impl Fn(f32) -> f32, mut a: f32, mut b: f32) -> f32 {
    const INV_PHI: f32 = 0.618_034;
    let mut c = b - INV_PHI * (b - a);
    let mut d = a + INV_PHI * (b - a);
    let (mut gc, mut gd) = (g(c), g(d));
    // 24 steps shrink the interval by 1e-5: plenty for a bracket end.
    for _ in 0..24 {
        if gc < gd {
            b = d;
            d = c;
            gd = gc;
            c = b - INV_PHI * (b - a);
            gc = g(c);
        } else {
            a = c;
            c = d;
            gc = gd;
            d = a + INV_PHI * (b - a);
            gd = g(d);
        }
    }
    // The minimum may sit at an end of the interval (monotonic g).
    let (ga, gb, gm) = (g(a), g(b), gc.min(gd));
    if ga <= gm && ga <= gb {
        a
    } else if gb <= gm {
        b
    } else if gc < gd {
        c
    } else {
        d
    }
}

/// Root of increasing `g(u) = t` in `[lo, hi]` with `g(lo) < t < g(hi)`.
fn illinois(
    g: &impl Fn(f32) -> f32,
    t: f32,
    mut lo: f32,
    mut hi: f32,
    g_lo: f32,
    g_hi: f32,
) -> f32 {
    let (mut e_lo, mut e_hi) = (g_lo - t, g_hi - t);
    let mut side = 0i8;
    let mut x = 0.5 * (lo + hi);
    for _ in 0..40 {
        x = (lo * e_hi - hi * e_lo) / (e_hi - e_lo);
        if !(x > lo && x < hi) {
            x = 0.5 * (lo + hi);
        }
        if hi - lo <= 4.0 * f32::EPSILON * hi {
            break;
        }
        let e = g(x) - t;
        if e == 0.0 {
            break;
        } else if e > 0.0 {
            hi = x;
            e_hi = e;
            if side == -1 {
                e_lo *= 0.5;
            }
            side = -1;
        } else {
            lo = x;
            e_lo = e;
            if side == 1 {
                e_hi *= 0.5;
            }
            side = 1;
        }
        if e.abs() <= 2.0 * f32::EPSILON * t.abs().max(1e-3) {
            break;
        }
    }
    x
}
