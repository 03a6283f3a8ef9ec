//! Radial and axial immersion from per-tooth average forces (paper 000, eq. 10-13).
//!
//! Two measured ratios remove `R_a` and the force scale (method.md section 2):
//! - motor route, `f_xt = F_ax / F_at` (feed motor gives `F_ax`, spindle motor `F_at`): the
//!   product's main route, solved with the fitted polynomial of [`crate::poly`] and the
//!   exact inversion where the polynomial does not apply;
//! - dynamometer route, `f_x = F_ax / |(F_ax, F_ay)|`: the exact inversion, or the paper's
//!   Table 3 on request.
//!
//! `R_a` then follows from eq. 13 with `K` at the estimated `t_a`: from `F_at` on the motor
//! route (it never crosses zero, unlike `F_ax`), from the resultant `|(F_ax, F_ay)|` on the
//! dynamometer route (eq. 13's two forms combined, again never zero).
//!
//! Config is checked once by [`EstimatorConfig::build`]; [`Estimator::estimate`] cannot fail:
//! every outcome is a finite number with a [`Status`].

use crate::coefficients::{CuttingCoefficients, TABLE2};
use crate::forward::Operating;
use crate::geometry::{MillingMode, Tool, RA_MAX, RR_MAX, RR_MIN};
use crate::invert::{invert, Ratio};
use crate::poly::FxtPoly;
use crate::status::Status;
use crate::{table3, ConfigError};

/// The polynomial result is replaced by the exact inversion when a Newton step from it
/// exceeds `POLY_CHECK_REL * R_r + POLY_CHECK_ABS`: three times the fit's worst error.
const POLY_CHECK_REL: f32 = 0.02;
const POLY_CHECK_ABS: f32 = 2e-3;

/// Per-tooth average forces as measured, by route (sign conventions in [`crate::geometry`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Measured {
    /// Feed force from the feed motor, tangential force from the spindle motor.
    Motor {
        /// `F_ax` [N].
        fx_n: f32,
        /// `F_at` [N].
        ft_n: f32,
    },
    /// Feed and normal forces from a dynamometer.
    Dynamometer {
        /// `F_ax` [N].
        fx_n: f32,
        /// `F_ay` [N].
        fy_n: f32,
    },
}

/// How `R_r` is obtained from the ratio.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum Solver {
    /// Motor route: fitted polynomial, inversion outside its range. Dynamometer: inversion.
    #[default]
    Auto,
    /// Motor route only: the fitted polynomial (inversion outside its range).
    Polynomial,
    /// Dynamometer route, down milling, Table 2 coefficients: the paper's Table 3.
    Table3,
    /// Exact inversion.
    Inversion,
}

/// What actually produced `R_r`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum Method {
    /// Nothing (not cutting, bad input).
    #[default]
    None,
    /// Fitted polynomial.
    Polynomial,
    /// Paper's Table 3.
    Table3,
    /// Exact inversion.
    Inversion,
}

impl Method {
    /// Short name for tables.
    pub fn name(self) -> &'static str {
        match self {
            Method::None => "none",
            Method::Polynomial => "polynomial",
            Method::Table3 => "table3",
            Method::Inversion => "inversion",
        }
    }
}

/// Estimator configuration, checked once by [`build`](Self::build).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct EstimatorConfig {
    /// The cutter.
    pub tool: Tool,
    /// Cutting coefficients (eq. 9).
    pub coeffs: CuttingCoefficients,
    /// Milling mode.
    pub mode: MillingMode,
    /// Below this tangential force (motor route) or feed-plane resultant (dynamometer) [N]
    /// the tool is taken as not cutting.
    pub force_floor_n: f32,
    /// How to solve for `R_r`.
    pub solver: Solver,
    /// Relative 1-sigma gain uncertainty of each force channel from calibration (e.g. 0.02
    /// for 2 %). A gain error does not average away (method.md section 2): it is added to
    /// the scatter in every uncertainty.
    pub gain_uncertainty: f32,
}

