//! f32 helpers that stay in single precision.
//!
//! Note: `libm::sinf`, `cosf` and `hypotf` compute in f64, which the Cortex-M4F's FPU does
//! not have: about 1 300 instructions a call in software (measured under QEMU, see
//! BENCHMARKS.md). The per-tooth path avoids them: the arc's sine follows from `R_r`
//! algebraically, and a hypotenuse of forces never comes near f32's range.

/// `sqrt(a^2 + b^2)` in f32; falls back to `libm::hypotf` only where squaring would
/// overflow or underflow (never for forces or velocities).
#[inline]
pub fn hypot(a: f32, b: f32) -> f32 {
    let m = a.abs().max(b.abs());
    if (1e-18..=1e18).contains(&m) {
        libm::sqrtf(a * a + b * b)
    } else {
        libm::hypotf(a, b)
    }
}
