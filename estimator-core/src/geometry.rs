//! Cutting geometry of peripheral end milling (paper 000, section 2; method.md section 1).
//!
//! # Sign conventions (the whole crate relies on these)
//! - `x` is the feed direction, `y` normal to it in the tool plane, `z` the tool axis.
//! - The immersion angle `phi` is measured so that the chip thickness is
//!   `h(phi) = t_c sin(phi)`: a tooth cuts only for `phi` in `(0, pi)`.
//! - Down (climb) milling: a tooth enters at `phi_en = acos(R_r - 1)` and leaves at `pi`
//!   (thick chip at entry, zero at exit). Up (conventional) milling mirrors it: enters at
//!   `0`, leaves at `acos(1 - R_r)`.
//! - Elemental forces (eq. 1-3): `dF_x = dF_t cos(phi) + dF_r sin(phi)`,
//!   `dF_y = -dF_t sin(phi) + dF_r cos(phi)`, `dF_z = dF_a`. With these, the average feed
//!   force `F_ax` is negative for light down-milling cuts (the cutter pulls the work) and
//!   positive in a slot.
//!
//! In both modes the engaged arc has the same length `acos(1 - R_r)`; only its position
//! differs, which flips the sign of the `sin cos` integral `a` and nothing else.

use core::f32::consts::PI;

/// Which way the tooth meets the work.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum MillingMode {
    /// Climb milling: chip thick at entry, zero at exit (the paper's case).
    #[default]
    Down,
    /// Conventional milling: chip zero at entry.
    Up,
}

/// Flat end mill.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Tool {
    /// Tool radius `R` [mm].
    pub radius_mm: f32,
    /// Number of flutes `N`.
    pub flutes: u8,
    /// Helix angle `beta` [deg]; the per-tooth averages do not depend on it.
    pub helix_deg: f32,
}

impl Tool {
    /// The paper's tool: 16 mm diameter, 4 flutes; helix 30 deg (not stated in the paper).
    pub const PAPER: Tool = Tool {
        radius_mm: 8.0,
        flutes: 4,
        helix_deg: 30.0,
    };

    /// Tooth period `phi_N = 2 pi / N` [rad].
    pub fn tooth_pitch_rad(&self) -> f32 {
        2.0 * PI / self.flutes as f32
    }

    /// Checks the tool once, so that the per-sample code need not.
    pub fn validate(&self) -> Result<(), crate::ConfigError> {
        use crate::ConfigError::*;
        if !self.radius_mm.is_finite() || !self.helix_deg.is_finite() {
            return Err(NonFinite("tool"));
        }
        if self.radius_mm <= 0.0 {
            return Err(OutOfRange("radius_mm"));
        }
        if self.flutes == 0 {
            return Err(OutOfRange("flutes"));
        }
        if !(0.0..90.0).contains(&self.helix_deg) {
            return Err(OutOfRange("helix_deg"));
        }
        Ok(())
    }
}

/// Smallest radial immersion ratio the estimators resolve; below it chip thickness and the
/// power-law coefficients run away (`t_a -> 0`).
pub const RR_MIN: f32 = 1e-3;
/// Largest axial immersion ratio reported (a flute length of 32 radii); beyond it the
/// forces are not from a cut and `R_a` is clamped and flagged.
pub const RA_MAX: f32 = 32.0;
/// Full slot.
pub const RR_MAX: f32 = 2.0;

/// Length of the engaged arc `acos(1 - R_r)` [rad], the same for up and down milling.
#[inline]
pub fn engaged_arc_rad(rr: f32) -> f32 {
    libm::acosf(1.0 - rr)
}

/// Entry and exit angles `(phi_st, phi_ex)` [rad] of a tooth.
pub fn entry_exit_rad(mode: MillingMode, rr: f32) -> (f32, f32) {
    let arc = engaged_arc_rad(rr);
    match mode {
        MillingMode::Down => (PI - arc, PI),
        MillingMode::Up => (0.0, arc),
    }
}

/// Average chip thickness over the engaged arc (eq. 8): `t_a = t_c R_r / arc` [mm].
#[inline]
pub fn average_chip_thickness_mm(tc_mm: f32, rr: f32, arc_rad: f32) -> f32 {
    tc_mm * rr / arc_rad
}