impl Default for EstimatorConfig {
    /// The paper's setting: R 8 mm, 4 flutes, down milling, Table 2.
    fn default() -> Self {
        EstimatorConfig {
            tool: Tool::PAPER,
            coeffs: TABLE2,
            mode: MillingMode::Down,
            force_floor_n: 2.0,
            solver: Solver::Auto,
            gain_uncertainty: 0.0,
        }
    }
}

impl EstimatorConfig {
    /// Validates and selects the fitted polynomial for these coefficients and mode, if any.
    pub fn build(self) -> Result<Estimator, ConfigError> {
        self.tool.validate()?;
        self.coeffs.validate()?;
        if !self.force_floor_n.is_finite() {
            return Err(ConfigError::NonFinite("force_floor_n"));
        }
        if self.force_floor_n < 0.0 {
            return Err(ConfigError::OutOfRange("force_floor_n"));
        }
        if !(0.0..1.0).contains(&self.gain_uncertainty) {
            return Err(ConfigError::OutOfRange("gain_uncertainty"));
        }
        let poly = crate::fxt_poly::ALL
            .iter()
            .chain(crate::fxt_poly_user::ALL)
            .find(|p| p.fits(&self.coeffs, self.mode));
        if self.solver == Solver::Polynomial && poly.is_none() {
            return Err(ConfigError::NoPolynomial);
        }
        if self.solver == Solver::Table3
            && (self.mode != MillingMode::Down || self.coeffs != TABLE2)
        {
            return Err(ConfigError::Table3NotApplicable);
        }
        Ok(Estimator { cfg: self, poly })
    }
}

/// One estimate. All numbers finite; trust them only if `status.is_valid()`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Estimate {
    /// Radial immersion ratio `R_r`.
    pub rr: f32,
    /// Axial immersion ratio `R_a`.
    pub ra: f32,
    /// Radial depth `d_r = R_r R` [mm].
    pub dr_mm: f32,
    /// Axial depth `d_a = R_a R` [mm].
    pub da_mm: f32,
    /// 1-sigma uncertainty of `R_r` from the force scatter and the gain uncertainty.
    pub rr_sigma: f32,
    /// 1-sigma uncertainty of `R_a`.
    pub ra_sigma: f32,
    /// Average chip thickness at the estimate [mm].
    pub t_a_mm: f32,
    /// What the flags say.
    pub status: Status,
    /// What produced `R_r`.
    pub method: Method,
}

/// A validated estimator. Stateless: `estimate` is a pure function of its inputs.
#[derive(Clone, Copy, Debug)]
pub struct Estimator {
    cfg: EstimatorConfig,
    poly: Option<&'static FxtPoly>,
}

impl Estimator {
    /// The configuration it was built from.
    pub fn config(&self) -> &EstimatorConfig {
        &self.cfg
    }

    /// Whether a fitted polynomial is available for this configuration.
    pub fn has_polynomial(&self) -> bool {
        self.poly.is_some()
    }

    /// Estimates `R_r`, `R_a` from per-tooth average forces at feed per tooth `tc_mm`, with
    /// the uncertainty from the gain uncertainty alone.
    pub fn estimate(&self, tc_mm: f32, m: Measured) -> Estimate {
        self.estimate_with_scatter(tc_mm, m, [0.0, 0.0])
    }

    /// Same, with the 1-sigma scatter `[of F_ax, of the other force]` [N] of the averages,
    /// propagated to first order through the model (`sigma_R = sigma_f / |df/dR|`).
    pub fn estimate_with_scatter(&self, tc_mm: f32, m: Measured, sigma_n: [f32; 2]) -> Estimate {
        self.estimate_with_variance(
            tc_mm,
            m,
            sigma_n.map(|s| if s.is_finite() { s * s } else { 0.0 }),
        )
    }

