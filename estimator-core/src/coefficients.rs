//! Specific cutting coefficients.
//!
//! The estimator uses the power laws of paper 000 (eq. 9): `K_s`, `r1`, `r2` as powers of
//! the average chip thickness `t_a`, evaluated once per tooth period at `t_a`
//! (see `geometry::average_chip_thickness_mm`). The voxel simulator of paper 004 uses the
//! linear shearing + edge model instead ([`LinearCoefficients`]).

/// `y = k * t_a^p`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PowerLaw {
    /// Value at `t_a` = 1 mm.
    pub k: f32,
    /// Exponent.
    pub p: f32,
}

impl PowerLaw {
    /// Evaluates the law at `t_a_mm` (> 0).
    #[inline]
    pub fn at(&self, t_a_mm: f32) -> f32 {
        self.k * libm::powf(t_a_mm, self.p)
    }

    /// Evaluates the law at `t_a = exp(ln_t_a)`: cheaper when several laws share `t_a`.
    #[inline]
    pub fn at_ln(&self, ln_t_a: f32) -> f32 {
        self.k * libm::expf(self.p * ln_t_a)
    }
}

/// The three power laws of eq. 9 and the feed range they were identified over.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct CuttingCoefficients {
    /// Specific cutting force `K_s` [N/mm^2] against `t_a` [mm].
    pub ks: PowerLaw,
    /// Radial-to-tangential force ratio `r1`.
    pub r1: PowerLaw,
    /// Axial-to-tangential force ratio `r2`.
    pub r2: PowerLaw,
    /// Feed per tooth range of the calibration cuts [mm/tooth]; outside it the laws are
    /// extrapolated and estimates are flagged.
    pub tc_fit_mm: (f32, f32),
}

/// Relative slack on the ends of [`CuttingCoefficients::tc_fit_mm`].
pub const TC_RANGE_MARGIN: f32 = 0.02;

/// Paper 000, Table 2: SB40 steel, 16 mm HSS 4-flute end mill, 600 rpm,
/// t_c 0.1042 to 0.4667 mm/tooth.
pub const TABLE2: CuttingCoefficients = CuttingCoefficients {
    ks: PowerLaw {
        k: 646.08,
        p: -0.4362,
    },
    r1: PowerLaw {
        k: 0.2201,
        p: -0.2667,
    },
    r2: PowerLaw {
        k: 0.1244,
        p: 0.1702,
    },
    tc_fit_mm: (0.1042, 0.4667),
};

impl CuttingCoefficients {
    /// Whether `tc_mm` lies in the range the laws were identified over, give or take
    /// [`TC_RANGE_MARGIN`]: a measured feed jitters by a sample of period length, and the
    /// paper's own feeds sit on the ends of its range.
    pub fn tc_in_fit_range(&self, tc_mm: f32) -> bool {
        tc_mm >= self.tc_fit_mm.0 * (1.0 - TC_RANGE_MARGIN)
            && tc_mm <= self.tc_fit_mm.1 * (1.0 + TC_RANGE_MARGIN)
    }

    /// Checks that every parameter is finite and the laws are usable (`k > 0`).
    pub fn validate(&self) -> Result<(), crate::ConfigError> {
        use crate::ConfigError::*;
        for (name, law) in [("ks", self.ks), ("r1", self.r1), ("r2", self.r2)] {
            if !law.k.is_finite() || !law.p.is_finite() {
                return Err(NonFinite(name));
            }
            if law.k <= 0.0 {
                return Err(OutOfRange(name));
            }
        }
        let (lo, hi) = self.tc_fit_mm;
        if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi >= lo) {
            return Err(OutOfRange("tc_fit_mm"));
        }
        Ok(())
    }
}

/// Linear shearing + edge coefficients (paper 004, paper 003 eq. 2):
/// `dF_t = K_tc h dz + K_te dz`, likewise radial and axial.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct LinearCoefficients {
    /// Tangential shearing [N/mm^2].
    pub ktc: f32,
    /// Radial shearing [N/mm^2].
    pub krc: f32,
    /// Axial shearing [N/mm^2].
    pub kac: f32,
    /// Tangential edge [N/mm].
    pub kte: f32,
    /// Radial edge [N/mm].
    pub kre: f32,
    /// Axial edge [N/mm].
    pub kae: f32,
}

/// Paper 004's Al6061 values.
pub const AL6061: LinearCoefficients = LinearCoefficients {
    ktc: 680.06,
    krc: 179.76,
    kac: 103.87,
    kte: 14.62,
    kre: 11.41,
    kae: -1.6,
};