/// `x - sin(x)` for small `x` (< 0.25), where the difference cancels: Taylor series to
/// x^9, relative error below 1e-9.
fn x_minus_sin_small(x: f32) -> f32 {
    let x2 = x * x;
    x * x2 * (1.0 / 6.0 - x2 * (1.0 / 120.0 - x2 * (1.0 / 5040.0 - x2 / 362_880.0)))
}

/// `tan` of a helix angle in `[0, 90)` degrees, as the ratio of `sin` and `cos` Taylor
/// series to `x^13` and `x^14` (no argument reduction: under `pi / 2` the first terms left
/// out are below 1e-9): libm's `tanf` would bring its reduction of large arguments, 8 KiB
/// of flash, to the board for one call at start-up.
pub fn tan_helix(helix_deg: f32) -> f32 {
    let x = helix_deg * (PI / 180.0);
    let x2 = x * x;
    // Horner in `x^2`, highest term first.
    let sin = x * [
        1.0 / 6_227_020_800.0,
        -1.0 / 39_916_800.0,
        1.0 / 362_880.0,
        -1.0 / 5_040.0,
        1.0 / 120.0,
        -1.0 / 6.0,
        1.0,
    ]
    .iter()
    .fold(0.0f32, |acc, &c| acc * x2 + c);
    let cos = [
        -1.0 / 87_178_291_200.0,
        1.0 / 479_001_600.0,
        -1.0 / 3_628_800.0,
        1.0 / 40_320.0,
        -1.0 / 720.0,
        1.0 / 24.0,
        -0.5,
        1.0,
    ]
    .iter()
    .fold(0.0f32, |acc, &c| acc * x2 + c);
    sin / cos
}

/// `sin(arc) = sqrt(R_r (2 - R_r))` for `arc = acos(1 - R_r)`: no trigonometry (libm's
/// `sinf` costs ~1 300 instructions on the Cortex-M4F, see [`crate::fmath`]).
#[inline]
pub fn arc_sin(rr: f32) -> f32 {
    libm::sqrtf(crate::fmath::max(rr * (2.0 - rr), 0.0))
}

/// Share of a cut's force an exit through a face square to the feed has taken once the
/// arc's far reach is `x R` past the face (`x >= 0`), for radial immersion `rr`.
///
/// The points of the arc `R sin(phi)` ahead of the centre beyond the face cut nothing: the
/// angles with `sin(phi) > s - x`, `s` the largest `sin` on the arc (1 when the arc holds
/// `pi/2`, `R_r >= 1`; `sin(arc)` at its end otherwise). With the chip `t_c sin(phi)` the
/// force lost is `int sin` over them: `q + min(q, R_r - 1)` with `q = sqrt(1 - (s - x)^2)`,
/// of `int sin = R_r` over the arc; both modes (mirror images). Where the arc holds
/// `pi/2` the loss grows as the square root of the travel: the thickest chip leaves first,
/// and fast. Edge forces (in proportion to the arc's length) and the chip exponent of the
/// cutting coefficient spread the loss more evenly: this share is an upper bound for them.
///
/// Out of line: the drop trip's share calls it twice, and inlined it cost the board 120 B
/// of flash.
#[inline(never)]
pub fn exit_loss_share(rr: f32, x: f32) -> f32 {
    let rr = rr.clamp(1e-6, 2.0);
    let s = if rr >= 1.0 { 1.0 } else { arc_sin(rr) };
    let y = s - crate::fmath::max(x, 0.0);
    // (Not `<=`: a NaN, from a NaN `R_r`, counts as everything gone.)
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    if !(y > 0.0) {
        return 1.0;
    }
    let q = libm::sqrtf(crate::fmath::max(1.0 - y * y, 0.0));
    crate::fmath::min((q + crate::fmath::min(q, rr - 1.0)) / rr, 1.0)
}

/// The largest [`exit_loss_share`] over `R_r` from 1 to 2 at a travel `x`: at `R_r = 1 + q`,
/// `q = sqrt(1 - (1 - x)^2)`, both halves of the arc losing alike, `2 q / (1 + q)`.
/// (Out of line: the drop trip's share calls it twice.)
#[inline(never)]
pub fn widest_exit_loss_share(x: f32) -> f32 {
    let q = libm::sqrtf(crate::fmath::max(x * (2.0 - x), 0.0));
    2.0 * q / (1.0 + q)
}