    /// [`Self::estimate_with_scatter`] with the scatter given as variances `[of F_ax, of the
    /// other force]` [N^2] (what the monitor's filter computes: no square root taken for
    /// it). A negative or non-finite variance counts as 0.
    pub fn estimate_with_variance(&self, tc_mm: f32, m: Measured, var_n2: [f32; 2]) -> Estimate {
        self.estimate_with_model(tc_mm, m, var_n2).0
    }

    /// [`Self::estimate_with_variance`], and eq. 7's `[F_ax, F_at]` at the estimate
    /// (`[0, 0]` when there is none): the forces the wear tracker compares with, computed
    /// here from the model terms the estimate already has, exactly as
    /// `Operating::forces` would compute them at the estimate's `R_r`, `R_a` and `t_c`.
    /// Not inlined: the monitor's per-tooth function is large enough already (inlined
    /// there, register pressure costs more than the call saves).
    #[inline(never)]
    pub(crate) fn estimate_with_model(
        &self,
        tc_mm: f32,
        m: Measured,
        var_n2: [f32; 2],
    ) -> (Estimate, [f32; 2]) {
        let (fx, other) = match m {
            Measured::Motor { fx_n, ft_n } => (fx_n, ft_n),
            Measured::Dynamometer { fx_n, fy_n } => (fx_n, fy_n),
        };
        if !(tc_mm.is_finite() && fx.is_finite() && other.is_finite()) || tc_mm <= 0.0 {
            let e = Estimate {
                status: Status::NON_FINITE,
                ..Estimate::default()
            };
            return (e, [0.0; 2]);
        }
        let (ratio, magnitude) = match m {
            Measured::Motor { ft_n, .. } => (Ratio::Fxt, ft_n),
            Measured::Dynamometer { fx_n, fy_n } => (Ratio::Fx, crate::fmath::hypot(fx_n, fy_n)),
        };
        // Written so that a NaN magnitude (cannot happen here, inputs are finite) also
        // counts as not cutting.
        let cutting = magnitude > self.cfg.force_floor_n && magnitude > 0.0;
        if !cutting {
            let e = Estimate {
                status: Status::NOT_CUTTING,
                ..Estimate::default()
            };
            return (e, [0.0; 2]);
        }
        let f = fx / magnitude;
        let mut status = Status::VALID;
        status.set_if(
            !self.cfg.coeffs.tc_in_fit_range(tc_mm),
            Status::TC_OUT_OF_RANGE,
        );
        let coeffs = &self.cfg.coeffs;
        // Up milling: f_xt -> 1 as R_r -> 0 and peaks above 1 at light cuts, so any ratio
        // above 1 is also produced by a lighter cut than the one reported (whichever solver).
        status.set_if(
            ratio == Ratio::Fxt && self.cfg.mode == MillingMode::Up && f > 1.0,
            Status::AMBIGUOUS,
        );
        let (mut rr, mut method) = self.solve_rr(ratio, f, tc_mm, &mut status);
        let mut op = Operating::new(coeffs, self.cfg.mode, rr, tc_mm);
        // The slopes the propagation needs: on the motor route `d f_xt / d R_r` (which the
        // polynomial check needs too) and `d ln F_at / d R_r` alone, without the
        // resultant's square root.
        let mut fxt_slopes = None;
        if method == Method::Polynomial {
            // The exact model checks the polynomial on every call, at the price of a few
            // multiplications (`op` is needed for R_a anyway): one Newton step's worth of
            // disagreement beyond the fit's own error means the point lies outside the
            // fitted domain (e.g. a ratio no immersion gives at this t_c).
            let (dfxt_drr, dln_t_drr) = op.slopes_fxt(coeffs, self.cfg.mode);
            let f_model = op.ratio_fxt();
            let newton_step = (f - f_model) / dfxt_drr;
            // At the slot (where the result was clamped) the ratio must not pass the slot's.
            let beyond_slot = rr >= RR_MAX
                && match self.cfg.mode {
                    MillingMode::Down => f > f_model,
                    MillingMode::Up => f < f_model,
                };
            status.set_if(beyond_slot, Status::RR_CLAMPED);
            // (A NaN step fails the comparison: fall back then too.)
            let trusted = newton_step.abs() <= POLY_CHECK_REL * rr + POLY_CHECK_ABS;
            if trusted {
                fxt_slopes = Some((dfxt_drr, dln_t_drr));
            } else {
                let inv = invert(coeffs, self.cfg.mode, ratio, f, tc_mm);
                status |= inv.status;
                (rr, method) = (inv.rr, Method::Inversion);
                op = Operating::new(coeffs, self.cfg.mode, rr, tc_mm);
            }
        }
        let scale = op.force_scale_n(coeffs, &self.cfg.tool, tc_mm);
        let per_ra = match ratio {
            Ratio::Fxt => scale * op.arc.c,
            Ratio::Fx => scale * op.resultant(),
        };
        let mut ra = magnitude / per_ra;
        if !(0.0..=RA_MAX).contains(&ra) {
            // Forces far beyond any cut the model knows (or a degenerate t_a): saturate.
            status |= Status::RA_CLAMPED;
            ra = if ra > 0.0 { RA_MAX } else { 0.0 };
        }
        // (d f / d R_r, d ln(force per unit R_a) / d R_r) of the route's ratio and magnitude.
        let (df_drr, dln_per_ra) = match ratio {
            Ratio::Fxt => fxt_slopes.unwrap_or_else(|| op.slopes_fxt(coeffs, self.cfg.mode)),
            Ratio::Fx => {
                let s = op.slopes(coeffs, self.cfg.mode);
                (s.dfx_drr, s.dln_resultant_drr)
            }
        };
        let (rr_sigma, ra_sigma) = self.propagate(df_drr, dln_per_ra, m, f, magnitude, var_n2, ra);
        let r = self.cfg.tool.radius_mm;
        // `Operating::forces(..., ra)`: `s = K' R_a`, `F_ax = s (a + r1 b)`, `F_at = s c`.
        let s = scale * ra;
        let model = [s * (op.arc.a + op.r1 * op.arc.b), s * op.arc.c];
        let e = Estimate {
            rr,
            ra,
            dr_mm: rr * r,
            da_mm: ra * r,
            rr_sigma,
            ra_sigma,
            t_a_mm: if op.t_a_mm.is_finite() {
                op.t_a_mm
            } else {
                0.0
            },
            status,
            method,
        };
        (e, model)
    }

