//! Exact inversion of the force ratios for `R_r`: the reference for the polynomial and its
//! fallback outside the fitted range.
//!
//! The unknown is `x = -sqrt(2 - R_r)` in `[-sqrt(2 - R_MIN), 0]` rather than `R_r`: near
//! the slot the ratios go as `f_slot - c sqrt(2 - R_r)` (`d f / d R_r -> infinity`), which is
//! linear in `x`, so a root finder in `x` sees a well-behaved function; `x` rises with
//! `R_r`, the slot is `x = 0`, and the engaged arc is `acos(x^2 - 1)` (a cheap `acosf`, no
//! `cosf`: see [`crate::fmath`]). On the branch that contains the slot each ratio is
//! monotonic in `u`; `f_xt` in down milling is monotonic on the whole range (method.md,
//! tested), the others turn over at light cuts (`r1` grows without bound as `t_a -> 0`),
//! so their branch ends at the extremum, found by golden-section search. Roots: Illinois
//! (regula falsi with the stale end halved), bracketed, so it cannot leave the interval.

use crate::coefficients::CuttingCoefficients;
use crate::forward::Operating;
use crate::geometry::{ArcIntegrals, MillingMode, RR_MIN};
use crate::status::Status;

/// Which measured ratio is being inverted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ratio {
    /// `f_xt = F_ax / F_at` (feed motor + spindle motor).
    Fxt,
    /// `f_x = F_ax / |(F_ax, F_ay)|` (dynamometer).
    Fx,
}

/// `R_r` at the solver's variable `x = -sqrt(2 - R_r)`.
#[inline]
fn rr_at(x: f32) -> f32 {
    2.0 - x * x
}

/// The ratio as a function of the solver's variable `x = -sqrt(2 - R_r)`.
pub fn ratio_at(
    coeffs: &CuttingCoefficients,
    mode: MillingMode,
    ratio: Ratio,
    x: f32,
    tc_mm: f32,
) -> f32 {
    let rr = rr_at(x);
    let arc = libm::acosf(1.0 - rr);
    let op = Operating::from_integrals(coeffs, ArcIntegrals::from_arc(mode, rr, arc), tc_mm);
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

/// Lower end of the search: `R_r = RR_MIN`.
fn x_min() -> f32 {
    -libm::sqrtf(2.0 - RR_MIN)
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
    // Work with g(x) = s * ratio(x), increasing in x on the branch that ends at the slot.
    let s = if rises(mode, ratio) { 1.0 } else { -1.0 };
    let g = |x: f32| s * ratio_at(coeffs, mode, ratio, x, tc_mm);
    let (x_min, x_slot) = (x_min(), 0.0);
    let x_lo = if ratio == Ratio::Fxt && mode == MillingMode::Down {
        x_min
    } else {
        argmin(&g, x_min, x_slot)
    };
    let t = s * target;
    let (g_lo, g_hi) = (g(x_lo), g(x_slot));
    let mut status = Status::VALID;
    let x = if t <= g_lo {
        status |= Status::RR_CLAMPED;
        x_lo
    } else if t >= g_hi {
        status |= Status::RR_CLAMPED;
        x_slot
    } else {
        // Any part of the other branch (x < x_lo) reaching the same value makes the
        // answer ambiguous; g on that branch lies between g(x_min) and g(x_lo).
        status.set_if(
            x_lo > x_min && t >= g_lo && t <= g(x_min),
            Status::AMBIGUOUS,
        );
        illinois(&g, t, x_lo, x_slot, g_lo, g_hi)
    };
    if x_lo > x_min && status.contains(Status::RR_CLAMPED) && x == x_lo {
        // Below the turning point the ratio is insensitive to R_r.
        status |= Status::AMBIGUOUS;
    }
    Inverted {
        rr: rr_at(x).clamp(RR_MIN, 2.0),
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
        // x ends at 0 (the slot): an absolute tolerance, at f32 resolution of x ~ 1.
        if hi - lo <= 4.0 * f32::EPSILON {
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
