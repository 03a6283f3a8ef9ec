//! Fixed polynomial for `R_r` from the motor-current ratio `f_xt` (the product's main route).
//!
//! The paper gives coefficients only for the dynamometer ratio `f_x` (Table 3). For
//! `f_xt = F_ax / F_at` they are fitted here, from the forward model, by the generator in
//! host-sim (`host-sim gen-poly`), which writes [`crate::fxt_poly`]. Same family as eq. 11,
//! two changes that make one set cover `t_c` 0.02-0.5 mm/tooth without the paper's split:
//! the feed enters as `ln(t_c)` (the coefficients are power laws of `t_a`), and both
//! variables are scaled to `[-1, 1]`:
//!
//! ```text
//! x = (f_xt - x_mid) / x_half,  y = (ln t_c - y_mid) / y_half,  R_r = sum_ik c[i][k] x^i y^k
//! ```
//!
//! A set is only valid for the coefficients and milling mode it was fitted for, inside its
//! fitted `t_c` and `R_r` ranges; elsewhere the estimator falls back to the exact inversion.

use crate::coefficients::CuttingCoefficients;
use crate::geometry::MillingMode;

/// Relative margin on the `R_r` range accepted from the polynomial (its worst error is
/// about 0.7 %).
pub const RR_MARGIN: f32 = 0.03;

/// Polynomial degree + 1 in each variable.
pub const TERMS: usize = 6;

/// One fitted set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FxtPoly {
    /// Coefficients the fit was made for.
    pub coeffs: CuttingCoefficients,
    /// Milling mode the fit was made for.
    pub mode: MillingMode,
    /// `(x_mid, x_half)` scaling of `f_xt`.
    pub x_scale: (f32, f32),
    /// `(y_mid, y_half)` scaling of `ln t_c`.
    pub y_scale: (f32, f32),
    /// Fitted feed range [mm/tooth].
    pub tc_mm: (f32, f32),
    /// Fitted radial immersion range; a result outside it is not trusted.
    pub rr: (f32, f32),
    /// `c[i][k]` multiplies `x^i y^k`.
    pub c: [[f32; TERMS]; TERMS],
}

impl FxtPoly {
    /// Whether this set was fitted for `coeffs`' laws and `mode`. Not their fitted feed
    /// range (`tc_fit_mm`, where the laws were identified): the polynomial inverts eq. 12
    /// for the laws over its own `tc_mm`, and a calibration that reaches lower feeds with
    /// the same laws leaves it as exact as before.
    pub fn fits(&self, coeffs: &CuttingCoefficients, mode: MillingMode) -> bool {
        let laws = |c: &CuttingCoefficients| (c.ks, c.r1, c.r2);
        self.mode == mode && laws(&self.coeffs) == laws(coeffs)
    }

    /// The polynomial alone, without range checks.
    pub fn eval_raw(&self, fxt: f32, tc_mm: f32) -> f32 {
        self.eval_scaled(
            (fxt - self.x_scale.0) / self.x_scale.1,
            (libm::logf(tc_mm) - self.y_scale.0) / self.y_scale.1,
        )
    }

    #[inline(always)]
    fn eval_scaled(&self, x: f32, y: f32) -> f32 {
        let mut rr = 0.0;
        for row in self.c.iter().rev() {
            let mut ci = 0.0;
            for &ck in row.iter().rev() {
                ci = ci * y + ck;
            }
            rr = rr * x + ci;
        }
        rr
    }

    /// [`Self::eval_scaled`] for finite `x` and `y`: each Horner chain starts at its top
    /// coefficient instead of at `0 * y + c`, which for finite `y` is exactly that
    /// coefficient (no fitted coefficient is zero): the same value, 7 operations fewer.
    #[inline(always)]
    fn eval_scaled_finite(&self, x: f32, y: f32) -> f32 {
        let horner = |row: &[f32; TERMS]| {
            let [c0, c1, c2, c3, c4, c5] = *row;
            ((((c5 * y + c4) * y + c3) * y + c2) * y + c1) * y + c0
        };
        let [r0, r1, r2, r3, r4, r5] = &self.c;
        ((((horner(r5) * x + horner(r4)) * x + horner(r3)) * x + horner(r2)) * x + horner(r1)) * x
            + horner(r0)
    }

    /// `R_r` if `(fxt, tc_mm)` lies in the fitted domain, else `None`.
    #[inline(always)]
    pub fn eval(&self, fxt: f32, tc_mm: f32) -> Option<f32> {
        let x = (fxt - self.x_scale.0) / self.x_scale.1;
        if !(tc_mm >= self.tc_mm.0 && tc_mm <= self.tc_mm.1 && (-1.0..=1.0).contains(&x)) {
            return None;
        }
        // `x` is in [-1, 1] and `t_c` in the fitted range here: both coordinates finite.
        let rr = self.eval_scaled_finite(x, (libm::logf(tc_mm) - self.y_scale.0) / self.y_scale.1);
        // Both ends get the fit's own error as margin, so that a cut exactly at the edge
        // (the slot, above all) is not pushed to the slower inversion; the caller clamps.
        (rr >= self.rr.0 * (1.0 - RR_MARGIN) && rr <= self.rr.1 * (1.0 + RR_MARGIN)).then_some(rr)
    }
}
