//! Linear least squares by Householder QR, in f64.
//!
//! Solves `min |A c - b|_2` for a tall `A` (rows >= cols) of full column rank. QR rather
//! than the normal equations because `A^T A` squares the condition number: the
//! polynomial fits of `gen_poly` have monomial columns up to `x^5 y^5`, where that would
//! cost most of f64's digits. Weights are the caller's business (scale each row of `A`
//! and `b` by the same factor).

use std::fmt;

/// Why a system could not be solved.
#[derive(Clone, Debug, PartialEq)]
pub enum LstsqError {
    /// The dimensions do not make a tall system.
    Shape {
        /// Elements in `A`.
        a_len: usize,
        /// Rows (length of `b`).
        rows: usize,
        /// Columns asked for.
        cols: usize,
    },
    /// Column `column` is (numerically) a combination of the ones before it.
    RankDeficient {
        /// 0-based column index.
        column: usize,
    },
    /// `A` or `b` holds a NaN or infinity.
    NonFinite,
}

impl fmt::Display for LstsqError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LstsqError::Shape { a_len, rows, cols } => write!(
                f,
                "least squares: A has {a_len} elements, expected {rows} rows x {cols} columns \
                 with rows >= columns > 0"
            ),
            LstsqError::RankDeficient { column } => write!(
                f,
                "least squares: column {column} is linearly dependent on the earlier ones"
            ),
            LstsqError::NonFinite => f.write_str("least squares: NaN or infinity in A or b"),
        }
    }
}

impl std::error::Error for LstsqError {}

/// Least-squares solution `c` (length `cols`) of `A c = b`, `A` row-major with `b.len()`
/// rows.
pub fn lstsq(a: &[f64], cols: usize, b: &[f64]) -> Result<Vec<f64>, LstsqError> {
    let rows = b.len();
    if cols == 0 || rows < cols || a.len() != rows * cols {
        return Err(LstsqError::Shape {
            a_len: a.len(),
            rows,
            cols,
        });
    }
    if !a.iter().chain(b).all(|v| v.is_finite()) {
        return Err(LstsqError::NonFinite);
    }
    // Column-major copy: every Householder step works down whole columns.
    let mut q: Vec<Vec<f64>> = (0..cols)
        .map(|j| (0..rows).map(|i| a[i * cols + j]).collect())
        .collect();
    let mut rhs = b.to_vec();
    let max_norm = q.iter().map(|col| norm(col)).fold(0.0, f64::max);
    // The usual numerical-rank threshold (as in LAPACK's xGELSY / numpy's lstsq).
    let tol = rows as f64 * f64::EPSILON * max_norm;
    let mut diag = vec![0.0; cols];
    for j in 0..cols {
        let (done, rest) = q.split_at_mut(j + 1);
        let v = &mut done[j][j..];
        let len = norm(v);
        if len <= tol {
            return Err(LstsqError::RankDeficient { column: j });
        }
        // Reflect v onto -sign(v0)|v| e1; the sign choice avoids cancellation in v0 - alpha.
        let alpha = if v[0] > 0.0 { -len } else { len };
        v[0] -= alpha;
        let v_len2 = dot(v, v);
        for col in rest.iter_mut() {
            reflect(v, v_len2, &mut col[j..]);
        }
        reflect(v, v_len2, &mut rhs[j..]);
        diag[j] = alpha;
    }
    // Back substitution on R: diagonal in `diag`, R[j][k] (k > j) in q[k][j].
    let mut c = vec![0.0; cols];
    for j in (0..cols).rev() {
        let s: f64 = (j + 1..cols).map(|k| q[k][j] * c[k]).sum();
        c[j] = (rhs[j] - s) / diag[j];
    }
    Ok(c)
}

/// Applies `I - 2 v v^T / |v|^2` to `x` in place.
fn reflect(v: &[f64], v_len2: f64, x: &mut [f64]) {
    let t = 2.0 * dot(v, x) / v_len2;
    for (xi, vi) in x.iter_mut().zip(v) {
        *xi -= t * vi;
    }
}