    /// First-order propagation of force scatter (variances `var_n2`) and gain uncertainty
    /// into `(sigma_R_r, sigma_R_a)`: independent errors on the two channels, exact
    /// Jacobian (checked against Monte Carlo in the tests). `df_drr`, `dln_per_ra`: slopes
    /// of the route's ratio and of its force per unit `R_a` (see
    /// [`Slopes`](crate::forward::Slopes)).
    #[allow(clippy::too_many_arguments)]
    fn propagate(
        &self,
        df_drr: f32,
        dln_per_ra: f32,
        m: Measured,
        f: f32,
        magnitude: f32,
        var_n2: [f32; 2],
        ra: f32,
    ) -> (f32, f32) {
        let g = self.cfg.gain_uncertainty;
        // (`w > 0` and finite: `0 < w < inf`, NaN fails both.)
        let usable = |w: f32| if w > 0.0 && w < f32::INFINITY { w } else { 0.0 };
        let (w0, w1) = (usable(var_n2[0]), usable(var_n2[1]));
        // Partial derivatives of the ratio and the magnitude with respect to both channels.
        let (df_d0, df_d1, dm_d0, dm_d1) = match m {
            Measured::Motor { ft_n, .. } => (1.0 / ft_n, -f / ft_n, 0.0, 1.0),
            Measured::Dynamometer { fx_n, fy_n } => {
                let m3 = magnitude * magnitude * magnitude;
                (
                    fy_n * fy_n / m3,
                    -fx_n * fy_n / m3,
                    fx_n / magnitude,
                    fy_n / magnitude,
                )
            }
        };
        let (v0, v1) = match m {
            Measured::Motor { fx_n, ft_n } => (fx_n, ft_n),
            Measured::Dynamometer { fx_n, fy_n } => (fx_n, fy_n),
        };
        // Each channel's total variance: scatter and gain error added.
        let (gv0, gv1) = (g * v0, g * v1);
        let q0 = w0 + gv0 * gv0;
        let q1 = w1 + gv1 * gv1;
        let sigma_f = norm(df_d0, q0, df_d1, q1);
        // dR/df; a flat ratio (turning point, or NaN at a degenerate point) identifies
        // nothing, an infinite slope (slot) pins R_r.
        let (rr_sigma, dr_df) = if df_drr.is_infinite() {
            (0.0, 0.0)
        } else if df_drr.abs() > 0.0 {
            (
                crate::fmath::min(sigma_f / df_drr.abs(), RR_MAX),
                1.0 / df_drr,
            )
        } else {
            (RR_MAX, 0.0)
        };
        // ln R_a = ln m(v0, v1) - ln per(R(f(v0, v1))): both channels move R_a directly and
        // through R_r, with correlated effects; first order, exact Jacobian.
        let k = if dln_per_ra.is_finite() {
            dln_per_ra * dr_df
        } else {
            0.0
        };
        let d0 = dm_d0 / magnitude - k * df_d0;
        let d1 = dm_d1 / magnitude - k * df_d1;
        let ra_sigma = ra * norm(d0, q0, d1, q1);
        let finite_or = |v: f32, alt: f32| if v.is_finite() { v } else { alt };
        (finite_or(rr_sigma, RR_MAX), finite_or(ra_sigma, RA_MAX))
    }

