//! f32 helpers that stay in single precision and out of library calls.
//!
//! Note: `libm::sinf`, `cosf` and `hypotf` compute in f64, which the Cortex-M4F's FPU does
//! not have: about 1 300 instructions a call in software (measured under QEMU, see
//! BENCHMARKS.md). The per-tooth path avoids them: the arc's sine follows from `R_r`
//! algebraically, and a hypotenuse of forces never comes near f32's range.
//!
//! `f32::max`/`f32::min` lower to calls of `fmaxf`/`fminf` on thumbv7em (the M4F has no
//! `VMAXNM`), about 15 instructions each; [`max`] and [`min`] give the same results with a
//! compare and a select. `libm::sqrtf` is a software loop there (~56 instructions; the
//! `VSQRT` instruction needs `unsafe` asm or an unstable intrinsic), so the per-tooth code
//! takes a square root only where a value needs one, not where a comparison will do.

/// `f32::max` without the library call: the larger of `a` and `b`, the other one if one is
/// NaN (NaN only if both are).
#[inline(always)]
pub fn max(a: f32, b: f32) -> f32 {
    // `b != b`: b is NaN.
    #[allow(clippy::eq_op)]
    if a > b || b != b {
        a
    } else {
        b
    }
}

/// `f32::min` without the library call: the smaller of `a` and `b`, the other one if one
/// is NaN (NaN only if both are).
#[inline(always)]
pub fn min(a: f32, b: f32) -> f32 {
    #[allow(clippy::eq_op)]
    if a < b || b != b {
        a
    } else {
        b
    }
}

/// `sqrt(a^2 + b^2)` in f32; scales by a power of two first only where squaring would
/// overflow or underflow (never for forces or velocities).
///
/// With one argument zero the result is the other's magnitude, without a square root:
/// the same value `sqrtf(a * a)` gives (in binary floating point with rounding to
/// nearest, `sqrt(a * a) == |a|` whenever `a * a` neither overflows nor underflows), and
/// the same `libm::hypotf` gives outside that range. A one-axis feed (`v_y = 0`) and a zero
/// gain uncertainty take this path.
#[inline]
pub fn hypot(a: f32, b: f32) -> f32 {
    if b == 0.0 {
        return a.abs();
    }
    if a == 0.0 {
        return b.abs();
    }
    // A plain compare, not `max`: with a NaN argument either choice ends in NaN (the
    // square root of a NaN sum, or `hypotf`), and an infinity is out of range either way.
    let (x, y) = (a.abs(), b.abs());
    let m = if x > y { x } else { y };
    if (1e-18..=1e18).contains(&m) {
        libm::sqrtf(a * a + b * b)
    } else {
        scaled_hypot(x, y, m)
    }
}

/// [`hypot`] where squaring would overflow or underflow: the magnitudes `x`, `y` (their
/// larger `m`) scaled by a power of two into the range, which is exact, and scaled back.
/// Not `libm::hypotf`: it computes in f64, and the double-precision routines it pulls in
/// are 2 KiB of the firmware's flash for a path no force takes.
#[cold]
fn scaled_hypot(x: f32, y: f32, m: f32) -> f32 {
    if x == f32::INFINITY || y == f32::INFINITY {
        return f32::INFINITY;
    }
    if x.is_nan() || y.is_nan() {
        return f32::NAN;
    }
    // 2^-70 takes the largest f32 (2^128) to 2^58; 2^90 takes the least subnormal
    // (2^-149) to 2^-59, whose square is still normal.
    let (up, down) = if m > 1.0 {
        (
            f32::from_bits((127 - 70) << 23),
            f32::from_bits((127 + 70) << 23),
        )
    } else {
        (
            f32::from_bits((127 + 90) << 23),
            f32::from_bits((127 - 90) << 23),
        )
    };
    let (xs, ys) = (x * up, y * up);
    libm::sqrtf(xs * xs + ys * ys) * down
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn max_min_match_std() {
        let v = [
            f32::NAN,
            f32::NEG_INFINITY,
            -3.5,
            -1.0,
            -0.0,
            0.0,
            1e-40,
            2.0,
            f32::MAX,
            f32::INFINITY,
        ];
        for &a in &v {
            for &b in &v {
                let same = |x: f32, y: f32| {
                    (x.is_nan() && y.is_nan())
                        || x == y && x.is_sign_negative() == y.is_sign_negative()
                };
                // Signed zeros: std leaves the choice open; only compare values there.
                if a == 0.0 && b == 0.0 {
                    assert_eq!(max(a, b), 0.0);
                    assert_eq!(min(a, b), 0.0);
                    continue;
                }
                assert!(same(max(a, b), a.max(b)), "max({a}, {b})");
                assert!(same(min(a, b), a.min(b)), "min({a}, {b})");
            }
        }
    }

    #[test]
    fn hypot_with_a_zero_is_the_square_root_of_the_square() {
        // The shortcut returns |a|; the square root of the rounded square must give the same
        // bits over the whole range where the square root path is taken, 1e-18..=1e18
        // (sampled here; checked exhaustively when the shortcut was written).
        let (lo, hi) = (1e-18f32.to_bits(), 1e18f32.to_bits());
        let mut bits = lo;
        while bits <= hi {
            let a = f32::from_bits(bits);
            assert_eq!(libm::sqrtf(a * a).to_bits(), a.to_bits(), "{a:e}");
            bits += 997;
        }
        for a in [0.0f32, -0.0, 1e-30, -1e-30, 5e30, f32::INFINITY, -2.5, 3.0] {
            assert_eq!(
                hypot(a, 0.0).to_bits(),
                libm::hypotf(a, 0.0).to_bits(),
                "{a}"
            );
            assert_eq!(
                hypot(0.0, a).to_bits(),
                libm::hypotf(0.0, a).to_bits(),
                "{a}"
            );
        }
        assert!(hypot(f32::NAN, 0.0).is_nan());
        assert!(hypot(f32::NAN, 1e30).is_nan() && hypot(1e-30, f32::NAN).is_nan());
        assert_eq!(hypot(f32::INFINITY, f32::NAN), f32::INFINITY);
        assert_eq!(hypot(-3.0, f32::NEG_INFINITY), f32::INFINITY);
        assert!(hypot(0.0, f32::NAN).is_nan());
        assert!(hypot(f32::NAN, 1.0).is_nan());
    }

    /// Out of the squaring range (the scaled path) against libm's f64 `hypotf`, which
    /// rounds once: within an ulp, from the least subnormal to the largest f32, ratios of
    /// the two arguments from 1 to beyond f32's precision.
    #[test]
    fn scaled_hypot_is_within_an_ulp_of_libm() {
        let mut bits = 1u32;
        while bits < f32::MAX.to_bits() {
            let a = f32::from_bits(bits);
            for r in [1.0f32, 0.75, 0.3, 1e-3, 1e-9, 0.0] {
                let b = -a * r;
                let (got, want) = (hypot(a, b), libm::hypotf(a, b));
                let ulps = got.to_bits().abs_diff(want.to_bits());
                assert!(ulps <= 1, "hypot({a:e}, {b:e}) = {got:e}, libm {want:e}");
            }
            bits += 9_973;
        }
    }
}