/// The travel `x` (in radii past the arc's far reach) at which an exit through a face has
/// taken `share` of the cut's force: the inverse of [`exit_loss_share`] (0 for a share of
/// 0 or less, the whole reach for 1 or more).
pub fn exit_travel(rr: f32, share: f32) -> f32 {
    let rr = rr.clamp(1e-6, 2.0);
    let share = share.clamp(0.0, 1.0);
    let (s, q) = if rr >= 1.0 {
        // Both halves of the arc lose alike up to `q = R_r - 1`, one alone beyond.
        let half = 0.5 * share * rr;
        (
            1.0,
            if half <= rr - 1.0 {
                half
            } else {
                share * rr - (rr - 1.0)
            },
        )
    } else {
        (arc_sin(rr), share * rr + 1.0 - rr)
    };
    let y = libm::sqrtf(crate::fmath::max(1.0 - q * q, 0.0));
    crate::fmath::max(s - y, 0.0)
}

/// The integrals over the engaged arc behind eq. 7, without the factor
/// `tan(beta) / phi_N` that cancels in every force (the paper's `A_r = tan(beta)/phi_N * a`):
/// `a = int sin cos`, `b = int sin^2`, `c = int sin`, plus the arc itself.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArcIntegrals {
    /// `int sin(t) cos(t) dt`: `(R_r^2 - 2 R_r)/2` down, its negative up.
    pub a: f32,
    /// `int sin^2(t) dt = (2 arc - sin(2 arc)) / 4`, both modes.
    pub b: f32,
    /// `int sin(t) dt = R_r`, both modes.
    pub c: f32,
    /// `int cos(t) dt`: `-sin(arc)` down, `sin(arc)` up (edge forces need it).
    pub cos_int: f32,
    /// Engaged arc [rad].
    pub arc: f32,
}

impl ArcIntegrals {
    /// Integrals for radial immersion ratio `rr` in `(0, 2]`.
    pub fn new(mode: MillingMode, rr: f32) -> Self {
        Self::from_arc(mode, rr, engaged_arc_rad(rr))
    }