fn dot(u: &[f64], v: &[f64]) -> f64 {
    u.iter().zip(v).map(|(a, b)| a * b).sum()
}

fn norm(v: &[f64]) -> f64 {
    // hypot-style scaling is unnecessary here: entries are O(1) monomials times weights.
    dot(v, v).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Row-major design matrix of the monomials `x^i y^k`, `i, k < n`, at `pts`.
    fn monomials(pts: &[(f64, f64)], n: usize) -> Vec<f64> {
        pts.iter()
            .flat_map(|&(x, y)| {
                (0..n).flat_map(move |i| (0..n).map(move |k| x.powi(i as i32) * y.powi(k as i32)))
            })
            .collect()
    }

    fn grid(n: usize) -> Vec<(f64, f64)> {
        let at = |i: usize| -1.0 + 2.0 * i as f64 / (n - 1) as f64;
        (0..n)
            .flat_map(|i| (0..n).map(move |k| (at(i), at(k))))
            .collect()
    }

    #[test]
    fn recovers_an_exact_polynomial() {
        // A 4x4 (degree 3 in each variable) polynomial with unequal, signed coefficients,
        // sampled on a 9x9 grid: the fit must return it to rounding.
        let n = 4;
        let truth: Vec<f64> = (0..n * n).map(|j| (j as f64 - 7.3) * 0.37).collect();
        let pts = grid(9);
        let a = monomials(&pts, n);
        let b: Vec<f64> = a
            .chunks(n * n)
            .map(|row| row.iter().zip(&truth).map(|(m, c)| m * c).sum())
            .collect();
        let c = lstsq(&a, n * n, &b).expect("full-rank system");
        for (j, (got, want)) in c.iter().zip(&truth).enumerate() {
            assert!((got - want).abs() < 1e-12, "c[{j}] = {got}, want {want}");
        }
    }

    #[test]
    fn residual_is_orthogonal_to_the_columns() {
        // An inconsistent system: the least-squares residual r = b - A c satisfies A^T r = 0.
        let pts = grid(7);
        let n = 3;
        let a = monomials(&pts, n);
        let b: Vec<f64> = pts
            .iter()
            .map(|&(x, y)| (3.0 * x).sin() + (x * y).exp())
            .collect();
        let c = lstsq(&a, n * n, &b).expect("full-rank system");
        let r: Vec<f64> = a
            .chunks(n * n)
            .zip(&b)
            .map(|(row, bi)| bi - dot(row, &c))
            .collect();
        assert!(norm(&r) > 1e-3, "test system should not be consistent");
        for j in 0..n * n {
            let atr: f64 = a.chunks(n * n).zip(&r).map(|(row, ri)| row[j] * ri).sum();
            assert!(atr.abs() < 1e-12, "column {j}: A^T r = {atr}");
        }
    }

    #[test]
    fn names_the_dependent_column() {
        // Column 2 = column 0 + column 1.
        let a = [1.0, 2.0, 3.0, 0.0, 1.0, 1.0, 4.0, -1.0, 3.0, 2.0, 2.0, 4.0];
        let b = [1.0, 2.0, 3.0, 4.0];
        assert_eq!(
            lstsq(&a, 3, &b),
            Err(LstsqError::RankDeficient { column: 2 })
        );
    }

    #[test]
    fn rejects_bad_shapes_and_values() {
        assert!(matches!(
            lstsq(&[1.0, 2.0], 2, &[1.0]),
            Err(LstsqError::Shape { .. })
        ));
        assert!(matches!(
            lstsq(&[1.0], 2, &[1.0]),
            Err(LstsqError::Shape { .. })
        ));
        assert_eq!(
            lstsq(&[1.0, f64::NAN], 1, &[1.0, 2.0]),
            Err(LstsqError::NonFinite)
        );
    }
}
