//! The forward model: per-tooth average forces from the engagement (paper 000, eq. 7).
//!
//! ```text
//! F_at = K' R_a c,   F_ax = K' R_a (a + r1 b),   F_ay = K' R_a (-b + r1 a),   F_az = K' r2 R_a c
//! K' = K_s(t_a) R t_c / phi_N
//! ```
//! with `a, b, c` the arc integrals of [`ArcIntegrals`]. This is the paper's eq. 7 with
//! `K = K_s R t_c / tan(beta)` and `A_r = tan(beta)/phi_N a` multiplied out: the helix angle
//! cancels. The averages are of the total force on the cutter (all flutes), over one tooth
//! period, with `K_s`, `r1`, `r2` taken once at the average chip thickness `t_a`.
//! Sign conventions: see [`crate::geometry`].

use crate::coefficients::{CuttingCoefficients, LinearCoefficients};
use crate::geometry::{average_chip_thickness_mm, ArcIntegrals, MillingMode, Tool};

/// What the cutter is doing: immersion ratios and feed per tooth.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Engagement {
    /// Radial immersion ratio `R_r = d_r / R`, in `(0, 2]`.
    pub rr: f32,
    /// Axial immersion ratio `R_a = d_a / R`.
    pub ra: f32,
    /// Feed per tooth `t_c` [mm/tooth].
    pub tc_mm: f32,
}

/// Per-tooth average forces [N] (sign conventions in [`crate::geometry`]).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AverageForces {
    /// Tangential `F_at` (torque / R).
    pub ft_n: f32,
    /// Feed direction `F_ax`.
    pub fx_n: f32,
    /// Normal to the feed `F_ay`.
    pub fy_n: f32,
    /// Axial `F_az`.
    pub fz_n: f32,
}

/// Everything eq. 7 needs at one radial immersion and feed: the arc integrals, `t_a` and
/// `r1` there. `K_s` and `r2` are evaluated only on request: each power law is a `powf`,
/// about 220 instructions on the Cortex-M4, and the ratio inversion needs `r1` alone.
#[derive(Clone, Copy, Debug)]
pub struct Operating {
    /// Arc integrals.
    pub arc: ArcIntegrals,
    /// Average chip thickness [mm].
    pub t_a_mm: f32,
    /// `ln t_a`, kept so that `K_s` and `r2` cost one `expf` each.
    pub ln_t_a: f32,
    /// `r1` at `t_a`.
    pub r1: f32,
}

impl Operating {
    /// Evaluates geometry and `r1` at `rr`, `tc_mm`.
    pub fn new(coeffs: &CuttingCoefficients, mode: MillingMode, rr: f32, tc_mm: f32) -> Self {
        Self::from_integrals(coeffs, ArcIntegrals::new(mode, rr), tc_mm)
    }

    /// Same, from arc integrals already evaluated.
    pub fn from_integrals(coeffs: &CuttingCoefficients, arc: ArcIntegrals, tc_mm: f32) -> Self {
        let t_a_mm = average_chip_thickness_mm(tc_mm, arc.c, arc.arc);
        // One log for all three power laws: k t^p = k exp(p ln t) (powf would be ~220
        // instructions each on the Cortex-M4F).
        let ln_t_a = libm::logf(t_a_mm);
        Operating {
            arc,
            t_a_mm,
            ln_t_a,
            r1: coeffs.r1.at_ln(ln_t_a),
        }
    }

    /// `f_xt = F_ax / F_at = (a + r1 b) / c` (eq. 12).
    #[inline]
    pub fn ratio_fxt(&self) -> f32 {
        (self.arc.a + self.r1 * self.arc.b) / self.arc.c
    }

    /// `|(a + r1 b, -b + r1 a)| = sqrt((1 + r1^2)(a^2 + b^2))`: the feed-plane resultant per
    /// unit `K' R_a`.
    #[inline]
    pub fn resultant(&self) -> f32 {
        let (a, b, r1) = (self.arc.a, self.arc.b, self.r1);
        libm::sqrtf((1.0 + r1 * r1) * (a * a + b * b))
    }

