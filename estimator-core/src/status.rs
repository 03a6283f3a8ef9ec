//! Status flags carried with every estimate (and, later, every per-tooth record).
//!
//! A value is only to be trusted when [`Status::is_valid`] holds; otherwise the flags say
//! why. Numbers that go with a non-valid status are still finite (clamped, or 0 where no
//! number exists): nothing downstream ever sees a NaN.

/// A set of flags; empty means valid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Status(pub u16);

impl Status {
    /// Nothing wrong.
    pub const VALID: Status = Status(0);
    /// Forces below the configured floor: air cut, retract, spindle idle.
    pub const NOT_CUTTING: Status = Status(1 << 0);
    /// The force ratio lies outside what any radial immersion in `(0, 2]` produces; `R_r`
    /// clamped to the nearest end.
    pub const RR_CLAMPED: Status = Status(1 << 1);
    /// `R_a` came out negative or absurdly large (forces inconsistent with the model) and
    /// was clamped to `[0, RA_MAX]`.
    pub const RA_CLAMPED: Status = Status(1 << 2);
    /// Feed per tooth outside the range the cutting coefficients were identified over:
    /// the estimate is an extrapolation.
    pub const TC_OUT_OF_RANGE: Status = Status(1 << 3);
    /// An input was NaN or infinite, or t_c was not positive.
    pub const NON_FINITE: Status = Status(1 << 4);
    /// The ratio is insensitive to `R_r` here, or two immersions give the same ratio
    /// (up milling, light cuts): the branch nearest the slot was taken.
    pub const AMBIGUOUS: Status = Status(1 << 5);

    /// The tooth period was too short, too long, jumped in length, or held a glitch pulse:
    /// its averages are not used.
    pub const PERIOD_INVALID: Status = Status(1 << 6);
    /// No tooth-sync pulse within the longest allowed period (spindle stopped, encoder lost).
    pub const NO_SYNC: Status = Status(1 << 7);
    /// Samples in the period were NaN, infinite or at the ADC's clipping level.
    pub const INPUT_FAULT: Status = Status(1 << 8);
    /// Force rising or falling from one revolution to the next: entry, exit, a step in
    /// engagement.
    pub const TRANSIENT: Status = Status(1 << 9);
    /// Feed per tooth changing: feed override, speed change, acceleration.
    pub const FEED_CHANGE: Status = Status(1 << 10);
    /// The filter window still holds data from before the last disturbance.
    pub const SETTLING: Status = Status(1 << 11);
    /// The averaging window's boundary moved to a new place in the tooth period (see
    /// [`crate::window`]) within this period: its average mixes two alignments.
    pub const WINDOW_MOVED: Status = Status(1 << 12);

    /// Names for printing, in bit order.
    pub const NAMES: [(Status, &'static str); 13] = [
        (Self::NOT_CUTTING, "not_cutting"),
        (Self::RR_CLAMPED, "rr_clamped"),
        (Self::RA_CLAMPED, "ra_clamped"),
        (Self::TC_OUT_OF_RANGE, "tc_out_of_range"),
        (Self::NON_FINITE, "non_finite"),
        (Self::AMBIGUOUS, "ambiguous"),
        (Self::PERIOD_INVALID, "period_invalid"),
        (Self::NO_SYNC, "no_sync"),
        (Self::INPUT_FAULT, "input_fault"),
        (Self::TRANSIENT, "transient"),
        (Self::FEED_CHANGE, "feed_change"),
        (Self::SETTLING, "settling"),
        (Self::WINDOW_MOVED, "window_moved"),
    ];

    /// Parses `valid` or names joined by `|` (the `Display` form).
    pub fn parse(s: &str) -> Option<Status> {
        let s = s.trim();
        if s == "valid" {
            return Some(Status::VALID);
        }
        let mut out = Status::VALID;
        for name in s.split('|') {
            let (flag, _) = Self::NAMES.iter().find(|(_, n)| *n == name.trim())?;
            out |= *flag;
        }
        Some(out)
    }

    /// No flag set.
    #[inline]
    pub const fn is_valid(self) -> bool {
        self.0 == 0
    }

    /// Whether every flag of `other` is set.
    #[inline]
    pub const fn contains(self, other: Status) -> bool {
        self.0 & other.0 == other.0
    }

    /// Whether any flag of `other` is set.
    #[inline]
    pub const fn intersects(self, other: Status) -> bool {
        self.0 & other.0 != 0
    }

    /// Union.
    #[inline]
    pub const fn with(self, other: Status) -> Status {
        Status(self.0 | other.0)
    }

    /// Sets the flags of `other` when `cond` holds.
    #[inline]
    pub fn set_if(&mut self, cond: bool, other: Status) {
        if cond {
            self.0 |= other.0;
        }
    }
}

impl core::ops::BitOr for Status {
    type Output = Status;
    fn bitor(self, rhs: Status) -> Status {
        self.with(rhs)
    }
}

impl core::ops::BitOrAssign for Status {
    fn bitor_assign(&mut self, rhs: Status) {
        self.0 |= rhs.0;
    }
}

impl core::fmt::Display for Status {
    /// `valid`, or the flag names joined by `|`.
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        if self.is_valid() {
            return f.write_str("valid");
        }
        let mut first = true;
        for (flag, name) in Self::NAMES {
            if self.contains(flag) {
                if !first {
                    f.write_str("|")?;
                }
                f.write_str(name)?;
                first = false;
            }
        }
        let known = Self::NAMES.iter().fold(0, |m, (s, _)| m | s.0);
        if self.0 & !known != 0 {
            write!(f, "{}0x{:x}", if first { "" } else { "|" }, self.0 & !known)?;
        }
        Ok(())
    }
}
