//! Small fixed-capacity lookup types for machine data: a piecewise-linear [`Table`] and
//! piecewise regression lines [`Segments`].
//!
//! Both hold their data in a `heapless::Vec` (no heap) and are checked once by
//! `validate`; evaluation never panics, also on an unvalidated (empty, unsorted) value or a
//! NaN argument, where it returns NaN or a meaningless but finite number. Motor data sheets
//! give a handful of points per curve (paper 003, Table 1: seven speeds per winding), so
//! the capacities are small.

use crate::ConfigError;

/// Most points a [`Table`] holds.
pub const TABLE_CAPACITY: usize = 8;
/// Most lines a [`Segments`] holds.
pub const SEGMENTS_CAPACITY: usize = 4;

/// Piecewise-linear function through `[x, y]` points, sorted by strictly increasing `x`,
/// held constant beyond the first and last points (clamped, not extrapolated: a data sheet
/// says nothing outside its range and a straight extrapolation can reach zero or change
/// sign).
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(transparent))]
pub struct Table {
    /// `[x, y]` points, `x` strictly increasing, at least one.
    pub points: heapless::Vec<[f32; 2], TABLE_CAPACITY>,
}

impl Table {
    /// From a constant array (a capacity overflow is a compile-time error); not validated.
    pub const fn from_array<const M: usize>(points: [[f32; 2]; M]) -> Table {
        Table {
            points: heapless::Vec::from_array(points),
        }
    }

    /// From a slice, validated; `OutOfRange("table")` if it holds more than
    /// [`TABLE_CAPACITY`] points.
    pub fn new(points: &[[f32; 2]]) -> Result<Table, ConfigError> {
        let points =
            heapless::Vec::from_slice(points).map_err(|_| ConfigError::OutOfRange("table"))?;
        let t = Table { points };
        t.validate()?;
        Ok(t)
    }

    /// Linear interpolation at `x`, clamped to the end values. NaN for a NaN `x` or an
    /// empty table.
    pub fn eval(&self, x: f32) -> f32 {
        let p = &self.points;
        let (Some(first), Some(last)) = (p.first(), p.last()) else {
            return f32::NAN;
        };
        if x.is_nan() {
            return f32::NAN;
        }
        if x <= first[0] {
            return first[1];
        }
        for w in p.windows(2) {
            let ([x0, y0], [x1, y1]) = (w[0], w[1]);
            if x <= x1 {
                // x0 < x <= x1 in a validated table, so the division is safe; an
                // unvalidated equal pair gives a non-finite value, never a panic.
                return y0 + (y1 - y0) * (x - x0) / (x1 - x0);
            }
        }
        last[1]
    }

    /// [`Self::validate_as`] naming the parameter `"table"`.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.validate_as("table")
    }

    /// Checks: at least one point, all finite (`NonFinite(name)`), `x` strictly increasing
    /// (`OutOfRange(name)`). `name` is the field the table sits in, so the error says which
    /// table is wrong.
    pub fn validate_as(&self, name: &'static str) -> Result<(), ConfigError> {
        if self.points.is_empty() {
            return Err(ConfigError::OutOfRange(name));
        }
        if self.points.iter().flatten().any(|v| !v.is_finite()) {
            return Err(ConfigError::NonFinite(name));
        }
        if self.points.windows(2).any(|w| w[1][0] <= w[0][0]) {
            return Err(ConfigError::OutOfRange(name));
        }
        Ok(())
    }
}

/// One regression line `y = slope * rpm + intercept`, valid from `from_rpm` up to the next
/// line's `from_rpm`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Segment {
    /// Lower end of the speed range [rpm].
    pub from_rpm: f32,
    /// [unit of `y` per rpm].
    pub slope: f32,
    /// `y` at 0 rpm [unit of `y`].
    pub intercept: f32,
}

/// Piecewise regression lines in spindle speed, e.g. paper 003's idle load (Table 2), which
/// changes slope at 11000 rpm. Each line holds from its `from_rpm` to the next one's; the
/// first line also covers speeds below its `from_rpm`, the last everything above.
///
/// Note: the lines need not meet: paper 003's idle load drops by 0.33 % at 11000 rpm, and
/// forcing continuity would move the fitted lines away from the measurements.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(transparent))]
pub struct Segments {
    /// Lines, `from_rpm` strictly increasing, at least one.
    pub lines: heapless::Vec<Segment, SEGMENTS_CAPACITY>,
}

impl Segments {
    /// From a constant array (a capacity overflow is a compile-time error); not validated.
    pub const fn from_array<const M: usize>(lines: [Segment; M]) -> Segments {
        Segments {
            lines: heapless::Vec::from_array(lines),
        }
    }

    /// From a slice, validated; `OutOfRange("segments")` if it holds more than
    /// [`SEGMENTS_CAPACITY`] lines.
    pub fn new(lines: &[Segment]) -> Result<Segments, ConfigError> {
        let lines =
            heapless::Vec::from_slice(lines).map_err(|_| ConfigError::OutOfRange("segments"))?;
        let s = Segments { lines };
        s.validate()?;
        Ok(s)
    }