    /// `f_x = F_ax / sqrt(F_ax^2 + F_ay^2)` (eq. 10).
    #[inline]
    pub fn ratio_fx(&self) -> f32 {
        (self.arc.a + self.r1 * self.arc.b) / self.resultant()
    }

    /// `K' = K_s R t_c / phi_N` [N]: the force scale of eq. 7 per unit `R_a`.
    #[inline]
    pub fn force_scale_n(&self, coeffs: &CuttingCoefficients, tool: &Tool, tc_mm: f32) -> f32 {
        coeffs.ks.at_ln(self.ln_t_a) * tool.radius_mm * tc_mm / tool.tooth_pitch_rad()
    }

    /// Eq. 7 at axial immersion `ra`.
    pub fn forces(
        &self,
        coeffs: &CuttingCoefficients,
        tool: &Tool,
        tc_mm: f32,
        ra: f32,
    ) -> AverageForces {
        let s = self.force_scale_n(coeffs, tool, tc_mm) * ra;
        let (a, b, c, r1) = (self.arc.a, self.arc.b, self.arc.c, self.r1);
        AverageForces {
            ft_n: s * c,
            fx_n: s * (a + r1 * b),
            fy_n: s * (-b + r1 * a),
            fz_n: s * coeffs.r2.at_ln(self.ln_t_a) * c,
        }
    }

    /// Derivatives with respect to `R_r` at this point, for propagating force scatter into
    /// `R_r` and `R_a` (section 2: `d f / d R_r`, and `d ln(K' c) / d R_r` for `R_a`).
    ///
    /// With `u` the engaged arc: `du/dR = 1/sin u`, `d ln t_a / dR = 1/R - 1/(u sin u)`,
    /// `dr1/dR = p1 r1 d ln t_a/dR`, `da/dR = +-(R - 1)`, `db/dR = sin u`, `dc/dR = 1`.
    /// At the slot `sin u = 0` and the slopes of `f` are infinite; returned as is.
    /// `sin u` is `|cos_int|` of the arc integrals (`-sin u` down, `sin u` up).
    pub fn slopes(&self, coeffs: &CuttingCoefficients, mode: MillingMode) -> Slopes {
        let t = self.slope_terms(coeffs, mode);
        let (a, b, r1) = (self.arc.a, self.arc.b, self.r1);
        let q = a * a + b * b;
        let dln_res = r1 * t.dr1 / (1.0 + r1 * r1) + (a * t.da + b * t.db) / q;
        let res = self.resultant();
        let dfx = (t.dn - t.n * dln_res) / res;
        Slopes {
            dfxt_drr: t.dfxt,
            dfx_drr: dfx,
            dln_tangential_drr: t.dln_ks + 1.0 / self.arc.c,
            dln_resultant_drr: t.dln_ks + dln_res,
        }
    }

    /// The two slopes the motor route needs, `(d f_xt / d R_r, d ln(F_at / R_a) / d R_r)`:
    /// the same values as [`Self::slopes`] gives, without the resultant's square root.
    #[inline]
    pub fn slopes_fxt(&self, coeffs: &CuttingCoefficients, mode: MillingMode) -> (f32, f32) {
        let t = self.slope_terms(coeffs, mode);
        (t.dfxt, t.dln_ks + 1.0 / self.arc.c)
    }

    /// What both slope sets share.
    #[inline(always)]
    fn slope_terms(&self, coeffs: &CuttingCoefficients, mode: MillingMode) -> SlopeTerms {
        let (a, b, c, r1, u) = (self.arc.a, self.arc.b, self.arc.c, self.r1, self.arc.arc);
        // = geometry::arc_sin(c), already taken by `ArcIntegrals::from_arc`.
        let sin_u = self.arc.cos_int.abs();
        let dln_ta = 1.0 / c - 1.0 / (u * sin_u);
        let dr1 = coeffs.r1.p * r1 * dln_ta;
        let da = match mode {
            MillingMode::Down => c - 1.0,
            MillingMode::Up => 1.0 - c,
        };
        let db = sin_u;
        let n = a + r1 * b;
        let dn = da + dr1 * b + r1 * db;
        SlopeTerms {
            dfxt: (dn * c - n) / (c * c),
            dr1,
            da,
            db,
            n,
            dn,
            dln_ks: coeffs.ks.p * dln_ta,
        }
    }
}

