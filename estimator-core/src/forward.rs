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

use crate::coefficients::{CuttingCoefficients, LinearCoefficients, Specific};
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
/// the coefficients there. Shared by the forward model and the estimators.
#[derive(Clone, Copy, Debug)]
pub struct Operating {
    /// Arc integrals.
    pub arc: ArcIntegrals,
    /// Average chip thickness [mm].
    pub t_a_mm: f32,
    /// `K_s`, `r1`, `r2` at `t_a`.
    pub k: Specific,
}

impl Operating {
    /// Evaluates geometry and coefficients at `rr`, `tc_mm`.
    pub fn new(coeffs: &CuttingCoefficients, mode: MillingMode, rr: f32, tc_mm: f32) -> Self {
        Self::from_integrals(coeffs, ArcIntegrals::new(mode, rr), tc_mm)
    }

    /// Same, from arc integrals already evaluated.
    pub fn from_integrals(coeffs: &CuttingCoefficients, arc: ArcIntegrals, tc_mm: f32) -> Self {
        let t_a_mm = average_chip_thickness_mm(tc_mm, arc.c, arc.arc);
        Operating {
            arc,
            t_a_mm,
            k: coeffs.at(t_a_mm),
        }
    }

    /// `f_xt = F_ax / F_at = (a + r1 b) / c` (eq. 12).
    #[inline]
    pub fn ratio_fxt(&self) -> f32 {
        (self.arc.a + self.k.r1 * self.arc.b) / self.arc.c
    }

    /// `f_x = F_ax / sqrt(F_ax^2 + F_ay^2) = (a + r1 b) / sqrt((1 + r1^2)(a^2 + b^2))` (eq. 10).
    #[inline]
    pub fn ratio_fx(&self) -> f32 {
        let (a, b, r1) = (self.arc.a, self.arc.b, self.k.r1);
        (a + r1 * b) / libm::sqrtf((1.0 + r1 * r1) * (a * a + b * b))
    }

    /// `K' = K_s R t_c / phi_N` [N]: the force scale of eq. 7 per unit `R_a`.
    #[inline]
    pub fn force_scale_n(&self, tool: &Tool, tc_mm: f32) -> f32 {
        self.k.ks * tool.radius_mm * tc_mm / tool.tooth_pitch_rad()
    }

    /// Eq. 7 at axial immersion `ra`.
    pub fn forces(&self, tool: &Tool, tc_mm: f32, ra: f32) -> AverageForces {
        let s = self.force_scale_n(tool, tc_mm) * ra;
        let (a, b, c) = (self.arc.a, self.arc.b, self.arc.c);
        let r1 = self.k.r1;
        AverageForces {
            ft_n: s * c,
            fx_n: s * (a + r1 * b),
            fy_n: s * (-b + r1 * a),
            fz_n: s * self.k.r2 * c,
        }
    }
}

/// Eq. 7: per-tooth average forces of a cut.
pub fn average_forces(
    tool: &Tool,
    coeffs: &CuttingCoefficients,
    mode: MillingMode,
    e: Engagement,
) -> AverageForces {
    Operating::new(coeffs, mode, e.rr, e.tc_mm).forces(tool, e.tc_mm, e.ra)
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