    /// `R_r` from the ratio value `f`, by the configured solver.
    fn solve_rr(&self, ratio: Ratio, f: f32, tc_mm: f32, status: &mut Status) -> (f32, Method) {
        let cfg = &self.cfg;
        match (ratio, cfg.solver) {
            (Ratio::Fxt, Solver::Auto | Solver::Polynomial) => {
                if let Some(rr) = self.poly.and_then(|p| p.eval(f, tc_mm)) {
                    return (rr.clamp(RR_MIN, RR_MAX), Method::Polynomial);
                }
            }
            (Ratio::Fx, Solver::Table3) => {
                let rr = table3::rr_from_fx(f, tc_mm, table3::Branch::Auto);
                let clamped = rr.clamp(RR_MIN, RR_MAX);
                status.set_if(!(rr == clamped), Status::RR_CLAMPED);
                // A NaN cannot arise from finite f and t_c; guard anyway.
                let clamped = if clamped.is_finite() { clamped } else { RR_MIN };
                return (clamped, Method::Table3);
            }
            _ => {}
        }
        let inv = invert(&cfg.coeffs, cfg.mode, ratio, f, tc_mm);
        *status |= inv.status;
        (inv.rr, Method::Inversion)
    }
}

/// `sqrt(x0^2 q0 + x1^2 q1)` for variances `q0, q1 >= 0`: the norm of `(x0 sigma0, x1
/// sigma1)` with one square root instead of three. Where the sum leaves the range in which
/// it is accurate (far beyond any force), the same from the standard deviations.
#[inline]
fn norm(x0: f32, q0: f32, x1: f32, q1: f32) -> f32 {
    let s = x0 * x0 * q0 + x1 * x1 * q1;
    if (1e-30..=1e30).contains(&s) {
        libm::sqrtf(s)
    } else if q0 == 0.0 && q1 == 0.0 && (x0 * 0.0 + x1 * 0.0) == 0.0 {
        // No scatter (finite `x`): `hypot(x0 * sqrt(0), x1 * sqrt(0))` is 0.
        0.0
    } else {
        crate::fmath::hypot(x0 * libm::sqrtf(q0), x1 * libm::sqrtf(q1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{average_forces, Engagement};

    fn est(mode: MillingMode) -> Estimator {
        EstimatorConfig {
            mode,
            ..Default::default()
        }
        .build()
        .unwrap()
    }

    fn motor(mode: MillingMode, rr: f32, ra: f32, tc: f32) -> Measured {
        let f = average_forces(
            &Tool::PAPER,
            &TABLE2,
            mode,
            Engagement { rr, ra, tc_mm: tc },
        );
        Measured::Motor {
            fx_n: f.fx_n,
            ft_n: f.ft_n,
        }
    }

    fn is_finite(e: &Estimate) -> bool {
        [e.rr, e.ra, e.dr_mm, e.da_mm, e.t_a_mm]
            .iter()
            .all(|v| v.is_finite())
    }

    #[test]
    fn paper_cut_is_valid() {
        let e =
            est(MillingMode::Down).estimate(0.2083, motor(MillingMode::Down, 0.25, 0.75, 0.2083));
        assert!(e.status.is_valid(), "{}", e.status);
        assert!(
            (e.dr_mm - 2.0).abs() < 0.02 && (e.da_mm - 6.0).abs() < 0.06,
            "{e:?}"
        );
    }

    #[test]
    fn non_finite_inputs_are_flagged_not_propagated() {
        let e = est(MillingMode::Down);
        let good = 100.0;
        for (tc, a, b) in [
            (f32::NAN, -10.0, good),
            (0.1, f32::NAN, good),
            (0.1, -10.0, f32::INFINITY),
            (f32::NEG_INFINITY, -10.0, good),
            (0.0, -10.0, good),
            (-0.1, -10.0, good),
        ] {
            for m in [
                Measured::Motor { fx_n: a, ft_n: b },
                Measured::Dynamometer { fx_n: a, fy_n: b },
            ] {
                let r = e.estimate(tc, m);
                assert_eq!(r.status, Status::NON_FINITE, "{tc} {m:?}");
                assert!(is_finite(&r));
            }
        }
    }

    #[test]
    fn forces_below_the_floor_are_not_cutting() {
        let e = est(MillingMode::Down);
        for ft in [0.0, 1.0, -50.0] {
            let r = e.estimate(
                0.1,
                Measured::Motor {
                    fx_n: -0.5,
                    ft_n: ft,
                },
            );
            assert_eq!(r.status, Status::NOT_CUTTING, "ft {ft}");
            assert_eq!((r.rr, r.ra), (0.0, 0.0));
        }
        let r = e.estimate(
            0.1,
            Measured::Dynamometer {
                fx_n: 1.0,
                fy_n: -1.0,
            },
        );
        assert_eq!(r.status, Status::NOT_CUTTING);
    }

    #[test]
    fn impossible_ratios_are_clamped_and_flagged() {
        let e = est(MillingMode::Down);
        // Feed force pulling harder than the tangential force: no R_r does that (f_xt > -1).
        let r = e.estimate(
            0.2,
            Measured::Motor {
                fx_n: -150.0,
                ft_n: 100.0,
            },
        );
        assert!(r.status.contains(Status::RR_CLAMPED));
        assert!(r.rr >= crate::geometry::RR_MIN && r.rr < 0.01 && is_finite(&r));
        // Feed force above what a slot gives (r1 pi / 4 ~ 0.3).
        let r = e.estimate(
            0.2,
            Measured::Motor {
                fx_n: 90.0,
                ft_n: 100.0,
            },
        );
        assert!(r.status.contains(Status::RR_CLAMPED));
        assert_eq!(r.rr, 2.0);
    }

    #[test]
    fn feed_outside_the_coefficients_range_is_flagged_but_estimated() {
        let e = est(MillingMode::Down);
        let r = e.estimate(0.03, motor(MillingMode::Down, 1.0, 1.0, 0.03));
        assert_eq!(r.status, Status::TC_OUT_OF_RANGE);
        assert!((r.rr - 1.0).abs() < 0.01);
    }

    #[test]
    fn laws_identified_down_to_a_lower_feed_keep_their_polynomial() {
        // A calibration that reached 0.04 mm/tooth and found Table 2's laws: a cut at 0.05
        // is in range now, estimated by the same polynomial (fitted for the laws down to
        // 0.02), and to the polynomial's error of the forward model's immersion (past the
        // light up-milling cuts that are ambiguous at any range).
        for mode in [MillingMode::Down, MillingMode::Up] {
            let mut c = EstimatorConfig {
                mode,
                ..Default::default()
            };
            c.coeffs.tc_fit_mm.0 = 0.04;
            let e = c.build().unwrap();
            assert!(e.has_polynomial());
            for rr in [0.9, 1.2, 1.6] {
                let r = e.estimate(0.05, motor(mode, rr, 1.0, 0.05));
                assert_eq!(r.status, Status::VALID, "{mode:?} {rr}");
                assert_eq!(r.method, Method::Polynomial);
                assert!((r.rr - rr).abs() < 0.01 * rr, "{mode:?} {r:?}");
            }
        }
    }

    #[test]
    fn light_up_milling_cut_is_ambiguous() {
        // f_xt turns over at light up-milling cuts (R_r ~ 0.1-0.25): two immersions give
        // the same ratio there.
        let e = est(MillingMode::Up);
        let r = e.estimate(0.05, motor(MillingMode::Up, 0.3, 1.0, 0.05));
        assert!(r.status.contains(Status::AMBIGUOUS), "{}", r.status);
        assert!((r.rr - 0.3).abs() < 0.01, "{r:?}");
        let r = e.estimate(0.2, motor(MillingMode::Up, 1.0, 1.0, 0.2));
        assert!(r.status.is_valid(), "{}", r.status);
        // Same on the polynomial's ground (R_r >= 0.5): a light cut that the polynomial
        // maps to the slot side must still be flagged.
        let r = e.estimate(0.02, motor(MillingMode::Up, 0.6, 1.0, 0.02));
        assert_eq!(r.method, Method::Polynomial);
        assert!(r.status.contains(Status::AMBIGUOUS), "{}", r.status);
    }

    #[test]
    fn arbitrary_inputs_never_give_nan() {
        // A small LCG over wild magnitudes and signs; the estimator must stay finite.
        let mut s = 0x1234_5678u32;
        let mut next = || {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let mant = (s >> 8) as f32 / (1u32 << 24) as f32 * 2.0 - 1.0;
            let exp = ((s & 0xff) as i32 % 60) - 30;
            mant * libm::powf(10.0, exp as f32)
        };
        for mode in [MillingMode::Down, MillingMode::Up] {
            let e = est(mode);
            for _ in 0..3000 {
                let (tc, a, b) = (next(), next(), next());
                for m in [
                    Measured::Motor { fx_n: a, ft_n: b },
                    Measured::Dynamometer { fx_n: a, fy_n: b },
                ] {
                    let r = e.estimate(tc, m);
                    assert!(is_finite(&r), "{tc} {m:?} -> {r:?}");
                    assert!(r.rr >= 0.0 && r.rr <= 2.0 && r.ra >= 0.0);
                }
            }
        }
    }

    #[test]
    fn reported_sigma_matches_monte_carlo_scatter() {
        // 1 % independent Gaussian noise on both averaged forces: the first-order sigma the
        // estimator reports must match the spread of the estimates it actually produces.
        let mut s = 0x9e37_79b9u32;
        let mut uniform = || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            (s as f32 + 0.5) / 4_294_967_296.0
        };
        let mut gauss = || {
            let (u1, u2) = (uniform(), uniform());
            libm::sqrtf(-2.0 * libm::logf(u1)) * libm::cosf(2.0 * core::f32::consts::PI * u2)
        };
        for mode in [MillingMode::Down, MillingMode::Up] {
            let e = est(mode);
            for (rr, tc) in [(0.25, 0.1042), (0.75, 0.2083), (1.0, 0.1042), (1.5, 0.4167)] {
                let Measured::Motor { fx_n, ft_n } = motor(mode, rr, 1.0, tc) else {
                    unreachable!()
                };
                let sig = [0.01 * ft_n, 0.01 * ft_n];
                let reported = e.estimate_with_scatter(tc, motor(mode, rr, 1.0, tc), sig);
                let n = 4000;
                let (mut m1, mut m2, mut a1, mut a2) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
                for _ in 0..n {
                    let m = Measured::Motor {
                        fx_n: fx_n + sig[0] * gauss(),
                        ft_n: ft_n + sig[1] * gauss(),
                    };
                    let r = e.estimate(tc, m);
                    m1 += r.rr as f64;
                    m2 += (r.rr as f64).powi(2);
                    a1 += r.ra as f64;
                    a2 += (r.ra as f64).powi(2);
                }
                let n = n as f64;
                let sd_rr = (m2 / n - (m1 / n).powi(2)).sqrt();
                let sd_ra = (a2 / n - (a1 / n).powi(2)).sqrt();
                let q_rr = reported.rr_sigma as f64 / sd_rr;
                let q_ra = reported.ra_sigma as f64 / sd_ra;
                assert!(
                    (0.8..1.25).contains(&q_rr) && (0.8..1.25).contains(&q_ra),
                    "{mode:?} rr {rr} tc {tc}: reported/actual sigma R_r {q_rr:.2}, R_a {q_ra:.2}"
                );
            }
        }
    }

    #[test]
    fn gain_uncertainty_widens_sigma() {
        let m = motor(MillingMode::Down, 0.5, 1.0, 0.2);
        let plain = est(MillingMode::Down).estimate(0.2, m);
        assert_eq!((plain.rr_sigma, plain.ra_sigma), (0.0, 0.0));
        let e = EstimatorConfig {
            gain_uncertainty: 0.05,
            ..Default::default()
        }
        .build()
        .unwrap();
        let r = e.estimate(0.2, m);
        // method.md: a 5 % gain error moves R_r by 7-9 % at R_r = 0.5.
        let rel = r.rr_sigma / r.rr;
        assert!(rel > 0.05 && rel < 0.15, "sigma R_r / R_r = {rel}");
    }

    #[test]
    fn bad_configs_name_the_parameter() {
        let mut c = EstimatorConfig::default();
        c.tool.radius_mm = -1.0;
        assert_eq!(c.build().unwrap_err(), ConfigError::OutOfRange("radius_mm"));
        let mut c = EstimatorConfig::default();
        c.coeffs.r1.k = f32::NAN;
        assert_eq!(c.build().unwrap_err(), ConfigError::NonFinite("r1"));
        let mut c = EstimatorConfig::default();
        c.tool.flutes = 0;
        assert_eq!(c.build().unwrap_err(), ConfigError::OutOfRange("flutes"));
        let c = EstimatorConfig {
            mode: MillingMode::Up,
            solver: Solver::Table3,
            ..Default::default()
        };
        assert_eq!(c.build().unwrap_err(), ConfigError::Table3NotApplicable);
        let mut c = EstimatorConfig {
            solver: Solver::Polynomial,
            ..Default::default()
        };
        c.coeffs.ks.k = 700.0;
        assert_eq!(c.build().unwrap_err(), ConfigError::NoPolynomial);
    }

    #[test]
    fn other_coefficients_fall_back_to_inversion() {
        let mut c = EstimatorConfig::default();
        c.coeffs.ks.k = 700.0;
        c.coeffs.r1.k = 0.3;
        let e = c.build().unwrap();
        let f = average_forces(
            &c.tool,
            &c.coeffs,
            c.mode,
            Engagement {
                rr: 0.8,
                ra: 1.0,
                tc_mm: 0.2,
            },
        );
        let r = e.estimate(
            0.2,
            Measured::Motor {
                fx_n: f.fx_n,
                ft_n: f.ft_n,
            },
        );
        assert_eq!(r.method, Method::Inversion);
        assert!(
            (r.rr - 0.8).abs() < 1e-3 && (r.ra - 1.0).abs() < 1e-3,
            "{r:?}"
        );
    }
}
