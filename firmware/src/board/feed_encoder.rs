//! The feed axis' quadrature encoder on TIM4.
//!
//! # Design
//!
//! TIM4 in encoder mode 3 (x4: every edge of A and B) counts the axis position in a 16-bit
//! counter (embassy-stm32's `Qei`, all HAL). The sampling task reads it once per block and
//! `firmware::frontend::FeedVelocity` turns the readings into a velocity over a window of
//! blocks; the counter may wrap freely, the travel between two readings (at most 32 767
//! counts per block) is what is used. Not needed when the configuration gives a nominal
//! feed (`feed_velocity = { nominal = [..] }`); it is read anyway, and ignored.

use embassy_stm32::peripherals::{PB6, PB7, TIM4};
use embassy_stm32::timer::qei::{Config, Qei};
use embassy_stm32::Peri;

/// The peripherals of the feed encoder.
pub struct Parts {
    /// Encoder timer.
    pub tim: Peri<'static, TIM4>,
    /// Channel A.
    pub a: Peri<'static, PB6>,
    /// Channel B.
    pub b: Peri<'static, PB7>,
}

/// The running encoder.
pub struct FeedEncoder {
    qei: Qei<'static, TIM4>,
}

impl FeedEncoder {
    /// Starts counting (x4, full 16-bit range; inputs without pulls: the line drivers'
    /// receiver drives them).
    pub fn new(p: Parts) -> Self {
        FeedEncoder {
            qei: Qei::new(p.tim, p.a, p.b, Config::default()),
        }
    }

    /// The counter now.
    pub fn count(&self) -> u16 {
        self.qei.count()
    }
}
