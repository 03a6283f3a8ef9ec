//! What the alarm output, the status LED and the watchdog do, decided here.
//!
//! # Design
//!
//! The output to the CNC is a relay (or an opto-coupler) that is **energised while all is
//! well** and drops on an alarm: a board that dies, resets, hangs (the watchdog resets it)
//! or loses power drops it too, so the CNC sees every failure as an alarm (fail safe). It
//! is energised only when the configuration built, the graph is running and no alarm is
//! latched ([`AlarmView::relay_energised`]).
//!
//! The LED: steady on while monitoring; fast blink (5 Hz) while an alarm is latched; slow
//! blink (1 Hz) on a wear warning; a short flash every 2 s when the configuration did not
//! build; off when the board is dead.
//!
//! The independent watchdog is fed only while the monitor task makes progress
//! ([`Liveness`]): a hung monitor, not only a hung executor, resets the board.

use estimator_core::alarm::Cause;

/// What the alarm-output task is told after every change.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct AlarmView {
    /// The configuration built and the graph runs.
    pub running: bool,
    /// The latched alarm's cause, if any.
    pub latched: Option<Cause>,
    /// Wear warning on.
    pub wear_warning: bool,
}

impl AlarmView {
    /// Whether the output to the CNC is energised ("all is well").
    pub fn relay_energised(&self) -> bool {
        self.running && self.latched.is_none()
    }

    /// The status LED's pattern.
    pub fn led(&self) -> Blink {
        match (self.running, self.latched, self.wear_warning) {
            (false, _, _) => Blink {
                on_ms: 100,
                off_ms: 1900,
            },
            (true, Some(_), _) => Blink {
                on_ms: 100,
                off_ms: 100,
            },
            (true, None, true) => Blink {
                on_ms: 500,
                off_ms: 500,
            },
            (true, None, false) => Blink::STEADY,
        }
    }
}

/// An LED pattern: on for `on_ms`, off for `off_ms`, repeated (`off_ms = 0`: steady on).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Blink {
    /// On time [ms].
    pub on_ms: u32,
    /// Off time [ms]; 0 is steady on.
    pub off_ms: u32,
}

impl Blink {
    /// Steady on.
    pub const STEADY: Blink = Blink {
        on_ms: 1000,
        off_ms: 0,
    };
}

/// Whether the monitor still makes progress, from its heartbeat counter (one per block).
#[derive(Clone, Copy, Debug, Default)]
pub struct Liveness {
    last: Option<u32>,
}

impl Liveness {
    /// Takes the heartbeat; true if it moved since the last call (the first call only
    /// records it and says true: the graph has just started).
    pub fn alive(&mut self, heartbeat: u32) -> bool {
        let moved = self.last != Some(heartbeat);
        self.last = Some(heartbeat);
        moved
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relay_is_energised_only_when_all_is_well() {
        let ok = AlarmView {
            running: true,
            latched: None,
            wear_warning: true,
        };
        assert!(
            ok.relay_energised(),
            "a wear warning does not stop the machine"
        );
        assert!(!AlarmView {
            latched: Some(Cause::Breakage),
            ..ok
        }
        .relay_energised());
        assert!(
            !AlarmView::default().relay_energised(),
            "not running: dropped"
        );
        assert_eq!(
            AlarmView {
                wear_warning: false,
                ..ok
            }
            .led(),
            Blink::STEADY
        );
    }

    #[test]
    fn a_stalled_heartbeat_is_not_alive() {
        let mut l = Liveness::default();
        assert!(l.alive(0));
        assert!(!l.alive(0));
        assert!(l.alive(1));
        assert!(l.alive(2));
    }
}