/// Intermediate terms of [`Operating::slopes`].
struct SlopeTerms {
    dfxt: f32,
    dr1: f32,
    da: f32,
    db: f32,
    n: f32,
    dn: f32,
    dln_ks: f32,
}

/// See [`Operating::slopes`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slopes {
    /// `d f_xt / d R_r`.
    pub dfxt_drr: f32,
    /// `d f_x / d R_r`.
    pub dfx_drr: f32,
    /// `d ln(F_at / R_a) / d R_r`: how the tangential force per unit `R_a` moves with `R_r`.
    pub dln_tangential_drr: f32,
    /// `d ln(|F_xy| / R_a) / d R_r`, likewise for the feed-plane resultant.
    pub dln_resultant_drr: f32,
}

/// Eq. 7: per-tooth average forces of a cut.
pub fn average_forces(
    tool: &Tool,
    coeffs: &CuttingCoefficients,
    mode: MillingMode,
    e: Engagement,
) -> AverageForces {
    Operating::new(coeffs, mode, e.rr, e.tc_mm).forces(coeffs, tool, e.tc_mm, e.ra)
}

/// Per-tooth averages for the linear shearing + edge model (paper 004's coefficients):
/// `dF_t = (K_tc h + K_te) dz`, likewise `r` and `a`, integrated exactly as eq. 7 is:
/// `F = d_a / phi_N * int_arc (elemental force per unit height) dphi`.
pub fn average_forces_linear(
    tool: &Tool,
    k: &LinearCoefficients,
    mode: MillingMode,
    e: Engagement,
) -> AverageForces {
    let i = ArcIntegrals::new(mode, e.rr);
    let sin_int = i.c;
    let s = e.ra * tool.radius_mm / tool.tooth_pitch_rad();
    let tc = e.tc_mm;
    AverageForces {
        ft_n: s * (k.ktc * tc * i.c + k.kte * i.arc),
        fx_n: s * (k.ktc * tc * i.a + k.kte * i.cos_int + k.krc * tc * i.b + k.kre * sin_int),
        fy_n: s * (-k.ktc * tc * i.b - k.kte * sin_int + k.krc * tc * i.a + k.kre * i.cos_int),
        fz_n: s * (k.kac * tc * i.c + k.kae * i.arc),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::TABLE2;

    #[test]
    fn slopes_match_finite_differences() {
        for mode in [MillingMode::Down, MillingMode::Up] {
            for rr in [0.05f32, 0.2, 0.6, 1.0, 1.4, 1.8] {
                for tc in [0.03f32, 0.1, 0.4] {
                    let at = |r: f32| Operating::new(&TABLE2, mode, r, tc);
                    let tool = Tool::PAPER;
                    let s = at(rr).slopes(&TABLE2, mode);
                    let h = 1e-3 * rr;
                    let (lo, hi) = (at(rr - h), at(rr + h));
                    let fd = |g: &dyn Fn(&Operating) -> f32| (g(&hi) - g(&lo)) / (2.0 * h);
                    let ln_t = |o: &Operating| libm::logf(o.forces(&TABLE2, &tool, tc, 1.0).ft_n);
                    let ln_r = |o: &Operating| {
                        let f = o.forces(&TABLE2, &tool, tc, 1.0);
                        libm::logf(libm::hypotf(f.fx_n, f.fy_n))
                    };
                    for (name, analytic, numeric) in [
                        ("dfxt", s.dfxt_drr, fd(&|o| o.ratio_fxt())),
                        ("dfx", s.dfx_drr, fd(&|o| o.ratio_fx())),
                        ("dln_t", s.dln_tangential_drr, fd(&ln_t)),
                        ("dln_r", s.dln_resultant_drr, fd(&ln_r)),
                    ] {
                        let tol = 2e-2 * analytic.abs().max(0.05);
                        assert!(
                            (analytic - numeric).abs() < tol,
                            "{mode:?} rr {rr} tc {tc}: {name} analytic {analytic} vs numeric {numeric}"
                        );
                    }
                }
            }
        }
    }
}
