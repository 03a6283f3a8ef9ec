//! Stage marks for instruction-count benches (tests/target-check's `icount-bench`).
//!
//! The per-tooth code is written once, generic over a [`Probe`] that is told when each stage
//! ends. The production entry points (`Monitor::process`, `Alarms::process`,
//! `Pipeline::process`) pass [`NoProbe`], whose marks are empty and inlined away: the code
//! they compile to is the same as without the marks. The `*_probed` entry points that take
//! another probe exist only with the `probe` feature, for the bench, which reads a timer in
//! [`Probe::mark`] to split a tooth update into its stages.

/// Where a stage of the per-tooth work ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Stage {
    /// `Timing::push` closed a tooth period (with the sample's own accumulation).
    Period,
    /// Means converted: speed, `t_c`, feed force, tangential force, the record started.
    Forces,
    /// Validity, cutting and feed-change checks, the tooth stored in the filter window.
    Checks,
    /// `Monitor::blocks`: revolution means, filter, scatter.
    Blocks,
    /// Transient test and the running noise variance.
    Transient,
    /// Filter output chosen, settling checked.
    Filter,
    /// The estimator.
    Estimate,
    /// The record's values complete (and, in the pipeline, its copy for the alarms
    /// written); the returned record is written right after, straight into its place.
    Record,
    /// Alarms: watched signal, resets, history.
    AlarmHistory,
    /// Alarms: revolution mean of the watched signal.
    AlarmRevMean,
    /// Alarms: breakage detector.
    AlarmBreakage,
    /// Alarms: tool-gone detector.
    AlarmToolGone,
    /// Alarms: overload detector.
    AlarmOverload,
    /// Alarms: teach-in check.
    AlarmTeach,
    /// Alarms: wear (EWRLS) update. (The output is then built straight into the caller's
    /// place: what follows the last mark is that and the return.)
    AlarmWear,
}

impl Stage {
    /// Number of stages.
    pub const COUNT: usize = 15;

    /// Every stage, in the order a full tooth update passes them.
    pub const ALL: [Stage; Stage::COUNT] = [
        Stage::Period,
        Stage::Forces,
        Stage::Checks,
        Stage::Blocks,
        Stage::Transient,
        Stage::Filter,
        Stage::Estimate,
        Stage::Record,
        Stage::AlarmHistory,
        Stage::AlarmRevMean,
        Stage::AlarmBreakage,
        Stage::AlarmToolGone,
        Stage::AlarmOverload,
        Stage::AlarmTeach,
        Stage::AlarmWear,
    ];

    /// Short name.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Period => "period",
            Stage::Forces => "forces",
            Stage::Checks => "checks",
            Stage::Blocks => "blocks",
            Stage::Transient => "transient",
            Stage::Filter => "filter",
            Stage::Estimate => "estimate",
            Stage::Record => "record",
            Stage::AlarmHistory => "alarm_history",
            Stage::AlarmRevMean => "alarm_rev_mean",
            Stage::AlarmBreakage => "alarm_breakage",
            Stage::AlarmToolGone => "alarm_tool_gone",
            Stage::AlarmOverload => "alarm_overload",
            Stage::AlarmTeach => "alarm_teach",
            Stage::AlarmWear => "alarm_wear",
        }
    }
}

/// Told where each stage of a tooth update ends.
pub trait Probe {
    /// `stage` has just ended.
    fn mark(&mut self, stage: Stage);
}

/// The production probe: does nothing, costs nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoProbe;

impl Probe for NoProbe {
    #[inline(always)]
    fn mark(&mut self, _stage: Stage) {}
}
