//! The whole board in one call: [`Monitor`] then [`Alarms`], per sample.
//!
//! The firmware's monitor task and host-sim's replay both run exactly this, so that the
//! records and the alarms they produce from the same samples are the same bit for bit.

use crate::alarm::{AlarmConfig, AlarmOutput, AlarmState, Alarms};
use crate::frontend::FrontEnd;
use crate::monitor::{Monitor, MonitorConfig, MonitorState, Sample, ToothRecord};
use crate::probe::{NoProbe, Probe, Stage};
use crate::tooth::Period;
use crate::ConfigError;

/// Everything a board is configured with: the one type host-sim reads from TOML
/// (`machine.toml`) and the firmware gets at build time.
#[derive(Clone, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MachineConfig {
    /// Signal chain and estimator.
    pub monitor: MonitorConfig,
    /// Detectors.
    pub alarms: AlarmConfig,
    /// The board's analog inputs and feed encoder (volts to signal units, counts to mm).
    /// Replay ignores it (a trace is already in signal units); a file without it gets the
    /// defaults.
    #[cfg_attr(feature = "serde", serde(default))]
    pub front_end: FrontEnd,
}

impl MachineConfig {
    /// Validates all three parts (the front end is checked, not kept: the pipeline runs on
    /// signal units).
    pub fn build(self) -> Result<Pipeline, ConfigError> {
        self.front_end.validate()?;
        let alarms = self.alarms.build(&self.monitor.estimator)?;
        let monitor = self.monitor.build()?;
        Ok(Pipeline { monitor, alarms })
    }
}

/// Validated monitor and alarms.
#[derive(Clone, Debug)]
pub struct Pipeline {
    monitor: Monitor,
    alarms: Alarms,
}

/// State of a [`Pipeline`].
#[derive(Clone, Debug, Default)]
pub struct PipelineState {
    /// Monitor state.
    pub monitor: MonitorState,
    /// Alarm state (the latched alarm lives here).
    pub alarms: AlarmState,
    /// The last record, where the alarms read it (see `Pipeline::tooth_update`).
    last: ToothRecord,
}

impl Pipeline {
    /// The monitor.
    pub fn monitor(&self) -> &Monitor {
        &self.monitor
    }

    /// The alarms.
    pub fn alarms(&self) -> &Alarms {
        &self.alarms
    }

    /// Feeds one sample; when a tooth period closes, its record and what the alarms say.
    /// A drop trip inside a period ([`crate::handover`]) latches the alarms between
    /// records: drive the output from [`AlarmState::output_latched`] (or
    /// [`AlarmState::output_cause`]) after every sample or block, not from the records
    /// alone.
    ///
    /// Not inlined, so that the result (168 bytes) is built straight into the caller's
    /// variable: bind it to a fresh `let` and match on a reference to it (`if let
    /// Some((rec, out)) = &result`); moving it elsewhere costs a `memcpy` call of about
    /// 200 instructions on the Cortex-M4.
    #[inline(never)]
    pub fn process(
        &self,
        st: &mut PipelineState,
        s: &Sample,
    ) -> Option<(ToothRecord, AlarmOutput)> {
        self.process_with(st, s, &mut NoProbe)
    }

    /// [`Self::process`], telling `probe` where each stage of a tooth update ends (for the
    /// instruction-count bench; see [`crate::probe`]).
    #[cfg(feature = "probe")]
    #[inline(never)]
    pub fn process_probed<P: Probe>(
        &self,
        st: &mut PipelineState,
        s: &Sample,
        probe: &mut P,
    ) -> Option<(ToothRecord, AlarmOutput)> {
        self.process_with(st, s, probe)
    }

    #[inline(always)]
    fn process_with<P: Probe>(
        &self,
        st: &mut PipelineState,
        s: &Sample,
        probe: &mut P,
    ) -> Option<(ToothRecord, AlarmOutput)> {
        match self.monitor.period(&mut st.monitor, s) {
            None => {
                if let Some((lost, limit)) = self.monitor.take_trip(&mut st.monitor, s) {
                    let at = st.monitor.last_sample();
                    self.alarms.trip(&mut st.alarms, lost, limit, at);
                }
                None
            }
            Some(p) => {
                probe.mark(Stage::Period);
                Some(self.tooth_update(st, &p, probe))
            }
        }
    }

    /// The record and what the alarms say, built straight into the caller's place: a
    /// `(ToothRecord, AlarmOutput)` is 168 bytes, and a value of that size built in a
    /// local and then moved is copied by a `memcpy` call (about 1.2 instructions per byte on
    /// the Cortex-M4).
    #[inline(never)]
    fn tooth_update<P: Probe>(
        &self,
        st: &mut PipelineState,
        p: &Period,
        probe: &mut P,
    ) -> (ToothRecord, AlarmOutput) {
        // The record goes straight into the result, and a second copy, written from the
        // same registers, into the state for the alarms to read: `rec` itself must not be
        // read before it is moved, or it is built aside and copied by `memcpy`.
        let rec = self
            .monitor
            .tooth_and_copy(&mut st.monitor, p, &mut st.last, probe);
        // The wear tracker's eq. 7 at the estimate, already computed by the estimator.
        let model = Some(st.monitor.model_n());
        let recut = st.monitor.recut_change_n();
        let var_t = st.monitor.change_var_n2();
        let quiet = st.monitor.lag_quiet();
        let moved = |back| self.monitor.boundary_moved_n(&st.monitor, back);
        let out = self.alarms.process_with(
            &mut st.alarms,
            &st.last,
            model,
            (recut, var_t, quiet, &moved),
            probe,
        );
        let (share, whole) = st.alarms.trip_shares_of_reference();
        self.monitor.arm_trip(
            &mut st.monitor,
            &st.last,
            share,
            st.alarms.trip_floor_n(),
            st.alarms.trip_quiet_n(),
            whole,
        );
        // The span measured after this record, for the alarms at the next. (Stored here,
        // after `rec` is moved: a store before it had the record built aside and copied,
        // about 200 instructions.)
        st.alarms.span_share = st.monitor.span_share();
        (rec, out)
    }

    /// The operator's reset of a latched alarm.
    pub fn reset_alarm(&self, st: &mut PipelineState) {
        self.alarms.reset(&mut st.alarms);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_machine_builds() {
        assert!(MachineConfig::default().build().is_ok());
    }

    #[test]
    fn alarm_config_is_checked_against_the_tool() {
        let mut c = MachineConfig::default();
        c.alarms.breakage.debounce_teeth = 9; // more than one revolution of 4 flutes
        assert_eq!(
            c.build().err(),
            Some(ConfigError::OutOfRange("breakage.debounce_teeth"))
        );
    }

    #[test]
    fn spindle_lag_is_checked() {
        for lag in [-1e-4, f32::NAN, f32::INFINITY, 0.02] {
            let mut c = MachineConfig::default();
            c.monitor.spindle_lag_s = lag;
            assert_eq!(
                c.build().err(),
                Some(ConfigError::OutOfRange("spindle_lag_s")),
                "{lag}"
            );
        }
        let mut c = MachineConfig::default();
        c.monitor.spindle_lag_s = crate::monitor::MAX_SPINDLE_LAG_S;
        assert!(c.build().is_ok());
    }

    #[test]
    fn front_end_is_checked() {
        let mut c = MachineConfig::default();
        c.front_end.feed.units_per_volt = 0.0;
        assert_eq!(
            c.build().err(),
            Some(ConfigError::OutOfRange("front_end.feed.units_per_volt"))
        );
    }
}