    /// The line covering `rpm`, evaluated there. NaN for a NaN `rpm` or no lines.
    pub fn eval(&self, rpm: f32) -> f32 {
        let Some(mut line) = self.lines.first() else {
            return f32::NAN;
        };
        for l in self.lines.iter().skip(1) {
            if rpm >= l.from_rpm {
                line = l;
            }
        }
        line.slope * rpm + line.intercept
    }

    /// [`Self::validate_as`] naming the parameter `"segments"`.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.validate_as("segments")
    }

    /// Checks: at least one line, all finite (`NonFinite(name)`), `from_rpm` strictly
    /// increasing (`OutOfRange(name)`).
    pub fn validate_as(&self, name: &'static str) -> Result<(), ConfigError> {
        if self.lines.is_empty() {
            return Err(ConfigError::OutOfRange(name));
        }
        if self
            .lines
            .iter()
            .any(|l| !(l.from_rpm.is_finite() && l.slope.is_finite() && l.intercept.is_finite()))
        {
            return Err(ConfigError::NonFinite(name));
        }
        if self
            .lines
            .windows(2)
            .any(|w| w[1].from_rpm <= w[0].from_rpm)
        {
            return Err(ConfigError::OutOfRange(name));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ConfigError::*;

    fn isclose(a: f32, b: f32, atol: f32) -> bool {
        (a - b).abs() <= atol
    }

    #[test]
    fn table_interpolates_and_clamps() {
        let t = Table::from_array([[1.0, 10.0], [3.0, 20.0], [4.0, 0.0]]);
        assert_eq!(t.validate(), Ok(()));
        assert!(isclose(t.eval(2.0), 15.0, 1e-6));
        assert!(isclose(t.eval(3.5), 10.0, 1e-6));
        assert_eq!(t.eval(3.0), 20.0);
        assert_eq!(t.eval(-100.0), 10.0);
        assert_eq!(t.eval(1e9), 0.0);
        assert_eq!(t.eval(f32::INFINITY), 0.0);
        assert!(t.eval(f32::NAN).is_nan());
        let one = Table::from_array([[5.0, 7.0]]);
        assert_eq!(one.validate(), Ok(()));
        assert_eq!(
            (one.eval(0.0), one.eval(5.0), one.eval(9.0)),
            (7.0, 7.0, 7.0)
        );
    }

    #[test]
    fn unvalidated_table_does_not_panic() {
        assert!(Table::default().eval(1.0).is_nan());
        let dup = Table::from_array([[1.0, 1.0], [1.0, 2.0], [0.0, 3.0]]);
        for x in [-1.0, 0.5, 1.0, 2.0, f32::NAN] {
            let _ = dup.eval(x);
        }
    }

    #[test]
    fn table_validation_names_the_table() {
        assert_eq!(Table::default().validate_as("lr"), Err(OutOfRange("lr")));
        let unsorted = Table::from_array([[2.0, 1.0], [1.0, 1.0]]);
        assert_eq!(unsorted.validate_as("lr"), Err(OutOfRange("lr")));
        let equal = Table::from_array([[1.0, 1.0], [1.0, 2.0]]);
        assert_eq!(equal.validate(), Err(OutOfRange("table")));
        let nan = Table::from_array([[1.0, f32::NAN]]);
        assert_eq!(nan.validate_as("lr"), Err(NonFinite("lr")));
        let inf = Table::from_array([[f32::INFINITY, 1.0]]);
        assert_eq!(inf.validate(), Err(NonFinite("table")));
        assert_eq!(Table::new(&[[0.0, 0.0]; 9]), Err(OutOfRange("table")));
        assert!(Table::new(&[[0.0, 1.0], [1.0, 2.0]]).is_ok());
    }

    #[test]
    fn segments_pick_the_line_in_range() {
        let s = Segments::from_array([
            Segment {
                from_rpm: 0.0,
                slope: 1.0,
                intercept: 0.0,
            },
            Segment {
                from_rpm: 10.0,
                slope: 0.0,
                intercept: 100.0,
            },
        ]);
        assert_eq!(s.validate(), Ok(()));
        assert_eq!(s.eval(-5.0), -5.0); // below the first: the first line
        assert_eq!(s.eval(9.5), 9.5);
        assert_eq!(s.eval(10.0), 100.0); // a line holds from its own from_rpm
        assert_eq!(s.eval(1e6), 100.0);
        assert!(s.eval(f32::NAN).is_nan());
        assert!(Segments::default().eval(1.0).is_nan());
    }

    #[test]
    fn segments_validation() {
        let line = |from_rpm| Segment {
            from_rpm,
            slope: 0.0,
            intercept: 0.0,
        };
        assert_eq!(Segments::default().validate(), Err(OutOfRange("segments")));
        assert_eq!(
            Segments::from_array([line(1.0), line(1.0)]).validate_as("idle"),
            Err(OutOfRange("idle"))
        );
        assert_eq!(
            Segments::from_array([line(f32::NAN)]).validate_as("idle"),
            Err(NonFinite("idle"))
        );
        assert_eq!(
            Segments::new(&[line(0.0), line(1.0), line(2.0), line(3.0), line(4.0)]),
            Err(OutOfRange("segments"))
        );
        assert!(Segments::new(&[line(0.0), line(1.0)]).is_ok());
    }
}
