//! The whole board in one call: [`Monitor`] then [`Alarms`], per sample.
//!
//! The firmware's monitor task and host-sim's replay both run exactly this, so that the
//! records and the alarms they produce from the same samples are the same bit for bit.

use crate::alarm::{AlarmConfig, AlarmOutput, AlarmState, Alarms};
use crate::monitor::{Monitor, MonitorConfig, MonitorState, Sample, ToothRecord};
use crate::probe::{NoProbe, Probe};
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
}

impl MachineConfig {
    /// Validates both parts.
    pub fn build(self) -> Result<Pipeline, ConfigError> {
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
        let rec = self.monitor.process_with(&mut st.monitor, s, probe)?;
        let out = self.alarms.process_with(&mut st.alarms, &rec, probe);
        Some((rec, out))
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
}