    /// Same, with the arc already known (`arc = acos(1 - rr)`).
    pub fn from_arc(mode: MillingMode, rr: f32, arc: f32) -> Self {
        let a_down = 0.5 * rr * (rr - 2.0);
        let sin_arc = arc_sin(rr);
        let (a, cos_int) = match mode {
            MillingMode::Down => (a_down, -sin_arc),
            MillingMode::Up => (-a_down, sin_arc),
        };
        // (2 arc - sin 2 arc) / 4 with sin 2 arc = 2 sin(arc) cos(arc), cos(arc) = 1 - R_r.
        let b = if arc < 0.125 {
            0.25 * x_minus_sin_small(2.0 * arc)
        } else {
            0.5 * (arc - sin_arc * (1.0 - rr))
        };
        ArcIntegrals {
            a,
            cos_int,
            b,
            c: rr,
            arc,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The series against `f64::tan` (std's, not the series) from 0 to 89.9 degrees:
    /// relatively within 4e-7 over `cos` (a few f32 roundings of each series, the ratio's
    /// error growing as `cos` goes to 0).
    #[test]
    fn the_helix_tangent_follows_tan() {
        for tenth in 0..900 {
            let deg = tenth as f32 / 10.0;
            let rad = f64::from(deg).to_radians();
            let (want, got) = (rad.tan(), f64::from(tan_helix(deg)));
            let tol = 4e-7 / rad.cos();
            assert!(
                (got - want).abs() <= tol * want.max(1e-3),
                "{deg} deg: {got} against {want}"
            );
        }
    }

    /// `int sin` over the arc's angles whose point lies beyond the face, over `int sin` on
    /// the whole arc, by the midpoint rule on `steps` angles.
    fn exit_loss_brute(mode: MillingMode, rr: f64, x: f64, steps: usize) -> f64 {
        let (a, b) = entry_exit_rad(mode, rr as f32);
        let (a, b) = (f64::from(a), f64::from(b));
        let h = (b - a) / steps as f64;
        let reach = (0..=1000)
            .map(|i| (a + (b - a) * i as f64 / 1000.0).sin())
            .fold(0.0f64, f64::max);
        let (mut lost, mut all) = (0.0, 0.0);
        for i in 0..steps {
            let s = (a + (i as f64 + 0.5) * h).sin();
            all += s;
            if s > reach - x {
                lost += s;
            }
        }
        lost / all
    }

    #[test]
    fn the_exit_loss_is_the_chip_of_the_angles_beyond_the_face() {
        for mode in [MillingMode::Down, MillingMode::Up] {
            for rr in [0.05, 0.2, 0.5, 0.9, 1.0, 1.1, 1.365, 1.7, 2.0] {
                for x in [0.0, 0.001, 0.01, 0.03, 0.0625, 0.12, 0.3, 0.7, 1.5] {
                    let want = exit_loss_brute(mode, rr, x, 1_000_000);
                    let got = f64::from(exit_loss_share(rr as f32, x as f32));
                    assert!(
                        (got - want).abs() < 2e-3,
                        "{mode:?} rr {rr} x {x}: {got} vs {want}"
                    );
                }
            }
        }
        // The square-root growth where the arc holds pi/2: half the force gone after a
        // travel of 1/16 of the radius at R_r = 1.35.
        assert!(exit_loss_share(1.35, 0.0625) > 0.5);
        assert!(exit_loss_share(0.3, 0.0625) < 0.25);
        assert_eq!(exit_loss_share(f32::NAN, 0.1), 1.0);
    }

    /// The travel that takes a share, found by bisection on the brute-force loss.
    #[test]
    fn the_exit_travel_takes_its_share() {
        for rr in [0.05, 0.2, 0.5, 0.9, 1.0, 1.1, 1.365, 1.7, 2.0] {
            for share in [0.01, 0.05, 0.1, 0.2, 0.35, 0.5, 0.7, 0.9] {
                let (mut lo, mut hi) = (0.0f64, 2.0f64);
                for _ in 0..30 {
                    let mid = 0.5 * (lo + hi);
                    if exit_loss_brute(MillingMode::Down, rr, mid, 20_000) < share {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let got = f64::from(exit_travel(rr as f32, share as f32));
                // The loss at the travel found, against the share (the travel itself is
                // ill-conditioned where the loss grows steeply).
                let at = exit_loss_brute(MillingMode::Down, rr, got, 20_000);
                assert!(
                    (at - share).abs() < 2e-3 && (got - lo).abs() < 1e-3 + 0.05 * lo,
                    "rr {rr} share {share}: {got} vs {lo} (loss {at})"
                );
            }
        }
        assert_eq!(exit_travel(1.2, 0.0), 0.0);
        assert_eq!(exit_travel(0.5, -1.0), 0.0);
    }

    /// The widest arcs' exit bounds every arc's: over `R_r` from 1 to 2, the share a
    /// travel takes is largest at `1 + q`; and combined with the travel a shown loss allows
    /// (largest at `R_r` 1 and 2, `exit_travel(RR_MAX, h)`) and a further travel `f`, the
    /// reach bounds every arc's from `R_r` 0.3 (where it is under the drop trip's largest
    /// share, 0.9), on a grid of losses shown (0 to 0.9) and further travels (0.01 to 0.2
    /// radii: a feed of 0.04-0.2 mm on radii of 4-8 mm, twice). Narrower arcs can pass it
    /// (`R_r` 0.2: by 0.02): a cut measured wider than a pitch has them only with a
    /// helix's lag over 0.77 rad on 4 flutes.
    #[test]
    fn the_widest_arcs_exit_bounds_the_others() {
        let grid =
            |n: usize, lo: f32, hi: f32| (0..=n).map(move |i| lo + (hi - lo) * i as f32 / n as f32);
        for x in grid(100, 0.0, 1.0) {
            let widest = widest_exit_loss_share(x);
            for rr in grid(100, 1.0, 2.0) {
                assert!(exit_loss_share(rr, x) <= widest + 1e-5, "{rr} {x}");
            }
        }
        let excess = |lo: f32| {
            let mut most = f32::NEG_INFINITY;
            for h in grid(45, 0.0, 0.9) {
                for f in grid(19, 0.01, 0.2) {
                    let bound = widest_exit_loss_share(exit_travel(RR_MAX, h) + f);
                    if bound > 0.9 {
                        continue;
                    }
                    for rr in grid(170, lo, 2.0) {
                        let reach = exit_loss_share(rr, exit_travel(rr, h) + f);
                        most = most.max(reach - bound);
                    }
                }
            }
            most
        };
        assert!(excess(0.3) <= 1e-5, "{}", excess(0.3));
        assert!(excess(0.2) > 0.01, "{}", excess(0.2));
    }
}
