//! Linear regression with the uncertainty of its coefficients, for the calibration fits.
//!
//! The solution comes from [`crate::lstsq`] (QR); the covariance `s^2 (A^T A)^-1` from the
//! same columns scaled to unit norm, so that a badly scaled column (a viscous term in N per
//! mm/min next to an offset in A) does not cost the inverse its digits. Intervals are
//! Student-t at 95 %: calibration fits have few points (a handful of feeds, a dozen
//! speeds), where 1.96 sigma would claim too much.

use crate::lstsq::lstsq;
use anyhow::{anyhow, Result};

/// A fitted linear model `y = A c`.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearFit {
    /// Coefficients.
    pub coef: Vec<f64>,
    /// Standard error of each coefficient (NaN without degrees of freedom).
    pub se: Vec<f64>,
    /// Half-width of each coefficient's 95 % confidence interval (NaN likewise).
    pub ci95: Vec<f64>,
    /// `y - A c` per row.
    pub residuals: Vec<f64>,
    /// Root mean square of the residuals.
    pub rms: f64,
    /// Rows minus columns.
    pub dof: usize,
}

/// Two-sided 95 % quantile of Student's t with `dof` degrees of freedom (`t_0.975`).
pub fn t95(dof: usize) -> f64 {
    // Tabulated to 30; beyond, the Cornish-Fisher expansion about the normal quantile is
    // good to 1e-4.
    const T: [f64; 30] = [
        12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160,
        2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056,
        2.052, 2.048, 2.045, 2.042,
    ];
    match dof {
        0 => f64::NAN,
        1..=30 => T[dof - 1],
        _ => {
            let z = 1.959_964;
            let v = dof as f64;
            let z3 = z * z * z;
            let z5 = z3 * z * z;
            z + (z3 + z) / (4.0 * v) + (5.0 * z5 + 16.0 * z3 + 3.0 * z) / (96.0 * v * v)
        }
    }
}

/// Least squares `min |A c - y|` (`A` row-major, `cols` columns) with standard errors.
pub fn fit_linear(a: &[f64], cols: usize, y: &[f64]) -> Result<LinearFit> {
    let coef = lstsq(a, cols, y).map_err(|e| anyhow!("{e}"))?;
    let rows = y.len();
    let residuals: Vec<f64> = (0..rows)
        .map(|i| y[i] - (0..cols).map(|j| a[i * cols + j] * coef[j]).sum::<f64>())
        .collect();
    let ssr: f64 = residuals.iter().map(|r| r * r).sum();
    let dof = rows - cols;
    let s2 = if dof > 0 { ssr / dof as f64 } else { f64::NAN };
    // (A^T A)^-1 of the unit-norm columns, then unscaled.
    let norms: Vec<f64> = (0..cols)
        .map(|j| {
            (0..rows)
                .map(|i| a[i * cols + j].powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .collect();
    let mut m = vec![0.0; cols * cols];
    for j in 0..cols {
        for k in 0..cols {
            m[j * cols + k] = (0..rows)
                .map(|i| a[i * cols + j] * a[i * cols + k])
                .sum::<f64>()
                / (norms[j] * norms[k]);
        }
    }
    let inv = invert(&m, cols).ok_or_else(|| anyhow!("least squares: singular normal matrix"))?;
    let t = t95(dof);
    let se: Vec<f64> = (0..cols)
        .map(|j| (s2 * inv[j * cols + j]).sqrt() / norms[j])
        .collect();
    let ci95 = se.iter().map(|s| s * t).collect();
    Ok(LinearFit {
        coef,
        se,
        ci95,
        rms: (ssr / rows as f64).sqrt(),
        residuals,
        dof,
    })
}

/// Inverse of the `n x n` row-major `m` by Gauss-Jordan with partial pivoting.
fn invert(m: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut a = m.to_vec();
    let mut inv: Vec<f64> = (0..n * n)
        .map(|i| if i / n == i % n { 1.0 } else { 0.0 })
        .collect();
    for col in 0..n {
        let pivot =
            (col..n).max_by(|&i, &j| a[i * n + col].abs().total_cmp(&a[j * n + col].abs()))?;
        if a[pivot * n + col].abs() < 1e-14 {
            return None;
        }
        for k in 0..n {
            a.swap(col * n + k, pivot * n + k);
            inv.swap(col * n + k, pivot * n + k);
        }
        let d = a[col * n + col];
        for k in 0..n {
            a[col * n + k] /= d;
            inv[col * n + k] /= d;
        }
        for row in 0..n {
            if row != col {
                let f = a[row * n + col];
                for k in 0..n {
                    a[row * n + k] -= f * a[col * n + k];
                    inv[row * n + k] -= f * inv[col * n + k];
                }
            }
        }
    }
    Some(inv)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Student's t density.
    fn t_pdf(x: f64, v: f64) -> f64 {
        // Gamma ratio by the log-gamma of Stirling's series (v >= 1 here).
        fn ln_gamma(z: f64) -> f64 {
            if z < 7.0 {
                return ln_gamma(z + 1.0) - z.ln();
            }
            (z - 0.5) * z.ln() - z + 0.5 * (2.0 * std::f64::consts::PI).ln() + 1.0 / (12.0 * z)
                - 1.0 / (360.0 * z.powi(3))
        }
        let c = (ln_gamma((v + 1.0) / 2.0) - ln_gamma(v / 2.0)).exp()
            / (v * std::f64::consts::PI).sqrt();
        c * (1.0 + x * x / v).powf(-(v + 1.0) / 2.0)
    }

    #[test]
    fn t_quantiles_hold_95_percent() {
        // Brute-force integral of the density from -t to t.
        for dof in [1usize, 2, 3, 5, 10, 30, 31, 60, 200] {
            let t = t95(dof);
            let n = 200_000;
            let h = 2.0 * t / n as f64;
            let p: f64 = (0..n)
                .map(|i| t_pdf(-t + (i as f64 + 0.5) * h, dof as f64) * h)
                .sum();
            assert!((p - 0.95).abs() < 2e-4, "dof {dof}: t {t} covers {p}");
        }
    }

    #[test]
    fn straight_line_and_its_standard_errors() {
        // y = 2 + 3 x with residuals +-e: the textbook formulas for a line.
        let xs = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        let e = [0.1, -0.1, 0.1, -0.1, 0.1, -0.1];
        let a: Vec<f64> = xs.iter().flat_map(|&x| [1.0, x]).collect();
        let y: Vec<f64> = xs.iter().zip(e).map(|(&x, e)| 2.0 + 3.0 * x + e).collect();
        let f = fit_linear(&a, 2, &y).unwrap();
        let n = xs.len() as f64;
        let mx = xs.iter().sum::<f64>() / n;
        let sxx: f64 = xs.iter().map(|x| (x - mx).powi(2)).sum();
        let ssr: f64 = f.residuals.iter().map(|r| r * r).sum();
        let s2 = ssr / (n - 2.0);
        let se_slope = (s2 / sxx).sqrt();
        let se_icpt = (s2 * (1.0 / n + mx * mx / sxx)).sqrt();
        assert!((f.se[1] - se_slope).abs() < 1e-12 * se_slope.max(1.0));
        assert!((f.se[0] - se_icpt).abs() < 1e-12 * se_icpt.max(1.0));
        assert!((f.ci95[1] - 2.776 * se_slope).abs() < 1e-9);
        assert!((f.coef[1] - 3.0).abs() < 0.1 && (f.coef[0] - 2.0).abs() < 0.2);
        assert_eq!(f.dof, 4);
    }
}
