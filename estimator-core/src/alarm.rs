//! Alarms on the per-tooth records: flute breakage, tool gone, overload, teach-in
//! excursions, and a wear (drift) warning (method.md sections 4-5).
//!
//! # Design
//! One small state machine fed with every [`ToothRecord`]; alarms latch until
//! [`Alarms::reset`]. Every alarm carries its cause, the value and threshold that raised it
//! and the record. Thresholds follow the engagement: they scale with the force eq. 7
//! predicts at the estimated (or configured) engagement and the current feed per tooth.
//!
//! - Breakage (Altintas and Yellowley): per-tooth resultant `F_i`, its first difference
//!   `D_i = F_i - F_{i-1}` and the change of that from the same tooth one revolution
//!   earlier, `E_i = D_i - D_{i-N}` (equivalently `E_i = R_i - R_{i-1}` with
//!   `R_i = F_i - F_{i-N}` the tooth's change from one revolution earlier). Steady runout
//!   repeats every revolution and cancels in `E`; a change common to all teeth (engagement,
//!   feed) gives a single spike of `E`; a flute that breaks hands its chip to the next flute
//!   and gives a `-, +, -` burst. Threshold `max(k F_expected, 5 sigma_E)`, widened by the
//!   revolution-mean growth (flutes of unequal chip grow at unequal rates during an entry);
//!   `sigma_E` is E's running spread (a plain mean over the first 32 values, then
//!   exponential; the rules decide from 16 values on, the variance scaled by `32 / count`
//!   until 32, so that a flute lost in a 2-flute tool's first 16 revolutions is seen). An
//!   alarm on either of:
//!   - `debounce_teeth` exceedances of `|E_i|` within one revolution, of both signs (a change
//!     of engagement moves every tooth one way, and a step that falls inside a tooth period
//!     gives two exceedances of one sign), or one of three times the threshold. An
//!     exceedance right after one of the other sign counts only where `R_i` or `R_{i-2}`
//!     carries [`MIRROR_SHARE`] of the threshold its way, or `R_{i-1}` passes it alone: one
//!     tooth's excursion in the noise is `+x, -x` in `E`; a broken flute loses its chip and
//!     the next tooth takes it. The first
//!     tooth of a change that is confined to it (the `N - 1` teeth before it unchanged from
//!     one revolution earlier) counts its exceedance against their growth, not against the
//!     growth its own drop makes (half of it with 2 flutes); later teeth, and the single
//!     3x test, keep the full growth term, so a step or a lost tool still needs its next
//!     tooth past a threshold widened by the whole change.
//!   - a redistribution within the revolution: `R` of both signs beyond
//!     `max(k F_expected, 4.5 sigma_R)` plus half the growth over the last `N` teeth (one
//!     tooth lost, another gained; the total stays). It sees a loss spread over two tooth
//!     periods (several flutes engaged at once), where no single `E` passes. The same
//!     against `SLOW_REVS` (3) revolutions earlier (the growth over those revolutions, and
//!     at the same speed): under runout the chips after a break settle over a few passes.
//!     And each tooth's mean over the newest two revolutions against its mean over the two
//!     `MEANS_BACK_REVS` (3) earlier, the floor `4.5 sigma_R / sqrt 2` (3 to 12 flutes,
//!     every revolution at the same speed, none of the two earlier flagged transient as
//!     far as the 32 newest records' flags reach): a loss the noise of single teeth hides;
//!     not on a drop alone (the newest tooth down, the teeth before it unchanged from one
//!     revolution earlier), whose gain against three revolutions back is old noise. There
//!     also the hand-over's pair, the newest tooth's gain and the loss of the tooth before
//!     it, each past 3 and together past 9 of that noise: a flute broken inside its cut
//!     loses part of its window in one revolution and the rest in the next.
//!   - a first tooth alone: out of a steady cut (the record before not transient, the
//!     noise figure settled), a tooth whose force rose from one revolution earlier by
//!     more than 35 % of it and 6 sigma_R, with at least the 3 (and the `N - 1`) teeth
//!     before it unchanged within 3 sigma_R: the flute before broke after its engagement
//!     and this one took its chip. And the hand-over: a tooth that rose as much right
//!     after a tooth that dropped (the flute broke inside its period), the teeth before
//!     both unchanged. A drop alone is never decided: the first tooth of an exit through
//!     a face square to the feed loses as much (the arc's far reach, where the chip is
//!     thickest, leaves the work first; the force falls as the square root of the
//!     travel). A breakage is told from an exit by the chip the next flute takes.
//!     A hand-over pair (as the drop trip's evidence below asks it) past
//!     [`PAIR_RAISE_SIGMAS`] (9.5) sigma_R together, each side past 3 and the two past
//!     `k F_expected`, raises at once: the gain may end a revolution after the break, and
//!     where the flute broke before its own window the trip on its next pass finds nothing
//!     to lose against a period already lost. So does such a pair whose loss was flagged
//!     transient in the revolutions after the history was forgotten out of a steady cut (a
//!     moved window, a lost pulse), where the revolutions that would show its cut held are
//!     not armed yet; it leaves no evidence there.
//!
//!   These three decide only with the spindle's speed settled: the newest two revolutions
//!   as long as the two 16 teeth (whole revolutions) earlier, to 3 % and two samples
//!   (`speed_settled`). The placed window boundary follows the pulses' tracked times,
//!   whose interval is a running mean over about 16 pulses: in a speed change it lags,
//!   and at a steep chip edge the lag moves force from one window into the next, one
//!   tooth down and the next up. Those of them that compare the newest revolution with
//!   the one before alone decide too where every boundary they compare lies where its
//!   tooth's did a revolution earlier, to the jitter (the hand-over stage's `lag_quiet`):
//!   the lag has caught up, while the lengths still differ from 16 teeth earlier. And
//!   `E` decides where it passes its threshold by as much force as the boundaries of its
//!   two newest periods may have moved (the hand-over stage's `boundary_moved_n`: the
//!   level at each end of the tooth's profile over the shift): boundaries in the cut's
//!   quiet stretch move a few newtons however far the lag swings.
//!   - the hand-over inside the period ([`crate::handover`], the record's `handover_z`,
//!     `handover_n`): a flute broken late in its cut loses only the rest of its chip, 5-20
//!     % of a tooth's force, under the threshold above; over the angles after the break
//!     the loss, and the next flute's gain a pitch later, stand out of the noise of those
//!     bins alone. Decided past `HANDOVER_SIGMAS` (4.5) and `HANDOVER_SHARE` (0.2) of the
//!     threshold `k F_expected`, out of a steady cut (the record before not transient),
//!     with the resultant watched (the spindle signal resolves teeth), the newest two
//!     revolutions as long as the two before and the boundaries quiet as the one-revolution
//!     rules above ask them (a speed change moves force across the bins).
//!   - the drop trip inside the next period ([`crate::handover`]): a flute broken late
//!     in its cut is certain only when it comes round; its period's samples so far lose
//!     more than [`TRIP_SHARE`] (half) of the tooth's force one revolution earlier (and
//!     6 sigma_R, every floor widened to the tangential channel's own noise where that is
//!     the wider: the trip measures that channel alone) before the flute reaches its break
//!     angle again. The whole period at its close is judged too, where the cut's span
//!     is within a pitch against the share with that channel's noise in its noise term
//!     where wider (a broken flute's next pass loses from its first angles, inside the
//!     period; an up-milling exit's first period loses at the window's far end, and its
//!     whole measured past a share with the resultant's noise: seed 8808 normal 14).
//!     Armed after a record
//!     out of a steady cut (not transient, nor two of the last `N`; the noise figure
//!     settled, no alarm latched; the newest revolution as long as the one before, whose
//!     bins the period's are judged against at the same samples),
//!     with no run of the newest `j <= N` teeth that lost more than `3 sqrt(j)
//!     sigma_R` together (the teeth armed with their own a revolution earlier: after the
//!     history was forgotten, from the `N + 1`-th record on; an exit's teeth all lose, the
//!     newest most; a broken flute's loss is followed by the next flute's gain; where the
//!     cut spans more than a pitch, 3 flutes or more, after such a loss too: a flute's cut
//!     begins in the window before its own, and the share covers the exit that the newest
//!     tooth's loss would show), nor a fall
//!     of the newest two revolutions against the two three revolutions earlier past
//!     `TRIP_FALL_SIGMAS` (4) of that change's noise (an exit that pauses inside its noise
//!     for a revolution), with the resultant watched. After a moved window (out of a
//!     steady cut) the records have no tooth a revolution earlier until the `N + 1`-th,
//!     but the hand-over stage re-cut its
//!     profiles at the new boundary: from the first record after the move the trip is
//!     armed at the plain share and 6 sigma_R, transient records too (the move's odd
//!     period upsets the monitor's revolution compare), and that stage checks the same
//!     walk on the periods since the move against their re-cut profiles
//!     ([`AlarmState::trip_quiet_n`]); armed on the share alone, exits begun at the move
//!     tripped. An exit through a face whose first tooth's loss hid in the noise
//!     can take more than half from its second: the arc's far reach, the thickest chip,
//!     leaves first, as the square root of the travel where the arc holds `pi/2`
//!     ([`crate::geometry::exit_loss_share`]). The share is raised to that exit's loss at
//!     two feeds per tooth of travel, or less where the newest tooth shows how far an
//!     exit under way can have gone (its own loss and 3 sigma_R of noise, not the walk's
//!     bound on it: at most the travel that takes that share of its force, and one feed
//!     more; after a loss past 3 sigma_R, that travel and a feed), plus `4 sigma_R` of
//!     the next period's noise (`TRIP_NOISE_SIGMAS`; 2 where that tooth handed over to
//!     the next one inside its period a revolution ago, a hand-over past 2.5 sigma in the
//!     record after its own, or in a cut wider than a pitch the tooth after it, whose
//!     window the broken flute's next cut begins before, `HANDED_NOISE_SIGMAS`: an exit's
//!     teeth all lose, none hands
//!     over, and a flute broken late in its cut hands over a little before it comes
//!     round), and the trip is not armed beyond 0.9. The floor counts the next tooth's
//!     loss a revolution ago (past 1.5 sigma_R, at least 2 sigma_R left): that period is the reference, and a
//!     flute broken inside it left less there to lose; the shares too are of the tooth's
//!     force before that loss, less the loss, as shares of the reference
//!     ([`AlarmState::trip_shares_of_reference`]: seed 12998 break 2, and 13285 break 26
//!     with no lag, 4 flutes at `R_r` 1.50-1.57, whose broken flute's next window lost its
//!     share of the force two revolutions back, not of the lighter reference, until past
//!     the revolution); the loss over the two revolutions
//!     together must pass 6 sigma_R (a difference of two tooth averages: the noise of one
//!     `R`). Only with the last `2N` records not transient: as an exit fades over
//!     revolutions each tooth's loss is the exit's (every loss credited let exits trip:
//!     seed 72 taught 22; and through flagged records, seed 36 normal 22). Where the
//!     tooth of the next period lost force a revolution ago and the tooth after it gained (together past 4.5 sigma_R, 5 where the loss's
//!     record is flagged transient and then only where the revolution before it held its
//!     force, each past 1.5, of the noise figure before the pair widened it, the record
//!     before the loss not transient nor more than one of the `4N` before it (an exit
//!     flagged on and off), and the pair past 2.5 against two revolutions earlier
//!     too, where the jitter's excursions of the revolution before, returning, make none:
//!     a flute broken inside its period, its loss and the next flute's gain under the
//!     rules above; as an exit fades, flutes of unequal runout leave at unequal times),
//!     the speed settled as those rules ask it (after a ramp the tracked boundary lags on
//!     and moves force from one window into the next, a pair),
//!     and the newest tooth lost under 2 sigma_R (an exit may begin right after a noise
//!     pair; no matter after a pair past 6 sigma_R, which noise makes about once in
//!     100 000 teeth, nor in the window before the handed tooth's where a cut spans more
//!     than a pitch: there the broken flute's next cut begins, and the share covers the
//!     exit that loss would show; a loss that keeps it from arming a period spends the
//!     evidence, an exit having begun), the trip is armed at 0.3 of the tooth and 4
//!     sigma_R less the loss already seen, at least 2 sigma_R: that pair happens by noise
//!     about once in 10 000 teeth, and then this period must lose more (its reference, the period of
//!     the loss, already lacks what the broken flute did not cut; not the shares, which
//!     the plain trip takes of the force before that loss: the pair was chosen for its
//!     loss, and a noise pair's stood high two revolutions back). The share is raised to
//!     what an exit that begins in that period could take (one feed's travel past what
//!     the newest tooth allows and the next flute's reach past that, a heavy flute's
//!     longer, even where that passes the two-feed exit; without the noise term, but
//!     where the newest tooth lost past 2 sigma_R, an exit maybe under way whose reach the
//!     period's loss passes by its noise alone: then with 3 sigma_R of it,
//!     `EVIDENCE_UNDER_WAY_SIGMAS`): the pair tells of the teeth before it, not of the
//!     period to come. Where the cut's span
//!     is within a pitch that trip is judged inside the period alone, not on the whole
//!     period at its close: the broken flute's next pass loses from its first angles, and a
//!     loss that passes only whole lies at the cut's far end, an up-milling exit's first
//!     period ([`crate::handover::Handover::arm_trip`]). The period before that
//!     tooth's is armed at 0.3 and 4 sigma_R too (3 flutes or more): where arcs are wider
//!     than a pitch no boundary falls between cuts, the broken flute's cut begins in the
//!     window before the one that lost most, and so does its next pass, and the loss seen
//!     there is the newest tooth's loss that a strong pair lets pass (where nothing tells
//!     the span; where an estimate does, the wide cut's rule, and without one where the
//!     hand-over stage's bins show no quiet stretch in the period, `SPAN_SHARE`,
//!     the same rule with the exit of the widest arcs: over `R_r` 0.3 to 2 the largest
//!     share a travel takes, `geometry::widest_exit_loss_share`). In the revolution
//!     after a moved window, where the records' history crosses the move, the pair is
//!     taken from the hand-over stage's re-cut profiles (each tooth's first period since
//!     the move against its profile): the loss and the gain as above, or, after the odd
//!     period (mixed alignments, its loss unmeasured), the gain alone past 4.5 sigma_R
//!     (an exit never gains); the periods since the move as long as as many before it;
//!     its noise figure from the revolution mean before the move (the gaining tooth's own
//!     force would widen it). Past three times the threshold of `E` it raises at once, as
//!     `E` does; the gain alone after the odd period past the first-tooth rule's 35 % of
//!     the tooth's profile and 6 sigma_R (the teeth before the move were a steady cut).
//!     The record after that revolution takes the same pair with its own change on the
//!     records and the tooth before's on its re-cut profile (its period a revolution
//!     earlier was the odd one): the rules on the records take no pair there yet. The monitor passes
//!     the trip only while the feed speed holds (a feed hold thins every chip at once).
//!     The trip latches the output at once (the event keeps that sample); the records
//!     after it name the cause: a rule that raises on them (no breakage on a tooth that
//!     collapsed: a tool lost late in the tripped period leaves it partly cut; no lost tool
//!     on one empty tooth alone: a broken flute's window is as empty), else after
//!     [`TRIP_NAMED_WITHIN`] records a lost tool if the last two teeth collapsed, a
//!     breakage otherwise.
//!   - two teeth in a row fallen below [`GONE_SHARE`] of their force one revolution
//!     earlier raise no breakage: nothing cuts (a lost tool, whose flutes of unequal
//!     runout fall by unequal amounts and swing `E` both ways, or an exit's end).
//!
//!   - after the tooth history is forgotten in a steady cut (the window moved, a lost
//!     pulse), until two revolutions are armed again: a tooth before the newest carrying
//!     under `MISSING_SHARE` (45 %) of the revolution mean while the cut goes on (a flute
//!     lost then would be the steady pattern by the time the rules above compare again;
//!     runout of 35 % leaves the weakest flute over 60 %).
//!
//!   Not decided on feed/speed changes, air cuts or bad input. A period flagged invalid
//!   only for its length jump (sync jitter at short periods), in tooth order and within a
//!   quarter of the previous length, is used and keeps the history; any other invalid
//!   period (a lost pulse) forgets it.
//! - Tool gone: the force falls from a steady cut near its recent peak to the not-cutting
//!   floor within a few teeth while the feed goes on: two teeth in a row below the floor
//!   that were above it a revolution earlier (or the monitor's not-cutting flag, on the
//!   revolution mean); with 2 flutes, on a cut within a pitch at the steady feed, one tooth
//!   below the floor after one that lost past [`GONE_BEFORE_SIGMAS`] (the tool lost inside
//!   that tooth's cut: the second empty tooth would come a revolution later; a broken
//!   flute's empty window follows the other flute's gain). Any other empty tooth there
//!   (any number of flutes) latches the output and the records after name its cause, as
//!   they name a drop trip's (a lost tool late in the tooth before's cut, a flute broken
//!   at its cut's start, a light flute's first loss too small to arm the trip: each
//!   stops the machine). An exit from the part lowers the
//!   force over revolutions first; a lost tool does not ("steady" excludes a revolution
//!   mean already falling by more than 10 % a revolution, and at most two good teeth
//!   since the last steady record may carry force over the floor: a fast exit, a few
//!   revolutions long, passes the 10 % test on its first tooth and then fades over
//!   many). A feed turned down in one step
//!   is not a collapse: the steady force scaled by the feed's share must stand clear of
//!   the floor.
//! - Overload: the revolution-mean force above what the configured maximum engagement
//!   gives at the current feed per tooth (eq. 7), or above a force limit.
//! - Teach-in: a recorded good cut's revolution-mean force against revolutions since the
//!   cut began ([`Envelope`]); excursions beyond its band (the bin's and its neighbours':
//!   a time tolerance for where the cut is seen to begin) alarm.
//! - Wear: exponentially weighted recursive least squares with one parameter (paper 002's
//!   single-parameter variant) tracks `theta` in `F_measured = theta * F_model`. Against the
//!   estimated engagement a uniform rise of `K_s` cannot be told from a deeper cut (both
//!   scale the forces), so the multiplier is meaningful against a known engagement: the
//!   taught or programmed one ([`DriftReference::Known`]).
//!
//! Cost: about 350 instructions per tooth on the Cortex-M4F, a square root (the watched
//! resultant) the largest part (BENCHMARKS.md); eq. 7 (`Operating::new`, two `expf`) only
//! when a breakage candidate needs its threshold, the feed changed (overload limit), or,
//! once per revolution, for the wear update when the record is fed alone (the pipeline
//! hands over the estimator's eq. 7 at the estimate instead). The breakage rules add a
//! subtraction and a compare per tooth (the newest `R` against its screen); E's square
//! root past `|E| > k F / 2`, and the `N`-tooth walks (confinement, the range of `R`) only
//! past their screens (not re-measured on the QEMU bench since).

use crate::estimator::EstimatorConfig;
use crate::forward::{AverageForces, Operating};
use crate::monitor::ToothRecord;
use crate::probe::{NoProbe, Probe, Stage};
use crate::status::Status;
use crate::ConfigError;

/// Teeth of history kept: a power of two (the ring index wraps with a mask), at least
/// two revolutions of the largest tool plus two.
const HISTORY: usize = 64;
const _: () = assert!(HISTORY.is_power_of_two() && HISTORY >= 2 * MAX_FLUTES + 2);
/// Most flutes the alarms handle.
pub const MAX_FLUTES: usize = 16;
/// Bins of a taught envelope.
pub const ENVELOPE_BINS: usize = 128;

/// Which per-tooth force the breakage detector watches.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum BreakageSignal {
    /// `hypot(F_ax, F_2)`: both channels (needs a spindle signal with tooth bandwidth).
    #[default]
    Resultant,
    /// `F_ax` alone: for a spindle-load input updated too slowly to resolve teeth.
    Feed,
}

/// Flute-breakage detector.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BreakageConfig {
    /// Off: never raises.
    pub enabled: bool,
    /// `k`: threshold on `|E_i|` as a fraction of the expected per-tooth force.
    pub threshold_rel: f32,
    /// Exceedances within one revolution that make an alarm (1 = no debounce).
    pub debounce_teeth: u8,
    /// Signal watched.
    pub signal: BreakageSignal,
}

/// Tool-gone detector.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ToolGoneConfig {
    /// Off: never raises.
    pub enabled: bool,
    /// The force must fall from a steady cut to the floor within this many revolutions.
    pub max_drop_revs: u8,
}

/// Overload detector.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct OverloadConfig {
    /// Off: never raises.
    pub enabled: bool,
    /// Largest radial immersion ratio the job may take.
    pub max_rr: f32,
    /// Largest axial immersion ratio.
    pub max_ra: f32,
    /// Absolute cap on the revolution-mean resultant [N] (infinite: none).
    pub force_limit_n: f32,
    /// Consecutive teeth above the limit that make an alarm.
    pub debounce_teeth: u8,
}

/// What the wear multiplier is measured against.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum DriftReference {
    /// The monitor's own estimate (sees only wear that changes the force ratio).
    #[default]
    Estimated,
    /// A known engagement (taught or programmed).
    Known {
        /// Radial immersion ratio.
        rr: f32,
        /// Axial immersion ratio.
        ra: f32,
    },
}

/// Wear tracking by EWRLS.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct DriftConfig {
    /// Off: multiplier stays 1.
    pub enabled: bool,
    /// Forgetting factor `lambda` in `(0, 1]` (0.995: memory of about 200 teeth).
    pub lambda: f32,
    /// Multiplier above which the wear warning is on.
    pub warn_multiplier: f32,
    /// Reference engagement.
    pub reference: DriftReference,
}

/// A taught force envelope: revolution-mean resultant [N] per bin of `revs_per_bin`
/// revolutions since the cut began.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Envelope {
    /// Revolutions per bin.
    pub revs_per_bin: u16,
    /// Bins in use.
    pub len: u16,
    /// Revolution-mean force [N] at which bin 0 begins: a quarter of the taught peak.
    /// Where a cut is seen to begin (the not-cutting floor crossed in a slow entry, in the
    /// noise) moves by revolutions from run to run; where it reaches a quarter of its peak
    /// does not.
    pub start_n: f32,
    /// Lowest force seen in each bin [N].
    #[cfg_attr(feature = "serde", serde(with = "serde_arrays"))]
    pub lo_n: [f32; ENVELOPE_BINS],
    /// Highest force seen in each bin [N].
    #[cfg_attr(feature = "serde", serde(with = "serde_arrays"))]
    pub hi_n: [f32; ENVELOPE_BINS],
}

/// Teach-in check.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct TeachConfig {
    /// Allowed excursion beyond the taught band, relative to the band's edge.
    pub tolerance_rel: f32,
    /// Consecutive teeth outside that make an alarm.
    pub debounce_teeth: u8,
    /// The envelope; none: teach-in off.
    pub envelope: Option<Envelope>,
}

/// All detectors.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AlarmConfig {
    /// Flute breakage.
    pub breakage: BreakageConfig,
    /// Tool gone.
    pub tool_gone: ToolGoneConfig,
    /// Overload.
    pub overload: OverloadConfig,
    /// Wear drift.
    pub drift: DriftConfig,
    /// Teach-in.
    pub teach: TeachConfig,
}

impl Default for AlarmConfig {
    fn default() -> Self {
        AlarmConfig {
            breakage: BreakageConfig {
                enabled: true,
                threshold_rel: 0.2,
                debounce_teeth: 2,
                signal: BreakageSignal::Resultant,
            },
            tool_gone: ToolGoneConfig {
                enabled: true,
                max_drop_revs: 2,
            },
            overload: OverloadConfig {
                enabled: true,
                max_rr: 2.0,
                max_ra: 2.5,
                force_limit_n: f32::INFINITY,
                debounce_teeth: 4,
            },
            drift: DriftConfig {
                enabled: true,
                lambda: 0.995,
                warn_multiplier: 1.3,
                reference: DriftReference::Estimated,
            },
            teach: TeachConfig {
                tolerance_rel: 0.25,
                debounce_teeth: 4,
                envelope: None,
            },
        }
    }
}

impl AlarmConfig {
    /// Validates against the estimator configuration the monitor runs with.
    pub fn build(self, est: &EstimatorConfig) -> Result<Alarms, ConfigError> {
        use ConfigError::*;
        est.tool.validate()?;
        est.coeffs.validate()?;
        let n = est.tool.flutes as usize;
        if n > MAX_FLUTES {
            return Err(OutOfRange("flutes"));
        }
        let b = &self.breakage;
        if !(b.threshold_rel.is_finite() && b.threshold_rel > 0.0) {
            return Err(OutOfRange("breakage.threshold_rel"));
        }
        if b.debounce_teeth == 0 || b.debounce_teeth as usize > n.max(1) {
            return Err(OutOfRange("breakage.debounce_teeth"));
        }
        if self.tool_gone.max_drop_revs == 0 {
            return Err(OutOfRange("tool_gone.max_drop_revs"));
        }
        let o = &self.overload;
        if !(o.max_rr > 0.0 && o.max_rr <= 2.0) {
            return Err(OutOfRange("overload.max_rr"));
        }
        if !(o.max_ra.is_finite() && o.max_ra > 0.0) {
            return Err(OutOfRange("overload.max_ra"));
        }
        if o.force_limit_n.is_nan() || o.force_limit_n <= 0.0 {
            return Err(OutOfRange("overload.force_limit_n"));
        }
        if o.debounce_teeth == 0 {
            return Err(OutOfRange("overload.debounce_teeth"));
        }
        let d = &self.drift;
        if !(d.lambda > 0.0 && d.lambda <= 1.0) {
            return Err(OutOfRange("drift.lambda"));
        }
        if !(d.warn_multiplier.is_finite() && d.warn_multiplier > 1.0) {
            return Err(OutOfRange("drift.warn_multiplier"));
        }
        if let DriftReference::Known { rr, ra } = d.reference {
            if !(rr > 0.0 && rr <= 2.0 && ra.is_finite() && ra > 0.0) {
                return Err(OutOfRange("drift.reference"));
            }
        }
        let t = &self.teach;
        if !(t.tolerance_rel.is_finite() && t.tolerance_rel >= 0.0) {
            return Err(OutOfRange("teach.tolerance_rel"));
        }
        if t.debounce_teeth == 0 {
            return Err(OutOfRange("teach.debounce_teeth"));
        }
        if let Some(e) = &t.envelope {
            if e.revs_per_bin == 0 || e.len as usize > ENVELOPE_BINS {
                return Err(OutOfRange("teach.envelope"));
            }
        }
        Ok(Alarms {
            cfg: self,
            est: *est,
            n,
            armed_rev: ones(n),
            armed_two_revs: ones(2 * n),
            armed_e: 0b11 | (0b11 << n),
            armed_slow: ones((SLOW_REVS + 1) * n),
            armed_means: if n >= 3 && (MEANS_BACK_REVS + 2) * n <= HISTORY {
                ones((MEANS_BACK_REVS + 2) * n)
            } else {
                0
            },
            armed_fade: if 5 * n <= HISTORY { ones(5 * n) } else { 0 },
            armed_two_back: 0b11 << (2 * n),
            armed_held: if 4 * n + 2 <= HISTORY {
                ones(4 * n + 2)
            } else {
                0
            },
            peak_decay: libm::expf(PEAK_DECAY_LN_PER_REV / n.max(1) as f32),
            tan_helix: crate::geometry::tan_helix(est.tool.helix_deg),
        })
    }
}

/// Why an alarm was raised.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Cause {
    /// A flute broke or chipped.
    Breakage,
    /// The force collapsed while feeding: tool gone.
    ToolGone,
    /// Force above the engagement or force limit.
    Overload,
    /// Force outside the taught envelope.
    TeachExcursion,
    /// Wear multiplier above its warning level (a warning: does not latch the output).
    Wear,
}

impl Cause {
    /// Short name.
    pub fn name(self) -> &'static str {
        match self {
            Cause::Breakage => "breakage",
            Cause::ToolGone => "tool_gone",
            Cause::Overload => "overload",
            Cause::TeachExcursion => "teach_excursion",
            Cause::Wear => "wear",
        }
    }
}

/// An alarm (or warning) as raised.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AlarmEvent {
    /// Why.
    pub cause: Cause,
    /// The quantity that crossed its threshold (force [N], or the multiplier for wear).
    pub value: f32,
    /// The threshold it crossed.
    pub threshold: f32,
    /// The record that raised it (or named the cause of a drop trip before it).
    pub record: ToothRecord,
    /// Sample at which the output latched (the wear warning: rose): the record's last
    /// sample, or, for a drop trip inside a period, the sample that tripped, up to
    /// [`TRIP_NAMED_WITHIN`] records before the one that names it. The latency the CNC
    /// sees runs to here.
    pub latched_sample: u64,
}

/// What the alarms say after a record.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct AlarmOutput {
    /// Raised by this record (alarms and the wear warning's first crossing), or named by
    /// it: a drop trip latched the output inside an earlier period (the event's
    /// `latched_sample`), and this record's rules name its cause.
    pub event: Option<AlarmEvent>,
    /// An alarm is latched: the output to the CNC must drop.
    pub latched: bool,
    /// Wear multiplier `theta` (1: as new).
    pub wear: f32,
    /// Wear multiplier above its warning level.
    pub wear_warning: bool,
}

/// Running state of [`Alarms`]: a few hundred bytes.
#[derive(Clone, Copy, Debug)]
pub struct AlarmState {
    /// Per tooth, a ring of `HISTORY` written at `head`: the watched force, the tooth
    /// index and the period's samples. Bit `k` of `armed`: the `k`-th most recent tooth is
    /// armed (its force usable); a tooth that is not is never read.
    hist_f: [f32; HISTORY],
    hist_tooth: [u8; HISTORY],
    hist_len: [u16; HISTORY],
    /// The revolution mean each record completed (`rev_mean`: its newest `N` teeth; 0
    /// where they were not armed, never read then).
    hist_rev: [f32; HISTORY],
    armed: u64,
    head: usize,
    /// Bit i: tooth i records back exceeded the breakage threshold upwards / downwards.
    exceed_pos: u32,
    exceed_neg: u32,
    /// Last valid estimate `(rr, ra)`, while cutting.
    held: Option<(f32, f32)>,
    /// Teeth since the last steady (armed, not transient) cutting record, those of them
    /// with good data over the not-cutting floor, its force and its feed per tooth.
    since_steady: u32,
    live_since_steady: u8,
    steady_force_n: f32,
    steady_tc_mm: f32,
    /// Running mean of E^2 (clipped) and the number of E values seen.
    e_var: f32,
    /// Running mean of the squared revolution mean over the same teeth [N^2].
    e_force2: f32,
    e_count: u16,
    /// Tooth index and length [samples] of the previous record (a jittered period).
    last_tooth: u8,
    last_samples: u32,
    /// Recent peak of the steady force (decaying).
    peak_force_n: f32,
    overload_run: u8,
    teach_run: u8,
    /// Teeth since the cut began (for the envelope).
    cut_teeth: u32,
    /// Not-cutting teeth in a row.
    air_teeth: u16,
    /// Cached overload limit and the feed it was computed for.
    limit_tc_mm: f32,
    limit_n: f32,
    theta: f32,
    p: f32,
    wear_warned: bool,
    latched: Option<AlarmEvent>,
    /// Bit `k`: the record `k` back (0 the newest) carried no transient flag.
    unflagged: u32,
    /// Bit `k`: the record `k` back held a hand-over inside its period past
    /// [`HANDED_Z_SIGMAS`] (from the tooth before it).
    handed_z: u16,
    /// The previous record's data was good and its watched force below the not-cutting
    /// floor (tool gone: two such teeth in a row).
    prev_dead: bool,
    /// Records left in which a steady cut resumes after the tooth history was forgotten
    /// (see [`Alarms::flute_missing`]); 0: not resuming.
    resumed: u8,
    /// The window moved out of a steady cut and the hand-over stage re-cut its profiles
    /// (the drop trip has a reference for every tooth's first period after it).
    realigned: bool,
    /// The drop trip's noise floor for the next period [N] (`INFINITY`: not armed).
    trip_floor_n: f32,
    /// ... and its share of the tooth's force ([`TRIP_SHARE`] or more).
    trip_share: f32,
    /// In the first revolution after a moved window, the loss per tooth since the move
    /// that the hand-over stage allows before it arms the trip [N] (`INFINITY`: none to
    /// check).
    trip_quiet_n: f32,
    /// ... and the share the whole period is judged against at its close
    /// (`Alarms::process_with`; `INFINITY`: not judged whole).
    trip_whole_share: f32,
    /// What the next tooth's period a revolution ago, the trip's reference, lost against
    /// the revolution before it, as a share of its force (negative: gained; the shares
    /// above are of the force before that loss, `of_two_back`).
    trip_credit: f32,
    /// The exit's loss share behind it, and the feed per tooth [mm] and `R_r` it is for
    /// (`R_r` -1: none valid).
    exit_share: f32,
    exit_key: (f32, f32),
    /// The share of a window's force cut by the flute after its own (`trip_share`).
    exit_wide: f32,
    /// A drop trip that latched the output and waits for its name.
    trip: Option<Trip>,
    /// A tooth that lost force while the next one gained it (see
    /// `Alarms::handed_over`), until its next period, and its loss [N].
    handed: Option<u8>,
    handed_loss_n: f32,
    /// ... the pair beyond [`EVIDENCE_STRONG_SIGMAS`].
    handed_strong: bool,
    /// The last record's change from its re-cut profile as a watched force [N] (NaN: none;
    /// `-INFINITY`: the moved window's odd period, whose loss is not measured).
    recut_last_n: f32,
    /// The hand-over stage's `span_share` before this record (NaN: not known).
    pub(crate) span_share: f32,
    /// `handed` came from re-cut profiles (`Alarms::handed_after_move`).
    handed_recut: bool,
}

/// A drop trip that latched the output (see [`Alarms::trip`]).
#[derive(Clone, Copy, Debug)]
struct Trip {
    /// The force lost and the limit it passed [N].
    lost_n: f32,
    limit_n: f32,
    /// Records left before it is named a breakage.
    left: u8,
    /// The sample that tripped.
    sample: u64,
}

impl Default for AlarmState {
    fn default() -> Self {
        AlarmState {
            hist_f: [0.0; HISTORY],
            hist_tooth: [0; HISTORY],
            hist_len: [0; HISTORY],
            hist_rev: [0.0; HISTORY],
            armed: 0,
            head: 0,
            exceed_pos: 0,
            exceed_neg: 0,
            held: None,
            since_steady: u32::MAX,
            live_since_steady: u8::MAX,
            steady_force_n: 0.0,
            steady_tc_mm: 0.0,
            peak_force_n: 0.0,
            e_var: 0.0,
            e_force2: 0.0,
            e_count: 0,
            last_tooth: 0,
            last_samples: 0,
            overload_run: 0,
            teach_run: 0,
            cut_teeth: 0,
            air_teeth: 0,
            limit_tc_mm: f32::NAN,
            limit_n: f32::INFINITY,
            theta: 1.0,
            p: P0,
            wear_warned: false,
            latched: None,
            unflagged: 0,
            handed_z: 0,
            prev_dead: false,
            resumed: 0,
            realigned: false,
            trip_floor_n: f32::INFINITY,
            trip_quiet_n: f32::INFINITY,
            trip_share: TRIP_SHARE,
            trip_whole_share: f32::INFINITY,
            trip_credit: 0.0,
            exit_share: 1.0,
            exit_key: (f32::NAN, f32::NAN),
            exit_wide: 0.0,
            trip: None,
            handed: None,
            handed_loss_n: 0.0,
            handed_strong: false,
            recut_last_n: f32::NAN,
            handed_recut: false,
            span_share: f32::NAN,
        }
    }
}

/// E values of a settled spread: from fewer it is too uncertain for a 4.5-sigma floor (a
/// cut entered through a face grows unevenly tooth to tooth for its first revolutions).
const SETTLED_E: usize = 32;
/// E values the breakage rules wait for (and at least two revolutions'); up to
/// [`SETTLED_E`] the variance is scaled by `SETTLED_E / count` (the floor by up to
/// `sqrt 2`). 32 values are 16 revolutions of a 2-flute tool: a flute broken within them
/// (7 revolutions into a held-out seed's cut) was the steady pattern before the rules
/// looked, and its alarm came at the exit.
const SETTLED_E_MIN: usize = 16;
/// Weight of a new E in its running variance (memory of about 32 teeth).
const E_ALPHA: f32 = 1.0 / 32.0;
/// Breakage threshold floor, in standard deviations of E. One tooth's noise excursion
/// swings `E` both ways at once (the breakage pattern: two exceedances of both signs, a
/// pair of `E` correlated -0.5), and the spread is estimated from about 32 teeth (its
/// variance within about 25 %). At 4, two steady cuts of held-out seeds (15) raised a
/// false breakage; at 4.5, one in the 15 million teeth of seeds 1-288's normal cuts (seed
/// 250 normal 84: `E` -40 N and +37.7 N against 35.8 N, the spread 9.0 N over the cut).
/// For Gaussian noise 5 makes that pair about 30 times rarer; [`MIRROR_SHARE`] 12.6 times
/// rarer again (independent Gaussian `R`, integrated numerically; seed 4002 normal 35: `R`
/// -44, +92, -41 N against sigma_R 17 N, `E` +136 and -133 N against 123 N).
const E_SIGMAS: f32 = 5.0;
/// Where `k F` is under it, each E is clipped at this many of E's running spread in that
/// spread: Gaussian noise then comes out 5 % low (at `k F` alone, at 0.6 of itself with `k
/// F` at 0.75 spreads, and lower as an exit's force fades), while a flute's loss under the
/// threshold (`-x, +2x, -x` in `E`) widens it little, for the rules that follow it up on
/// two revolutions' means (at 3 and 5 they no longer decided the loss of
/// `a_loss_under_single_teeths_noise_is_decided_on_two_revolutions_means`).
const E_CLIP_SIGMAS: f32 = 2.0;
/// Share of the breakage threshold that `R_0` or `R_2` must carry, each in the newest
/// `E`'s direction, for that `E` to count after an exceedance of the other sign on the
/// tooth before (see [`E_SIGMAS`]: one tooth's excursion is a pair of `E` of both signs,
/// `E_1 = R_1 - R_2`, `E_0 = R_0 - R_1`), unless `R_1` alone passes the threshold. A
/// break's `-L, +(L + G), -G` keeps its pair on either side of the shared tooth: `G` in
/// `R_0`, or `L` in `R_2`. The likeliest noise that passes then takes three teeth's `R`
/// at half the threshold `T` each (`0.75 T^2` of squared deviation, against `2/3 T^2` for
/// `-T/3, +2T/3, -T/3`; `R_1` past `T` alone is `T^2`).
const MIRROR_SHARE: f32 = 0.5;
/// The redistribution's floor, in standard deviations of `R`: two teeth's changes of both
/// signs past it, which one tooth's excursion does not make.
const R_SIGMAS: f32 = 4.5;

/// First-tooth decision: the newest tooth's force fell from one revolution earlier by more
/// than this share of what it was (and by [`FIRST_TOOTH_SIGMAS`] of the noise), with the
/// `N - 1` teeth before it unchanged. A flute lost between its engagements takes its whole
/// period's force: a light cut loses all of it, a slot with two flutes engaged half. The
/// next tooth, which the other rules need, may come after the revolution is over.
const FIRST_TOOTH_SHARE: f32 = 0.35;
/// ... and by this many standard deviations of `R = F_i - F_{i-N}` (`sigma_E / sqrt 2`):
/// one-sided, on a single tooth, 6 sigma is 1e-9 a tooth (a false alarm in over a
/// thousand hours at 720 000 teeth an hour).
const FIRST_TOOTH_SIGMAS: f32 = 6.0;
/// The teeth before count as unchanged within this many standard deviations of `R`.
const FIRST_TOOTH_QUIET_SIGMAS: f32 = 3.0;
/// At least this many teeth before the first tooth must be quiet.
const FIRST_TOOTH_QUIET_TEETH: usize = 3;
/// ... nor rising together by more than this many sigma of their sum.
const FIRST_TOOTH_TREND_SIGMAS: f32 = 2.5;
/// Two teeth in a row below this share of their force one revolution earlier: nothing
/// cuts any more (a lost tool, the last teeth of an exit), not a lost flute.
const GONE_SHARE: f32 = 0.3;
/// With 2 flutes, a tooth dead after one that lost more than this many sigma_R of its
/// force one revolution earlier: the tool was lost inside that tooth's cut. A flute
/// broken at its cut's start leaves its window dead after the other flute's unchanged
/// one (at 0.9 of its force instead, 28 breaks of 23 040 were named lost tools by noise).
const GONE_BEFORE_SIGMAS: f32 = 4.5;
/// After the tooth history was forgotten, a tooth before the newest under this share of
/// the revolution mean carries too little for a flute in place (`Alarms::flute_missing`).
const MISSING_SHARE: f32 = 0.45;
/// A lost tool: at most this many good teeth since the last steady record carried force
/// over the not-cutting floor (the tooth in which it was lost, and one for the drive's lag
/// or noise); an exit's teeth fade over revolutions.
const GONE_LIVE_TEETH: u8 = 2;

/// The hand-over inside a period (`ToothRecord::handover_z`) decides beyond this many
/// standard deviations. Under Gaussian noise a loss and a gain each past 4 would be 1e-9 a
/// bin position, but each sigma is a running spread over 32 periods and the encoder's
/// jitter at steep chip edges is not Gaussian: at 4, three cuts of seeds 673-864 with no
/// damage yet (z 4.02-4.12) raised a breakage. At 4.5 none did, and about 11 more of 23 040
/// breaks came later than a revolution (BENCHMARKS.md).
const HANDOVER_SIGMAS: f32 = 4.5;
/// ... and beyond this share of the breakage threshold (`k` times the expected force):
/// a hand-over too small to matter (a very quiet signal) is not a breakage.
const HANDOVER_SHARE: f32 = 0.2;

/// The drop trip inside a period ([`crate::handover`]): the open period's bins so far
/// have lost this share of the tooth's whole force one revolution earlier.
pub const TRIP_SHARE: f32 = 0.5;
/// ... armed only when no run of the newest `j <= N` teeth lost more than this many
/// standard deviations of its sum (`sqrt(j) sigma_R`) from one revolution earlier.
const TRIP_QUIET_SIGMAS: f32 = 3.0;
/// ... and by this many of the next period's `sigma_R` (the noise of its loss, on the
/// resultant or, at the close, the trip channel, whichever is wider) over the exit's
/// share: the trip looks at the loss after every bin, and an exit's first period in a
/// wide cut loses up to the exit's share (its thickest chips first, in the period's
/// first bins). At 3, seed 10264 normal 6 (3 flutes, `R_r` 1.26, 744 N) tripped: its
/// exit's second period lost 0.475 in the truth against an exit share of 0.471 (at the
/// estimate's `R_r`, 0.02 low) and 0.548 with the noise; at the close 0.54 (one noise
/// seed in 16; at 3.5 it still tripped).
const TRIP_NOISE_SIGMAS: f32 = 4.0;
/// ... or this many where the tooth handed over to the next one inside its period a
/// revolution ago, past [`HANDED_Z_SIGMAS`] (an exit's teeth all lose: no hand-over), or
/// in a cut wider than a pitch the tooth after it (`Alarms::trip_share`). A
/// flute broken late in its cut hands little over in its first revolution, under the
/// hand-over's own 4.5 sigma, and is certain only on its next pass, whose window loses
/// about as much as an exit's first in a wide cut: in 45 of 62 such late breaks (seeds
/// 10785-11168) that hand-over stood at 2-4.5 sigma. At 2, the late breaks of seeds
/// 11169-11360 went from 21 to 15, with no false alarm there or at 1-96 and 10785-10880.
const HANDED_NOISE_SIGMAS: f32 = 2.0;
/// A hand-over inside the period (`ToothRecord::handover_z`) that lowers the losing
/// tooth's next drop trip to [`HANDED_NOISE_SIGMAS`]; noise passes it about once in
/// 2 000 records of a steady cut.
const HANDED_Z_SIGMAS: f32 = 2.5;
/// ... raised where an exit through a face could take that much from the next period
/// (`Alarms::trip_share`); beyond this share it is not armed (a broken flute's period,
/// with the next flute's gain in it, rarely loses more).
const TRIP_MAX_SHARE: f32 = 0.9;
/// A tooth's loss and the next tooth's gain, together beyond this many sigma of `R` (the
/// gaining tooth's `E`, about 3.2 sigma_E; see `Alarms::handed_over`): the drop trip of
/// the losing tooth's next period is armed at [`EVIDENCE_SHARE`] and
/// [`EVIDENCE_TRIP_SIGMAS`]. The loss is often the larger: the broken flute's is in its
/// own period, the next flute's gain spreads over two where the arcs overlap.
const EVIDENCE_SIGMAS: f32 = 4.5;
/// ... or this many where the loss's own record was flagged transient (an exit may begin
/// with a flagged record: seed 110, normal case 81, a pair of 4.7 at 4.5 alone), and
/// then the gain of its own past [`EVIDENCE_EACH_SIGMAS`] too: a sudden exit's first loss
/// alone passes the pair's sum (seed 6125 normal 104: 3 flutes under heavy runout, the
/// exit's first tooth lost 5.5 sigma_R on a flagged record, the next tooth's loss hidden by
/// the spindle current's lag left it 15 N up, and its period then lost 39 %).
const EVIDENCE_FLAGGED_SIGMAS: f32 = 5.0;
/// ... and, flagged or not, only where the revolution before the loss held its force
/// against the one three revolutions earlier (an exit fades slowly), to this many sigma of
/// that change (`Alarms::fell_before_loss`).
const EVIDENCE_FALL_SIGMAS: f32 = 2.0;
/// ... where the loss's record is unflagged, this many (a steady cut's revolutions differ
/// by noise past 2 of it about once in 40: at 2, a break and 13 chips of seeds 1729-1920
/// went past their revolution).
const EVIDENCE_STEADY_FALL_SIGMAS: f32 = 4.0;
/// ... the loss beyond this many.
const EVIDENCE_EACH_SIGMAS: f32 = 1.5;
/// ... and the pair against two revolutions earlier beyond this many (where those are
/// armed): a break's loss and gain stand against every revolution before it, while a pair
/// of excursions in the revolution before (the encoder's jitter moves force between
/// adjacent windows) returns as a loss and a gain against it alone (seed 382 taught 14: 50
/// N against one revolution earlier, 4.8 sigma_R; 18.5 N, 1.8, against two).
const EVIDENCE_BACK_SIGMAS: f32 = 2.5;
/// ... the trip's share then (at least: see `Alarms::trip_share`) ...
const EVIDENCE_SHARE: f32 = 0.3;
/// ... with [`EVIDENCE_NOISY_SIGMAS`] of the period's `sigma_R` over the exit's reach
/// where the pair's loss could be noise (the watched tooth kept [`EVIDENCE_NOISY_KEPT`] of
/// its force) and the cut lies within a pitch but for [`EVIDENCE_NOISY_WIDE`] of its span:
/// there a broken flute's next window loses all but that share, far past the reach and
/// its noise, and the margin costs no break (seed 13070 normal 28 without current-loop
/// lag: 3 flutes, `R_r` 1.2, 9 % of the span past a pitch; a noise pair whose loss was 10 %
/// of the tooth, then an exit whose handed window lost 42 % in the truth against a reach
/// of 0.43, 47 % measured). Wider, the broken flute's window keeps the next flute's start
/// and loses about the reach itself (the margin everywhere: 13 breaks of seeds
/// 12993-13088 late, not 6).
const EVIDENCE_NOISY_WIDE: f32 = 0.15;
/// ... this many sigma_R (as [`HANDED_NOISE_SIGMAS`]) ...
const EVIDENCE_NOISY_SIGMAS: f32 = 2.0;
/// ... where the watched tooth kept this share of its force over the pair's revolution:
/// a loss of a fifth is about 5 sigma_R at 3 % noise, a break's or a chip's, and asks no
/// margin (asked at 4.5 sigma_R instead, where the pair's own spread widens sigma_R,
/// 11 more chips of seeds 12993-13088 past their revolution).
const EVIDENCE_NOISY_KEPT: f32 = 0.8;
/// ... and its floor in sigma of `R`, less the tooth's loss a revolution ago, ...
const EVIDENCE_TRIP_SIGMAS: f32 = 4.0;
/// ... but at least this many; and only where the newest tooth lost less than this many.
const EVIDENCE_MIN_SIGMAS: f32 = 2.0;
const EVIDENCE_KEPT_SIGMAS: f32 = 2.0;
/// ... and where it lost more (an exit may be under way: the share is its reach), this
/// many of the period's `sigma_R` over that reach.
const EVIDENCE_UNDER_WAY_SIGMAS: f32 = 3.0;
/// ... unless the pair was beyond this many sigma of `R` (4.2 sigma of the pair, about
/// once in 100 000 teeth by noise; at 7, seed 45 case 34's 6.3 was late).
const EVIDENCE_STRONG_SIGMAS: f32 = 6.0;
/// A hand-over pair past this many sigma of `R` together raises a breakage at once, on
/// one record (6.7 sigma of the pair). Over seeds 1-96, every set, the pairs before any
/// damage reached 7.4; their count fell about fourfold a half sigma from 5 to 7 (103 past
/// 6, 28 past 6.5, 4 past 7), about 0.03 past 9 a block if that held on. It did not: at
/// 9 a noise pair in a steady cut raised a false alarm (seed 13805 chip 29, 10.6
/// revolutions before the damage: 4 flutes, a tooth 53 N down and the next 69 N up, each
/// from two tooth averages 2.5-3.7 sigma off, 9.04 sigma_R together; the first in 672
/// seeds' blocks). The noise figure it is judged by is itself a running estimate over
/// about 32 teeth, so the ratio's tail is wider than the normal one. At 9.5 the block
/// 13761-13856 keeps its breaks (6 late either way), detects one chip more and 29 fewer
/// within a revolution (of 5 760); at 10, one break more late and 49 chips fewer.
const PAIR_RAISE_SIGMAS: f32 = 9.5;
/// The hand-over pairs the redistribution rules take on changes over revolutions (against
/// three revolutions earlier with 2 flutes, on two revolutions' means with 3 or more):
/// past this many sigma of that change's `R`.
const PAIR_REVS_SIGMAS: f32 = 9.0;
/// ... with the loss and the gain each past this many: a break hands its chip on.
const PAIR_EACH_SIGMAS: f32 = 3.0;
/// Where the tooth before the loss lost more than this many sigma of `R`, a pair is
/// evidence only if its gain takes half of both losses (`Alarms::handed_over`): an exit's
/// first teeth lose too (seed 908 normal 79: about 2.7). Asked of every pair at 2, four
/// more breaks of 23 040 at seeds 673-864 came past their revolution (the two traced: the
/// tooth before had lost 2.2 and 2.4 by noise).
const EVIDENCE_BEFORE_SIGMAS: f32 = 2.5;
/// A pair's gain must stand above what an exit would leave the gaining tooth by more than
/// this many sigma of `R` (`Alarms::handed_over`): an exit takes about the same share of
/// every tooth's force, so there the next tooth loses the losing tooth's share of its own
/// force, and on a light flute (runout) that loss hides in the noise (seed 968 normal 32:
/// a heavy flute lost 5 sigma_R, the light one after it, at a quarter of its force,
/// gained 0.4, 1.7 above the exit's share).
const EVIDENCE_EXIT_SIGMAS: f32 = 2.5;
/// Teeth over which the breakage rules that compare revolutions ask the spindle's speed
/// steady (`Alarms::speed_settled`): the window stage's running mean of the interval
/// between pulses weighs a new one by 1/16 (`crate::window`), so a ramp's lag of its
/// tracked boundary settles over about 16 pulses.
const SPEED_SETTLED_TEETH: usize = 16;
/// ... to `1 / SPEED_SETTLED_PER` of their length (and two samples), 3 %: the tracked
/// interval lags a steady change of `x` over 16 pulses by about `15 x / 16` of a period,
/// and the placed boundary by its phase's share of that, under 3 % of a period here. At 1 %
/// (as `same_speed`, revolution against revolution over the 16 teeth) the pulses' jitter
/// and a speed's slow settling held back 100 of 5 760 chips and 6 of 11 520 breaks past
/// their revolution at seeds 1057-1152; at 1 %, two revolutions against two, 20 chips and
/// one break.
const SPEED_SETTLED_PER: u32 = 33;
const _: () = assert!(SPEED_SETTLED_TEETH + 3 * MAX_FLUTES <= HISTORY);
/// The plain drop trip (no hand-over's evidence) is not armed where the newest two
/// revolutions fell against the two three revolutions earlier by more than this many of
/// that difference's noise: an exit fading over revolutions can pause for a revolution
/// inside its noise, and then its next tooth loses half (seed 299 normal 4: 2 flutes, 5.5
/// of it; the newest revolution alone 3.4, where a steady cut's noise reaches too: at 3
/// the trip of seed 288 break case 116 was not armed for the broken flute's first pass).
const TRIP_FALL_SIGMAS: f32 = 4.0;
/// A trip is named by the rules on the records after it, or after this many records: a
/// lost tool leaves the tripped period partly cut and the two after it empty.
pub const TRIP_NAMED_WITHIN: u8 = 3;

/// The redistribution is also judged against this many revolutions earlier: with runout,
/// the chips the other flutes take after a break settle over a few passes (each chip is
/// cut from the surface all the flutes before it left), and a change spread over them
/// passes no threshold one revolution at a time. (`(SLOW_REVS + 1) MAX_FLUTES` teeth fit
/// the history.)
const SLOW_REVS: usize = 3;
/// The redistribution of two revolutions' means: the newest two against the two this many
/// revolutions earlier. Not 2 (the two revolutions right before): under runout the next
/// flute's gain grows over its second pass after the break, and the newest pair must be
/// past the break while the pair it is compared with is before it. Not with 2 flutes:
/// there a loss on one tooth and a gain on the other is the only shape any change of the
/// force's split between the two windows takes, and over five revolutions the split drifts
/// (after a speed change, seed 31 taught 21 and seed 91 break 65: one tooth 10 N a
/// revolution up, the other down, the total steady).
const MEANS_BACK_REVS: usize = 3;
const _: () = assert!((SLOW_REVS + 1) * MAX_FLUTES <= HISTORY);

/// A single `E` beyond this multiple of the threshold raises a breakage by itself.
const SINGLE_EXCEEDANCE: f32 = 3.0;

/// Teach-in: a taught envelope begins where the force first reaches this share of its peak.
const START_SHARE: f32 = 0.25;

/// Share of the recent peak force that counts as cutting strongly (tool gone vs exit).
const STRONG_SHARE: f32 = 0.6;
/// Fall of the revolution-mean force per revolution, relative to it, beyond which the cut
/// is leaving (an exit), not steady.
const FALLING_SHARE: f32 = 0.1;
/// Decay of the recent peak force per revolution (0.98), as its logarithm: a tooth's
/// decay is `exp` of its `N`-th part (`expf` is on the board for the power laws; `powf`
/// for this alone cost 600 B of flash).
const PEAK_DECAY_LN_PER_REV: f32 = -0.020_202_707;

/// Initial covariance of the wear multiplier (large: the first teeth decide).
const P0: f32 = 1.0;

/// The armed-bit mask of the newest `k` records (all 64 from 64 on).
#[inline(always)]
const fn ones(k: usize) -> u64 {
    if k >= 64 {
        u64::MAX
    } else {
        (1u64 << k) - 1
    }
}

/// A drop trip's `share` of a tooth's force two revolutions back as a share of its
/// reference period, the tooth's force a revolution back, where that period had lost
/// `credit` of its own force against the revolution before it (negative: gained):
/// `share` of the force before the loss, less the loss. A flute broken inside that period
/// left it lighter, and its next pass loses less against it than the share an exit's
/// reach sets for the whole tooth; an exit begun there took its part of the same whole.
/// (An infinite share stays so.)
#[inline(always)]
fn of_two_back(share: f32, credit: f32) -> f32 {
    if share.is_finite() {
        share - (1.0 - share) * credit
    } else {
        share
    }
}

/// Whether the pair's gain `r0` stands above what an exit would leave the gaining
/// tooth by [`EVIDENCE_EXIT_SIGMAS`] of `R` (`var_r`): `r0 + s F_next`, the loss `r1`
/// as a share `s = -r1 / F_lost` of the losing tooth's force a revolution earlier
/// (`then_lost`; the gaining tooth's `then_next`, `F_next`) [N],
/// times `F_lost` (no division). A break hands the chip on: its gain is the loss, or a
/// good part of it where it spreads over two periods, far above. True where the
/// losing tooth's force was not positive (no share); false on NaN.
#[inline(never)]
fn above_exit_of(r0: f32, r1: f32, (then_lost, then_next): (f32, f32), var_r: f32) -> bool {
    let above = r0 * then_lost - r1 * then_next;
    let bound = EVIDENCE_EXIT_SIGMAS * then_lost;
    then_lost <= 0.0 || above > 0.0 && above * above > bound * bound * var_r
}

impl AlarmState {
    /// The latched alarm, if any.
    pub fn latched(&self) -> Option<&AlarmEvent> {
        self.latched.as_ref()
    }

    /// The drop trip's noise floor for the period after the last record [N]; `INFINITY`
    /// where it is not armed.
    pub fn trip_floor_n(&self) -> f32 {
        self.trip_floor_n
    }

    /// The drop trip's share (see [`TRIP_SHARE`]).
    pub fn trip_share(&self) -> f32 {
        self.trip_share
    }

    /// The share of the tooth's force the armed drop trip asks of the whole period at its
    /// close (`INFINITY`: not judged whole; see [`crate::handover::Handover::arm_trip`]).
    pub fn trip_whole_share(&self) -> f32 {
        self.trip_whole_share
    }

    /// [`Self::trip_share`] and [`Self::trip_whole_share`] as shares of the trip's
    /// reference, the next tooth's period a revolution ago, which the hand-over stage
    /// measures: less what that period had lost against the revolution before it, where
    /// the arming counted it (a flute broken inside it; `of_two_back`).
    pub fn trip_shares_of_reference(&self) -> (f32, f32) {
        (
            of_two_back(self.trip_share, self.trip_credit),
            of_two_back(self.trip_whole_share, self.trip_credit),
        )
    }

    /// The hand-over stage's measure of the cut's span
    /// ([`crate::handover::HandoverState::span_share`]).
    pub fn span_share(&self) -> f32 {
        self.span_share
    }

    /// Where the drop trip is armed in the first revolution after a moved window: the
    /// loss per tooth since the move it allows [N] (`INFINITY` elsewhere).
    pub fn trip_quiet_n(&self) -> f32 {
        self.trip_quiet_n
    }

    /// The output to the CNC is latched: an alarm, or a drop trip whose cause the next
    /// records name.
    pub fn output_latched(&self) -> bool {
        self.latched.is_some() || self.trip.is_some()
    }

    /// The cause the output shows: the latched alarm's, or a breakage while a drop trip
    /// waits for its name (a lost tool is named so within three records).
    pub fn output_cause(&self) -> Option<Cause> {
        match (&self.latched, self.trip) {
            (Some(e), _) => Some(e.cause),
            (None, Some(_)) => Some(Cause::Breakage),
            (None, None) => None,
        }
    }

    /// Ring index of the `k`-th most recent tooth (0 = newest).
    #[inline(always)]
    fn slot(&self, k: usize) -> usize {
        self.head.wrapping_sub(1).wrapping_sub(k) & (HISTORY - 1)
    }

    /// How many of the `count` records (1-31) from `skip` records back (0: the newest)
    /// were flagged transient (of the 32 newest: none counted beyond).
    #[inline(always)]
    fn flagged(&self, skip: u32, count: usize) -> u32 {
        let back = (!self.unflagged).checked_shr(skip).unwrap_or(0);
        (back & (u32::MAX >> (32 - count.clamp(1, 31)))).count_ones()
    }

    /// Whether every tooth of `mask` is armed; false for an empty mask (a rule that is
    /// off for this tool).
    #[inline(always)]
    fn all_armed(&self, mask: u64) -> bool {
        mask != 0 && self.armed & mask == mask
    }

    /// Watched force of the `k`-th most recent tooth.
    #[inline(always)]
    fn force(&self, k: usize) -> f32 {
        self.hist_f.get(self.slot(k)).copied().unwrap_or(0.0)
    }

    /// Tooth index of the `k`-th most recent tooth.
    #[inline(always)]
    fn tooth(&self, k: usize) -> u8 {
        self.hist_tooth.get(self.slot(k)).copied().unwrap_or(0)
    }
}

/// Without an estimate, a cut spans more than a pitch where the hand-over stage's
/// `span_share` passes this: the least bin of the tooth's profile (the lag undone) carries
/// a tenth of a bin's share of the tooth's force. On the 684 break cases without an estimate
/// of seeds 12225-12240, every cut within 0.95 of a pitch (its arc and the helix's lag over
/// the depth) measured under it, every one past 1.15 over it (host-sim's ignored test
/// `the_span_share_measures_the_span_of_the_cut`).
pub const SPAN_SHARE: f32 = 0.1;

/// No hand-over stage told how far a record's boundaries moved (`Alarms::process_with`).
pub(crate) const NOT_TOLD: fn(usize) -> f32 = |_| f32::INFINITY;

/// Record flags that make a tooth's force unusable: no cut, or bad data.
const BAD_DATA: Status = Status(
    Status::NOT_CUTTING.0
        | Status::NON_FINITE.0
        | Status::PERIOD_INVALID.0
        | Status::NO_SYNC.0
        | Status::INPUT_FAULT.0
        | Status::WINDOW_MOVED.0,
);

/// Flags that also keep the breakage detector from deciding. Not `TRANSIENT`: the
/// monitor's sliding revolution means see a breakage as a transient for a revolution
/// (the redistributed chip enters the newest block before its counterpart does), and the
/// detector tells a breakage from an engagement change by itself (see `process`).
const NO_BREAKAGE_DECISION: Status = Status(BAD_DATA.0 | Status::FEED_CHANGE.0);

/// Flags that keep the wear tracker from a record when its reference is a known
/// engagement: bad data, and filtered forces that are not yet a steady cut's.
const NO_WEAR_UPDATE: Status =
    Status(BAD_DATA.0 | Status::TRANSIENT.0 | Status::FEED_CHANGE.0 | Status::SETTLING.0);

/// Validated alarms.
#[derive(Clone, Copy, Debug)]
pub struct Alarms {
    cfg: AlarmConfig,
    est: EstimatorConfig,
    n: usize,
    /// `AlarmState::armed` masks: the newest `n` teeth, the newest `2 n`, teeth
    /// `0, 1, n, n + 1` back (`E_i`), the newest `(SLOW_REVS + 1) n`, and the newest
    /// `(MEANS_BACK_REVS + 2) n` (0 where that rule is off: 2 flutes, and over 12, where
    /// the history is shorter), the newest `4 n + 2` (`fell_before_loss`; 0 over 15
    /// flutes), the newest `5 n` (the drop trip's fall test; 0 over 12 flutes), and teeth
    /// `2 n, 2 n + 1` back (the hand-over's pair against two revolutions earlier).
    armed_rev: u64,
    armed_two_revs: u64,
    armed_e: u64,
    armed_slow: u64,
    armed_means: u64,
    armed_held: u64,
    armed_fade: u64,
    armed_two_back: u64,
    /// Per-tooth decay of the recent peak force.
    peak_decay: f32,
    /// `tan` of the tool's helix angle (the helix's lag over the depth, `trip_share`).
    tan_helix: f32,
}

impl Alarms {
    /// The configuration.
    pub fn config(&self) -> &AlarmConfig {
        &self.cfg
    }

    /// Clears the latched alarm (the operator's reset); detectors start afresh.
    pub fn reset(&self, st: &mut AlarmState) {
        let (theta, p) = (st.theta, st.p);
        *st = AlarmState::default();
        // Wear is a property of the tool, not of the alarm: keep it.
        st.theta = theta;
        st.p = p;
    }

    /// Per-tooth force watched by the breakage detector. (Out of line, as are
    /// `expected_signal`, `decision_var` and `gone_candidate`: inlined at their calls the
    /// four cost the board 400 B of flash, out of line about 50 instructions a record.)
    #[inline(never)]
    fn signal(&self, fx: f32, f2: f32) -> f32 {
        match self.cfg.breakage.signal {
            BreakageSignal::Resultant => crate::fmath::hypot(fx, f2),
            BreakageSignal::Feed => fx,
        }
    }

    /// Eq. 7 forces at an engagement, as the watched signal.
    #[inline(never)]
    fn model_signal(&self, rr: f32, ra: f32, tc_mm: f32) -> f32 {
        let op = Operating::new(&self.est.coeffs, self.est.mode, rr, tc_mm);
        // `F_ax` and `F_at` as `Operating::forces` gives them (the same expressions),
        // without the axial force and its `r2` power law.
        let s = op.force_scale_n(&self.est.coeffs, &self.est.tool, tc_mm) * ra;
        let f = AverageForces {
            ft_n: s * op.arc.c,
            fx_n: s * (op.arc.a + op.r1 * op.arc.b),
            ..AverageForces::default()
        };
        // The monitor's second force is F_at (motor) or F_ay (dynamometer); the motor
        // route is the product's, and for the resultant the difference is second order.
        self.signal(f.fx_n, f.ft_n).abs()
    }

    /// Eq. 7's watched force at the `held` engagement (the last valid estimate's), or
    /// `fallback` (the measured force) without one: the force `k F_expected` scales.
    #[inline(never)]
    fn expected_signal(&self, held: Option<(f32, f32)>, tc_mm: f32, fallback: f32) -> f32 {
        match held {
            Some((rr, ra)) => self.model_signal(rr, ra, tc_mm),
            None => fallback,
        }
    }

    /// Feeds one record.
    #[inline(always)]
    pub fn process(&self, st: &mut AlarmState, rec: &ToothRecord) -> AlarmOutput {
        self.process_with(st, rec, None, (f32::NAN, 0.0, 0, &NOT_TOLD), &mut NoProbe)
    }

    /// [`Self::process`], telling `probe` where each stage ends (for the instruction-count
    /// bench; see [`crate::probe`]).
    #[cfg(feature = "probe")]
    pub fn process_probed<P: Probe>(
        &self,
        st: &mut AlarmState,
        rec: &ToothRecord,
        probe: &mut P,
    ) -> AlarmOutput {
        self.process_with(st, rec, None, (f32::NAN, 0.0, 0, &NOT_TOLD), probe)
    }

    /// Never inlined: one copy serves `process` and `Pipeline::process`.
    ///
    /// `model_n`: eq. 7's `[F_ax, F_at]` at `rec`'s own estimate (`R_r`, `R_a`, filtered
    /// `t_c`), when the caller has it (the pipeline: the estimator computed it); used only
    /// for a valid record, where it is exactly what `model_signal` would recompute.
    /// `recut_n`: `rec`'s change of tangential force from its tooth's profile re-cut at a
    /// moved window ([`crate::handover::HandoverState::recut_change_n`]; NaN: none), and
    /// `trip_var_n2`: the noise of the channel the drop trip measures, as a variance
    /// ([`crate::handover::HandoverState::change_var_n2`]; 0: none); `lag_quiet`: the
    /// boundaries in a row that lie where their tooth's did a revolution earlier
    /// ([`crate::handover::HandoverState::lag_quiet`]; 0: not known);
    /// `boundary_moved_n(back)`: how much tangential force [N] the boundaries of the
    /// record `back` before `rec` (0: `rec`'s own) may have moved against its tooth's a
    /// revolution earlier ([`crate::handover::Handover::boundary_moved_n`]; `INFINITY`: not
    /// known, as [`NOT_TOLD`] says), asked only where a decision needs it.
    #[inline(never)]
    pub(crate) fn process_with<P: Probe, M: Fn(usize) -> f32 + ?Sized>(
        &self,
        st: &mut AlarmState,
        rec: &ToothRecord,
        model_n: Option<[f32; 2]>,
        (recut_n, trip_var_n2, lag_quiet, boundary_moved_n): (f32, f32, u8, &M),
        probe: &mut P,
    ) -> AlarmOutput {
        let n = self.n;
        // A period flagged only for its length jump (the sync pulse's jitter at a short
        // period) that follows the previous tooth in order, within a quarter of its length:
        // the teeth still line up and its average is good to the noise; forgetting the
        // history there would blind the detector for two revolutions.
        let jittered = rec.status.contains(Status::PERIOD_INVALID)
            && !rec.status.contains(Status::NO_SYNC)
            && st.last_samples > 0
            && rec.tooth as usize == (st.last_tooth as usize + 1) % n.max(1)
            && rec.samples.abs_diff(st.last_samples) <= st.last_samples / 4;
        st.last_tooth = rec.tooth;
        st.last_samples = rec.samples;
        // The cut was steady before this record (the one before it unflagged); and before
        // that one.
        let (prev_steady, prev2_steady) = (st.unflagged & 1 != 0, st.unflagged & 2 != 0);
        st.unflagged = st.unflagged << 1 | u32::from(!rec.status.contains(Status::TRANSIENT));
        st.handed_z = st.handed_z << 1 | u16::from(rec.handover_z > HANDED_Z_SIGMAS);
        if st.handed == Some(rec.tooth) {
            // Its next period is over: the evidence was for that one.
            st.handed = None;
        }
        let (bad_data, no_decision) = if jittered {
            let keep = !Status::PERIOD_INVALID.0;
            (
                Status(BAD_DATA.0 & keep),
                Status(NO_BREAKAGE_DECISION.0 & keep),
            )
        } else {
            (BAD_DATA, NO_BREAKAGE_DECISION)
        };
        let armed = !rec.status.intersects(bad_data);
        let f = self.signal(rec.fx_n, rec.f2_n);
        let f = if f.is_finite() { f } else { 0.0 };
        // Two teeth in a row with good data and nothing above the not-cutting floor: the
        // monitor's own flag waits for a whole revolution of them (its test is on the
        // revolution mean, so that a lost flute's empty period does not count).
        let dead = libm::fabsf(f) < self.est.force_floor_n
            && !rec
                .status
                .intersects(Status(bad_data.0 & !Status::NOT_CUTTING.0));
        let two_dead = dead && st.prev_dead;
        st.prev_dead = dead;
        // A lost or swallowed tooth, or a moved window, breaks the tooth alignment the
        // detector relies on.
        if (rec.status.contains(Status::PERIOD_INVALID) && !jittered)
            || rec
                .status
                .intersects(Status(Status::NO_SYNC.0 | Status::WINDOW_MOVED.0))
        {
            // Forgets every tooth (none is armed any more). Out of a steady cut, the
            // two revolutions until the rules compare revolutions again, and one more, are
            // watched for a flute that carries nothing (`flute_missing`).
            st.armed = 0;
            st.exceed_pos = 0;
            st.exceed_neg = 0;
            st.handed = None;
            // (Steady within the last revolution: the period after a moved window or a
            // lost pulse is often flagged for its length too, a second forget.)
            st.resumed = if st.since_steady <= n as u32 {
                (3 * n + 2).min(u8::MAX as usize) as u8
            } else {
                0
            };
            st.realigned = st.resumed > 0
                && rec.status.contains(Status::WINDOW_MOVED)
                && !rec.status.contains(Status::NO_SYNC);
        }
        if rec.status.contains(Status::NOT_CUTTING) {
            st.resumed = 0;
            st.realigned = false;
        }
        if rec.status.is_valid() {
            st.held = Some((rec.rr, rec.ra));
        }
        let head = st.head & (HISTORY - 1);
        if let Some(slot) = st.hist_f.get_mut(head) {
            *slot = f;
        }
        if let Some(slot) = st.hist_tooth.get_mut(head) {
            *slot = rec.tooth;
        }
        if let Some(slot) = st.hist_len.get_mut(head) {
            *slot = rec.samples.min(u16::MAX as u32) as u16;
        }
        st.head = (head + 1) & (HISTORY - 1);
        st.armed = (st.armed << 1) | armed as u64;
        st.exceed_pos <<= 1;
        st.exceed_neg <<= 1;
        probe.mark(Stage::AlarmHistory);

        // Two teeth in a row fallen to a fraction of their force one revolution earlier:
        // nothing cuts any more (a lost tool, or the last teeth of an exit), not a flute
        // lost (its chip goes to the next tooth). With unequal flutes (runout) the drops
        // differ and `E` swings both ways: the breakage rules leave it to tool gone.
        let (f0, back0) = (st.force(0), st.force(n));
        let newest_collapsed = f0 < GONE_SHARE * back0;
        // (The tooth before only where the newest collapsed: most records stop here.)
        let (f1, back1) = if newest_collapsed {
            (st.force(1), st.force(n + 1))
        } else {
            (f32::INFINITY, 0.0)
        };
        let collapsed = newest_collapsed && f1 < GONE_SHARE * back1;
        // ... or the newest did and the two together (a trip's naming, below).
        let pair_collapsed = newest_collapsed && f0 + f1 < GONE_SHARE * (back0 + back1);
        // Two teeth under the floor that carried force over it a revolution earlier: a
        // runout larger than the chip leaves flutes in a row idle at a low feed, every
        // revolution (a feed override turned down).
        let floor = self.est.force_floor_n;
        // The newest dead on a cut within a pitch at the steady cut's feed, over the floor a
        // revolution earlier (`one_dead`: a flute that cut nothing, see the tool-gone
        // stage). Or, with 2 flutes, that and
        // the tooth before down on its own past the noise: the tooth the tool was lost in
        // keeps part of its force, and the second dead tooth would come a revolution after
        // the first (seed 10018 gone 28: 59 % left, then nothing). A broken flute's window
        // goes dead after the other flute's gain, or after its unchanged window where it
        // broke at its cut's start; a feed turned down leaves a light flute under runout
        // idle and the heavy one lower, not at the steady feed. (With more flutes the two
        // dead teeth come within the revolution.)
        let one_dead = dead
            && newest_collapsed
            && back0 >= floor
            && st.exit_wide <= 0.0
            && !rec.status.contains(Status::FEED_CHANGE)
            && libm::fabsf(rec.tc_mm - st.steady_tc_mm) <= 0.05 * st.steady_tc_mm;
        let lost_in_before = n == 2
            && one_dead
            && back1 > f1
            && self.decision_var(st, back1).is_some_and(|var| {
                (back1 - f1) * (back1 - f1) > GONE_BEFORE_SIGMAS * GONE_BEFORE_SIGMAS * 0.5 * var
            });
        let two_dead =
            (two_dead && collapsed || lost_in_before) && back0 >= floor && back1 >= floor;
        if rec.status.contains(Status::NOT_CUTTING) && !self.gone_candidate(st, rec, two_dead) {
            st.held = None;
        }
        // The first alarm raised: cause, value, threshold (the event, with its copy of the
        // record, is made once at the end). In a cell: the breakage rules' speed test
        // takes back what they raised, while `raise` still holds it.
        // While a trip waits for its name, a tooth that collapsed is left to the naming
        // (the output latched already): a tool lost inside the tripped period leaves that
        // period partly cut and the next tooth alone collapsed (seed 3731 gone 23: 31 %
        // left, then 1 %, named a breakage).
        let naming = st.trip.is_some_and(|t| t.left > 1);
        let collapsed_now = collapsed || newest_collapsed && naming;
        let raised_cell = core::cell::Cell::new(None::<(Cause, f32, f32)>);
        let raise = |cause, value, threshold| {
            if raised_cell.get().is_none() && !(cause == Cause::Breakage && collapsed_now) {
                raised_cell.set(Some((cause, value, threshold)));
            }
        };
        // The first raised by a rule that compares the newest revolution with the one
        // before alone (see the speed test below).
        let one_rev_cell = core::cell::Cell::new(false);
        let raise_one_rev = |value, threshold| {
            let first = raised_cell.get().is_none();
            raise(Cause::Breakage, value, threshold);
            one_rev_cell.set(one_rev_cell.get() || first && raised_cell.get().is_some());
        };

        // Revolution mean of the watched force (runout-free), when the last N are armed
        // (summed newest first, from -0 as `Sum` does), and, when the last 2N are, the
        // change of that mean from the revolution before (`revolution_change`): one walk.
        let (rev_mean, rev_change) = self.revolution_means(st);
        let newest = st.slot(0);
        if let Some(slot) = st.hist_rev.get_mut(newest) {
            *slot = rev_mean.unwrap_or(0.0);
        }
        probe.mark(Stage::AlarmRevMean);

        // --- breakage ---------------------------------------------------------------
        // A flute that breaks (or chips) hands its chip to the next flute: the per-tooth
        // pattern redistributes, so `E` swings both ways within a revolution while the
        // revolution total stays. Engagement, feed and speed changes move every tooth the
        // same way: `E` then has one sign. Both signs are required.
        let deciding = !rec.status.intersects(no_decision);
        if self.cfg.breakage.enabled && deciding {
            if let Some(e) = self.first_difference_change(st) {
                let k = self.cfg.breakage.threshold_rel;
                let measured = rev_mean.unwrap_or(f);
                // While the engagement changes (an entry), flutes of unequal chip (runout)
                // grow at unequal rates and E swings both ways too, by at most the runout's
                // share of the growth per revolution: the threshold widens by that growth.
                // A breakage keeps the revolution total, so its own threshold barely moves.
                // Without two whole armed revolutions (just after an entry) there is no
                // growth figure: no decision yet.
                let common = rev_change.map_or(f32::INFINITY, f32::abs);
                // Noise floor: E's own running spread (each tooth's contribution clipped at
                // the threshold, so that a breakage cannot raise it). Light cuts, where a
                // sensor's noise is large against the force, would otherwise alarm on it.
                // The spread is updated after the decision, and not by an exceedance; it
                // is scaled up with the force past the force it was learned at
                // (`decision_var`).
                let clip = k * measured;
                let mut exceeded = false;
                // How far `E` passed its threshold where it raised first (the speed test
                // below; -INFINITY: it did not).
                let mut e_margin = f32::NEG_INFINITY;
                let noise = self.decision_var(st, measured);
                let (settled, e_var) = (noise.is_some(), noise.unwrap_or(st.e_var));
                // Cheap screen first: the model threshold is only needed near the limit, and
                // no threshold is below `max(screen, floor)`: the square root is taken only
                // past `screen`, the model only past that.
                let screen = 0.5 * k * measured;
                // Not `>`: with a NaN (absurd forces) the full test below decides, as it
                // would without the shortcut.
                #[allow(clippy::neg_cmp_op_on_partial_ord)]
                let past_screen = !(e.abs() <= screen);
                if settled && past_screen {
                    let floor = E_SIGMAS * libm::sqrtf(e_var);
                    let lo = crate::fmath::max(screen, floor);
                    // The first tooth of a change (see `confined_growth`): its exceedance
                    // counts against the growth of the teeth before it, not its own.
                    #[allow(clippy::neg_cmp_op_on_partial_ord)]
                    let bit_common = if !(e.abs() <= lo + common) || rev_change.is_none() {
                        common
                    } else {
                        match self.confined_growth(st, 0.5 * lo) {
                            Some(g) => crate::fmath::min(g, common),
                            None => common,
                        }
                    };
                    #[allow(clippy::neg_cmp_op_on_partial_ord)]
                    if !(e.abs() <= lo + bit_common) {
                        let expected = self.expected_signal(st.held, rec.tc_mm, measured);
                        let base = crate::fmath::max(k * expected, floor);
                        let threshold = base + common;
                        if e.abs() > base + bit_common {
                            exceeded = true;
                            // After an exceedance of the other sign on the tooth before,
                            // `E_1 = R_1 - R_2` and `E_0 = R_0 - R_1` share `R_1`: this one
                            // counts only where `R_0` or `R_2` carries a share of its own
                            // (a broken flute's loss `R_2`, its next flute's gain `R_0`),
                            // or `R_1` alone passes the threshold, past any single tooth's
                            // noise (the next flute's gain, lagged by the current loop, may
                            // fall mostly in the window after: seed 3981 break 28), and past
                            // its own share of the revolution's change: through an exit each
                            // tooth loses in proportion to its force, a heavy flute under
                            // runout the most (seed 4712 normal 100: 2 flutes, 715 and 186 N,
                            // the heavy one lost 306 N with the revolution's mean 272 N and
                            // its change 146 N).
                            let (sign, before) = if e > 0.0 {
                                (1.0, st.exceed_neg)
                            } else {
                                (-1.0, st.exceed_pos)
                            };
                            let r = |k: usize| sign * (st.force(k) - st.force(k + n));
                            let share = crate::fmath::max(st.force(1 + n) / measured, 1.0);
                            let counts = before & 2 == 0
                                || crate::fmath::max(r(0), r(2)) > MIRROR_SHARE * base
                                || -r(1) > base + share * common;
                            if counts && e > 0.0 {
                                st.exceed_pos |= 1;
                            } else if counts {
                                st.exceed_neg |= 1;
                            }
                            let mask = if n >= 32 { u32::MAX } else { (1u32 << n) - 1 };
                            let (pos, neg) = (st.exceed_pos & mask, st.exceed_neg & mask);
                            let count = (pos | neg).count_ones();
                            // One exceedance three times over is a breakage too: a step of
                            // engagement widens the threshold by its own revolution change
                            // (`common`, not the confined growth) and cannot pass 3x it; the
                            // chip a broken flute leaves doubles the next flute's force.
                            let both_signs = pos != 0
                                && neg != 0
                                && count >= self.cfg.breakage.debounce_teeth as u32;
                            if both_signs || e.abs() > SINGLE_EXCEEDANCE * threshold {
                                if raised_cell.get().is_none() {
                                    e_margin = e.abs() - threshold;
                                }
                                raise_one_rev(e.abs(), threshold);
                            }
                        }
                    }
                }
                // Redistribution within the revolution: the changes from one revolution
                // earlier, `R_k = F_k - F_{k+N}` over the last N teeth, of both signs beyond
                // the threshold at once (one tooth lost force, another gained it). This
                // sees a breakage whose loss is spread over two tooth periods (several
                // flutes engaged at once, or the break in the middle of a pass), where no
                // single `E` passes. An engagement change (a step, an entry with runout, a
                // lost tool) moves every `R` one way. `R`'s noise is `E`'s over sqrt 2; the
                // threshold widens by half the revolution growth. Screened on the newest
                // `R` (it makes the pattern complete). The same against SLOW_REVS
                // revolutions earlier: the same noise (two teeth's), the growth over those
                // revolutions. And each tooth's mean over the last two revolutions against
                // its mean over the two [`MEANS_BACK_REVS`] earlier (`span` 2): half the
                // noise variance, for a loss spread over two periods that the noise of
                // single teeth hides (arcs wider than a pitch, where the encoder's jitter
                // moves the steep edges inside the cut across the boundaries: seeds 244 and
                // 263, 4 flutes, sigma_R 5-7 % of the tooth; never decided before).
                for (back, armed) in [
                    (n, rev_change.is_some()),
                    (SLOW_REVS * n, st.armed & self.armed_slow == self.armed_slow),
                ] {
                    #[allow(clippy::neg_cmp_op_on_partial_ord)]
                    let newest_past = !(libm::fabsf(st.force(0) - st.force(back)) <= screen);
                    if settled && newest_past && armed {
                        let c = (k, measured, screen, e_var);
                        if let Some((v, t)) = self.redistribution(st, rec.tc_mm, back, 1, c) {
                            if back == n {
                                raise_one_rev(v, t);
                            } else {
                                raise(Cause::Breakage, v, t);
                            }
                        }
                    }
                }
                // (The two earlier revolutions a steady cut's: in an exit fading over
                // revolutions a heavy flute loses while a light one gains, both past the
                // floor over three revolutions, seed 2906 normal 57 at 3 flutes.)
                // (Nor on a drop alone: the newest tooth down past the screen from one
                // revolution earlier, the teeth before it within it. The means' gain is
                // then three revolutions old, noise there, and the drop is a lost tool's
                // first window as much as a broken flute's, decided on the next record by
                // the next tooth's gain or its empty window. Seed 12018 gone 0: 3 flutes,
                // the tool lost inside a tooth's cut, 55 % down, against two teeth whose
                // means three revolutions back lay 40 and 27 N under their level: named a
                // breakage.)
                if settled
                    && st.all_armed(self.armed_means)
                    && st.flagged(3 * n as u32, 2 * n) == 0
                    && !(st.force(0) - st.force(n) < -screen
                        && self.changes_within(st, 1, n, screen).is_some())
                {
                    let back = MEANS_BACK_REVS * n;
                    let newest = st.force(0) + st.force(n) - st.force(back) - st.force(back + n);
                    #[allow(clippy::neg_cmp_op_on_partial_ord)]
                    if !(libm::fabsf(0.5 * newest) <= screen) {
                        let c = (k, measured, screen, e_var);
                        if let Some((v, t)) = self.redistribution(st, rec.tc_mm, back, 2, c) {
                            raise(Cause::Breakage, v, t);
                        }
                    }
                }
                // The first tooth of a flute lost between its engagements (see
                // FIRST_TOOTH_SHARE): decided on this tooth alone, its cause on the next.
                // The first-tooth rules, past a cheap screen (see `first_tooth`).
                let (r0, before) = (st.force(0) - st.force(n), st.force(n));
                if let Some(var) = noise {
                    // (Out of a steady cut: the record before the loss not transient. As
                    // an exit fades, flutes of unequal runout leave at unequal times.)
                    // (A flagged loss only out of a cut steady for the 2N records before
                    // it, the loss's bits 2.. of `unflagged`, whose force held: in a cut that
                    // keeps changing, a pair is its change of shape (seed 200 normal 44); an
                    // exit flagged for its first revolutions fades on unflagged, each tooth
                    // at its own time (seed 276 normal 52).) An unflagged loss out of 4N
                    // records with at most one flagged: an exit flagged on and off is a cut
                    // still changing (seed 2743 normal 75, 5 of 8; seed 2969 normal 119, 1
                    // of the 6 before its pair, 6 of the 12). And out of a cut that
                    // held its force before the loss, flagged or not: an exit's slow tail
                    // goes unflagged for revolutions at a time (seed 1786 normal 30).
                    // (The pair first: the flags' count on nearly every tooth costs 20
                    // instructions of the tooth update, measured under QEMU.)
                    // After the history was forgotten out of a steady cut (`resumed`: a
                    // moved window, a lost pulse) the revolutions that would show a flagged
                    // loss's cut held are not armed yet: such a pair only raises at once,
                    // as far past the noise as `pair_raises` asks, and leaves no evidence
                    // (seed 13375 break 9: 4 flutes, a window moved 5 teeth before the
                    // break, a pair of 20 sigma_R; the trip on the broken flute's next
                    // pass came 1.04 revolutions after the first missed cut).
                    let held = prev_steady || st.all_armed(self.armed_held);
                    if prev2_steady
                        && self.handed_over(st, r0, var, prev_steady)
                        && st.flagged(2, 4 * n) <= u32::from(prev_steady)
                        && (held || st.resumed > 0)
                        && !self.fell_before_loss(st, var, prev_steady)
                    {
                        let loss_n = st.force(n + 1) - st.force(1);
                        let pair = r0 + loss_n;
                        // Far past the noise it is decided at once: its gain may end a
                        // revolution after the break, and the trip that waits for the
                        // broken flute's next pass has nothing to find where the flute
                        // broke before its own window (seed 9102 break 113: a pair of 9.6,
                        // raised 2 revolutions late).
                        let raises = self.pair_raises(st, rec, (r0, loss_n), (var, measured));
                        if held {
                            st.handed = Some(st.tooth(1));
                            st.handed_recut = false;
                            st.handed_loss_n = loss_n;
                            st.handed_strong = pair * pair
                                > EVIDENCE_STRONG_SIGMAS * EVIDENCE_STRONG_SIGMAS * 0.5 * var;
                        }
                        if let Some(t) = raises {
                            raise_one_rev(pair, t);
                        }
                    }
                }
                #[allow(clippy::neg_cmp_op_on_partial_ord)]
                let moved = !(r0 <= FIRST_TOOTH_SHARE * before);
                if moved && rev_change.is_some() {
                    if let Some((value, threshold)) =
                        self.first_tooth(st, r0, before, prev_steady, noise)
                    {
                        raise_one_rev(value, threshold);
                    }
                }
                // The rules above compare teeth across revolutions: not while the
                // spindle's speed changes or just after. The placed boundary follows the
                // pulses' tracked times, whose interval is a running mean over about 16
                // pulses: in a speed change it lags by several samples and settles over
                // that many pulses after, and at a steep chip edge the lag moves much force
                // from one window into the next (seed 1190 gone 14: 2 flutes under runout,
                // 15 % faster in 0.15 s, the light tooth 58 -> 122 N and the heavy one 184
                // -> 128 through the ramp, raised by `E`, then by the redistribution
                // against three revolutions earlier in the settling). Only where one was
                // raised: the test walks the periods' lengths. But a rule that compares
                // the newest revolution with the one before alone (`E`, the redistribution
                // against it, the first tooth's) stands where every boundary it compares
                // lies where its tooth's did a revolution earlier (`lag_quiet`, the
                // window's lag caught up to the jitter): at a steady speed after a ramp
                // the periods' lengths still differ from those 16 teeth earlier for
                // revolutions, and a flute broken there waited for them (seed 6123 break
                // 93: 2 flutes 12 % slower, the break 9 teeth after the ramp; its first
                // pair, `E` 4.9 times the threshold, taken back, and the alarm came 3.9
                // revolutions late). Its records from `E`'s newest two and their ends:
                // three boundaries, or the revolution's N and its end. And `E` stands where
                // it passes its threshold by what the boundaries of its two newest periods
                // may have moved (`past_moved`): where they lie in the cut's quiet stretch,
                // a few newtons however far the lag swings (seeds 12739 break 29 and 12793
                // break 37: 2 flutes, 13 and 9 teeth after a ramp, `E` 3.3 and 4.3 times
                // its threshold against 12 N moved; taken back, the trip came a revolution
                // after the first missed cut).
                let quiet = one_rev_cell.get() && usize::from(lag_quiet) > n.max(2);
                if matches!(raised_cell.get(), Some((Cause::Breakage, ..)))
                    && !quiet
                    && !self.speed_settled(st)
                    && !self.past_moved(e_margin, f / rec.f2_n, boundary_moved_n)
                {
                    raised_cell.set(None);
                }
                // The hand-over inside a period (`crate::handover`): a flute broken late
                // in its cut, the loss and the next flute's gain over the same angles,
                // out of a steady cut, its bins where they were a revolution earlier: the
                // periods' lengths alike, and the boundaries' lag caught up after a ramp
                // (seed 8345 normal 17: 2 flutes 14 % slower, 7 teeth after the ramp the
                // periods alternated 202 and 206 samples while the lag still moved, and
                // one tooth's 1.5 sigma_R of noise made a hand-over of 4.9 sigma).
                if settled
                    && prev_steady
                    && rec.handover_z > HANDOVER_SIGMAS
                    && self.cfg.breakage.signal == BreakageSignal::Resultant
                    && self.same_speed(st, 2 * n, 2)
                    && usize::from(lag_quiet) > n.max(2)
                {
                    let expected = self.expected_signal(st.held, rec.tc_mm, measured);
                    let t = HANDOVER_SHARE * k * expected;
                    if rec.handover_n > t {
                        raise(Cause::Breakage, rec.handover_n, t);
                    }
                }
                if !exceeded {
                    // A plain mean over the first values (an average started at zero
                    // underestimates the spread for its first few dozen teeth: false alarms
                    // just after an entry), exponential from 1 / E_ALPHA values on.
                    let w = if (st.e_count as f32) < 1.0 / E_ALPHA {
                        1.0 / (st.e_count as f32 + 1.0)
                    } else {
                        E_ALPHA
                    };
                    // Clipped at `E_CLIP_SIGMAS` of the spread instead where that is
                    // higher (a light cut, an exit's tail): at `k F` alone the clip cuts
                    // into the noise itself as the force falls, the spread shrinks with
                    // the force, and so does every floor set in it (seed 3642 normal
                    // 103: an exit's tail at 30 N a tooth, `k F` 6 N, noise 4.5 N a
                    // tooth; sigma_R learned as 4.6 N against 6.4, and the drop trip's
                    // floor of 6 of it passed by a tooth 10 N up, then 17 N down).
                    let floor2 = E_CLIP_SIGMAS * E_CLIP_SIGMAS * st.e_var;
                    let e2 = crate::fmath::min(e * e, crate::fmath::max(clip * clip, floor2));
                    st.e_var += w * (e2 - st.e_var);
                    if measured.is_finite() {
                        st.e_force2 += w * (measured * measured - st.e_force2);
                    }
                    st.e_count = st.e_count.saturating_add(1);
                }
            }
        }
        // A cut resuming after the history was forgotten (the window moved, a lost
        // pulse): until two revolutions are armed nothing above can compare, and a flute
        // lost in that time would never be seen (its pattern is steady by then). Decided
        // on every record of those two revolutions that has a revolution mean, the second
        // one's too: on a 2-flute tool whose flute broke in the first period armed, the
        // first one's empty period is the newest (left out) until the second revolution.
        // And one revolution more: a flute broken early in its period in the second
        // revolution leaves that window half its force, over the share, and its first
        // empty one is the newest on the second revolution's last record (seed 414 break
        // case 72, caught at the exit, 92 revolutions on).
        if st.resumed > 0 {
            st.resumed -= 1;
            if let (true, Some(mean)) = (self.cfg.breakage.enabled && deciding, rev_mean) {
                if let Some((least, limit)) = self.flute_missing(st, mean) {
                    raise(Cause::Breakage, least, limit);
                }
            }
        }

        // The drop trip for the next period: out of a steady cut with a settled noise
        // figure, where the next tooth's loss a revolution ago was handed to the one after
        // it (`handed_over`), or with no run of the newest teeth losing force (an exit's
        // teeth all lose).
        st.trip_floor_n = f32::INFINITY;
        st.trip_quiet_n = f32::INFINITY;
        // Armed from the first tooth that has its own a revolution earlier (not only with
        // two revolutions armed): a flute broken just after the history was forgotten (a
        // lost pulse) would otherwise be caught only past a revolution. In the revolution
        // after a moved window, from the first record: the hand-over stage's re-cut
        // profiles are the reference, and it checks the periods since for a loss.
        let since_move = (!st.armed).trailing_zeros() as usize;
        // The record after that revolution: its own change from a revolution earlier is on
        // the records, the one before's only against its re-cut profile (its period then
        // was the odd one), and the rules on the records cannot take that pair yet.
        let bridging = st.realigned && since_move == n + 1;
        let fresh = st.realigned && since_move <= n;
        st.realigned = fresh;
        // (The revolution before the move where the newest has none: a tooth's own force,
        // the gain of a hand-over, would widen the noise it is judged against.)
        let level = match rev_mean {
            Some(m) => m,
            None if fresh => {
                let m = st.hist_rev.get(st.slot(since_move + 1)).copied();
                m.filter(|&m| m > 0.0).unwrap_or(f)
            }
            None => f,
        };
        let noise = self.decision_var(st, level);
        // The record before's change from its re-cut profile (`handed_after_move` keeps
        // this one's); the odd period's is not measured.
        let odd = rec.status.contains(Status::WINDOW_MOVED) && fresh;
        let before_recut = core::mem::replace(
            &mut st.recut_last_n,
            if odd { f32::NEG_INFINITY } else { f32::NAN },
        );
        if self.cfg.breakage.enabled
            && deciding
            && st.latched.is_none()
            && st.trip.is_none()
            && (fresh || bridging || !rec.status.contains(Status::TRANSIENT))
            && self.cfg.breakage.signal == BreakageSignal::Resultant
        {
            if let Some(var) = noise {
                let var_r = 0.5 * var;
                let sigma_r = libm::sqrtf(var_r);
                let next = (rec.tooth as usize + 1) % n.max(1);
                // (Bridging: the newest's change a revolution back, as a tangential
                // change, as the re-cut's are. Seed 5147 break 8, 2 flutes: broken in the
                // first period after the move, the next tooth 90 % up on its second.)
                let change = if bridging && rec.f2_n > 0.0 && f > 0.0 {
                    (st.force(0) - st.force(n)) * rec.f2_n / f
                } else {
                    recut_n
                };
                if fresh || bridging && before_recut.is_finite() {
                    let (changes, figures) = ((before_recut, change), (var_r, level));
                    if let Some((e, t)) = self.handed_after_move(st, rec, f, changes, figures) {
                        raise(Cause::Breakage, e, t);
                    }
                }
                // The tooth before the handed one: where no boundary falls between cuts
                // (arcs wider than a pitch), the broken flute's cut begins in its window,
                // and there its next pass loses from the cut's first angles on.
                let before_handed = n >= 3 && st.handed == Some(((next + 1) % n) as u8);
                let handed_next = st.handed == Some(next as u8);
                // (After the gain, the newest tooth must not have lost: an exit's
                // first tooth right after a noise pair that passed as evidence. The
                // newest tooth's loss may be the broken flute's cut where it begins, in the
                // window before: where the cut spans more than a pitch (known from an
                // estimate, or measured on the window's bins without one,
                // `spans_windows`) and the newest window is the one before the handed tooth's (seed
                // 2352 break 45, 4 flutes, `R_r` 1.41, that window lost 25 % and the handed
                // one 59 %; the share then covers an exit that took the newest tooth's
                // loss), and after a strong pair where nothing tells the span (seeds 20
                // break 0 and 69 break 57). Not after a strong pair on an arc known to lie
                // within a pitch: seed 9859 normal 9, 4 flutes at `R_r` 0.61, a pair of 6.1
                // sigma_R by noise, then an exit's first teeth; the newest lost 3 sigma_R
                // and the handed tooth's period, armed at 0.3, lost 30 %.)
                let kept = st.handed_strong && st.held.is_none()
                    || st.force(0) - st.force(n) >= -EVIDENCE_KEPT_SIGMAS * sigma_r
                    || handed_next && self.spans_windows(st);
                let pending = before_handed || handed_next;
                // (The newest revolution as long as the one before: in a speed ramp the
                // current loop's lag, a time, moves force across the windows' boundaries,
                // and a pair in the noise is no rarer (seed 678 gone 8: 10 % faster over
                // 8 teeth of a 2-flute tool; the period armed at 0.3 lost 33 %). Not the
                // two revolutions before too: a lost pulse's long record there would keep
                // the evidence out for two revolutions, and 5 breaks of seeds 673-864 late.
                // And the speed settled as the rules above ask, 16 teeth back: after a ramp
                // the tracked boundary lags on while the last revolutions are as long,
                // moving force from one window into the next, a pair (seed 3890 break 103
                // before its damage: 2 flutes, 9 % faster over 8 teeth, the light tooth 55
                // -> 29 N, the other 36 -> 60 N as the speed came to its end; the handed
                // tooth's period, armed at 0.3, lost 35 %). A lost pulse's record is not
                // armed there: settled.)
                let evidence = pending
                    && kept
                    && if st.handed_recut {
                        self.same_speed_across_move(st)
                    } else {
                        self.same_speed(st, n, 1)
                    }
                    && self.speed_settled(st);
                if pending && !kept {
                    // The loss that voids the evidence voids it for the period after too:
                    // an exit has begun (seed 2452 normal 65: a pair in an exit's noise, the
                    // next tooth 24 % down, the one after 1 sigma_R, and the handed tooth's
                    // period, armed at 0.3, lost 29 %).
                    st.handed = None;
                }
                let evidence_floor = if !evidence {
                    None
                } else if before_handed {
                    Some(EVIDENCE_TRIP_SIGMAS * sigma_r)
                } else {
                    // Not an exit so far (the next tooth gained), and the loss in the pair
                    // is no recent loss. The tooth's loss a revolution ago counts toward
                    // the floor: its period then is the reference now, and a flute broken
                    // inside it left less there to lose.
                    Some(crate::fmath::max(
                        EVIDENCE_TRIP_SIGMAS * sigma_r - st.handed_loss_n,
                        EVIDENCE_MIN_SIGMAS * sigma_r,
                    ))
                };
                // (After a pair, the share covers an exit that begins in that period:
                // the pair tells of the teeth before it, not of the period to come.)
                let armed = if let Some(floor) = evidence_floor {
                    // (Every tooth since the gain lost, the newest too: an exit may have
                    // begun right after the gain, a feed a tooth since. Seed 3213 normal
                    // 99: a noise pair, then two teeth 1.5 sigma_R down each, then the
                    // handed tooth's period, armed at 0.3, lost 32 %.)
                    let mut lost = 0;
                    while handed_next
                        && lost + 2 < n
                        && st.force(lost + n) - st.force(lost) > EVIDENCE_EACH_SIGMAS * sigma_r
                    {
                        lost += 1;
                    }
                    let lost_since = lost.saturating_sub(1);
                    // (Its shares not from two revolutions back: the pair was chosen for
                    // its loss, and where that is noise the force two back stood high by
                    // it, which the evidence's share, without a noise term, does not
                    // allow for. Seed 13203 normal 51 with no lag: a noise pair whose
                    // loss, 93 N, stood 41 N high two back, then an exit's first period
                    // 81 N down against a trip at 0.20 of its reference.)
                    self.trip_share(st, rec.tc_mm, sigma_r, 0.0, Some(lost_since), 0.0)
                        .map(|(share, whole)| (share, floor, whole, 0.0))
                } else if let Some(run_lost) = if fresh {
                    Some(0.0)
                } else {
                    // (After a run of the newest teeth that lost, at the share of the exit
                    // that took it: `recent_loss`.)
                    self.recent_loss(st, var_r, sigma_r).filter(|_| {
                        !(st.all_armed(self.armed_fade)
                            && self.fell(st, var, 0, 2, TRIP_FALL_SIGMAS))
                        // (Nor with two of the last 2N records flagged transient: a cut
                        // still changing. Seed 1723 normal 113: an exit's tail of 150-200 N
                        // a tooth, flagged on and off for revolutions, ended inside one
                        // period past the share and 6 sigma_R; seed 3126 taught 9 with
                        // the boundary at the pulses' tracked times, a variant: 3 flutes,
                        // the tail swinging by 2-5 sigma_R a revolution, 2 of the last 6
                        // flagged. The evidence's arming above is not affected.)
                        && st.flagged(0, 2 * n) < 2
                        // (Nor in a speed ramp, the newest revolution as long as neither
                        // the one before nor the one before that, `steady_speed`: the
                        // period's bins are judged against that one's at
                        // the same samples, and a light cut's short arc moves across them.
                        // Seed 5318 normal 35: 2 flutes, 54 N, 6 % slower over two
                        // revolutions; a period whose whole loss was 4.5 N tripped. Where a
                        // tooth of the two is not armed, a lost pulse's or a moved window's
                        // odd period, its length says nothing of the speed. The hand-over
                        // stage allows inside the period for the growth it has seen, which
                        // a ramp's start outruns: without this test, 2 of 16 noise seeds of
                        // that case still tripped.)
                        && (!st.all_armed(self.armed_two_revs) || self.steady_speed(st))
                    })
                } {
                    // (After a move the hand-over stage walks the periods since; and no
                    // credit: two revolutions are not armed.)
                    if fresh {
                        st.trip_quiet_n = TRIP_QUIET_SIGMAS * sigma_r;
                    }
                    // The trip channel's noise on the resultant's scale, for the close.
                    let sigma_t = libm::sqrtf(trip_var_n2) * f / rec.f2_n;
                    self.trip_share(st, rec.tc_mm, sigma_r, sigma_t, None, run_lost)
                        .map(|(share, whole)| {
                            // The next tooth's loss a revolution ago, out of a steady cut: its
                            // period then is the reference now.
                            let lost = st.force(2 * n - 1) - st.force(n - 1);
                            let two_revs = st.armed & self.armed_two_revs == self.armed_two_revs;
                            let credited = two_revs
                                && (!st.unflagged).trailing_zeros() as usize >= 2 * n
                                && lost > EVIDENCE_EACH_SIGMAS * sigma_r;
                            // Where it gained instead, its reference now stands that high over
                            // its own level: the floor rises by it (seed 2256 normal 48: a
                            // tooth 2.3 sigma_R up on the last flat revolution of an exit, then
                            // the exit's step).
                            let raised = two_revs && -lost > EVIDENCE_EACH_SIGMAS * sigma_r;
                            let lost = if credited || raised { lost } else { 0.0 };
                            let floor = FIRST_TOOTH_SIGMAS * sigma_r - lost;
                            (
                                share,
                                crate::fmath::max(floor, EVIDENCE_MIN_SIGMAS * sigma_r),
                                whole,
                                lost,
                            )
                        })
                } else {
                    None
                };
                if let Some((share, floor, whole, lost)) = armed {
                    // The floors are in the resultant's noise; the trip measures the
                    // tangential channel, whose own noise can be wider (seed 3723 normal
                    // 34: an exit's tail, the resultant's sigma_R 15.8 N against that
                    // channel's 23 N, a pair of 3.8 of it tripped at 6 of the first).
                    // (A root only where it widens.)
                    let wider = trip_var_n2 / var_r;
                    st.trip_floor_n = if wider > 1.0 {
                        floor * libm::sqrtf(wider)
                    } else {
                        floor
                    };
                    st.trip_share = share;
                    st.trip_whole_share = whole;
                    // The shares are of the tooth two revolutions back where its period a
                    // revolution ago, the reference, lost (`of_two_back`).
                    let back = st.force(n - 1);
                    st.trip_credit = if back > 0.0 { lost / back } else { 0.0 };
                }
            }
        }

        probe.mark(Stage::AlarmBreakage);

        // --- tool gone ----------------------------------------------------------------
        // A lost tool takes the revolution-mean force from near its recent peak to the
        // not-cutting floor within a revolution or so; an exit from the part lowers it over
        // many. "Strong": the revolution mean within STRONG_SHARE of the recent peak, which
        // decays by 2 % a revolution (PEAK_DECAY_LN_PER_REV) so that a lighter cut later
        // counts too.
        // "Steady": strong and not already falling by more than FALLING_SHARE of itself a
        // revolution; a quick exit (a few revolutions) passes through strong on its way
        // down and would otherwise look like a collapse at its end.
        st.peak_force_n *= self.peak_decay;
        let steady = match rev_mean {
            Some(m) if armed => {
                st.peak_force_n = crate::fmath::max(st.peak_force_n, m);
                let falling = rev_change.is_some_and(|c| c < -FALLING_SHARE * m);
                m >= STRONG_SHARE * st.peak_force_n && !falling
            }
            _ => false,
        };
        if let (true, Some(m)) = (steady, rev_mean) {
            st.since_steady = 0;
            st.live_since_steady = 0;
            st.steady_force_n = m;
            st.steady_tc_mm = rec.tc_mm;
        } else {
            // A moved window's odd period is the move's, not a tooth of the cut: no record
            // after it is steady until a revolution mean spans the move again (seed 8572
            // gone 5: the tool lost a tooth after a move, its first not-cutting record the
            // fifth since the last steady one, against 2 revolutions of 2 flutes).
            let moved = rec.status.contains(Status::WINDOW_MOVED);
            st.since_steady = st.since_steady.saturating_add(u32::from(!moved));
            st.live_since_steady = st
                .live_since_steady
                .saturating_add((armed && f >= floor) as u8);
        }
        // While a trip waits for its name, one tooth that collapsed is a broken flute's
        // empty window as well as a lost tool's: the monitor's not-cutting flag (on the
        // revolution mean) can come before the next flute takes the chip (seed 8800 break
        // 22: 2 flutes, the heavy one 82 % of the load, its window emptied, the mean 23.9
        // N against a floor of 24). The naming waits for a second (the output latched
        // already).
        if self.cfg.tool_gone.enabled
            && self.gone_candidate(st, rec, two_dead)
            && (two_dead || !naming)
        {
            raise(Cause::ToolGone, f, self.est.force_floor_n);
            st.held = None;
        } else if self.cfg.tool_gone.enabled && one_dead && self.gone_candidate(st, rec, true) {
            // The newest dead, not yet named: with 2 flutes after a tooth that lost under
            // GONE_BEFORE_SIGMAS, a tool lost late in that tooth's cut, whose second empty
            // window comes a revolution after the first (seeds 13378 gone 7, 13381 gone
            // 15 and 13387 gone 16: the tooth before 4.4, 3.2 and 3.4 sigma_R down, named
            // 1.16-1.23 revolutions after the first missed cut); or a flute broken at its
            // cut's start, or a light flute whose first missed cut took too little to arm
            // the drop trip on its next pass (seeds 13291 break 117, 2 flutes, 70 N beside
            // 253; 13076 break 107, 3 flutes, 38 N beside 126 and 185). Either stops the
            // machine: the output latches now, and the records after name the cause as
            // they name a drop trip's (the next window empty too: a lost tool; its gain:
            // a breakage).
            Self::pend(
                st,
                back0 - f0,
                (1.0 - GONE_SHARE) * back0,
                rec.end_sample,
                TRIP_NAMED_WITHIN + 1,
            );
        }

        probe.mark(Stage::AlarmToolGone);

        // --- overload -----------------------------------------------------------------
        if let (true, Some(mean)) = (self.cfg.overload.enabled, rev_mean) {
            let o = &self.cfg.overload;
            // Recomputed when the feed moved by 1 % (the cache starts as NaN: recompute).
            let cached = libm::fabsf(rec.tc_mm - st.limit_tc_mm) <= 0.01 * rec.tc_mm;
            if !cached {
                st.limit_tc_mm = rec.tc_mm;
                st.limit_n = crate::fmath::min(
                    self.model_signal(o.max_rr, o.max_ra, rec.tc_mm),
                    o.force_limit_n,
                );
            }
            if mean > st.limit_n {
                st.overload_run = st.overload_run.saturating_add(1);
                if st.overload_run >= o.debounce_teeth {
                    raise(Cause::Overload, mean, st.limit_n);
                }
            } else {
                st.overload_run = 0;
            }
        }

        probe.mark(Stage::AlarmOverload);

        // --- teach-in -----------------------------------------------------------------
        // Teeth since the cut began, as `EnvelopeRecorder::finish` aligns them: from the
        // first tooth whose revolution mean reaches the envelope's start, every tooth; a
        // revolution of air ends the cut (a tooth that dips under the not-cutting floor
        // does not restart it).
        if rec.status.contains(Status::NOT_CUTTING) {
            st.air_teeth = st.air_teeth.saturating_add(1);
            if st.air_teeth as usize >= n {
                st.cut_teeth = 0;
            }
        } else {
            st.air_teeth = 0;
        }
        // With an envelope, the cut's count starts where it reaches the envelope's start.
        let started = match (&self.cfg.teach.envelope, rev_mean) {
            (Some(env), Some(m)) => m >= env.start_n,
            (Some(_), None) => false,
            (None, _) => !rec.status.contains(Status::NOT_CUTTING),
        };
        if st.cut_teeth > 0 || started {
            st.cut_teeth = st.cut_teeth.saturating_add(1);
        }
        if let (Some(env), Some(mean), true) =
            (&self.cfg.teach.envelope, rev_mean, st.cut_teeth > 0)
        {
            let bin = (st.cut_teeth as usize / n.max(1)) / env.revs_per_bin.max(1) as usize;
            if bin < env.len as usize {
                // The band of this bin and its neighbours: where the cut is seen to begin
                // moves by a tooth or two with the noise, and in a fast entry a bin's worth
                // of shift is a large change of force (a time tolerance, as commercial
                // teach-in monitors have).
                let (mut lo, mut hi) = (f32::INFINITY, 0.0f32);
                for k in bin.saturating_sub(1)..=(bin + 1).min(env.len as usize - 1) {
                    lo = crate::fmath::min(lo, env.lo_n.get(k).copied().unwrap_or(0.0));
                    hi = crate::fmath::max(hi, env.hi_n.get(k).copied().unwrap_or(f32::INFINITY));
                }
                let tol = self.cfg.teach.tolerance_rel;
                let (lo, hi) = (lo * (1.0 - tol), hi * (1.0 + tol));
                if mean < lo || mean > hi {
                    st.teach_run = st.teach_run.saturating_add(1);
                    if st.teach_run >= self.cfg.teach.debounce_teeth {
                        raise(Cause::TeachExcursion, mean, if mean > hi { hi } else { lo });
                    }
                } else {
                    st.teach_run = 0;
                }
            }
        }

        probe.mark(Stage::AlarmTeach);
        let mut raised = raised_cell.get();

        // --- wear (EWRLS, one parameter) --------------------------------------------
        // Value and threshold of a wear warning raised by this record.
        let mut wear_event = None;
        // Wear is slow: one update per revolution is plenty and keeps eq. 7 off most teeth.
        // Against the estimate, only a valid one; against a known engagement, any settled
        // steady cut (an estimate flagged for the feed range or a clamp is irrelevant there).
        let usable = match self.cfg.drift.reference {
            DriftReference::Estimated => rec.status.is_valid(),
            DriftReference::Known { .. } => !rec.status.intersects(NO_WEAR_UPDATE),
        };
        if self.cfg.drift.enabled && usable && rec.tooth == 0 {
            let phi = match (self.cfg.drift.reference, model_n) {
                // The estimator's eq. 7 at this very estimate: no second evaluation.
                (DriftReference::Estimated, Some([fx, ft])) => self.signal(fx, ft).abs(),
                (DriftReference::Estimated, None) => {
                    self.model_signal(rec.rr, rec.ra, rec.tc_filt_mm)
                }
                (DriftReference::Known { rr, ra }, _) => self.model_signal(rr, ra, rec.tc_filt_mm),
            };
            let y = self.signal(rec.fx_filt_n, rec.f2_filt_n).abs();
            if phi > 0.0 && phi.is_finite() && y.is_finite() {
                // Regressor scaled to order one so that P stays well conditioned in f32.
                let (x, z) = (1.0, y / phi);
                let lambda = self.cfg.drift.lambda;
                let gain = st.p * x / (lambda + x * x * st.p);
                st.theta += gain * (z - x * st.theta);
                st.p = (st.p - gain * x * st.p) / lambda;
            }
            let warn = st.theta > self.cfg.drift.warn_multiplier;
            if warn && !st.wear_warned {
                wear_event = Some((st.theta, self.cfg.drift.warn_multiplier));
            }
            st.wear_warned = warn;
        }

        probe.mark(Stage::AlarmWear);

        // Built by one struct expression, straight into the caller's place (an
        // `AlarmOutput` is 96 bytes: built in a local and returned, it is copied by a
        // `memcpy` call).
        // A drop trip inside a period latched the output; its cause is named by the rules
        // on the records after it, else on the last of TRIP_NAMED_WITHIN: a lost tool when
        // the two newest teeth collapsed, or the newest did and the two together (the
        // drives swing as the load goes at once: seed 8473 gone 29, 3 flutes, the tooth
        // before the newest at 30.4 % of its force through the feed drive's swing, the
        // two at 12 %), a breakage otherwise (a lost flute's chip goes to the next tooth).
        let mut latched_sample = rec.end_sample;
        if let Some(trip) = st.trip.take() {
            latched_sample = trip.sample;
            if raised.is_none() {
                if trip.left > 1 {
                    st.trip = Some(Trip {
                        left: trip.left - 1,
                        ..trip
                    });
                } else if pair_collapsed {
                    raised = Some((Cause::ToolGone, f, self.est.force_floor_n));
                } else {
                    raised = Some((Cause::Breakage, trip.lost_n, trip.limit_n));
                }
            }
        }
        if raised.is_none() && wear_event.is_none() {
            return AlarmOutput {
                event: None,
                latched: st.latched.is_some() || st.trip.is_some(),
                wear: st.theta,
                wear_warning: st.wear_warned,
            };
        }
        Self::output_with_event(st, rec, raised, wear_event, latched_sample)
    }

    /// The drop trip passed inside the open period (see [`crate::handover`]) at `sample`:
    /// `lost` of the tooth's force one revolution earlier against `limit` [N]. Latches the
    /// output; the records after it name the cause (see `process`), and the event keeps
    /// `sample` as its [`AlarmEvent::latched_sample`].
    #[cold]
    #[inline(never)]
    pub fn trip(&self, st: &mut AlarmState, lost: f32, limit: f32, sample: u64) {
        Self::pend(st, lost, limit, sample, TRIP_NAMED_WITHIN);
    }

    /// Latches the output at `sample` unless it is already, its cause named on the
    /// `left` records from this one on (a trip's: those after it).
    #[cold]
    #[inline(never)]
    fn pend(st: &mut AlarmState, lost: f32, limit: f32, sample: u64, left: u8) {
        if st.latched.is_none() && st.trip.is_none() {
            st.trip = Some(Trip {
                lost_n: lost,
                limit_n: limit,
                left,
                sample,
            });
        }
    }

    /// The output of a record that raised an alarm or the wear warning (rare: out of the
    /// way of the common path).
    #[cold]
    #[inline(never)]
    fn output_with_event(
        st: &mut AlarmState,
        rec: &ToothRecord,
        raised: Option<(Cause, f32, f32)>,
        wear_event: Option<(f32, f32)>,
        latched_sample: u64,
    ) -> AlarmOutput {
        let event = match (st.latched.is_none(), raised, wear_event) {
            (true, Some((cause, value, threshold)), _) => {
                let e = AlarmEvent {
                    cause,
                    value,
                    threshold,
                    record: *rec,
                    latched_sample,
                };
                st.latched = Some(e);
                Some(e)
            }
            (_, _, Some((value, threshold))) => Some(AlarmEvent {
                cause: Cause::Wear,
                value,
                threshold,
                record: *rec,
                latched_sample: rec.end_sample,
            }),
            _ => None,
        };
        AlarmOutput {
            event,
            latched: st.latched.is_some(),
            wear: st.theta,
            wear_warning: st.wear_warned,
        }
    }

    /// `(mean of the newest revolution, newest revolution mean minus the one before)` of
    /// the watched force: the first when the last `N` teeth are armed, the second when the
    /// last `2N` are. Sums in the order of the definitions: `sum_k F_k` from -0 (`Sum`),
    /// `sum_k (F_k - F_{k+N})` from 0, `k` newest first.
    #[inline(always)]
    fn revolution_means(&self, st: &AlarmState) -> (Option<f32>, Option<f32>) {
        let n = self.n;
        let inv = n as f32;
        if st.armed & self.armed_two_revs == self.armed_two_revs {
            let (mut sum, mut d) = (-0.0f32, 0.0f32);
            let (mut i, mut j) = (st.slot(0), st.slot(n));
            for _ in 0..n {
                let a = st.hist_f.get(i).copied().unwrap_or(0.0);
                let b = st.hist_f.get(j).copied().unwrap_or(0.0);
                sum += a;
                d += a - b;
                i = i.wrapping_sub(1) & (HISTORY - 1);
                j = j.wrapping_sub(1) & (HISTORY - 1);
            }
            (Some(sum / inv), Some(d / inv))
        } else if st.armed & self.armed_rev == self.armed_rev {
            let mut sum = -0.0f32;
            let mut i = st.slot(0);
            for _ in 0..n {
                sum += st.hist_f.get(i).copied().unwrap_or(0.0);
                i = i.wrapping_sub(1) & (HISTORY - 1);
            }
            (Some(sum / inv), None)
        } else {
            (None, None)
        }
    }

    /// The cut spans more than a pitch (`exit_wide`, from the last valid estimate; without
    /// one, the window's bins show no quiet stretch, `span_share` over
    /// [`SPAN_SHARE`]) with 3 flutes or more: a flute's cut begins in the window
    /// before its own, and a loss there may be a broken flute's next pass rather than an
    /// exit's first tooth.
    #[inline(always)]
    fn spans_windows(&self, st: &AlarmState) -> bool {
        self.n >= 3 && (st.exit_wide > 0.0 || st.held.is_none() && st.span_share > SPAN_SHARE)
    }

    /// The plain trip's loss of the newest teeth in sigma_R (`var_r`, `sigma_r`): 0 where
    /// no run of them lost ([`Alarms::no_recent_loss`] at [`TRIP_QUIET_SIGMAS`]); else the
    /// most any run of the newest `j <= N` teeth lost (`-S_j`, the newest tooth in it
    /// though a wide cut's test leaves it out). An exit may be under way: `trip_share`
    /// takes that run's loss as the newest tooth's, the exit's reach then the newest's
    /// travel for it and the noise, and asks as much more as the next tooth's chip can
    /// take. A run's sum, not its newest tooth: an exit's windows need not lose in order
    /// (seeds 8770 normal 2 and 8783 normal 7 lost 24-29 %, then 21-22 %, then 54-57 %;
    /// their sum asks about 0.9). Before, such a run left the trip unarmed, and a flute
    /// broken after two teeth that lost to noise waited for its next flute's gain (seed
    /// 12791 break 118: 3 flutes at `R_r` 1.49, the newest two -54 and -33 N measured,
    /// -29 and +19 in the truth, then the broken flute's window 95 % down, 1.35
    /// revolutions late). `None` without a tooth armed with its own a revolution earlier.
    #[inline(always)]
    fn recent_loss(&self, st: &AlarmState, var_r: f32, sigma_r: f32) -> Option<f32> {
        if self.no_recent_loss(st, TRIP_QUIET_SIGMAS * TRIP_QUIET_SIGMAS * var_r) {
            return Some(0.0);
        }
        self.run_loss_sigmas(st, sigma_r)
    }

    /// ... the largest `-S_j` over the newest `j <= N` armed teeth, in `sigma_r`.
    #[cold]
    #[inline(never)]
    fn run_loss_sigmas(&self, st: &AlarmState, sigma_r: f32) -> Option<f32> {
        let n = self.n;
        let pairs = ((!st.armed).trailing_zeros() as usize)
            .saturating_sub(n)
            .min(n);
        let (mut sum, mut worst) = (0.0f32, 0.0f32);
        for j in 0..pairs {
            sum += st.force(j) - st.force(j + n);
            worst = crate::fmath::max(worst, -sum);
        }
        (pairs > 0).then_some(worst / sigma_r)
    }

    /// Whether no run of the newest teeth lost force from one revolution earlier: every
    /// sum `S_j` of `R_k = F_k - F_{k+N}` over the newest `j <= N` teeth above
    /// `-sqrt(j var)` (`var`: the bound's square for one tooth). An exit's teeth all lose,
    /// the newest most; a broken flute's loss is followed by the next flute's gain. Only
    /// teeth armed with their own a revolution earlier count; false if there is none.
    /// Where the cut spans more than a pitch (3 flutes or more, the newest two armed) the
    /// newest tooth is left out: a flute's cut begins in the window before its own, where
    /// a broken flute's next pass loses first (seed 9527 break 33), and `trip_share` covers
    /// the exit that its loss would show. Where a run lost, the plain trip asks what the
    /// exit that took the run's loss takes ([`Alarms::recent_loss`]).
    #[inline(never)]
    fn no_recent_loss(&self, st: &AlarmState, var: f32) -> bool {
        let skip = (self.spans_windows(st) && st.all_armed(self.armed_e)) as usize;
        // Newest teeth armed in a row, less a revolution: those that have a partner.
        let run = (!st.armed).trailing_zeros() as usize;
        let pairs = run.saturating_sub(self.n).min(self.n).saturating_sub(skip);
        let (mut i, mut k) = (st.slot(skip), st.slot(self.n + skip));
        let mut sum = 0.0f32;
        for j in 1..=pairs {
            sum +=
                st.hist_f.get(i).copied().unwrap_or(0.0) - st.hist_f.get(k).copied().unwrap_or(0.0);
            #[allow(clippy::neg_cmp_op_on_partial_ord)]
            if !(sum >= 0.0 || sum * sum <= j as f32 * var) {
                return false;
            }
            i = i.wrapping_sub(1) & (HISTORY - 1);
            k = k.wrapping_sub(1) & (HISTORY - 1);
        }
        pairs > 0
    }

    /// The drop trip's share for the next period and the share its whole period is asked
    /// at the close, `None` where it is not armed: what the
    /// next period of an exit through a face, its first tooth's loss hidden in the noise,
    /// could lose, that is the exit's loss at a travel of two feeds per tooth past the
    /// arc's far reach ([`crate::geometry::exit_loss_share`], at the last valid `R_r`;
    /// without one, the worst `R_r`), or the next flute's chip (a feed; more for a flute
    /// heavier than the revolution's mean) past what the newest tooth's loss allows
    /// (its loss, 0 for a gain, and `TRIP_QUIET_SIGMAS` of its own noise for the plain
    /// trip, 3 + 3 sigma_R where that tooth's change is not armed, the newest run's loss
    /// `run_lost` [sigma_R] where that is more; the bound it was checked
    /// against, 2 + 3 after a hand-over's evidence; where it lost past the bound (in a wide
    /// cut, the window before the handed tooth's, or any window for the plain trip): the
    /// exit it shows may be past the two feeds, and is as far as that loss
    /// tells, not a feed at most; none after a strong
    /// pair, which does not check it), plus `TRIP_NOISE_SIGMAS sigma_R` of the next
    /// tooth's force one revolution earlier (`sigma_t`, the trip channel's, where it is
    /// measured and narrower); at least [`TRIP_SHARE`], at most
    /// [`TRIP_MAX_SHARE`]. At the close (`f32::INFINITY`: not judged whole): the plain
    /// trip asks its noise term at the wider of `sigma_R` and `sigma_t` (the trip
    /// channel's noise on the resultant's scale); the evidence trip the same share on a
    /// cut wider than a pitch (`exit_wide`), and within one it is not judged whole. After
    /// a hand-over's `evidence`, at least [`EVIDENCE_SHARE`] and
    /// no noise term: the pair is already rare by noise (about once in 10 000 teeth), and
    /// the exit's loss over the period is its mean over the travel, under the loss at the
    /// period's end (seeds 417, 489, 537 and 627, normal cases: a pair in the noise, then
    /// an exit whose first period lost 30-37 % against a trip at 0.3). With the noise term
    /// too, 12 more breaks of 5 760 at seeds 1-48 went past their revolution, 1 without.
    /// The exit's share (and the cut's span past a pitch) is kept until the feed moves by
    /// 1 % or `R_r` by 0.01 (two square roots and an `acosf` saved on most teeth).
    #[inline(never)]
    fn trip_share(
        &self,
        st: &mut AlarmState,
        tc_mm: f32,
        sigma_r: f32,
        sigma_t: f32,
        evidence: Option<usize>,
        run_lost: f32,
    ) -> Option<(f32, f32)> {
        // (-1: no valid `R_r`, the worst one.)
        let rr = st.held.map_or(-1.0, |(rr, _)| rr);
        let (key_tc, key_rr) = st.exit_key;
        let kept = libm::fabsf(tc_mm - key_tc) <= 0.01 * tc_mm && libm::fabsf(rr - key_rr) <= 0.01;
        if !kept {
            let x = 2.0 * tc_mm / self.est.tool.radius_mm;
            st.exit_share = if rr < 0.0 {
                crate::geometry::widest_exit_loss_share(x)
            } else {
                crate::geometry::exit_loss_share(rr, x)
            };
            st.exit_key = (tc_mm, rr);
            // Where a cut's span, its arc and the helix's lag over the depth (`R_a tan
            // beta`), is wider than a pitch, each window holds the end of one flute's cut
            // and the start of the next one's, a feed further on: about this share of it.
            let ra = st.held.map_or(0.0, |(_, ra)| ra);
            let rr_arc = crate::fmath::min(crate::fmath::max(rr, 0.0), crate::geometry::RR_MAX);
            let span = crate::geometry::engaged_arc_rad(rr_arc) + ra * self.tan_helix;
            let wide = (span - self.est.tool.tooth_pitch_rad()) / span;
            st.exit_wide = crate::fmath::min(crate::fmath::max(wide, 0.0), 1.0);
        }
        let lost = (st.force(self.n) - st.force(0)) / sigma_r;
        // The next period's tooth a revolution ago: the noise terms are shares of it.
        let before = st.force(self.n - 1);
        let (least, noise, noise_t, checked, under_way) = if evidence.is_some() {
            let under_way = !st.handed_strong && lost > EVIDENCE_KEPT_SIGMAS;
            // (The newest tooth's own loss, 0 for a gain, as the plain trip takes it, not
            // the bound `kept` checked it against: an exit under way took at most that and
            // its noise. With the bound, 2 sigma_R more, the reach of a 4-flute cut at
            // `R_r` 1.6 was 0.46 against 0.42, and the broken flute's first whole window
            // lost 0.457: seed 11755 break 118, 1.16 revolutions late. Without its own
            // change, after a move: the bound.)
            let own = if st.all_armed(self.armed_e) {
                crate::fmath::max(lost, 0.0)
            } else {
                EVIDENCE_KEPT_SIGMAS
            };
            let checked = (!st.handed_strong).then_some(own);
            // (With an exit possibly under way the share is that exit's reach, which the
            // period's loss passes by its noise alone: seed 11206 taught 16, 3 flutes at
            // `R_r` 1.26, a noise pair of 4.9 sigma_R, then an exit's first tooth down 22
            // %; the handed tooth's period lost 44 % in the truth, 57 % measured, against a
            // reach of 0.47.)
            let noise = if under_way {
                EVIDENCE_UNDER_WAY_SIGMAS * sigma_r / before
            } else if st.held.is_some()
                && st.exit_wide <= EVIDENCE_NOISY_WIDE
                && before >= EVIDENCE_NOISY_KEPT * st.force(2 * self.n - 1)
            {
                EVIDENCE_NOISY_SIGMAS * sigma_r / before
            } else {
                0.0
            };
            (EVIDENCE_SHARE, noise, noise, checked, under_way)
        } else {
            // (Its own loss: the walk's bound on it, 3 sigma_R, and the noise again on top
            // put an exit 6 sigma_R of its force on, a share 0.02-0.04 higher at 4 flutes
            // in wide arcs, where breaks lost 55-63 %: seeds 9231 break 118, 9246 break
            // 48. Without its own change, after a move: the bound.)
            let lost = crate::fmath::max(
                if st.all_armed(self.armed_e) {
                    lost
                } else {
                    TRIP_QUIET_SIGMAS
                },
                run_lost,
            );
            // The next period's tooth handed over a revolution ago (its hand-over shows
            // in the record after its own, `N - 2` back); or, where the cut spans more
            // than a pitch, the tooth after it (`N - 3` back): the broken flute's next cut
            // begins in the window before the handed tooth's, as for the evidence's
            // `before_handed` (seeds 13467 break 88 and 13542 break 14, 4 flutes at `R_r`
            // 1.55-1.57, the second with no estimate: that window lost 0.54 and 0.58 of
            // its force in the truth against an exit's reach of 0.42 and 4 sigma_R, 0.21
            // and 0.16 of it).
            let handed_at = |back: usize| st.handed_z >> back & 1 != 0;
            let handed = self.n >= 2 && handed_at(self.n - 2)
                || self.n >= 3
                    && handed_at(self.n - 3)
                    && (st.exit_wide > 0.0 || rr < 0.0 && self.spans_windows(st));
            let sigmas = if handed {
                HANDED_NOISE_SIGMAS
            } else {
                TRIP_NOISE_SIGMAS
            };
            (
                TRIP_SHARE,
                // Inside the period, the trip channel's own noise where it is measured and
                // the narrower, the feed force's noise being most of the resultant's (seeds
                // 12421 break 6, 12465 break 119 and 12488 break 82 within a revolution with
                // it). Where it is the wider only the close asks it: inside too, seed 12276
                // break 107 was missed, its period 0.77 down against 0.80.
                sigmas
                    * if sigma_t > 0.0 && sigma_t < sigma_r {
                        sigma_t
                    } else {
                        sigma_r
                    }
                    / before,
                sigmas * sigma_t / before,
                Some(crate::fmath::max(lost, 0.0)),
                lost > TRIP_QUIET_SIGMAS,
            )
        };
        // (An exit the newest tooth shows may be past the two feeds.)
        let mut exit = if under_way || evidence.is_some_and(|k| k > 0) {
            1.0
        } else {
            st.exit_share
        };
        // Without an estimate, where the window's bins show a cut wider than a pitch
        // (`spans_windows`), the exit is bounded as for the widest arcs: over `R_r` from 1
        // to 2, the travel that takes a share and the share a travel takes are largest at
        // the ends and at `1 + q` (`geometry::widest_exit_loss_share`).
        let unknown_wide = rr < 0.0 && self.spans_windows(st);
        if let Some(bound) = checked
            .filter(|_| (rr >= 0.0 || unknown_wide) && (evidence.is_some() || exit + noise > least))
        {
            // The newest tooth lost `bound` sigma_R (its own loss for the plain trip, the
            // bound `kept` checked after a pair): an exit already under way took at most
            // that and its noise of its force, so it has travelled at most as far as takes
            // that share, and one feed more by the next period's end.
            let hidden = (bound + TRIP_QUIET_SIGMAS) * sigma_r / st.force(self.n);
            let feed = tc_mm / self.est.tool.radius_mm;
            let travel = crate::geometry::exit_travel(
                if unknown_wide {
                    crate::geometry::RR_MAX
                } else {
                    rr
                },
                hidden,
            );
            let x = if under_way {
                travel
            } else {
                crate::fmath::min(travel, feed * (1 + evidence.unwrap_or(0)) as f32)
            };
            // The next flute reaches past the newest one's by its own chip, `f_t + r_next -
            // r_newest` under runout: a heavy flute's is thicker, by about its force over
            // the revolution's mean (less the edge force's share; seed 1900 normal 32: the
            // heaviest of 4 flutes, 18 % over the mean, lost 55 % at an exit's first
            // period, past the trip's share at a feed).
            let mean = st.hist_rev.get(st.slot(0)).copied().unwrap_or(0.0);
            let ahead = if before > mean && mean > 0.0 {
                before / mean
            } else {
                1.0
            };
            let wide = if unknown_wide { 1.0 } else { st.exit_wide };
            let next_x = x + feed * (ahead + wide);
            let reach = if unknown_wide {
                crate::geometry::widest_exit_loss_share(next_x)
            } else {
                crate::geometry::exit_loss_share(rr, next_x)
            };
            // (After a pair, that reach whatever the two-feed exit: where that is under
            // EVIDENCE_SHARE, a heavy flute's chip reaching further was cut back to it.
            // Seed 3804 normal 11: a noise pair, then an exit; the handed tooth, 17 % over
            // the revolution's mean, lost 30 % against 0.30; its reach asks 0.32.) Without
            // an estimate the widest arcs' two-feed exit already bounds every reach of an
            // exit not under way (its next flute's chip under two feeds): the bound comes in
            // only where the exit may be past that (seeds 12225-12608 with it in everywhere:
            // 4-6 chips a block of 96 seeds later than a revolution that were not).
            exit = if evidence.is_some() && !unknown_wide {
                reach
            } else {
                crate::fmath::min(exit, reach)
            };
        }
        let need = crate::fmath::max(exit + noise, least);
        // Within a pitch the window holds the whole cut, and a broken flute's next pass
        // loses from its first angles, past the share well before the period ends; a loss
        // that passes it only whole, at the close, lies at the cut's far end, an
        // up-milling exit's first period. After evidence that is not judged at all (seed
        // 5435 normal 51: 2 flutes, a noise pair, then the exit's first period lost 29 %
        // against 0.32); the plain trip asks it past the trip channel's noise too (seed
        // 8808 normal 14). Wider, the next flute's cut reaches into the window, and the
        // close catches breaks at the share (seeds 14 break 61 and 85 break 108, 4 flutes
        // at `R_r` 1.58), the plain trip's past that channel's noise as well (seed 9690
        // taught 7: 3 flutes, an exit's first tooth lost 5.5 sigma_R, the next window's
        // period 0.507 of its force against a reach of 0.41 and 0.5: the trip channel's
        // sigma 0.033 of it, the resultant's 0.024).
        let whole = if evidence.is_some() && st.exit_wide <= 0.0 {
            f32::INFINITY
        } else {
            crate::fmath::max(exit + crate::fmath::max(noise, noise_t), least)
        };
        (need <= TRIP_MAX_SHARE).then_some((need, whole))
    }

    /// A hand-over pair (`gain`, `loss`: positive, of the watched force) that raises a
    /// breakage at once: together past [`PAIR_RAISE_SIGMAS`] of `R`, each past
    /// [`PAIR_EACH_SIGMAS`], and past the engagement's threshold `k F_expected`
    /// (`measured`, the revolution mean, without an estimate). The threshold if it raises.
    #[inline(always)]
    fn pair_raises(
        &self,
        st: &AlarmState,
        rec: &ToothRecord,
        (gain, loss): (f32, f32),
        (var, measured): (f32, f32),
    ) -> Option<f32> {
        let sigma_r = libm::sqrtf(0.5 * var);
        let each = PAIR_EACH_SIGMAS * sigma_r;
        if !(gain > each && loss > each && gain + loss > PAIR_RAISE_SIGMAS * sigma_r) {
            return None;
        }
        let expected = self.expected_signal(st.held, rec.tc_mm, measured);
        let t = crate::fmath::max(
            self.cfg.breakage.threshold_rel * expected,
            PAIR_RAISE_SIGMAS * sigma_r,
        );
        (gain + loss > t).then_some(t)
    }

    /// Whether the tooth before the newest lost force from one revolution earlier and the
    /// newest gained (`r0`), together by more than [`EVIDENCE_SIGMAS`] of `R` (or
    /// [`EVIDENCE_FLAGGED_SIGMAS`] unless `loss_steady`, the loss's record unflagged), the
    /// loss (and after a flagged loss the gain) by [`EVIDENCE_EACH_SIGMAS`] (`var`: E's
    /// variance before this tooth's `E` widens it): a flute that broke inside its period, its loss and the next flute's gain under the
    /// thresholds. The gain need only be one: where the arcs overlap, the next flute's
    /// gain spreads over two periods, and an exit's next tooth loses more, never gains; but
    /// it must stand above the loss an exit's share would take from it
    /// ([`EVIDENCE_EXIT_SIGMAS`], `above_exit_of`), which on a light flute hides in
    /// the noise. The pair must stand against two revolutions earlier too
    /// ([`EVIDENCE_BACK_SIGMAS`]). Squares: no root.
    #[inline(always)]
    fn handed_over(&self, st: &AlarmState, r0: f32, var: f32, loss_steady: bool) -> bool {
        let var_r = 0.5 * var;
        let r1 = st.force(1) - st.force(self.n + 1);
        // Where the tooth before the loss lost too (its period before it, against a
        // revolution earlier), the gain takes at least half of both losses: a flute broken
        // in the window before, its cut going on into the loss's (arcs wider than a pitch),
        // hands both to the next flute; an exit takes from every tooth, the earliest the
        // least, and hands nothing. (Seed 908 normal 79: an exit's first teeth lost about
        // 2.7 and 5.4 sigma_R, a light flute after them gained 1.4 by noise: a strong pair,
        // and the trip armed at 0.3 on the first tooth's window passed. Seed 94 break 119:
        // the break's windows lost 61 and 126 N, the next gained 165. NaN: no evidence.)
        let r2 = st.force(2) - st.force(self.n + 2);
        let held = EVIDENCE_BEFORE_SIGMAS * EVIDENCE_BEFORE_SIGMAS * var_r;
        let before_lost = !(r2 >= 0.0 || r2 * r2 <= held);
        let each = EVIDENCE_EACH_SIGMAS * EVIDENCE_EACH_SIGMAS * var_r;
        let both = r0 - r1;
        let sigmas = if loss_steady {
            EVIDENCE_SIGMAS
        } else {
            EVIDENCE_FLAGGED_SIGMAS
        };
        r0 > 0.0
            && r1 < 0.0
            && r1 * r1 > each
            && (loss_steady || r0 * r0 > each)
            && (!before_lost || r0 > -0.5 * (r1 + r2))
            && both * both > sigmas * sigmas * var_r
            && above_exit_of(r0, r1, (st.force(self.n + 1), st.force(self.n)), var_r)
            && self.stands_two_back(st, var_r)
    }

    /// In the first revolution after a moved window, where the alarm's history crosses
    /// the move: a hand-over seen on the hand-over stage's re-cut profiles. The newest
    /// record gained from its profile, and the one before lost (as [`Self::handed_over`]'s
    /// pair, `recut_last_n`); or that one was the odd period, whose loss is unmeasured,
    /// and the gain alone passes [`EVIDENCE_SIGMAS`]: an exit never gains, and a flute
    /// broken in the odd period hands its chip to the next one's first period (seed 2459
    /// break 73, 4 flutes: 40 % up, then the broken flute's period armed at the plain
    /// share tripped a sample past its revolution). And on the record after that
    /// revolution, `recut_n` its change on the records (as a tangential change). `(value,
    /// threshold)` where it raises a breakage at once (`level`: the revolution mean where
    /// there is no estimate).
    #[cold]
    #[inline(never)]
    fn handed_after_move(
        &self,
        st: &mut AlarmState,
        rec: &ToothRecord,
        f: f32,
        (r1, recut_n): (f32, f32),
        (var_r, level): (f32, f32),
    ) -> Option<(f32, f32)> {
        // As a change of the watched force: the tangential change scaled by the record's
        // ratio (the chip's feed force changes with its tangential force).
        let r0 = if rec.f2_n > 0.0 {
            recut_n * f / rec.f2_n
        } else {
            f32::NAN
        };
        st.recut_last_n = r0;
        let odd = r1 == f32::NEG_INFINITY;
        let both = if odd { r0 } else { r0 - r1 };
        let each = EVIDENCE_EACH_SIGMAS * EVIDENCE_EACH_SIGMAS * var_r;
        // An exit's share of the gaining tooth, as `above_exit_of` takes it, against the
        // profiles (each tooth's force less its change); after the odd period, no loss.
        let then = if odd {
            (1.0, 0.0)
        } else {
            (st.force(1) - r1, f - r0)
        };
        let pair = r0 > 0.0
            && (odd || r1 < 0.0 && r1 * r1 > each)
            && both * both > EVIDENCE_SIGMAS * EVIDENCE_SIGMAS * var_r
            && above_exit_of(r0, if odd { 0.0 } else { r1 }, then, var_r);
        if pair && self.same_speed_across_move(st) {
            let n = self.n.max(1);
            st.handed = Some(((rec.tooth as usize + n - 1) % n) as u8);
            st.handed_loss_n = if odd { 0.0 } else { -r1 };
            // (Strong: the newest tooth's change a revolution back, which `kept` and the
            // share check for an exit begun after the pair, crosses the move.)
            st.handed_strong = true;
            st.handed_recut = true;
            // As `E` three times past its threshold it raises: the pair's change is the
            // first difference's, the gain alone after the odd period is `R`'s (its noise).
            let expected = self.expected_signal(st.held, rec.tc_mm, level);
            let var_e = if odd { var_r } else { 2.0 * var_r };
            let floor = E_SIGMAS * libm::sqrtf(var_e);
            let threshold = crate::fmath::max(self.cfg.breakage.threshold_rel * expected, floor);
            // After the odd period the gain alone raises as a first tooth does
            // (`first_tooth`): the teeth before the move were a steady cut (it is made
            // out of one), and the flute broken in the odd period left its whole chip to
            // this one (seed 5089 break 34: 52 % up, against three times the threshold).
            let first = crate::fmath::max(
                FIRST_TOOTH_SHARE * (f - r0),
                FIRST_TOOTH_SIGMAS * libm::sqrtf(var_r),
            );
            if odd && both > first {
                return Some((both, first));
            }
            return (both > SINGLE_EXCEEDANCE * threshold).then_some((both, threshold));
        }
        None
    }

    /// The plain trip's speed test: the newest revolution as long as the one before, or as
    /// the one before that (`same_speed`). A ramp moves every revolution's length the same
    /// way; after one, the tracked boundaries that a placed window follows swing by a few
    /// samples for some 20 pulses (the tracker's second-order settling) while the spindle
    /// turns steadily, and a revolution between two of one length is that swing (seed 11513
    /// break 89: 2 flutes, 12 pulses after a 14 % slowdown, revolutions of 406, 404 and 411
    /// samples; the heavy flute broke and its next pass, 90 % down, had no trip armed).
    /// With three revolutions armed only: a lost pulse's record says nothing of the speed.
    #[cold]
    #[inline(never)]
    fn steady_speed(&self, st: &AlarmState) -> bool {
        let n = self.n;
        self.same_speed(st, n, 1)
            || st.all_armed(ones(3 * n)) && self.lengths_within(st, 2 * n, n, 100)
    }

    /// `same_speed` for the periods since a moved window (`k` of them, the newest armed in
    /// a row): the newest `min(k, N)` as long as as many before the odd period, and as
    /// many a revolution before those. A window can move in the middle of a ramp, where the
    /// periods next to the odd one agree though the speed changes (seed 12813 normal 115:
    /// 2 flutes, the spindle 18 % slower over 10 teeth, 107 against 106 samples; the re-cut
    /// profiles, off by the ramp, passed as a hand-over's evidence, and the drop trip armed
    /// at 0.30 fired). Not one period against its tooth's: the ramp's periods alternate by
    /// more than it grows in a tooth (100, 99, 103, 101, 106 at another noise seed).
    #[cold]
    #[inline(never)]
    fn same_speed_across_move(&self, st: &AlarmState) -> bool {
        let n = self.n;
        let k = ((!st.armed).trailing_zeros() as usize).min(2 * n);
        let m = k.min(n);
        // (At most `4 N + 1` periods back: within the history for up to 15 flutes; at 16
        // the ring's newest are read, which agree only where the speed has held.)
        m > 0
            && self.lengths_within(st, k + 1, m, 100)
            && self.lengths_within(st, k + 1 + n, m, 100)
    }

    /// The hand-over's pair against two revolutions earlier: see [`EVIDENCE_BACK_SIGMAS`]
    /// (true where those teeth are not armed, after the history was forgotten).
    #[cold]
    #[inline(never)]
    fn stands_two_back(&self, st: &AlarmState, var_r: f32) -> bool {
        let back = 2 * self.n;
        if !st.all_armed(self.armed_two_back) {
            return true;
        }
        let both = (st.force(0) - st.force(back)) - (st.force(1) - st.force(back + 1));
        both > 0.0 && both * both > EVIDENCE_BACK_SIGMAS * EVIDENCE_BACK_SIGMAS * var_r
    }

    /// Whether the revolution before the loss (the tooth before the newest) fell against
    /// the revolution three earlier: its sum by more than [`EVIDENCE_FALL_SIGMAS`] of that
    /// difference's noise (`sqrt N sigma_R`; `var`: E's variance), or
    /// [`EVIDENCE_STEADY_FALL_SIGMAS`] where the loss's record is unflagged (`loss_steady`).
    /// An exit fades over revolutions (at seed 276, normal case 52, the sum fell 297 N, 4.7
    /// of it, before a flagged loss that passed as a hand-over; 1.8 against two revolutions
    /// earlier; at seed 1786 normal 30, 2 flutes, 138 N, 4.8 of it, before an unflagged
    /// pair of 4.6 sigma_R); a cut settling after its entry holds (seed 20 break case 0).
    /// False without the history (after a forget, over 15 flutes).
    #[cold]
    #[inline(never)]
    fn fell_before_loss(&self, st: &AlarmState, var: f32, loss_steady: bool) -> bool {
        let sigmas = if loss_steady {
            EVIDENCE_STEADY_FALL_SIGMAS
        } else {
            EVIDENCE_FALL_SIGMAS
        };
        st.all_armed(self.armed_held) && self.fell(st, var, 2, 1, sigmas)
    }

    /// Whether the `revs N` teeth from the `from`-th newest fell against the same teeth
    /// three revolutions earlier by more than `sigmas` of that difference's noise (`sqrt
    /// (revs N) sigma_R`; `var`: E's variance), from the stored revolution means. The
    /// caller checks the teeth are armed (to the `from + (revs + 3) N - 1`-th).
    #[inline(never)]
    fn fell(&self, st: &AlarmState, var: f32, from: usize, revs: usize, sigmas: f32) -> bool {
        let n = self.n;
        let mean = |k: usize| st.hist_rev.get(st.slot(k)).copied().unwrap_or(0.0);
        let fall = (0..revs)
            .map(|r| from + r * n)
            .map(|k| mean(k + 3 * n) - mean(k))
            .sum::<f32>()
            * n as f32;
        let teeth = (revs * n) as f32;
        fall > 0.0 && fall * fall > sigmas * sigmas * teeth * 0.5 * var
    }

    /// E's variance for the breakage thresholds and the drop trip, `None` before
    /// [`SETTLED_E_MIN`] values (and two revolutions'); scaled by `SETTLED_E / count` under
    /// [`SETTLED_E`]. Scaled up where the revolution mean `measured` is above the force the
    /// spread was learned at: part of the noise grows with the force (the encoder jitter
    /// moves a share of it between teeth), and a spread learned early in an entry would
    /// stay behind the force. (Not down: a cut that lightens keeps its sensor noise.)
    #[inline(never)]
    fn decision_var(&self, st: &AlarmState, measured: f32) -> Option<f32> {
        let m = st.e_count as usize;
        if m < (2 * self.n).max(SETTLED_E_MIN) {
            return None;
        }
        let m2 = measured * measured;
        let var = if m2 > st.e_force2 && st.e_force2 > 0.0 {
            st.e_var * (m2 / st.e_force2)
        } else {
            st.e_var
        };
        Some(if m < SETTLED_E {
            var * (SETTLED_E as f32 / m as f32)
        } else {
            var
        })
    }

    /// Whether the newest `revs` revolutions are as long as the `revs` from `back` teeth
    /// earlier, to 1 % and two samples (the pulses' jitter at their ends): the current
    /// loop's lag is a time, and its share of a period, which moves force across the
    /// window's boundaries, follows the speed. Over a speed ramp the force moves one way at
    /// each boundary, a little a revolution: past the threshold over several.
    #[inline(always)]
    fn same_speed(&self, st: &AlarmState, back: usize, revs: usize) -> bool {
        self.lengths_within(st, back, revs * self.n, 100)
    }

    /// ... the newest `teeth` as long as the `teeth` from `back` earlier, to `1 / per` and
    /// two samples.
    #[cold]
    #[inline(never)]
    fn lengths_within(&self, st: &AlarmState, back: usize, teeth: usize, per: u32) -> bool {
        let len = |from: usize| -> u32 {
            (from..from + teeth)
                .map(|k| st.hist_len.get(st.slot(k)).copied().unwrap_or(0) as u32)
                .sum()
        };
        let (now, then) = (len(0), len(back));
        now.abs_diff(then) <= now / per.max(1) + 2
    }

    /// Whether `E` passed its threshold (by `e_margin`; -INFINITY: `E` did not raise) by as
    /// much as the boundaries of its two teeth's newest periods may have moved (told by the
    /// hand-over stage in tangential force; `scale`: the watched signal's per newton of it).
    #[cold]
    #[inline(never)]
    fn past_moved<M: Fn(usize) -> f32 + ?Sized>(
        &self,
        e_margin: f32,
        scale: f32,
        moved: &M,
    ) -> bool {
        // (Asked too where `E` did not raise: -INFINITY passes nothing, and a guard costs
        // 16 B of flash on a rare path.)
        e_margin > (moved(0) + moved(1)) * libm::fabsf(scale)
    }

    /// Whether the newest two revolutions are as long as the two from
    /// `SPEED_SETTLED_TEETH` teeth earlier (whole revolutions; `same_speed`): the spindle's
    /// speed has not changed for as long as the window's tracked pulse interval takes to
    /// settle. Two revolutions against two, as far apart as that: a ramp shows in full,
    /// the pulses' jitter only at the four ends. Where a tooth of either pair is not armed
    /// (a lost pulse's or a moved window's odd period, flagged for its length), settled.
    #[cold]
    #[inline(never)]
    fn speed_settled(&self, st: &AlarmState) -> bool {
        let n = self.n.max(1);
        let back = SPEED_SETTLED_TEETH.next_multiple_of(n);
        let two = self.armed_two_revs;
        !st.all_armed(two | two << back)
            || self.lengths_within(st, back, 2 * self.n, SPEED_SETTLED_PER)
    }

    /// The redistribution against `back` teeth earlier (`span` 2: two revolutions' means,
    /// see `change_range`), past its screen on the newest tooth: `(spread, threshold)` where
    /// it is decided. `(k, measured, screen, e_var)`: the breakage rules' relative
    /// threshold, revolution-mean force, screen and E's variance. Out of line: most teeth
    /// stop at the screen.
    #[inline(never)]
    fn redistribution(
        &self,
        st: &AlarmState,
        tc_mm: f32,
        back: usize,
        span: usize,
        (k, measured, screen, e_var): (f32, f32, f32, f32),
    ) -> Option<(f32, f32)> {
        let n = self.n;
        let (r_max, r_min, r_sum) = self.change_range(st, back, span);
        let spread = crate::fmath::min(r_max, -r_min);
        let widen = 0.5 * libm::fabsf(r_sum / n as f32);
        // (NaN: not decided.)
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(spread > screen + widen) {
            return None;
        }
        let sigma_r = libm::sqrtf(0.5 * e_var / span as f32);
        let expected = self.expected_signal(st.held, tc_mm, measured);
        let t = crate::fmath::max(crate::fmath::max(k * expected, R_SIGMAS * sigma_r), screen);
        // With 2 flutes, against revolutions earlier, the two changes also as a hand-over
        // pair (as [`Alarms::pair_raises`] asks it, past [`PAIR_REVS_SIGMAS`] together,
        // whose noise is one change's over revolutions): a flute broken inside its cut loses
        // part of its window in one revolution and the rest in the next, and the other
        // flute gains the same way, so that no revolution's change stands out, nor each
        // of the two past the floor on its own (seed 10573 break 21: a light flute of 64
        // N beside one of 285 N under runout after a feed cut; `E` 52, 62 and 79 N
        // against 85-93 N, the changes over three revolutions -57 and +75 N against 59 N,
        // together 10 sigma_R). The gain on the newest tooth, the loss on the one before:
        // a flute's chip goes to the flute after it (seed 10632 gone 10: the tool lost
        // inside the newest tooth's window, 82 N down, after the other tooth's noise, 40 N
        // up, named a breakage).
        let pair = r_max - r_min;
        let pair_t = crate::fmath::max(k * expected, PAIR_REVS_SIGMAS * sigma_r);
        // With 3 flutes or more, on the two revolutions' means, the same hand-over pair:
        // the newest tooth's gain and the loss of the one before it, each past
        // `PAIR_EACH_SIGMAS` (the chip a broken flute leaves goes to the flute after it; a
        // loss two teeth before the gain is no hand-over). A light flute under runout
        // broken inside its cut, split over two revolutions as above, against two heavy
        // ones: seed 13076 break 107 at noise seed 3347570, 3 flutes of 37, 127 and 184 N,
        // its window 14.6 then 7.6 N, the next flute 36 N up, the threshold of `R` 36 N:
        // never decided. The pair on the means, 61 N against 60 N, caught it 1.51
        // revolutions after the first missed cut. (No false alarm in 576 seeds' blocks;
        // 18-33 more chippings detected a block, BENCHMARKS.md.) (The two changes again,
        // not returned by `change_range`'s walk: that cost 228 B of flash.)
        let means = |j: usize| {
            0.5 * (st.force(j) + st.force(j + n) - st.force(j + back) - st.force(j + back + n))
        };
        let (gain, loss) = (means(0), -means(1));
        let (v, t) = if spread > t + widen {
            (spread, t + widen)
        } else if n == 2
            && span == 1
            && back > n
            && spread > PAIR_EACH_SIGMAS * sigma_r
            && pair > pair_t + widen
            && st.force(0) > st.force(back)
        {
            (pair, pair_t + widen)
        } else if n >= 3
            && span == 2
            && crate::fmath::min(gain, loss) > PAIR_EACH_SIGMAS * sigma_r
            && gain + loss > pair_t + widen
        {
            (gain + loss, pair_t + widen)
        } else {
            return None;
        };
        // (Over the means, every revolution at the newest's speed: after a speed change the
        // current loop's lag keeps moving force between the teeth for revolutions, as the
        // flutes' chips settle.)
        let speed = || match span {
            1 => back == n || self.same_speed(st, back, 1),
            _ => (1..=MEANS_BACK_REVS + 1).all(|j| self.same_speed(st, j * n, 1)),
        };
        speed().then_some((v, t))
    }

    /// Largest and smallest change from `back` teeth earlier over the newest `N` teeth, and
    /// their sum: `F_k - F_{k+back}`, or for `span` 2 the tooth's mean over two
    /// revolutions, `(F_k + F_{k+N} - F_{k+back} - F_{k+back+N}) / 2` (the caller has the
    /// last `N + back + (span - 1) N` armed).
    ///
    /// For `span` 2 with 3 flutes or more the largest is also over two neighbouring teeth
    /// together (in time order within the newest `N`): where the arcs are wider than a
    /// pitch, the next flute's cut, which takes a broken flute's chip, spans two windows and
    /// its gain is split between them (seed 1543 break 101: 4 flutes, R_r 1.54, one window
    /// down 430 N, the next two up 230 and 200 N, each under the threshold of about 260 N,
    /// never decided in the 70 revolutions to the exit). Two revolutions' means: one
    /// period's encoder jitter is no such pair. Only with none of those two revolutions'
    /// records flagged transient: the pair's noise is `sqrt 2` of one tooth's against the
    /// same floor, and as a cut changes its shape its teeth's shares move in pairs too
    /// (seed 2101 normal 90: an exit's tail of 50 N a tooth, flagged, two teeth up 17 and
    /// 14 N against one down 33 N, 3.9 and 5.8 of their noise; at seed 1543 a steady cut,
    /// 3.4 and 5.8).
    #[inline(never)]
    fn change_range(&self, st: &AlarmState, back: usize, span: usize) -> (f32, f32, f32) {
        let (mut hi, mut lo, mut sum) = (f32::NEG_INFINITY, f32::INFINITY, 0.0f32);
        let at = |k: usize| st.hist_f.get(k & (HISTORY - 1)).copied().unwrap_or(0.0);
        let (mut i, mut j) = (st.slot(0), st.slot(back));
        let mut prev = f32::NEG_INFINITY;
        let pairs = span == 2 && self.n >= 3 && st.flagged(0, 2 * self.n) == 0;
        for _ in 0..self.n {
            let r = if span == 2 {
                0.5 * (at(i) + at(i.wrapping_sub(self.n)) - at(j) - at(j.wrapping_sub(self.n)))
            } else {
                at(i) - at(j)
            };
            if pairs {
                // (`prev` is -inf on the first tooth: no pair.)
                hi = crate::fmath::max(hi, r + prev);
                prev = r;
            }
            hi = crate::fmath::max(hi, r);
            lo = crate::fmath::min(lo, r);
            sum += r;
            i = i.wrapping_sub(1) & (HISTORY - 1);
            j = j.wrapping_sub(1) & (HISTORY - 1);
        }
        (hi, lo, sum)
    }

    /// `E_i = D_i - D_{i-N}` for the newest tooth, when all four teeth it needs are armed
    /// and the tooth indices line up.
    #[inline(always)]
    fn first_difference_change(&self, st: &AlarmState) -> Option<f32> {
        let n = self.n;
        let ok = st.armed & self.armed_e == self.armed_e
            && st.tooth(0) == st.tooth(n)
            && st.tooth(1) == st.tooth(n + 1);
        ok.then(|| (st.force(0) - st.force(1)) - (st.force(n) - st.force(n + 1)))
    }

    /// The first-tooth rules (module docs) for the newest tooth, whose change from one
    /// revolution earlier `r0` is beyond `FIRST_TOOTH_SHARE` of what it was (`before`);
    /// the caller has the last `2 N` teeth armed. Out of the common path: most teeth never
    /// get here.
    #[inline(never)]
    fn first_tooth(
        &self,
        st: &AlarmState,
        r0: f32,
        before: f32,
        prev_steady: bool,
        var: Option<f32>,
    ) -> Option<(f32, f32)> {
        // Both rules need a noise figure the rules may decide on.
        let var = var?;
        let n = self.n;
        let sigma_r = libm::sqrtf(0.5 * var);
        let t = crate::fmath::max(FIRST_TOOTH_SHARE * before, FIRST_TOOTH_SIGMAS * sigma_r);
        let quiet_bound = FIRST_TOOTH_QUIET_SIGMAS * sigma_r;
        // A tooth alone, only out of a steady cut: an entry, exit or other ramp (the
        // Monitor flags it transient) changes teeth by a share a revolution, noise on top.
        // The noise figure must be a good one (a few dozen teeth into the cut), and at
        // least FIRST_TOOTH_QUIET_TEETH teeth before it quiet (one tooth, with two flutes,
        // says little about a ramp beginning).
        let quiet_teeth = (n - 1).max(FIRST_TOOTH_QUIET_TEETH);
        let mask = ones(quiet_teeth + n + 1);
        // (Nor where the quiet teeth rose together: an entry, each tooth under the bound
        // but their sum past FIRST_TOOTH_TREND_SIGMAS of its noise. Seed 3279 wear 5 with
        // the boundary at the pulses' tracked times, a variant: 3 teeth up 1.3-2 sigma_R
        // each, then a flute's step into the cut, 6.1 sigma_R.)
        let trend = FIRST_TOOTH_TREND_SIGMAS * FIRST_TOOTH_TREND_SIGMAS * 0.5 * var;
        if prev_steady
            && st.armed & mask == mask
            && st.tooth(0) == st.tooth(n)
            && r0 > t
            && self
                .changes_within(st, 1, 1 + quiet_teeth, quiet_bound)
                .is_some_and(|sum| sum <= 0.0 || sum * sum <= trend * quiet_teeth as f32)
        {
            // The flute before broke after its engagement and this one took its chip.
            // A drop alone is not decided: the first tooth of an exit through a face
            // loses as much (the thickest chip, at the arc's far reach, leaves first).
            return Some((r0, t));
        }
        let r1 = st.force(1) - st.force(n + 1);
        // The hand-over: the tooth after a drop takes the lost chip (its force up by as much
        // as a first-tooth drop), the teeth before the drop unchanged. The drop itself may
        // have been partial (the flute broke inside its period); an engagement step moves
        // both teeth the same way.
        let handed = n >= 2
            && r0 > t
            && st.tooth(1) == st.tooth(n + 1)
            && r1 < -quiet_bound
            && self.quiet_from(st, 2, quiet_bound);
        handed.then_some((r0, t))
    }

    /// `|sum of R_k| / N` over the `N - 1` teeth before the newest, `R_k = F_k - F_{k+N}`
    /// their change from one revolution earlier, when every one of them is within
    /// `bound` (the newest tooth's change is then confined to it); `None` otherwise. The
    /// caller has the last `2 N` teeth armed.
    ///
    /// Why: the threshold widens by the revolution-mean growth (`common`) so that flutes
    /// of unequal chip growing at unequal rates (an entry with runout) do not alarm. At the
    /// first tooth of a breakage that growth is the breakage's own drop (or rise) over N:
    /// for 2 flutes half of it, and the first evidence tooth misses its exceedance. An
    /// engagement change that is under way shows in the teeth before (not confined), and
    /// the teeth after the first keep the full `common`: a step or a lost tool, which move
    /// every following tooth the same way, still needs its next tooth past a threshold
    /// widened by the whole change.
    #[inline(never)]
    fn confined_growth(&self, st: &AlarmState, bound: f32) -> Option<f32> {
        self.changes_within(st, 1, self.n, bound)
            .map(|sum| sum.abs() / self.n as f32)
    }

    /// Whether the changes from one revolution earlier of the teeth `from..N` back are all
    /// within `bound` (the caller has them and their predecessors armed).
    fn quiet_from(&self, st: &AlarmState, from: usize, bound: f32) -> bool {
        self.changes_within(st, from, self.n, bound).is_some()
    }

    /// The sum of `R_k = F_k - F_{k+N}` over the teeth `k` in `from..to` back when every
    /// one is within `bound`; `None` otherwise.
    #[inline(never)]
    fn changes_within(&self, st: &AlarmState, from: usize, to: usize, bound: f32) -> Option<f32> {
        let n = self.n;
        let mut sum = 0.0f32;
        let (mut i, mut j) = (st.slot(from), st.slot(n + from));
        for _ in from..to {
            let r =
                st.hist_f.get(i).copied().unwrap_or(0.0) - st.hist_f.get(j).copied().unwrap_or(0.0);
            #[allow(clippy::neg_cmp_op_on_partial_ord)]
            if !(r.abs() <= bound) {
                return None;
            }
            sum += r;
            i = i.wrapping_sub(1) & (HISTORY - 1);
            j = j.wrapping_sub(1) & (HISTORY - 1);
        }
        Some(sum)
    }

    /// A flute that carries too little in a cut that goes on: the least of the `N - 1`
    /// teeth before the newest below [`MISSING_SHARE`] of the mean of the newest `N`
    /// (armed), the mean a steady cut's (within [`STRONG_SHARE`] of the force before).
    /// Runout of 35 % leaves the weakest flute over 60 % of the mean; in a cut where
    /// windows hold one flute each, a lost flute leaves its period empty, but where the
    /// arcs are wider than a pitch its window keeps the end of the cut before it (a third
    /// of the mean at seed 30, break case 80; seed 118, case 62). The newest tooth is left
    /// out: empty alone it is the first of a lost tool (two empty in a row are
    /// `collapsed`, tool gone). Returns the least and the limit.
    #[cold]
    #[inline(never)]
    fn flute_missing(&self, st: &AlarmState, mean: f32) -> Option<(f32, f32)> {
        if !(mean >= STRONG_SHARE * st.steady_force_n && st.steady_force_n > 0.0) {
            return None;
        }
        let mut least = f32::INFINITY;
        for k in 1..self.n {
            least = crate::fmath::min(least, st.force(k));
        }
        let limit = MISSING_SHARE * mean;
        (least < limit).then_some((least, limit))
    }

    /// Whether `rec` is a force collapse right after a steady cut while feeding.
    ///
    /// The steady force is scaled by the feed's change since: a feed override turned down
    /// in one step to a tenth takes a light cut to the floor with the tool in place, so the
    /// force the feed alone leaves must stand clear of the floor. (Linear in `t_c`: the edge
    /// force keeps the real one above it, so this errs towards no alarm.)
    #[inline(never)]
    fn gone_candidate(&self, st: &AlarmState, rec: &ToothRecord, two_dead: bool) -> bool {
        // (`F t_c' > 3 floor t_c` for `t_c' = min(t_c now, t_c steady)`: no division.)
        (rec.status.contains(Status::NOT_CUTTING) || two_dead)
            && rec.tc_mm > 0.0
            && st.since_steady <= self.cfg.tool_gone.max_drop_revs as u32 * self.n as u32
            && st.live_since_steady <= GONE_LIVE_TEETH
            && st.steady_force_n * crate::fmath::min(rec.tc_mm, st.steady_tc_mm)
                > 3.0 * self.est.force_floor_n * st.steady_tc_mm
    }
}

/// Records a taught envelope from a good cut's records.
#[derive(Clone, Copy, Debug)]
pub struct EnvelopeRecorder {
    env: Envelope,
    teeth: u32,
    flutes: usize,
    window: [f32; MAX_FLUTES],
}

impl EnvelopeRecorder {
    /// A recorder for a tool of `flutes` flutes, `revs_per_bin` revolutions per bin.
    pub fn new(flutes: u8, revs_per_bin: u16) -> Self {
        EnvelopeRecorder {
            env: Envelope {
                revs_per_bin: revs_per_bin.max(1),
                len: 0,
                start_n: 0.0,
                lo_n: [f32::INFINITY; ENVELOPE_BINS],
                hi_n: [0.0; ENVELOPE_BINS],
            },
            teeth: 0,
            flutes: (flutes as usize).clamp(1, MAX_FLUTES),
            window: [0.0; MAX_FLUTES],
        }
    }

    /// Adds a record of the good cut (air before the cut is skipped; the same resultant
    /// revolution mean as the detector's).
    pub fn push(&mut self, rec: &ToothRecord) {
        if rec.status.contains(Status::NOT_CUTTING) && self.teeth == 0 {
            return;
        }
        let f = crate::fmath::hypot(rec.fx_n, rec.f2_n);
        if let Some(w) = self.window.get_mut(self.teeth as usize % self.flutes) {
            *w = if f.is_finite() { f } else { 0.0 };
        }
        self.teeth += 1;
        if (self.teeth as usize) < self.flutes {
            return;
        }
        let mean = self.window.iter().take(self.flutes).sum::<f32>() / self.flutes as f32;
        let bin = (self.teeth as usize / self.flutes) / self.env.revs_per_bin as usize;
        if let (Some(lo), Some(hi)) = (self.env.lo_n.get_mut(bin), self.env.hi_n.get_mut(bin)) {
            *lo = lo.min(mean);
            *hi = hi.max(mean);
            self.env.len = self.env.len.max(bin as u16 + 1);
        }
    }

    /// The envelope so far.
    /// The envelope, its bins from the one where the force first reached a quarter of
    /// its peak ([`Envelope::start_n`]).
    pub fn finish(&self) -> Envelope {
        let mut env = self.env;
        let len = env.len as usize;
        let peak = env.hi_n.iter().take(len).fold(0.0f32, |a, &b| a.max(b));
        env.start_n = START_SHARE * peak;
        let b0 = env
            .hi_n
            .iter()
            .take(len)
            .position(|&h| h >= env.start_n)
            .unwrap_or(0);
        env.lo_n.copy_within(b0..len, 0);
        env.hi_n.copy_within(b0..len, 0);
        env.len = (len - b0) as u16;
        env
    }
}

#[cfg(feature = "serde")]
mod serde_arrays {
    //! serde for `[f32; ENVELOPE_BINS]` (serde derives arrays only up to 32).
    use super::ENVELOPE_BINS;
    use serde::{de::Error, Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(a: &[f32; ENVELOPE_BINS], s: S) -> Result<S::Ok, S::Error> {
        a.as_slice().serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[f32; ENVELOPE_BINS], D::Error> {
        let v = heapless::Vec::<f32, ENVELOPE_BINS>::deserialize(d)?;
        let mut a = [0.0; ENVELOPE_BINS];
        a.get_mut(..v.len())
            .ok_or_else(|| D::Error::custom("too many bins"))?
            .copy_from_slice(&v);
        Ok(a)
    }
}

#[cfg(test)]
mod tests {
    //! The breakage rules on hand-made records (the integration tests in
    //! `tests/alarm.rs` run them on simulated cuts through the monitor).
    #![allow(clippy::unwrap_used)]
    extern crate std;
    use super::*;
    use std::vec::Vec;

    /// Tooth-average forces [N] of a steady cut of 4 flutes, flute 0 out by 30 %, with
    /// deterministic noise of `noise` N (uniform, +-sqrt(3) sigma), `revs` revolutions,
    /// then `after` (a per-tooth change from the steady level, tooth by tooth).
    fn forces(noise: f32, revs: usize, after: &[f32]) -> Vec<f32> {
        forces_at(RUNOUT_30, noise, revs, after)
    }

    /// The steady levels of `forces`: flute 0 out by 30 %.
    const RUNOUT_30: [f32; 4] = [130.0, 100.0, 100.0, 100.0];

    /// `forces` with the flutes' steady `levels` [N].
    fn forces_at(levels: [f32; 4], noise: f32, revs: usize, after: &[f32]) -> Vec<f32> {
        let mut x = 0x2545_f491u32;
        let mut rnd = || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            (x as f32 / u32::MAX as f32 - 0.5) * 2.0 * 1.732 * noise
        };
        let level = |k: usize| levels[k % 4];
        let mut out: Vec<f32> = (0..4 * revs).map(|k| level(k) + rnd()).collect();
        for (j, d) in after.iter().enumerate() {
            let k = 4 * revs + j;
            out.push(level(k) + d + rnd());
        }
        out
    }

    /// Record `i` of a 4-flute cut at 600 rpm, 250 samples a tooth, feed force `fx`.
    fn record(i: usize, fx: f32, status: Status) -> ToothRecord {
        ToothRecord {
            end_sample: 250 * (i as u64 + 1),
            tooth: (i % 4) as u8,
            samples: 250,
            rpm: 600.0,
            tc_mm: 0.2,
            fx_n: fx,
            f2_n: 0.0,
            status,
            ..ToothRecord::default()
        }
    }

    /// Feeds the forces as records (tooth in order, not a valid estimate: the threshold is
    /// on the measured revolution mean); the index of the first breakage, if any.
    fn first_breakage(f: &[f32]) -> Option<usize> {
        first_breakage_as(f, Status::TRANSIENT)
    }

    /// ... each record's status `status`.
    fn first_breakage_as(f: &[f32], status: Status) -> Option<usize> {
        let est = EstimatorConfig::default();
        let a = AlarmConfig::default().build(&est).unwrap();
        let mut st = AlarmState::default();
        for (i, &fx) in f.iter().enumerate() {
            let rec = record(i, fx, status);
            let out = a.process(&mut st, &rec);
            if out.event.is_some_and(|e| e.cause == Cause::Breakage) {
                return Some(i);
            }
        }
        None
    }

    /// A drop alone is not decided on two revolutions' means: the newest tooth 55 N down
    /// from one revolution earlier, the teeth before it unchanged, while two teeth's means
    /// three revolutions back lay 15 N under their level each (a pair of gains against
    /// them; seed 12018 gone 0, a lost tool's first window named a breakage). With one of
    /// the teeth before the drop up 20 N on the revolution before (a gain the newest
    /// revolution shows), the same drop is a breakage.
    #[test]
    fn a_drop_alone_is_not_decided_against_old_means() {
        let drop_after = |gain: f32| {
            let mut after = [0.0f32; 20];
            for rev in 0..2 {
                after[4 * rev + 1] = -15.0;
                after[4 * rev + 2] = -15.0;
            }
            after[18] = gain;
            after[19] = -55.0;
            let f = forces(3.0, 40, &after);
            // (Unflagged: the means are decided only out of a steady cut.)
            (first_breakage_as(&f, Status::AMBIGUOUS), f.len() - 1)
        };
        let (first, drop) = drop_after(0.0);
        assert_eq!(first, None, "the drop at {drop}");
        let (first, drop) = drop_after(20.0);
        assert_eq!(first, Some(drop));
    }

    /// The default alarms over a not-cutting floor of 5 N.
    fn alarms_at_5n() -> Alarms {
        let est = EstimatorConfig {
            force_floor_n: 5.0,
            ..EstimatorConfig::default()
        };
        AlarmConfig::default().build(&est).unwrap()
    }

    /// Feeds the forces as records of a steady cut (not flagged transient, the first-tooth
    /// rules apply; `AMBIGUOUS` keeps the threshold on the measured force) until the first
    /// tooth in `gone_from..` where nothing cuts; returns the index where the output first
    /// latched, and the first event's: index, index of the record it carries, cause.
    #[allow(clippy::type_complexity)]
    fn first_latch(f: &[f32], gone_from: usize) -> (Option<usize>, Option<(usize, usize, Cause)>) {
        let a = alarms_at_5n();
        let mut st = AlarmState::default();
        let (mut latch, mut event) = (None, None);
        for (i, &fx) in f.iter().enumerate() {
            let cutting = i < gone_from || fx > 5.0;
            let status = if cutting {
                Status::AMBIGUOUS
            } else {
                Status::NOT_CUTTING
            };
            let rec = record(i, fx, status);
            let out = a.process(&mut st, &rec);
            if out.latched && latch.is_none() {
                latch = Some(i);
            }
            if let (None, Some(e)) = (event, out.event) {
                // Raised by a record's rules: latched at the last sample of the record the
                // output latched at (this one, or an empty tooth's before it).
                let latched = latch.map(|k| 250 * (k as u64 + 1));
                assert_eq!(Some(e.latched_sample), latched);
                event = Some((i, (e.record.end_sample / 250 - 1) as usize, e.cause));
            }
        }
        (latch, event)
    }

    /// Feeds the forces as `first_latch` does; before record `trip_at`, the drop trip of
    /// its period passes, at its 100th sample. Returns whether the output latched at the
    /// trip, and the first event: index and cause. Every event carries the trip's sample.
    fn trip_then(f: &[f32], trip_at: usize, gone_from: usize) -> (bool, Option<(usize, Cause)>) {
        let a = alarms_at_5n();
        let mut st = AlarmState::default();
        let (mut latched, mut event) = (false, None);
        for (i, &fx) in f.iter().enumerate() {
            if i == trip_at {
                assert!(st.trip_floor_n().is_finite(), "armed out of the steady cut");
                a.trip(&mut st, 100.0, 50.0, trip_sample(trip_at));
                latched = st.output_latched() && st.output_cause() == Some(Cause::Breakage);
            }
            let cutting = i < gone_from || fx > 5.0;
            let status = if cutting {
                Status::AMBIGUOUS
            } else {
                Status::NOT_CUTTING
            };
            let out = a.process(&mut st, &record(i, fx, status));
            assert_eq!(out.latched, i >= trip_at, "record {i}");
            if let (None, Some(e)) = (event, out.event) {
                assert_eq!(e.latched_sample, trip_sample(trip_at), "record {i}");
                assert!(e.record.end_sample > e.latched_sample);
                event = Some((i, e.cause));
            }
        }
        (latched, event)
    }

    /// The sample of record `i`'s period (of 250, see `record`) where a trip passes.
    fn trip_sample(i: usize) -> u64 {
        250 * i as u64 + 100
    }

    /// The trip's arming, after steady forces with `after` appended.
    fn trip_floor_after(after: &[f32]) -> f32 {
        trip_arming_after(after).0
    }

    /// The trip's floor and share, after steady forces with `after` appended.
    fn trip_arming_after(after: &[f32]) -> (f32, f32) {
        let (st, _) = armed_after(after, None);
        (st.trip_floor_n(), st.trip_share())
    }

    /// A state whose last valid estimate is a narrow arc's (`R_r` 0.3, `R_a` where eq. 7
    /// gives `mean_n` at the records' 0.2 mm a tooth): an exit's first feed of travel
    /// takes 8 % of its force (the drop trip's share after a hand-over's evidence).
    fn narrow_arc(a: &Alarms, mean_n: f32) -> AlarmState {
        AlarmState {
            held: Some((0.3, mean_n / a.model_signal(0.3, 1.0, 0.2))),
            ..AlarmState::default()
        }
    }

    /// Whether the drop trip is armed under the plain trip's least share: on a hand-over's
    /// evidence.
    fn evidence_armed(st: &AlarmState) -> bool {
        st.trip_floor_n().is_finite() && st.trip_share() < TRIP_SHARE
    }

    /// The state after steady forces with `after` appended (`forces(3.0, 40, after)`), as
    /// records, the record `flagged` transient; and the events raised; the last valid
    /// estimate a narrow arc's (`narrow_arc`).
    fn armed_after(after: &[f32], flagged: Option<usize>) -> (AlarmState, usize) {
        armed_after_faster(after, flagged, 0)
    }

    /// ... the spindle faster by `shorter` samples a tooth over the last 4 records.
    fn armed_after_faster(
        after: &[f32],
        flagged: Option<usize>,
        shorter: u32,
    ) -> (AlarmState, usize) {
        armed_at(RUNOUT_30, after, flagged.as_slice(), shorter)
    }

    /// ... the flutes' steady forces at `levels`, the records `flagged` transient.
    fn armed_at(
        levels: [f32; 4],
        after: &[f32],
        flagged: &[usize],
        shorter: u32,
    ) -> (AlarmState, usize) {
        armed_on_arc(0.3, levels, after, flagged, shorter)
    }

    /// ... the last valid estimate's `R_r` at `rr` (its `R_a` where eq. 7 gives the mean;
    /// no estimate for a negative `rr`).
    fn armed_on_arc(
        rr: f32,
        levels: [f32; 4],
        after: &[f32],
        flagged: &[usize],
        shorter: u32,
    ) -> (AlarmState, usize) {
        armed_on_arc_at_speed(rr, levels, after, flagged, |i, len| {
            if i + 4 >= len {
                shorter
            } else {
                0
            }
        })
    }

    /// ... record `i` of `len` shorter by `shorter(i, len)` samples.
    fn armed_on_arc_at_speed(
        rr: f32,
        levels: [f32; 4],
        after: &[f32],
        flagged: &[usize],
        shorter: impl Fn(usize, usize) -> u32,
    ) -> (AlarmState, usize) {
        let est = EstimatorConfig::default();
        let a = AlarmConfig::default().build(&est).unwrap();
        let mean_n = levels.iter().sum::<f32>() / 4.0;
        let mut st = AlarmState {
            held: (rr >= 0.0).then(|| (rr, mean_n / a.model_signal(rr, 1.0, 0.2))),
            ..AlarmState::default()
        };
        let mut events = 0;
        let f = forces_at(levels, 3.0, 40, after);
        for (i, &fx) in f.iter().enumerate() {
            let status = if flagged.contains(&i) {
                Status::TRANSIENT
            } else {
                Status::AMBIGUOUS
            };
            let mut rec = record(i, fx, status);
            faster(&mut rec, shorter(i, f.len()));
            events += usize::from(a.process(&mut st, &rec).event.is_some());
        }
        (st, events)
    }

    /// The drop trip measures the tangential channel; its floor, set in the resultant's
    /// noise, widens by that channel's own noise where it is the wider (seed 3723 normal
    /// 34), and stays where it is not.
    #[test]
    fn the_trips_floor_widens_by_its_channels_noise() {
        let a = AlarmConfig::default()
            .build(&EstimatorConfig::default())
            .unwrap();
        let f = forces(3.0, 40, &[]);
        let run = |trip_sigma_n: f32| {
            let mut st = AlarmState::default();
            for (i, &fx) in f.iter().enumerate() {
                let rec = record(i, fx, Status::AMBIGUOUS);
                let var_t = trip_sigma_n * trip_sigma_n;
                a.process_with(
                    &mut st,
                    &rec,
                    None,
                    (f32::NAN, var_t, 0, &NOT_TOLD),
                    &mut NoProbe,
                );
            }
            st.trip_floor_n()
        };
        // The plain floor: about 6 sigma_R of the resultant (3 N a tooth: sigma_R 4-5 N).
        let plain = run(0.0);
        assert!(plain.is_finite() && plain > 0.0, "armed in a steady cut");
        assert_eq!(run(1.0), plain);
        // Past the resultant's, in proportion to the channel's noise.
        let (wide, wider) = (run(20.0), run(40.0));
        assert!(wide > 2.0 * plain, "{wide} {plain}");
        assert!((wider / wide - 2.0).abs() < 1e-5, "{wider} {wide}");
    }

    /// A tooth that handed its chip over to the next one inside its period a revolution ago
    /// (the record after its own past `HANDED_Z_SIGMAS`) has its next drop trip armed with
    /// `HANDED_NOISE_SIGMAS` of noise instead of `TRIP_NOISE_SIGMAS`: half the noise term
    /// (here about a quarter of the tooth). An exit's teeth all lose and hand nothing
    /// over. Where the cut spans more than a pitch so is the tooth before the handed one
    /// (the broken flute's next cut begins in its window), and not where the arc lies
    /// within a pitch. A hand-over on another record, or under the sigmas, leaves the plain
    /// share.
    #[test]
    fn a_tooth_that_handed_over_is_armed_with_less_noise() {
        let a = AlarmConfig::default()
            .build(&EstimatorConfig::default())
            .unwrap();
        // Noisy enough that the smaller term still takes a wide arc's exit share over the
        // plain share's least (a narrow arc's, far smaller, with more noise).
        let mean_n = RUNOUT_30.iter().sum::<f32>() / 4.0;
        let arm = |rr: f32, handed: Option<(usize, f32)>| {
            let f = forces_at(RUNOUT_30, if rr > 1.0 { 6.0 } else { 12.0 }, 40, &[]);
            let mut st = AlarmState {
                held: Some((rr, mean_n / a.model_signal(rr, 1.0, 0.2))),
                ..AlarmState::default()
            };
            for (i, &fx) in f.iter().enumerate() {
                let mut rec = record(i, fx, Status::AMBIGUOUS);
                if let Some((back, z)) = handed {
                    if i + 1 + back == f.len() {
                        rec.handover_z = z;
                    }
                }
                assert!(a.process(&mut st, &rec).event.is_none(), "record {i}");
            }
            assert!(st.trip_floor_n().is_finite(), "armed");
            (st.trip_share(), st.exit_wide)
        };
        let (plain, wide) = arm(1.4, None);
        assert!(wide > 0.0, "R_r 1.4 spans more than a pitch: {wide}");
        // The next period's tooth is the newest's plus one; its own record 3 back, the
        // one after it 2 back; the tooth after it 1 back.
        let handed = arm(1.4, Some((2, HANDED_Z_SIGMAS + 0.1))).0;
        assert!(
            handed > TRIP_SHARE,
            "{handed}: not the least share ({plain})"
        );
        assert!(plain - handed > 0.1, "{plain} against {handed}");
        assert_eq!(arm(1.4, Some((1, 9.0))).0, handed);
        for other in [(0, 9.0), (3, 9.0), (2, HANDED_Z_SIGMAS - 0.1)] {
            assert_eq!(arm(1.4, Some(other)).0, plain, "{other:?}");
        }
        // Within a pitch only the handed tooth itself.
        let (plain, wide) = arm(0.15, None);
        assert_eq!(wide, 0.0, "R_r 0.15 lies within a pitch");
        let handed = arm(0.15, Some((2, 9.0))).0;
        assert!(plain - handed > 0.1, "{plain} against {handed}");
        assert_eq!(arm(0.15, Some((1, 9.0))).0, plain);
    }

    /// The recent peak decays by 2 % a revolution, whatever the flutes.
    #[test]
    fn the_peak_decays_by_two_percent_a_revolution() {
        for flutes in [2u8, 3, 4, 7, 16] {
            let est = EstimatorConfig {
                tool: crate::geometry::Tool {
                    flutes,
                    ..EstimatorConfig::default().tool
                },
                ..EstimatorConfig::default()
            };
            let a = AlarmConfig::default().build(&est).unwrap();
            let rev = f64::from(a.peak_decay).powi(i32::from(flutes));
            assert!((rev - 0.98).abs() < 1e-6, "{flutes} flutes: {rev}");
        }
    }

    /// `rec` of a period `by` samples shorter than `record`'s, its speed to match.
    fn faster(rec: &mut ToothRecord, by: u32) {
        rec.samples -= by;
        rec.rpm = 600.0 * 250.0 / rec.samples as f32;
    }

    /// The noise floor follows the force up: a cut whose force doubles (with its noise, as
    /// the encoder jitter's share of it does) has, two revolutions on, the trip's floor
    /// doubled too; the spread in newtons alone has barely moved by then.
    #[test]
    fn the_noise_floor_follows_the_force_up() {
        let est = EstimatorConfig::default();
        let a = AlarmConfig::default().build(&est).unwrap();
        let floor = |scale: f32| {
            let mut st = AlarmState::default();
            // The growth over four revolutions (a wall is entered over travel), then two.
            for (i, &fx) in forces(3.0, 46, &[]).iter().enumerate() {
                let grown = (i.saturating_sub(4 * 40) as f32 / 16.0).min(1.0);
                let s = 1.0 + (scale - 1.0) * grown;
                let out = a.process(&mut st, &record(i, s * fx, Status::AMBIGUOUS));
                assert!(out.event.is_none(), "scale {scale}, record {i}");
            }
            st.trip_floor_n()
        };
        let (plain, up) = (floor(1.0), floor(2.0));
        assert!(plain.is_finite());
        assert!(up > 1.8 * plain && up < 2.2 * plain, "{up} vs {plain}");
    }

    /// After a hand-over's evidence the trip is judged inside the period alone where the
    /// cut's span (its arc and the helix's lag) is within a pitch: the placed window then
    /// holds the whole cut, and a flute that broke in it loses its next pass from its
    /// first angles, past the evidence's share well before the period ends. A loss that
    /// passes it only with the whole period at the close lies at the cut's far end, an
    /// up-milling exit's first period (seed 5435 normal 51: 2 flutes, `R_r` 1.09, a noise
    /// pair, then the exit's first period lost 29 % against 0.32, judged whole at its
    /// close). Where the span is wider than a pitch the next flute's cut reaches into the
    /// window, and the close judges it too (seeds 14 break 61 and 85 break 108: 4 flutes at
    /// `R_r` 1.58, caught at the close); the plain arming is judged whole too.
    #[test]
    fn the_evidence_trip_is_judged_whole_only_on_a_cut_wider_than_a_pitch() {
        let pair = [0.0, -24.0, 24.0, 0.0, 0.0];
        let tool = EstimatorConfig::default().tool;
        let span = |rr: f32, st: &AlarmState| {
            let ra = st.held.map_or(0.0, |(_, ra)| ra);
            crate::geometry::engaged_arc_rad(rr) + ra * libm::tanf(tool.helix_deg.to_radians())
        };
        for (rr, wide) in [(0.3, false), (1.9, true)] {
            let (st, events) = armed_on_arc(rr, RUNOUT_30, &pair, &[], 0);
            let (plain, _) = armed_on_arc(rr, RUNOUT_30, &[0.0; 5], &[], 0);
            assert_eq!(events, 0);
            // By the evidence: its floor under the plain arming's 6 sigma.
            assert!(st.trip_floor_n() < plain.trip_floor_n(), "R_r {rr}");
            assert!(st.trip_share() >= EVIDENCE_SHARE, "R_r {rr}");
            assert_eq!(span(rr, &st) > tool.tooth_pitch_rad(), wide, "R_r {rr}");
            assert_eq!(st.trip_whole_share() < f32::INFINITY, wide, "R_r {rr}");
            assert!(plain.trip_floor_n().is_finite(), "R_r {rr}: armed plain");
            assert!(
                plain.trip_whole_share() >= plain.trip_share(),
                "R_r {rr}: plain"
            );
        }
    }

    /// A flute broken inside its period a revolution ago: tooth 1 lost 24 N and tooth 2
    /// gained them (about 4 sigma_R each with the spread they add, under every rule on
    /// the records: no alarm latched, the trip armed). The trip of
    /// tooth 1's next period is armed at 0.3 of the tooth and a lower floor (not 6 sigma_R
    /// and a half), so that it passes before the flute reaches its break angle again; also
    /// where the next tooth gained little (the gain spread over two periods). An exit (each
    /// tooth loses more than the one before), a gain alone, the pair on other teeth, and a
    /// pair of excursions a revolution earlier that returned leave it as it was.
    #[test]
    fn a_loss_handed_to_the_next_tooth_arms_that_teeths_trip_lower() {
        // (No valid estimate: the share for the worst R_r, over a half.)
        let (plain_floor, plain_share) = trip_arming_after(&[0.0; 5]);
        assert!(plain_share >= TRIP_SHARE);
        let (floor, share) = trip_arming_after(&[0.0, -24.0, 24.0, 0.0, 0.0]);
        assert!(floor.is_finite(), "armed, no alarm latched");
        assert_eq!(share, EVIDENCE_SHARE);
        // Lower than the plain 6 sigma, though the pair widened the spread.
        assert!(floor < 0.9 * plain_floor, "{floor} vs {plain_floor}");
        // The gain need only be one: 27 N lost and 6 N gained (about 1 sigma_R).
        let (floor, share) = trip_arming_after(&[0.0, -27.0, 6.0, 0.0, 0.0]);
        assert!(
            floor.is_finite() && share == EVIDENCE_SHARE,
            "{floor} {share}"
        );
        for after in [
            [0.0, -24.0, -30.0, -36.0, -42.0],
            [0.0, 0.0, 24.0, 0.0, 0.0],
            // (The pair on teeth 3 and 0, the next period tooth 1's. On teeth 2 and 3 it
            // would arm tooth 1 as the window before the handed tooth.)
            [0.0, 0.0, 0.0, -24.0, 24.0],
        ] {
            let (floor, share) = trip_arming_after(&after);
            assert!(share >= TRIP_SHARE, "{after:?}: {share}");
            assert!(floor >= plain_floor, "{after:?}: {floor} vs {plain_floor}");
        }
        // Nor a pair of excursions in the revolution before returning (the encoder's
        // jitter moved 16 N from tooth 2's window to tooth 1's): against it tooth 1 lost
        // 16 N and tooth 2 gained 16, against two revolutions earlier neither changed.
        let returned = [0.0, 16.0, -16.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let (floor, share) = trip_arming_after(&returned);
        assert!(floor.is_finite() && share >= TRIP_SHARE, "{floor} {share}");
        // A step of 12 N from tooth 2 to tooth 1 that stays is one.
        let step = [0.0, 0.0, 0.0, 0.0, 0.0, -12.0, 12.0, 0.0, 0.0];
        assert_eq!(trip_arming_after(&step).1, EVIDENCE_SHARE);
    }

    /// Where the tooth before the loss lost too, a pair is evidence only if the gain takes
    /// half of both losses: a flute broken in the window before, its cut going on into the
    /// loss's (arcs wider than a pitch), hands both on; an exit's first teeth lose and hand
    /// nothing, and a gain after them may be noise (seed 908 normal 79: the exit's first
    /// teeth lost about 2.7 and 5.4 sigma_R, a light flute gained 1.4 after them). A loss
    /// of 18 N and a gain of 12 (past `EVIDENCE_SIGMAS` together): after the tooth before
    /// lost 2 sigma_R the trip is armed lower, after it lost 3 (13 N) it is not; with a
    /// gain of 26, over half of both losses, it is (the pair under `PAIR_RAISE_SIGMAS`,
    /// past which it would raise at once).
    #[test]
    fn a_pair_after_the_tooth_before_lost_asks_the_gain_of_both() {
        let (st, _) = armed_after(&[0.0; 5], None);
        let sigma_r = libm::sqrtf(0.5 * st.e_var);
        // (Without the evidence the plain arming, at half the tooth; its floor may credit
        // the loss.)
        let lower = |before: f32, gain: f32| {
            let (floor, share) = trip_arming_after(&[-before * sigma_r, -18.0, gain, 0.0, 0.0]);
            assert!(floor.is_finite(), "{before} {gain}");
            assert!(
                share == EVIDENCE_SHARE || share >= TRIP_SHARE,
                "{before} {gain}: {share}"
            );
            share == EVIDENCE_SHARE
        };
        assert!(lower(2.0, 12.0));
        assert!(!lower(3.0, 12.0));
        assert!(lower(3.0, 26.0));
    }

    /// A pair's gain must stand above what an exit would leave the gaining tooth: an exit
    /// takes about the same share from every flute, and on a light flute (runout) that
    /// share hides in the noise (seed 968 normal 32). A heavy flute (300 N) loses 6 sigma_R
    /// and the light one after it (30 N: the exit's share there is a loss of 0.6) gains
    /// 0.5 or 1.6 (1.1 and 2.2 above the exit's share, in the steady cut's sigma_R; the
    /// loss widens the one it is judged in by about a tenth): no evidence; 4 is. After a
    /// flute of the same force (the exit's share a loss of 6) a gain of 0.5 is evidence.
    /// (The pairs exactly so: the steady forces' noise taken out of them.)
    #[test]
    fn a_light_flutes_gain_must_stand_above_an_exits_share() {
        let arming = |levels: [f32; 4], gain: f32| {
            let steady = forces_at(levels, 3.0, 40, &[0.0; 5]);
            let (st, _) = armed_at(levels, &[0.0; 5], &[], 0);
            let sigma_r = libm::sqrtf(0.5 * st.e_var);
            let noise = |k: usize| steady[160 + k] - steady[156 + k];
            let after = [
                0.0,
                -6.0 * sigma_r - noise(1),
                gain * sigma_r - noise(2),
                0.0,
                0.0,
            ];
            let (st, events) = armed_at(levels, &after, &[], 0);
            assert_eq!(events, 0, "{levels:?} {gain}");
            assert!(st.trip_floor_n().is_finite(), "{levels:?} {gain}");
            st.trip_share() == EVIDENCE_SHARE
        };
        let light = [100.0, 300.0, 30.0, 100.0];
        assert!(!arming(light, 0.5));
        assert!(!arming(light, 1.6));
        assert!(arming(light, 4.0));
        assert!(arming([100.0, 300.0, 300.0, 100.0], 0.5));
    }

    /// A hand-over's evidence counts only at a steady speed: the current loop's lag, a
    /// time, moves force across the windows' boundaries as the speed changes (seed 678
    /// gone 8: a 2-flute tool 10 % faster over 8 teeth, a pair in the noise armed the trip
    /// at 0.3 of the tooth and the period lost 33 %). The pair of
    /// `a_loss_handed_to_the_next_tooth_arms_that_teeths_trip_lower`, the spindle faster by
    /// `shorter` samples a tooth from the pair's loss on: by 1 (the newest revolution 0.4 %
    /// shorter than the one before, within 1 % and two samples) it arms lower; by 4 (1.6 %)
    /// the trip is armed at the plain share (half the tooth; the floor may keep the plain
    /// credit for the loss), or not at all.
    #[test]
    fn a_pair_in_a_speed_change_is_no_evidence() {
        let arming = |after: &[f32], shorter: u32| {
            let (st, events) = armed_after_faster(after, None, shorter);
            assert_eq!(events, 0, "{after:?} {shorter}");
            (st.trip_floor_n(), st.trip_share())
        };
        let pair = [0.0, -24.0, 24.0, 0.0, 0.0];
        let (plain_floor, _) = arming(&[0.0; 5], 0);
        let (floor, share) = arming(&pair, 1);
        assert_eq!(share, EVIDENCE_SHARE);
        assert!(floor < 0.9 * plain_floor, "{floor} vs {plain_floor}");
        let (floor, share) = arming(&pair, 4);
        assert!(
            floor.is_infinite() || share >= TRIP_SHARE,
            "{floor} {share}"
        );
    }

    /// The plain trip is not armed in a speed ramp either (seed 5318 normal 35: a 2-flute
    /// tool at 54 N, 6 % slower over two revolutions; the period's bins judged against the
    /// revolution before's at the same samples, the light cut's short arc later in them,
    /// tripped on a whole loss of 4.5 N). A steady cut, the spindle faster by `shorter`
    /// samples a tooth over the last revolution: by 2 (the newest revolution 0.8 % shorter,
    /// within 1 % and two samples) armed at the plain share; by 4 (1.6 %) not armed.
    #[test]
    fn the_plain_trip_is_not_armed_in_a_speed_ramp() {
        let arming = |shorter: u32| {
            let (st, events) = armed_after_faster(&[0.0; 5], None, shorter);
            assert_eq!(events, 0, "{shorter}");
            (st.trip_floor_n(), st.trip_share())
        };
        let (floor, share) = arming(2);
        assert!(floor.is_finite() && share >= TRIP_SHARE, "{floor} {share}");
        assert!(arming(4).0.is_infinite());
    }

    /// ... but armed where only the revolution before the newest was off, the newest as
    /// long as the one before that: the tracked boundaries' swing after a ramp, not a ramp
    /// (seed 11513 break 89). Records are 250 samples; `by(r)` samples a tooth shorter in
    /// the `r`-th revolution back (0 the newest). The middle one 4 shorter (1.6 %, past 1 %
    /// and two samples against both neighbours): armed at the plain share. A ramp, each
    /// revolution 4 a tooth shorter than the one before: not armed; nor a step whose newest
    /// revolution stands off the two before it.
    #[test]
    fn a_revolution_swung_between_two_of_one_length_is_no_ramp() {
        let arming = |by: [u32; 3]| {
            let shorter = |i: usize, len: usize| {
                let back = (len - 1 - i) / 4;
                by.get(back).copied().unwrap_or(0)
            };
            let (st, events) = armed_on_arc_at_speed(0.3, RUNOUT_30, &[0.0; 5], &[], shorter);
            assert_eq!(events, 0, "{by:?}");
            (st.trip_floor_n(), st.trip_share())
        };
        let (floor, share) = arming([0, 4, 0]);
        assert!(floor.is_finite() && share >= TRIP_SHARE, "{floor} {share}");
        assert!(arming([8, 4, 0]).0.is_infinite(), "a ramp");
        assert!(arming([4, 0, 0]).0.is_infinite(), "a step");
    }

    /// ... nor just after a speed change, while the tracked boundary still lags: the speed
    /// settled as the rules that compare revolutions ask it, the newest two revolutions as
    /// long as the two 16 teeth earlier (seed 3890 break 103 before its damage: a 2-flute
    /// tool 9 % faster over 8 teeth, the last revolutions as long, the light tooth's force
    /// moving into the other's window; the handed tooth's period, armed at 0.3, lost 35 %).
    /// The same pair after the spindle came `ramp` samples a tooth faster over 8 teeth,
    /// then held for the last 9: by 0 it arms lower; by 3 (9.6 %) the trip is armed at the
    /// plain share, or not at all.
    #[test]
    fn a_pair_just_after_a_speed_change_is_no_evidence() {
        let arming = |ramp: u32| {
            let pair = [0.0, -24.0, 24.0, 0.0, 0.0];
            let into_ramp = |i: usize, len: usize| (i + 17).saturating_sub(len).min(8) as u32;
            let (st, events) = armed_on_arc_at_speed(0.3, RUNOUT_30, &pair, &[], |i, len| {
                ramp * into_ramp(i, len)
            });
            assert_eq!(events, 0, "{ramp}");
            (st.trip_floor_n(), st.trip_share())
        };
        assert_eq!(arming(0).1, EVIDENCE_SHARE);
        let (floor, share) = arming(3);
        assert!(
            floor.is_infinite() || share >= TRIP_SHARE,
            "{floor} {share}"
        );
    }

    /// The rules that compare revolutions decide only at a settled speed: in a speed
    /// change the window's tracked boundary lags and moves force from one window into the
    /// next (seed 1190 gone 14). Tooth 1 gives 40 N of its force to tooth 2 from a
    /// revolution on, for good: at a steady speed that is a breakage's pattern, raised;
    /// with the periods shortening by `ramp` samples a tooth from 4 teeth before it (the
    /// spindle 1.2 or 1.6 % a tooth faster over 12 teeth, 15 or 20 % in all, as at seed
    /// 1190), nothing is raised.
    #[test]
    fn a_speed_change_moves_force_between_windows_with_no_breakage() {
        let est = EstimatorConfig::default();
        let a = AlarmConfig::default().build(&est).unwrap();
        let raised = |moved: f32, ramp: u32| {
            let after: Vec<f32> = (0..8)
                .flat_map(|_| [0.0, -moved, moved, 0.0])
                .skip(4)
                .collect();
            let f = forces(3.0, 40, &after);
            let mut st = narrow_arc(&a, 107.5);
            let from = f.len() - after.len() - 4;
            let mut raised = 0;
            for (i, &fx) in f.iter().enumerate() {
                let mut rec = record(i, fx, Status::AMBIGUOUS);
                if i >= from {
                    faster(&mut rec, ramp * (i - from + 1).min(12) as u32);
                }
                raised += usize::from(a.process(&mut st, &rec).event.is_some());
            }
            raised
        };
        assert_eq!(raised(40.0, 0), 1);
        assert_eq!(raised(40.0, 3), 0);
        assert_eq!(raised(40.0, 4), 0);
    }

    /// After a speed ramp, the periods' lengths differ from those 16 teeth earlier for
    /// revolutions after the window's tracked times have caught up with the pulses. A
    /// breakage raised there by a rule that compares the newest revolution with the one
    /// before stands where the caller tells that the boundaries it compares lie where their
    /// teeth's did a revolution earlier (`lag_quiet` past N, here 4: seed 6123 break 93, 3.9
    /// revolutions late), or, raised by `E`, where `E` passes its threshold by what the
    /// boundaries of its two newest periods may have moved (told by the hand-over stage:
    /// seeds 12739 break 29 and 12793 break 37, 2 flutes, the next flute's gain 13 and 9
    /// teeth after a ramp, an `E` of 3.3 and 4.3 thresholds taken back, and the trip a
    /// revolution on). It is taken back as before where neither holds (not told, told of N
    /// alone, told that the boundaries moved as much force as the pair's). Tooth 1 hands 40
    /// N to tooth 2 from 4 teeth after the spindle came 3 samples a tooth faster over 8
    /// teeth (10 %), and on, as `a_speed_change_moves_force_between_windows_with_no_breakage`'s
    /// pattern; the force is 0.6 feed and 0.8 tangential.
    #[test]
    fn after_a_ramp_a_breakage_stands_where_the_boundaries_are_quiet() {
        let est = EstimatorConfig::default();
        let a = AlarmConfig::default().build(&est).unwrap();
        let first_event = |quiet: u8, moved: &dyn Fn(usize) -> f32| {
            let after: Vec<f32> = (0..8)
                .flat_map(|_| [0.0, -40.0, 40.0, 0.0])
                .skip(4)
                .collect();
            let f = forces(3.0, 40, &after);
            let mut st = narrow_arc(&a, 107.5);
            let from = f.len() - after.len() - 12;
            f.iter().enumerate().position(|(i, &force)| {
                let mut rec = record(i, 0.6 * force, Status::AMBIGUOUS);
                rec.f2_n = 0.8 * force;
                if i >= from {
                    faster(&mut rec, 3 * (i - from + 1).min(8) as u32);
                }
                let c = (f32::NAN, 0.0, quiet, moved);
                let out = a.process_with(&mut st, &rec, None, c, &mut NoProbe);
                out.event.is_some()
            })
        };
        // The pair's gain is record `gain`; the alarm at once, or within the revolution.
        let gain = 40 * 4 + 2;
        let within = |at: Option<usize>| at.is_some_and(|i| (gain..gain + 4).contains(&i));
        let quiet = first_event(5, &NOT_TOLD);
        assert!(within(quiet), "{quiet:?}");
        // Told of boundaries that moved 2 N of tangential force each (2.5 N of the signal):
        // `E`, 80 N, stands.
        let still = first_event(0, &|_| 2.0);
        assert!(within(still), "{still:?}");
        // Not told (the length test alone), or not quiet over the revolution, or told that
        // each boundary moved 32 N (40 N of the signal, the pair's own): later, or never.
        for (q, m) in [(0, f32::INFINITY), (4, f32::INFINITY), (0, 32.0)] {
            let late = first_event(q, &|_| m);
            assert!(late.is_none_or(|i| i >= gain + 4), "{q} {m}: {late:?}");
        }
    }

    /// Where arcs are wider than a pitch, a flute's cut begins in the window before the
    /// one that holds most of it: after tooth 1 lost 24 N and tooth 2 gained them, the
    /// trip of tooth 0's next period (armed after tooth 3's record) is armed at 0.3 of the
    /// tooth and 4 sigma_R too, under the plain floor. Not after an exit, nor where the
    /// pair is on other teeth, nor where the newest tooth lost after a weaker pair (an
    /// exit begun after a noise pair).
    #[test]
    fn the_window_before_a_handed_tooth_is_armed_lower_too() {
        let (plain_floor, _) = trip_arming_after(&[0.0; 4]);
        let (floor, share) = trip_arming_after(&[0.0, -24.0, 24.0, 0.0]);
        assert_eq!(share, EVIDENCE_SHARE);
        assert!(floor < 0.9 * plain_floor, "{floor} vs {plain_floor}");
        for after in [
            [0.0, -24.0, -30.0, -36.0],
            [0.0, 0.0, -24.0, 24.0],
            [0.0, -16.0, 16.0, -20.0],
        ] {
            let (floor, share) = trip_arming_after(&after);
            assert!(share >= TRIP_SHARE, "{after:?}: {share}");
            assert!(
                floor >= plain_floor || floor.is_infinite(),
                "{after:?}: {floor} vs {plain_floor}"
            );
        }
    }

    /// A loss and a gain after a transient record are no hand-over: as an exit fades over
    /// revolutions (the monitor flags its records transient, not every one), flutes of
    /// unequal runout leave the work at unequal times, one tooth down while the next is
    /// up (seed 84, normal case 95: a pair of 5.3 sigma_R, then the exit's end emptied the
    /// losing tooth's next period). The same pair out of a steady cut arms the trip lower.
    #[test]
    fn a_pair_after_a_transient_record_is_no_hand_over() {
        let arming = |transient: Option<usize>| {
            let (st, _) = armed_after(&[0.0, -24.0, 24.0, 0.0, 0.0], transient);
            (st.trip_floor_n(), st.trip_share())
        };
        assert_eq!(arming(None).1, EVIDENCE_SHARE);
        // Record 160 is the one before the loss (161).
        let (floor, share) = arming(Some(160));
        assert!(
            floor.is_infinite() || share >= TRIP_SHARE,
            "{floor} {share}"
        );
    }

    /// A pair out of a cut that fell over the revolutions before it, every record
    /// unflagged, is no hand-over (seed 1786 normal 30: an exit's slow tail, the
    /// revolution before the pair 4.8 of that change's noise under three earlier): every
    /// tooth down by 20 N over a revolution (3 N of noise: the revolution's sum 9 sigma of
    /// its change's noise under three earlier), two revolutions flat, then a pair of 20 N
    /// each way. Out of the steady cut the same pair arms the trip at `EVIDENCE_SHARE`.
    #[test]
    fn a_pair_out_of_a_fading_cut_is_no_hand_over() {
        let pair = [0.0, -20.0, 20.0, 0.0, 0.0];
        let fading: std::vec::Vec<f32> = [0.0, 0.0, 0.0, 0.0, 0.0, -5.0, -10.0, -15.0]
            .into_iter()
            .chain([-20.0; 8])
            .chain(pair.iter().map(|p| p - 20.0))
            .collect();
        let (st, events) = armed_after(&fading, None);
        assert_eq!(events, 0);
        assert!(
            st.trip_floor_n().is_infinite() || st.trip_share() >= TRIP_SHARE,
            "{} {}",
            st.trip_floor_n(),
            st.trip_share()
        );
        let (st, events) = armed_after(&pair, None);
        assert_eq!(events, 0);
        assert!(
            evidence_armed(&st),
            "{} {}",
            st.trip_floor_n(),
            st.trip_share()
        );
    }

    /// A pair out of a cut still changing is no hand-over: an exit flagged transient on and
    /// off (seed 2743 normal 75: 4 flutes, the helix's lag making the cut wider than a
    /// pitch, an exit fading over revolutions; 5 of the 8 records before an unflagged pair
    /// of 88 N down and 55 up were flagged, and the trip armed at 0.3 on it passed; seed
    /// 2969 normal 119: 3 flutes, a deep exit whose teeth swung by a third from one
    /// revolution to the next, 1 of the 6 before its pair flagged and 6 of the 12). Two
    /// flagged records among the `4N` before the loss: no evidence; one: a hand-over.
    #[test]
    fn a_pair_out_of_a_cut_still_changing_is_no_evidence() {
        // (The loss at record 161, the gain at 162.)
        let after = [0.0, -24.0, 24.0, 0.0, 0.0];
        let arming = |flagged: &[usize]| {
            let (st, _) = armed_at(RUNOUT_30, &after, flagged, 0);
            (st.trip_floor_n(), st.trip_share())
        };
        assert_eq!(arming(&[]).1, EVIDENCE_SHARE);
        assert_eq!(arming(&[157]).1, EVIDENCE_SHARE);
        assert_eq!(arming(&[146]).1, EVIDENCE_SHARE);
        for flagged in [[157, 154], [160, 153], [157, 147], [146, 145]] {
            let (floor, share) = arming(&flagged);
            assert!(
                floor.is_infinite() || share >= TRIP_SHARE,
                "{flagged:?}: {floor} {share}"
            );
        }
    }

    /// The trip's floor and share after `armed_after(after, ..)`, the loss's record (161)
    /// `flagged`; and the pair (loss at 161, gain at 162) and the gain alone in sigma_R of
    /// `E`'s spread before the gain widened it.
    fn pair_arming(after: &[f32], flagged: bool) -> (f32, f32, f32, f32) {
        let flagged = flagged.then_some(161);
        let f = forces(3.0, 40, after);
        let r = |k: usize| f[k] - f[k - 4];
        let (before, _) = armed_after(&after[..2], flagged);
        let sigma_r = libm::sqrtf(0.5 * before.e_var);
        let (st, _) = armed_after(after, flagged);
        let (pair, gain) = ((r(162) - r(161)) / sigma_r, r(162) / sigma_r);
        (st.trip_floor_n(), st.trip_share(), pair, gain)
    }

    /// A hand-over pair past [`PAIR_RAISE_SIGMAS`] raises a breakage on its gain's record,
    /// where no other rule does: a loss of 19 N (under the redistribution's threshold, `k F`
    /// of 21.5 N) and gains from 24 to 40 N, each past [`PAIR_EACH_SIGMAS`]. Under it
    /// nothing is raised, and neither is a pair whose gain alone is under
    /// [`PAIR_EACH_SIGMAS`] (the decision itself, `Alarms::pair_raises`, with the state's
    /// noise: a loss of 8 sigma_R and a gain of 2 is no hand-over of a chip).
    #[test]
    fn a_pair_far_past_the_noise_raises_at_once() {
        let (mut raised, mut held) = (0, 0);
        for gain in [24.0, 27.0, 30.0, 32.0, 37.0, 40.0] {
            let after = [0.0, -19.0, gain, 0.0, 0.0];
            let (_, _, pair, gain_sigmas) = pair_arming(&after, false);
            assert!(gain_sigmas > PAIR_EACH_SIGMAS, "{gain}: {gain_sigmas}");
            // (Not within 0.2 of the threshold: the pair here is in the noise before the
            // loss, the rule's in the noise the loss widened.)
            assert!((pair - PAIR_RAISE_SIGMAS).abs() > 0.2, "{gain}: {pair}");
            assert_eq!(armed_after(&after[..2], None).1, 0);
            let events = armed_after(&after[..3], None).1;
            assert_eq!(
                events,
                usize::from(pair > PAIR_RAISE_SIGMAS),
                "{gain}: {pair}"
            );
            raised += events;
            held += 1 - events;
        }
        assert!(raised >= 2 && held >= 2, "{raised} {held}");
        let (st, _) = armed_after(&[0.0; 5], None);
        let (a, var) = (alarms_at_5n(), st.e_var);
        let sigma_r = libm::sqrtf(0.5 * var);
        let rec = record(0, 100.0, Status::AMBIGUOUS);
        let decide = |gain: f32, loss: f32| {
            a.pair_raises(&st, &rec, (gain * sigma_r, loss * sigma_r), (var, 100.0))
        };
        assert!(decide(5.0, 5.0).is_some());
        // (9.2 sigma_R together: a steady cut's noise pair reached 9.04, seed 13805 chip 29.)
        assert!(decide(4.6, 4.6).is_none());
        assert!(decide(8.0, 2.0).is_none() && decide(2.0, 8.0).is_none());
        // Past the engagement's threshold too: at 400 N, `k F` is 80 N.
        let heavy = a.pair_raises(&st, &rec, (10.0 * sigma_r, 10.0 * sigma_r), (var, 400.0));
        assert_eq!(heavy.is_some(), 20.0 * sigma_r > 80.0, "{sigma_r}");
    }

    /// A pair between 4.5 and 5 sigma_R is a hand-over where the loss's own record is not
    /// transient, and none where it is (seed 110, normal case 81: a light cut whose exit
    /// began with a flagged record, one tooth down and the next up by 4.7 sigma_R).
    #[test]
    fn a_weak_pair_needs_its_loss_unflagged() {
        let after = [0.0, -14.5, 14.5, 0.0, 0.0];
        let arming = |flagged: bool| {
            let (floor, share, pair, _) = pair_arming(&after, flagged);
            (floor, share, pair)
        };
        let (_, share, pair) = arming(false);
        assert!(
            pair > EVIDENCE_SIGMAS && pair < EVIDENCE_FLAGGED_SIGMAS,
            "{pair}"
        );
        assert_eq!(share, EVIDENCE_SHARE, "{pair}");
        let (floor, share, _) = arming(true);
        assert!(
            floor.is_infinite() || share >= TRIP_SHARE,
            "{floor} {share}"
        );
    }

    /// After a flagged loss, the pair's sum past [`EVIDENCE_FLAGGED_SIGMAS`] is no hand-over
    /// unless the gain stands on its own past [`EVIDENCE_EACH_SIGMAS`] (seed 6125 normal 104:
    /// a sudden exit's first tooth lost 5.5 sigma_R on a flagged record, the next tooth's
    /// loss hidden by the spindle current's lag left it a little up, and its period lost 39
    /// %). The same pair after an unflagged loss is a hand-over, and so is a flagged loss
    /// with a gain of its own.
    #[test]
    fn after_a_flagged_loss_the_gain_stands_on_its_own() {
        let arming = |gain: f32, flagged: bool| pair_arming(&[0.0, -30.0, gain, 0.0, 0.0], flagged);
        let (_, share, pair, gain) = arming(6.0, false);
        assert!(
            pair > EVIDENCE_FLAGGED_SIGMAS && gain > 0.0 && gain < EVIDENCE_EACH_SIGMAS,
            "{pair} {gain}"
        );
        assert_eq!(share, EVIDENCE_SHARE, "{pair} {gain}");
        let (floor, share, pair, gain) = arming(6.0, true);
        assert!(
            floor.is_infinite() || share >= TRIP_SHARE,
            "{floor} {share}: {pair} {gain}"
        );
        let (_, share, pair, gain) = arming(18.0, true);
        assert!(gain > EVIDENCE_EACH_SIGMAS, "{gain}");
        assert_eq!(share, EVIDENCE_SHARE, "{pair} {gain}");
    }

    /// After a pair beyond 6 sigma_R (24 N lost and gained, about 10 sigma_R together), the
    /// newest tooth lost 20 N (about 4 sigma_R). Where no estimate tells the arc's span,
    /// the losing tooth's trip is still armed lower than the plain trip: on an arc wider
    /// than a pitch that loss is the broken flute's cut where it begins, in the window
    /// before. On an arc known to lie within a pitch it is an exit's first tooth, and a
    /// strong pair is no proof against one (seed 9859 normal 9: a pair of 6.1 sigma_R by
    /// noise, then an exit): not armed lower. After a pair of 16 N (about 6 sigma_R with
    /// the noise) the same loss disarms it either way.
    #[test]
    fn after_a_strong_pair_the_newest_tooths_loss_disarms_a_known_narrow_arc() {
        let unknown_arc = |after: &[f32]| {
            let (st, events) = armed_on_arc(-1.0, RUNOUT_30, after, &[], 0);
            assert_eq!(events, 0, "{after:?}");
            assert!(st.held.is_none());
            (st.trip_floor_n(), st.trip_share())
        };
        let strong_lost = [0.0, -24.0, 24.0, 0.0, -20.0];
        let (floor, share) = unknown_arc(&strong_lost);
        assert!(floor.is_finite() && share < TRIP_SHARE, "{floor} {share}");
        let (floor, share) = trip_arming_after(&strong_lost);
        assert!(
            floor.is_infinite() || share >= TRIP_SHARE,
            "{floor} {share}"
        );
        let (_, share) = trip_arming_after(&[0.0, -24.0, 24.0, 0.0, 0.0]);
        assert_eq!(share, EVIDENCE_SHARE, "a hand-over");
        let weak_lost = [0.0, -16.0, 16.0, 0.0, -20.0];
        for (floor, share) in [trip_arming_after(&weak_lost), unknown_arc(&weak_lost)] {
            assert!(
                floor.is_infinite() || share >= TRIP_SHARE,
                "{floor} {share}"
            );
        }
    }

    /// After a hand-over's pair, the handed tooth's trip is armed at 0.3; where every tooth
    /// since the gain lost past 1.5 sigma_R (the newest under the 2 that voids the
    /// evidence), an exit may have begun right after the gain, a feed a tooth since: the
    /// share covers it (seed 3213 normal 99: a noise pair, two teeth 1.5 sigma_R down, then
    /// the handed tooth's period lost 32 %). One of them alone: as before. A broken flute's
    /// whole loss still passes it.
    #[test]
    fn an_exit_begun_after_the_gain_raises_the_evidences_share() {
        // Half immersion: an exit's loss at two feeds (0.05 R) is 0.31, over 0.3.
        let exit = crate::geometry::exit_loss_share(1.0, 2.0 * 0.2 / 8.0);
        assert!(exit > EVIDENCE_SHARE, "{exit}");
        // A light cut: the newest tooth's loss hidden in the noise bounds the travel past
        // two feeds.
        const LIGHT: [f32; 4] = [65.0, 50.0, 50.0, 50.0];
        // The pair at records 161-162; teeth 3 and 0 (records 163, 164) by `x3` and `x0`.
        let arming = |x3: f32, x0: f32| {
            let after = [0.0, -16.0, 16.0, x3, x0];
            let (st, events) = armed_on_arc(1.0, LIGHT, &after, &[], 0);
            assert_eq!(events, 0);
            let f = forces_at(LIGHT, 3.0, 40, &after);
            let s = libm::sqrtf(0.5 * st.e_var);
            let lost = |k: usize| (f[k - 4] - f[k]) / s;
            (
                st.trip_floor_n(),
                st.trip_share(),
                [lost(163), lost(164)],
                st.exit_wide,
            )
        };
        // (A feed past the newest tooth and one more, and the window's share of the next
        // flute's cut a feed further on: the newest tooth's loss bounds the travel.)
        let (_, base, _, wide) = arming(0.0, 0.0);
        let reach = crate::geometry::exit_loss_share(1.0, (2.0 + wide) * 0.2 / 8.0);
        assert!(
            base >= EVIDENCE_SHARE && base <= reach + 1e-4,
            "{base} {reach}"
        );
        for (x3, x0) in [(-5.0, 0.0), (0.0, -7.0)] {
            let (floor, share, _, _) = arming(x3, x0);
            assert!(
                floor.is_finite() && (share - base).abs() < 0.01,
                "{x3} {x0}: {share}"
            );
        }
        let (floor, share, lost, _) = arming(-5.0, -7.0);
        assert!(
            lost.iter().all(|&l| l > EVIDENCE_EACH_SIGMAS) && lost[1] < EVIDENCE_KEPT_SIGMAS,
            "{lost:?}"
        );
        // Armed still: a broken flute's whole loss passes it.
        assert!(
            floor < 0.5 * LIGHT[1] && share > base + 0.05 && share < 0.5,
            "{floor} {share}"
        );
    }

    /// A loss that keeps a pair from arming the window before the handed tooth's voids the
    /// evidence for the handed tooth's period too: an exit has begun, and its next tooth
    /// may lose little (seed 2452 normal 65: the tooth after the pair 24 % down, the next
    /// 1 sigma_R, and the handed tooth's period, armed at 0.3 without this, lost 29 %).
    #[test]
    fn a_loss_after_a_pair_spends_its_evidence() {
        let (_, share) = trip_arming_after(&[0.0, -16.0, 16.0, 0.0, 0.0]);
        assert_eq!(share, EVIDENCE_SHARE, "a hand-over");
        let (floor, share) = trip_arming_after(&[0.0, -16.0, 16.0, -20.0, 0.0]);
        assert!(
            floor.is_infinite() || share >= TRIP_SHARE,
            "{floor} {share}"
        );
    }

    /// The plain trip is not armed with two of the last 2N records flagged transient: a cut
    /// still changing (seed 1723 normal 113, an exit's tail flagged on and off; seed 3126
    /// taught 9, 3 flutes, the tail swinging by 2-5 sigma_R a revolution, 2 of the last 6
    /// flagged and 1 of the last 3). One of them, or the second before the 2N: armed.
    #[test]
    fn the_plain_trip_waits_out_a_cut_flagged_on_and_off() {
        // Records 160-171 steady; the newest 2N are 164-171.
        let after = [0.0; 12];
        let floor = |flagged: &[usize]| armed_at(RUNOUT_30, &after, flagged, 0).0.trip_floor_n();
        for flagged in [&[][..], &[165], &[169], &[161, 169]] {
            assert!(floor(flagged).is_finite(), "{flagged:?}");
        }
        assert!(floor(&[165, 169]).is_infinite());
    }

    /// The plain trip's floor (6 sigma_R) counts the loss the next tooth took a revolution
    /// ago, past 1.5 sigma_R, out of a steady cut: that period is the trip's reference, and
    /// a flute broken inside it left less there to lose (a weak flute under runout,
    /// whose whole force is about 6 sigma_R, is caught on its next pass). Not a loss in the
    /// noise, nor one with a transient record in the two revolutions (an exit: each
    /// tooth's loss a revolution ago is the exit's).
    #[test]
    fn the_loss_the_next_tooth_took_counts_toward_the_plain_floor() {
        // Tooth 1 (the next period's) loses `loss` in the revolution before the last;
        // `transient`: a record of the last revolution flagged.
        let arming = |loss: f32, transient: bool| {
            let (st, events) = armed_after(&[0.0, -loss, 0.0, 0.0, 0.0], transient.then_some(163));
            assert_eq!(events, 0, "{loss}");
            let sigma_r = libm::sqrtf(0.5 * st.e_var);
            (st.trip_floor_n(), st.trip_share(), sigma_r)
        };
        let (plain, plain_share, sigma_r) = arming(0.0, false);
        assert!(plain_share >= TRIP_SHARE);
        assert!(
            (plain / sigma_r - FIRST_TOOTH_SIGMAS).abs() < 0.3,
            "{plain} {sigma_r}"
        );
        for loss in [12.0, 16.0] {
            let (floor, share, s) = arming(loss, false);
            let want = FIRST_TOOTH_SIGMAS * s - loss;
            assert!((floor - want).abs() < 0.1 * s, "{loss}: {floor} vs {want}");
            // (The share is not lowered: its noise term grows as the reference falls.)
            assert!(share >= plain_share, "{loss}: {share}");
        }
        // Under 1.5 sigma_R: noise.
        let (floor, _, s) = arming(4.0, false);
        assert!((floor / s - FIRST_TOOTH_SIGMAS).abs() < 0.3, "{floor} {s}");
        let (floor, _, s) = arming(16.0, true);
        assert!(floor >= 0.95 * FIRST_TOOTH_SIGMAS * s, "{floor} {s}");
    }

    /// ... and its gain a revolution ago (past 1.5 sigma_R) raises the floor by as much: the
    /// trip's reference stands that high over the tooth's own level (seed 2256 normal 48:
    /// a tooth 2.3 sigma_R up on the last flat revolution of an exit, then the exit's step
    /// passed the trip against it). Under 1.5 sigma_R: noise, the plain floor.
    #[test]
    fn the_gain_the_next_tooth_took_raises_the_plain_floor() {
        let arming = |gain: f32| {
            let (st, events) = armed_after(&[0.0, gain, 0.0, 0.0, 0.0], None);
            assert_eq!(events, 0, "{gain}");
            (st.trip_floor_n(), libm::sqrtf(0.5 * st.e_var))
        };
        for gain in [12.0, 16.0] {
            let (floor, s) = arming(gain);
            let want = FIRST_TOOTH_SIGMAS * s + gain;
            assert!((floor - want).abs() < 0.3 * s, "{gain}: {floor} vs {want}");
        }
        let (floor, s) = arming(4.0);
        assert!((floor / s - FIRST_TOOTH_SIGMAS).abs() < 0.3, "{floor} {s}");
    }

    /// Where the next tooth's period a revolution ago, the trip's reference, lost past 1.5
    /// sigma_R (a flute broken inside it), the trip's shares are of the tooth's force two
    /// revolutions back, less that loss, as the hand-over stage measures against the
    /// reference: `(s 100 - l) / (100 - l)` for a tooth of 100 N that lost `l` (its noise, 3
    /// N, moves that by under 0.01). The plain trip's, after a gain the other way; not the
    /// evidence's (a noise pair's loss stood high two revolutions back); not under 1.5
    /// sigma_R (4 N), where the reference is the tooth's level to the noise.
    #[test]
    fn the_trip_counts_from_two_revolutions_back_where_its_reference_lost() {
        let of_reference = |after: &[f32], l: f32| {
            let (st, events) = armed_after(after, None);
            assert_eq!(events, 0, "{after:?}");
            assert!(st.trip_floor_n().is_finite(), "{after:?}");
            let (share, whole) = st.trip_shares_of_reference();
            let want = |s: f32| (s * 100.0 - l) / (100.0 - l);
            assert!(
                (share - want(st.trip_share())).abs() < 0.01,
                "{after:?}: {share} against {} of {}",
                want(st.trip_share()),
                st.trip_share()
            );
            if whole.is_finite() {
                assert!((whole - want(st.trip_whole_share())).abs() < 0.01);
            }
            (share, st.trip_share())
        };
        for l in [12.0, -12.0] {
            let (share, plain) = of_reference(&[0.0, -l, 0.0, 0.0, 0.0], l);
            assert_eq!(share < plain, l > 0.0, "{l}: {share} {plain}");
        }
        // Not the evidence's (seed 13203 normal 51).
        let (st, _) = armed_after(&[0.0, -12.0, 24.0, 0.0, 0.0], None);
        assert_eq!(st.trip_share(), EVIDENCE_SHARE);
        assert_eq!(st.trip_shares_of_reference().0, EVIDENCE_SHARE);
        let (st, _) = armed_after(&[0.0, -4.0, 0.0, 0.0, 0.0], None);
        assert_eq!(st.trip_shares_of_reference().0, st.trip_share());
    }

    /// The loss the handed tooth took a revolution ago counts toward its trip's floor
    /// (`4 sigma_R` less that loss, at least `2 sigma_R`): that period is the trip's
    /// reference, and a flute broken inside it left less there to lose. Not after a newest
    /// tooth that lost 2 sigma_R (an exit begun after a noise pair). And a weak flute
    /// (runout), whose plain trip's noise term (3 sigma_R is most of its force) takes its
    /// share near 0.9, is armed at 0.3 after the pair.
    #[test]
    fn the_loss_a_handed_tooth_took_counts_toward_its_trip() {
        let est = EstimatorConfig::default();
        let a = AlarmConfig::default().build(&est).unwrap();
        // Teeth at 100 N but tooth 1 at `weak`, noise 3 N a tooth; then `after`.
        let arming = |weak: f32, after: &[f32]| {
            let f = forces(3.0, 40, after);
            let mut st = narrow_arc(&a, (330.0 + weak) / 4.0);
            for (i, &fx) in f.iter().enumerate() {
                let fx = if i % 4 == 1 { fx - 100.0 + weak } else { fx };
                let out = a.process(&mut st, &record(i, fx, Status::AMBIGUOUS));
                assert!(out.event.is_none(), "{weak} {after:?}: record {i}");
            }
            (st.trip_floor_n(), st.trip_share(), st.e_var)
        };
        // The floor in sigma_R, from the spread the arming used (E's over 2).
        let sigmas = |(floor, _, var): (f32, f32, f32)| floor / libm::sqrtf(0.5 * var);
        // Losses of 8-12 N (about 1.5-2 sigma_R: the pair's least) and 24 N, each with a
        // 24 N gain: the floor falls from 4 sigma_R by the loss, to 2 sigma_R.
        let mut last = EVIDENCE_TRIP_SIGMAS;
        for l in [8.0, 9.0, 10.0, 12.0] {
            let x = arming(100.0, &[0.0, -l, 24.0, 0.0, 0.0]);
            assert_eq!(x.1, EVIDENCE_SHARE, "{l}");
            let k = sigmas(x);
            assert!(
                k < last - 0.1 && k > EVIDENCE_MIN_SIGMAS,
                "{l}: {k} after {last}"
            );
            last = k;
        }
        let large = sigmas(arming(100.0, &[0.0, -24.0, 24.0, 0.0, 0.0]));
        assert!((large - EVIDENCE_MIN_SIGMAS).abs() < 0.02, "{large}");
        // The newest tooth (the one the arming follows) lost 15 N, 2.6 sigma_R, under the
        // armed walk's 3: an exit's first tooth may follow a noise pair (16 N each way,
        // under `EVIDENCE_STRONG_SIGMAS` together). Not armed lower; a loss of 6 N is
        // noise.
        let exit = arming(100.0, &[0.0, -16.0, 16.0, 0.0, -15.0]);
        assert!(exit.1 >= TRIP_SHARE, "{exit:?}");
        assert_eq!(
            arming(100.0, &[0.0, -16.0, 16.0, 0.0, -6.0]).1,
            EVIDENCE_SHARE
        );
        // The weak flute: the plain trip's share near 0.9 (its noise term), 0.3 after the
        // pair (the narrow arc's exit).
        let plain = arming(15.0, &[0.0; 5]);
        assert!(plain.0.is_infinite() || plain.1 > 0.8, "{plain:?}");
        let weak = arming(15.0, &[0.0, -10.0, 20.0, 0.0, 0.0]);
        assert!(weak.0.is_finite(), "{weak:?}");
        assert_eq!(weak.1, EVIDENCE_SHARE);
    }

    /// The drop trip `(floor, share)` within a pitch (`R_r` 0.3) after a loss of
    /// `lost_share` of the newest tooth's force: armed, at no less than `TRIP_SHARE` and the
    /// share of the exit that took that loss, a feed (`feed`, in radii) further on.
    fn armed_past_the_narrow_exit((floor, share): (f32, f32), lost_share: f32, feed: f32) {
        let shown = crate::geometry::exit_travel(0.3, lost_share);
        let least = crate::geometry::exit_loss_share(0.3, shown + feed);
        assert!(
            floor.is_finite() && share >= least.max(TRIP_SHARE),
            "{floor} {share}: {least}"
        );
    }

    /// Alarms for a 3 mm tool, and the wide arc its records `wide_record` carry: `(alarms,
    /// R_r, feed)`, `R_r` 1.4 (the arc holds pi/2), one feed 0.2 mm of the 3 mm radius.
    fn wide_arc() -> (Alarms, f32, f32) {
        let mut est = EstimatorConfig::default();
        est.tool.radius_mm = 3.0;
        (AlarmConfig::default().build(&est).unwrap(), 1.4, 0.2 / 3.0)
    }

    /// Record `i` of `wide_arc`'s cut, valid.
    fn wide_record(i: usize, fx: f32) -> ToothRecord {
        ToothRecord {
            rr: 1.4,
            ra: 1.0,
            ..record(i, fx, Status::VALID)
        }
    }

    /// `wide_arc`'s alarms after its steady cut and `after` (`forces(noise, 40, after)`),
    /// valid records at `R_r` `rr`, none raising: the drop trip's floor and share, and
    /// sigma_R.
    fn wide_arming(a: &Alarms, rr: f32, noise: f32, after: &[f32]) -> (f32, f32, f32) {
        let st = wide_state(a, rr, noise, after, None);
        (
            st.trip_floor_n(),
            st.trip_share(),
            libm::sqrtf(0.5 * st.e_var),
        )
    }

    /// ... the state; with `trip_sigma` the records carry the trip channel as their second
    /// force (the feed force's level: the resultant is sqrt(2) of it) and its noise at that
    /// sigma.
    fn wide_state(
        a: &Alarms,
        rr: f32,
        noise: f32,
        after: &[f32],
        trip_sigma: Option<f32>,
    ) -> AlarmState {
        let mut st = AlarmState::default();
        for (i, &fx) in forces(noise, 40, after).iter().enumerate() {
            let rec = ToothRecord {
                rr,
                f2_n: trip_sigma.map_or(0.0, |_| fx),
                ..wide_record(i, fx)
            };
            let out = match trip_sigma {
                None => a.process(&mut st, &rec),
                Some(s) => a.process_with(
                    &mut st,
                    &rec,
                    None,
                    (f32::NAN, s * s, 0, &NOT_TOLD),
                    &mut NoProbe,
                ),
            };
            assert!(out.event.is_none(), "{rr} {after:?}: record {i}");
        }
        st
    }

    /// A hand-over's evidence lowers the drop trip's share to what an exit that begins in
    /// the armed period could take, not below: the pair says the flute before lost and
    /// the next gained, nothing of the period to come (seeds 417, 489, 537 and 627, normal
    /// cases: a pair in the noise, then an exit whose first period lost 30-37 %). R_r 1.4,
    /// 3 mm radius, 0.2 mm a tooth (`wide_arc`): one feed's travel takes 51 %. After a pair of 5 N each
    /// way (noise of 1 N a tooth: past `EVIDENCE_SIGMAS`, under `EVIDENCE_STRONG_SIGMAS`)
    /// the floor is lowered and the share covers one feed's exit (0.3 before).
    #[test]
    fn a_pair_arms_no_lower_than_an_exit_beginning_after_it() {
        let (a, rr, feed) = wide_arc();
        let arming = |after: &[f32]| {
            let mut st = AlarmState::default();
            for (i, &fx) in forces(1.0, 40, after).iter().enumerate() {
                let rec = wide_record(i, fx);
                assert!(
                    a.process(&mut st, &rec).event.is_none(),
                    "{after:?}: record {i}"
                );
            }
            let evidence = st.handed.is_some() && !st.handed_strong;
            (st.trip_floor_n(), st.trip_share(), evidence)
        };
        let (plain_floor, _, _) = arming(&[0.0; 5]);
        let (floor, share, evidence) = arming(&[0.0, -5.0, 5.0, 0.0, 0.0]);
        assert!(evidence && floor < plain_floor, "{floor} {plain_floor}");
        let one_feed = crate::geometry::exit_loss_share(rr, feed);
        assert!(one_feed > 0.5, "{one_feed}");
        assert!(share > one_feed, "{share}: {one_feed}");
    }

    /// Where a cut spans more than a pitch (its arc and the helix's lag over the depth), a
    /// flute broken inside its period begins its next cut in the window before its own:
    /// after the pair that window loses, and the handed tooth's period is armed all the
    /// same, at what an exit that took that loss would take a feed further on (seed 2352
    /// break 45: 4 flutes, `R_r` 1.41, the window before lost 25 %, the handed one 59 %,
    /// 1.3 revolutions late when that loss disarmed the trip). Where the cut spans less
    /// (`R_r` 0.3 at the same depth: 0.80 + 0.58 rad against `pi/2`), a window that loses
    /// after a pair may be an exit's first tooth: the evidence is void, and the plain trip
    /// asks what that exit takes a feed on (`Alarms::recent_loss`).
    #[test]
    fn a_wide_cut_begins_in_the_window_before_the_handed_tooth() {
        let (a, rr, feed) = wide_arc();
        let arming =
            |rr: f32, newest: f32| wide_arming(&a, rr, 1.0, &[0.0, -5.0, 5.0, 0.0, newest]);
        // 8 N lost: past the evidence's 2 sigma_R and the plain walk's 3.
        let (floor, share, sigma_r) = arming(rr, -8.0);
        assert!(8.0 > 3.0 * sigma_r, "{sigma_r}");
        assert!(floor.is_finite(), "{floor}");
        // At least what the exit that took those 8 N (of tooth 0's 130) takes a feed on.
        let shown = crate::geometry::exit_travel(rr, 8.0 / 130.0);
        let least = crate::geometry::exit_loss_share(rr, shown + feed);
        assert!(
            share >= least && share >= EVIDENCE_SHARE,
            "{share}: {least}"
        );
        // An exit that took more is further on.
        let further = arming(rr, -10.0);
        assert!(
            further.0.is_finite() && further.1 > share,
            "{further:?}: {share}"
        );
        // Within a pitch the evidence is void (an exit's first tooth may follow a pair),
        // and the plain trip asks what an exit that took the newest's loss takes a feed on.
        let (floor, share, _) = arming(0.3, -8.0);
        armed_past_the_narrow_exit((floor, share), 8.0 / 130.0, feed);
        // (Without the loss both are armed.)
        assert!(arming(0.3, 0.0).0.is_finite());
    }

    /// Without an estimate (a feed under the calibrated range) the span is the hand-over
    /// stage's measure: where the window's bins show no quiet stretch (`span_share` over
    /// [`SPAN_SHARE`]) the broken flute's next cut begins in the window before the
    /// handed tooth's, as with an estimate wider than a pitch, and after the pair and that
    /// window's loss the handed tooth's period is armed at the widest arcs' exit that the
    /// loss shows, a feed and the next flute's reach further (seeds 12523 break 1 and 12535
    /// break 105: 4 flutes at 0.07 and 0.05 mm a tooth, `R_r` 1.53 and 1.43; 1.28 and 1.29
    /// revolutions late when the loss disarmed the trip, now 0.98 and 0.94). With a quiet
    /// stretch, or nothing measured, that loss is an exit's first tooth: not armed.
    #[test]
    fn without_an_estimate_the_measured_span_keeps_the_evidence() {
        let (a, _, feed) = wide_arc();
        let arming = |edge: f32, newest: f32| {
            let mut st = AlarmState::default();
            for (i, &fx) in forces(1.0, 40, &[0.0, -5.0, 5.0, 0.0, newest])
                .iter()
                .enumerate()
            {
                st.span_share = edge;
                let rec = record(i, fx, Status::TC_OUT_OF_RANGE);
                assert!(a.process(&mut st, &rec).event.is_none(), "record {i}");
            }
            (st.trip_floor_n(), st.trip_share())
        };
        let (floor, share) = arming(0.3, -8.0);
        assert!(
            floor.is_finite() && share <= TRIP_MAX_SHARE,
            "{floor} {share}"
        );
        let shown = crate::geometry::exit_travel(crate::geometry::RR_MAX, 8.0 / 130.0);
        let least = crate::geometry::widest_exit_loss_share(shown + 2.0 * feed);
        assert!(share >= least, "{share}: {least}");
        for edge in [0.05, f32::NAN] {
            assert!(arming(edge, -8.0).0.is_infinite(), "{edge}");
            assert!(arming(edge, 0.0).0.is_finite(), "{edge}");
        }
    }

    /// Where a cut spans more than a pitch a flute's cut begins in the window before its
    /// own, and a broken flute's next pass loses there first (seeds 9527 break 33 and
    /// 9446 break 57: 4 flutes, the window before lost 9-17 %, past 3 sigma_R, its own
    /// 67-70 %, and the next alarm was the next flute's gain, a period past the
    /// revolution). The plain trip is armed after that loss too, at the share of the exit
    /// that loss would show: as far on as the loss and 3 sigma_R of noise take it, a feed
    /// further and the next flute's reach. Where the tooth before lost too, as far on as
    /// the two losses together show (an exit's windows need not lose in order: seeds 8770
    /// normal 2 and 8783 normal 7 tripped on the newest's alone), and further for a larger
    /// loss. Within a pitch as far as the newest's loss shows, and at least `TRIP_SHARE`.
    #[test]
    fn a_wide_cut_arms_the_trip_after_the_newest_tooths_loss() {
        let (a, rr, feed) = wide_arc();
        let arming_after = |rr: f32, before: f32, newest: f32| {
            wide_arming(&a, rr, 1.0, &[0.0, 0.0, 0.0, before, newest])
        };
        let arming = |rr: f32, newest: f32| arming_after(rr, 0.0, newest);
        // 8 N of tooth 0's 130 lost: past the plain walk's 3 sigma_R.
        let (floor, share, sigma_r) = arming(rr, -8.0);
        assert!(8.0 > 4.0 * sigma_r, "{sigma_r}");
        assert!(
            floor.is_finite() && share <= TRIP_MAX_SHARE,
            "{floor} {share}"
        );
        let shown = crate::geometry::exit_travel(rr, 8.0 / 130.0);
        let least = crate::geometry::exit_loss_share(rr, shown + feed);
        assert!(share > least, "{share}: {least}");
        // An exit that took more is further on; one that took nothing, nearer.
        let further = arming(rr, -10.0);
        assert!(
            further.0.is_finite() && further.1 > share,
            "{further:?}: {share}"
        );
        let quiet = arming(rr, 0.0);
        assert!(quiet.0.is_finite() && quiet.1 < share, "{quiet:?}: {share}");
        // The tooth before lost too: an exit may have taken both (its windows need not lose
        // in order), and is as far on as their sum shows.
        let both = arming_after(rr, -8.0, -8.0);
        let shown = crate::geometry::exit_travel(rr, 16.0 / 130.0);
        let least = crate::geometry::exit_loss_share(rr, shown + feed);
        assert!(
            both.0.is_finite() && both.1 >= least && both.1 > share,
            "{both:?}: {least} {share}"
        );
        let more = arming_after(rr, -30.0, -8.0);
        assert!(
            more.0.is_finite() && more.1 > both.1 + 0.05,
            "{more:?} {both:?}"
        );
        // Within a pitch the plain trip asks that of the newest tooth's loss, and at least
        // `TRIP_SHARE`.
        let (floor, share, _) = arming(0.3, -8.0);
        armed_past_the_narrow_exit((floor, share), 8.0 / 130.0, feed);
        assert!(arming(0.3, 0.0).0.is_finite());
    }

    /// The plain trip's exit is as far on as the newest tooth's own loss shows, with 3
    /// sigma_R of its noise, not as far as the walk's bound on that loss allows (3 sigma_R
    /// more): seeds 9231 break 118 and 9246 break 48, 4 flutes in wide arcs, the broken
    /// flute's next period lost 63 % and 55 % against shares of 0.66 and 0.62, and the
    /// alarms came 0.19 and 0.23 revolutions late; now 0.05 and 0.01 early. Here 3 N of
    /// noise a tooth (sigma_R 4.3-4.5 N): a newest tooth that held asks 0.015 less than one
    /// that lost 12 N (2.7 sigma_R, under the walk's 3); with the bound both asked the
    /// same, to the noise figure's change (0.003).
    #[test]
    fn the_plain_trip_takes_the_exit_the_newest_tooth_shows() {
        let (a, rr, _) = wide_arc();
        let arming = |newest: f32| wide_arming(&a, rr, 3.0, &[0.0, 0.0, 0.0, 0.0, newest]);
        let held = arming(0.0);
        let lost = arming(-12.0);
        assert!(
            held.0.is_finite() && lost.0.is_finite(),
            "{held:?} {lost:?}"
        );
        assert!(12.0 < 3.0 * lost.2, "{lost:?}");
        assert!(held.1 + 0.01 < lost.1, "{held:?} {lost:?}");
        // A tooth that gained shows no exit either.
        let gained = arming(5.0);
        assert!((gained.1 - held.1).abs() < 0.005, "{gained:?} {held:?}");
    }

    /// The plain trip is judged in its own channel's noise where the hand-over stage has
    /// measured it: where that is narrower than the resultant's, inside the period and at
    /// the close (seeds 12421 break 6, 12465 break 119 and 12488 break 82 within a
    /// revolution with it, not without); where it is wider, at the close (seed 9690 taught
    /// 7: 3 flutes, an exit's next window lost 0.507 of its period against a reach of 0.41
    /// plus the resultant's noise, under 0.5; the trip channel's sigma 0.033 of it, the
    /// resultant's 0.024), inside the period the resultant's. The noise term is
    /// `TRIP_NOISE_SIGMAS` of that sigma (on the resultant's scale) over the next tooth's
    /// force a revolution earlier. `wide_arc` after a tooth that lost 12 N (the exit it
    /// shows puts the share over `TRIP_SHARE`); the channel not measured, at half the
    /// resultant's noise and at three times it.
    #[test]
    fn the_trips_share_is_in_its_channels_noise() {
        let (a, rr, _) = wide_arc();
        let arming = |sigma_t: f32| {
            let after = [0.0, 0.0, 0.0, 0.0, -12.0];
            let st = wide_state(&a, rr, 3.0, &after, Some(sigma_t));
            let sigma_r = libm::sqrtf(0.5 * st.e_var);
            let before = st.force(a.n - 1);
            assert!(st.trip_floor_n().is_finite(), "{sigma_t}");
            (st.trip_share(), st.trip_whole_share(), sigma_r, before)
        };
        let (plain, whole, sigma_r, before) = arming(0.0);
        assert!(plain > TRIP_SHARE && plain < TRIP_MAX_SHARE, "{plain}");
        assert_eq!(whole, plain);
        // On the resultant's scale the trip channel's sigma is sqrt(2) of its own.
        let sigma_t = |times: f32| times * sigma_r / core::f32::consts::SQRT_2;
        let close = |times: f32, share: f32| {
            let expect = TRIP_NOISE_SIGMAS * (times - 1.0) * sigma_r / before;
            assert!(libm::fabsf(expect) > 0.015, "{times}: {expect}");
            assert!(
                libm::fabsf(share - plain - expect) < 0.2 * libm::fabsf(expect),
                "{times}: {share} {plain} {expect}"
            );
        };
        let (share, whole, _, _) = arming(sigma_t(0.5));
        close(0.5, share);
        assert_eq!(whole, share);
        let (share, whole, _, _) = arming(sigma_t(3.0));
        assert!(libm::fabsf(share - plain) < 0.01, "{share} {plain}");
        close(3.0, whole);
    }

    /// The trip's share where an exit through a face could take more than half the next
    /// period (R_r 1.4: the arc holds pi/2, the loss grows as the square root of the
    /// travel; 3 mm radius, 0.2 mm a tooth: one feed's travel takes 51 %, two 64 %). An
    /// exit that has begun took its share from the newest tooth too, and that tooth did
    /// not lose: the share is below the two-feed exit's (plus the noise term, 0.70 here).
    /// Exits whose face is reached at every tooth of a revolution and at fractions of a
    /// tooth's travel (the first tooth's loss hidden in the noise, or not), noise-free
    /// losses from the exit's geometry: wherever the trip is armed, the next tooth's loss
    /// stays under its share.
    #[test]
    fn an_exit_that_has_begun_shows_in_the_newest_tooth() {
        let (a, rr, feed) = wide_arc();
        let valid = wide_record;
        let noise = forces(1.0, 60, &[]);
        // Steady: the share against the two-feed exit's.
        let mut st = AlarmState::default();
        for (i, &fx) in noise.iter().take(4 * 40).enumerate() {
            a.process(&mut st, &valid(i, fx));
        }
        let sigma_r = libm::sqrtf(0.5 * st.e_var);
        let two_feed = crate::geometry::exit_loss_share(rr, 2.0 * feed) + 3.0 * sigma_r / 100.0;
        assert!(st.trip_floor_n().is_finite());
        assert!(two_feed > 0.6, "{two_feed}");
        assert!(
            st.trip_share() < two_feed - 0.03,
            "{} vs {two_feed}",
            st.trip_share()
        );
        // Exits; armed before each one's first tooth, and after it where its loss hid.
        let armed = exits_under_the_share(RUNOUT_30, [0.0; 4], 0.0);
        assert!(armed > 4 * EXIT_FRACS.len(), "{armed}");
    }

    /// Where an exit's face is reached, in a tooth's travel.
    const EXIT_FRACS: [f32; 8] = [0.001, 0.003, 0.01, 0.03, 0.1, 0.3, 0.6, 0.9];

    /// `wide_arc`'s cut, the flutes' steady `levels` (1 N of noise), leaving through a face
    /// reached at every tooth of a revolution and at each of `EXIT_FRACS`: tooth `k`'s
    /// flute `ahead[k % 4]` feeds further past it than its place in the sequence (runout),
    /// and `wide` of its window's force is the next flute's cut, a feed further on.
    /// Noise-free losses from the exit's geometry: wherever the trip is armed, the next
    /// tooth's loss stays under its share. The count of records armed in the exits.
    fn exits_under_the_share(levels: [f32; 4], ahead: [f32; 4], wide: f32) -> usize {
        let (a, rr, feed) = wide_arc();
        let noise = forces_at(levels, 1.0, 60, &[]);
        let level = |k: usize| levels[k % 4];
        let mut armed = 0;
        for (start, frac) in (4 * 40..4 * 41).flat_map(|k| EXIT_FRACS.map(|f| (k, f))) {
            // The face reached at `frac` of tooth `start`'s travel.
            let clean = |k: usize| {
                let x = (k as f32 - start as f32 + frac + ahead[k % 4]).max(0.0) * feed;
                let lost = (1.0 - wide) * crate::geometry::exit_loss_share(rr, x)
                    + wide * crate::geometry::exit_loss_share(rr, x + feed);
                level(k) * (1.0 - lost)
            };
            let mut st = AlarmState::default();
            for (i, &fx) in noise.iter().enumerate() {
                let f = fx - level(i) + clean(i);
                a.process(&mut st, &wide_record(i, f));
                if i + 1 >= start && st.trip_floor_n().is_finite() {
                    armed += 1;
                    let (before, after) = (clean(i + 1 - 4), clean(i + 1));
                    assert!(
                        before - after < st.trip_share() * before,
                        "exit from {start} at {frac}, record {i}: {} of {before} against {}",
                        before - after,
                        st.trip_share()
                    );
                }
            }
        }
        armed
    }

    /// An exit under runout: flute 0 out by 0.3 of the feed cuts a chip of 1.3 feeds and
    /// flute 1 of 0.7 (forces 130, 70, 100, 100 N), and flute 0's reach past the face is
    /// 0.3 of a tooth's travel ahead of its place (seed 1900 normal 32: the heaviest of 4
    /// flutes lost past the share computed at one feed). Every exit stays under the share.
    #[test]
    fn a_heavy_flute_reaches_its_chip_past_an_exit_face() {
        let armed = exits_under_the_share([130.0, 70.0, 100.0, 100.0], [0.3, 0.0, 0.0, 0.0], 0.0);
        assert!(armed > 4 * EXIT_FRACS.len(), "{armed}");
    }

    /// After a hand-over's pair the share covers what an exit hidden in the newest tooth
    /// takes at the next flute's reach, a heavy flute's too, where the two-feed exit is
    /// under `EVIDENCE_SHARE` (seed 3804 normal 11: 3 flutes, 8 mm, `R_r` 1.0, 0.18 mm a
    /// tooth, a noise pair, then an exit; the handed tooth, 17 % over the revolution's
    /// mean, lost 30 % against a share of 0.30, the two-feed exit's; its reach asks 0.32).
    /// Here 4 flutes of that cut, one 40 % heavy, its tooth's loss handed on by 14 N (3 N
    /// of noise a tooth: evidence, not a strong pair; 32 N at 4 N): armed for it, the share is the exit's
    /// at the travel the newest tooth's own loss allows (that loss, 0 for a gain, and 3
    /// sigma_R of its force; a feed at most) and the heavy flute's chip further, `F_next /
    /// F_mean + wide` feeds; and, the pair's loss being one noise could make in a cut
    /// within a pitch, `EVIDENCE_NOISY_SIGMAS` of its noise over that (seed 13070 normal 28
    /// with no current-loop lag: an exit's handed window 42 % down in the truth against a
    /// reach of 0.43, 47 % measured). Not where the tooth lost past `1 -
    /// EVIDENCE_NOISY_KEPT` of its force, nor in a cut whose span passes a pitch by more than
    /// `EVIDENCE_NOISY_WIDE` of it (a broken flute's window there loses about the reach).
    #[test]
    fn a_pair_arms_over_a_heavy_flutes_reach() {
        let (rr, tc_mm) = (1.0, 0.18);
        let est = EstimatorConfig::default();
        assert_eq!(est.tool.radius_mm, 8.0);
        let feed = tc_mm / est.tool.radius_mm;
        // The case this is about: two feeds' exit under the evidence's least share.
        assert!(crate::geometry::exit_loss_share(rr, 2.0 * feed) < EVIDENCE_SHARE);
        let a = AlarmConfig::default().build(&est).unwrap();
        let levels = [140.0, 60.0, 100.0, 100.0];
        // The share armed after the heavy flute's loss and the next one's gain, on a cut
        // whose helix lags over `ra`; and the share computed here, with the noise term
        // if `noisy`.
        let armed = |ra: f32, (loss, gain): (f32, f32), noise: f32, noisy: bool| {
            let f = forces_at(levels, noise, 40, &[-loss, gain, 0.0, 0.0]);
            let mut st = AlarmState::default();
            for (i, &fx) in f.iter().enumerate() {
                let rec = ToothRecord {
                    rr,
                    ra,
                    tc_mm,
                    ..record(i, fx, Status::VALID)
                };
                assert!(a.process(&mut st, &rec).event.is_none(), "record {i}");
            }
            // Armed for tooth 0 on the pair's evidence.
            assert!(
                st.handed == Some(0) && !st.handed_strong && st.trip_floor_n().is_finite(),
                "{ra} {loss} {gain}"
            );
            let k = f.len() - 1;
            let before = f[k - 3];
            let ahead = before / (f[k - 3..].iter().sum::<f32>() / 4.0);
            let span = crate::geometry::engaged_arc_rad(rr) + ra * libm::tanf(30f32.to_radians());
            let wide = ((span - core::f32::consts::FRAC_PI_2) / span).max(0.0);
            // The exit the newest tooth allows: its own loss (0 for a gain) and 3 sigma_R
            // of its force a revolution earlier, a feed at most.
            let mean = st.hist_rev[st.slot(0)];
            let sigma_r = libm::sqrtf(0.5 * a.decision_var(&st, mean).unwrap());
            let own = ((f[k - 4] - f[k]) / sigma_r).max(0.0);
            let hidden = (own + TRIP_QUIET_SIGMAS) * sigma_r / f[k - 4];
            let x = crate::geometry::exit_travel(rr, hidden).min(feed);
            // (For the pair noise could make, under a feed: the own loss decides, not the
            // bound `kept` checked.)
            assert!(x < feed || !noisy, "{x} {feed}");
            let reach = crate::geometry::exit_loss_share(rr, x + feed * (ahead + wide));
            assert!(reach > EVIDENCE_SHARE, "{reach}");
            // The watched tooth's force kept over the pair's revolution.
            let kept = before / f[k - 7];
            let could_be_noise = kept >= EVIDENCE_NOISY_KEPT;
            assert_eq!(
                could_be_noise && wide <= EVIDENCE_NOISY_WIDE,
                noisy,
                "{kept} {wide}"
            );
            let noise = if noisy {
                EVIDENCE_NOISY_SIGMAS * sigma_r / before
            } else {
                0.0
            };
            // (A margin the trip can tell: 2 sigma_R is 7 % of the tooth here.)
            assert!(!noisy || noise > 0.05, "{noise}");
            (st.trip_share(), reach + noise)
        };
        for (ra, pair, noise, noisy) in [
            // A pair noise could make (14 N, a tenth of the tooth), within a pitch.
            (0.05, (14.0, 14.0), 3.0, true),
            // A loss past a fifth of the tooth (32 N; at 4 N of noise, with its gain, no
            // strong pair).
            (0.05, (32.0, 3.0), 4.0, false),
            // The helix's lag over 1.2 times the radius puts the span 29 % past a pitch.
            (1.2, (14.0, 14.0), 3.0, false),
        ] {
            let (share, expected) = armed(ra, pair, noise, noisy);
            assert!(
                (share - expected).abs() < 1e-3,
                "{ra} {pair:?}: {share} vs {expected}"
            );
        }
    }

    /// `wide_arc`'s cut spans its arc, `acos(1 - R_r)` = 1.98 rad, and the helix's lag
    /// over the depth, `R_a tan 30 deg` = 0.58 rad: 2.56 rad against a pitch of 1.57. Each
    /// window holds the start of the next flute's cut too, 39 % of its force, a feed
    /// further on (seed 1981 normal 10: 4 flutes, `R_r` 1.18, the span 2.36 rad; an
    /// exit's window lost 57 % after the one before lost nothing, against a share of
    /// 0.58; held out, `a_window_holding_two_flutes_cuts_loses_a_feed_further_on`). Every
    /// exit stays under the share (here with the noise term's margin without the span
    /// too).
    #[test]
    fn a_window_that_holds_two_flutes_cuts_loses_a_feed_further_on() {
        let span = libm::acosf(1.0 - 1.4) + libm::tanf(30.0f32.to_radians());
        let wide = (span - core::f32::consts::FRAC_PI_2) / span;
        assert!((wide - 0.386).abs() < 0.002, "{wide}");
        let armed = exits_under_the_share(RUNOUT_30, [0.0; 4], wide);
        assert!(armed > 4 * EXIT_FRACS.len(), "{armed}");
    }

    /// The drop trip inside a period (`crate::handover`) is armed out of a steady cut, at
    /// 6 sigma of `R = F_k - F_{k-N}` (noise of 3 N on each tooth: sigma_R = 3 sqrt 2 N);
    /// after teeth that lost force at the share of the exit their loss shows, a feed on
    /// (an exit: every tooth loses), not where that exit takes most of the force; not after
    /// a revolution that held where the ones before fell (an exit that paused); and again
    /// after a loss the next tooth took back (a flute broken in its period).
    #[test]
    fn the_drop_trip_is_armed_out_of_a_steady_cut_and_not_in_an_exit() {
        let floor = trip_floor_after(&[]);
        // (Plus the next tooth's gain a revolution ago where past 1.5 sigma_R: its
        // reference stands that high.)
        let sigma_r = 3.0 * core::f32::consts::SQRT_2;
        let f = forces(3.0, 40, &[]);
        let gain = f[156] - f[152];
        let expected = 6.0 * sigma_r + if gain > 1.5 * sigma_r { gain } else { 0.0 };
        assert!(
            (floor - expected).abs() < 0.25 * expected,
            "{floor} vs {expected}"
        );
        // The newest tooth lost 20 N (4.7 sigma_R), or the two newest 12 N each: an exit may
        // be under way, as far on as that loss shows with its noise (`narrow_arc`, 0.2 mm a
        // tooth at the default radius), and the trip asks what it takes a feed further on.
        // A run that lost most of the teeth's force: it takes the rest.
        let feed = 0.2 / EstimatorConfig::default().tool.radius_mm;
        let (_, quiet) = trip_arming_after(&[]);
        for (after, lost) in [
            ([0.0, 0.0, 0.0, -20.0], 20.0),
            ([0.0, 0.0, -12.0, -12.0], 24.0),
        ] {
            let (floor, share) = trip_arming_after(&after);
            armed_past_the_narrow_exit((floor, share), lost / 100.0, feed);
            assert!(share > quiet, "{after:?}: {share} {quiet}");
        }
        assert!(trip_floor_after(&[0.0, -40.0, -40.0, -40.0]).is_infinite());
        // A hand-over: tooth 1 lost 15 N (3.5 sigma_R), tooth 2 gained them.
        assert!(trip_floor_after(&[0.0, -15.0, 15.0, 0.0]).is_finite());
        // An exit that lost 8 N a tooth each revolution for three, then paused for one:
        // its newest revolution lost nothing, but the newest two lost 160 N against the two
        // three revolutions earlier (about 13 of that change's noise). A cut that rose so
        // is armed.
        let fading = |d: f32| [[d; 4], [2.0 * d; 4], [3.0 * d; 4], [3.0 * d; 4]].concat();
        assert!(trip_floor_after(&fading(-8.0)).is_infinite());
        assert!(trip_floor_after(&fading(8.0)).is_finite());
    }

    /// After the history is forgotten at a lost pulse, the trip is armed again from the
    /// first tooth armed with its own a revolution earlier, `N + 1` records on (not after
    /// two revolutions: a flute broken there would be caught past a revolution). At a
    /// moved window out of a steady cut, from the first record after it (the hand-over
    /// stage re-cut its profiles), asking that stage to check the periods since for a loss
    /// (`trip_quiet_n`, `TRIP_QUIET_SIGMAS sigma_R`), until the records have their own.
    #[test]
    fn the_drop_trip_is_armed_again_after_a_forget() {
        let est = EstimatorConfig::default();
        let a = AlarmConfig::default().build(&est).unwrap();
        let f = forces(3.0, 42, &[]);
        let at = 40 * 4;
        let armed = |forget: Status| {
            let mut st = AlarmState::default();
            let mut out = Vec::new();
            for (i, &fx) in f.iter().enumerate() {
                let status = if i == at {
                    Status(Status::AMBIGUOUS.0 | forget.0)
                } else {
                    Status::AMBIGUOUS
                };
                a.process(&mut st, &record(i, fx, status));
                out.push((st.trip_floor_n(), st.trip_quiet_n()));
            }
            out
        };
        let lost = armed(Status(Status::NO_SYNC.0 | Status::PERIOD_INVALID.0));
        assert!(lost[at - 1].0.is_finite());
        for (k, (floor, _)) in lost.iter().enumerate().skip(at).take(5) {
            assert!(floor.is_infinite(), "{} records after: {floor}", k - at);
        }
        assert!(lost[at + 5].0.is_finite() && lost[at + 5].1.is_infinite());
        let moved = armed(Status(Status::WINDOW_MOVED.0 | Status::PERIOD_INVALID.0));
        assert!(moved[at].0.is_infinite());
        for (k, &(floor, quiet)) in moved.iter().enumerate().skip(at + 1).take(4) {
            assert!(floor.is_finite(), "{} records after", k - at);
            // (The floor there is FIRST_TOOTH_SIGMAS sigma_R.)
            let want = TRIP_QUIET_SIGMAS / FIRST_TOOTH_SIGMAS * floor;
            assert!((quiet - want).abs() < 1e-3 * want, "{quiet} against {want}");
        }
        assert!(moved[at + 5].0.is_finite() && moved[at + 5].1.is_infinite());
    }

    /// Record `i` of a cut whose window moved at record `at` (its odd period 375 samples,
    /// 250 before, `len` after): its tangential force, the watched one, at `f2_n`.
    fn record_across_move(i: usize, at: usize, f2_n: f32, len: u32) -> ToothRecord {
        let moved = Status(Status::WINDOW_MOVED.0 | Status::PERIOD_INVALID.0);
        let mut rec = record(i, 0.0, if i == at { moved } else { Status::AMBIGUOUS });
        rec.f2_n = f2_n;
        rec.samples = match i {
            _ if i == at => 375,
            _ if i > at => len,
            _ => 250,
        };
        rec
    }

    /// Processes record `i` carrying its change from its re-cut profile `recut` [N] (NaN:
    /// none), keeping the first event's index and cause in `raised`.
    fn process_recut(
        a: &Alarms,
        st: &mut AlarmState,
        (i, rec): (usize, &ToothRecord),
        recut: f32,
        raised: &mut Option<(usize, Cause)>,
    ) {
        let ev = a
            .process_with(st, rec, None, (recut, 0.0, 0, &NOT_TOLD), &mut NoProbe)
            .event;
        if let (None, Some(e)) = (*raised, ev) {
            *raised = Some((i, e.cause));
        }
    }

    /// A flute broken in a moved window's odd period: the alarm's history crosses the move,
    /// but the hand-over stage's re-cut profiles show the next flute's gain in the first
    /// period after it. The odd tooth's next period (and, 4 flutes, the one before it) is
    /// armed on that evidence: 4 sigma_R instead of 6, the evidence's share instead of the
    /// plain one. Not on a gain under 4.5 sigma_R, nor on a loss (an exit's), nor where the
    /// periods since the move are shorter than those before it (a speed change moves force
    /// across the boundaries), nor where they are as long as those before the odd period
    /// but longer than those a revolution before that (a ramp under way as the window
    /// moved, 2 samples a tooth: seed 12813 normal 115).
    #[test]
    fn a_gain_on_its_recut_profile_after_a_move_arms_the_odd_tooths_next_period() {
        let est = EstimatorConfig::default();
        let a = AlarmConfig::default().build(&est).unwrap();
        let f = forces(3.0, 42, &[]);
        let at = 40 * 4;
        // (floor, share) after each record; `first`: the change of the first period after
        // the move from its re-cut profile [N] (the rest of that revolution: none), `len`:
        // the periods' length after it.
        let run_ramped = |first: f32, len: u32, ramp: u32| {
            let mut st = AlarmState::default();
            let mut out = Vec::new();
            let mut raised = None;
            for (i, &force) in f.iter().enumerate() {
                // (The tangential channel alone: the watched force is it, and so is the
                // re-cut change, which the record carries.)
                let f2_n = if i == at + 1 && first.is_finite() {
                    force + first
                } else {
                    force
                };
                let mut rec = record_across_move(i, at, f2_n, len);
                if i < at && i + 8 >= at {
                    rec.samples = 250 - ramp * (at - i) as u32;
                }
                let recut = match i - at.min(i) {
                    1 => first,
                    2..=4 => 0.0,
                    _ => f32::NAN,
                };
                process_recut(&a, &mut st, (i, &rec), recut, &mut raised);
                out.push((st.trip_floor_n(), st.trip_share()));
            }
            (out, raised)
        };
        let run = |first: f32, len: u32| run_ramped(first, len, 0);
        // The odd tooth (0) opens after tooth 3's record, 3 after the first one.
        let (plain, none) = run(f32::NAN, 250);
        let plain = plain[at + 3];
        let sigma_r = plain.0 / FIRST_TOOTH_SIGMAS;
        assert!(
            plain.0.is_finite() && plain.1 >= TRIP_SHARE && none.is_none(),
            "{plain:?}"
        );
        let (handed, raised) = run(6.0 * sigma_r, 250);
        assert_eq!(raised, None);
        for k in [at + 2, at + 3] {
            let (floor, share) = handed[k];
            let want = EVIDENCE_TRIP_SIGMAS * sigma_r;
            assert!(
                (floor - want).abs() < 1e-3 * want,
                "{k}: {floor} against {want}"
            );
            assert!(share >= EVIDENCE_SHARE && share < plain.1, "{k}: {share}");
        }
        for (first, len, ramp) in [
            (4.0 * sigma_r, 250, 0),
            (-6.0 * sigma_r, 250, 0),
            (6.0 * sigma_r, 245, 0),
            (6.0 * sigma_r, 250, 2),
        ] {
            let armed = run_ramped(first, len, ramp).0;
            for (floor, share) in [armed[at + 2], armed[at + 3]] {
                assert!(
                    floor >= plain.0 && share >= plain.1,
                    "{first} {len} {ramp}: {floor} {share}"
                );
            }
        }
        // Raised at the gain as a first tooth is: past `FIRST_TOOTH_SHARE` of the gaining
        // tooth's profile (its force less the gain) and `FIRST_TOOTH_SIGMAS` sigma_R; under
        // both, armed as above. Three times `E`'s threshold (on the revolution mean, no
        // estimate; its noise floor `R`'s), which alone raised before, lies far above.
        let first = (FIRST_TOOTH_SHARE * f[at + 1]).max(FIRST_TOOTH_SIGMAS * sigma_r);
        let mean = RUNOUT_30.iter().sum::<f32>() / 4.0;
        let k = AlarmConfig::default().breakage.threshold_rel;
        let limit = SINGLE_EXCEEDANCE * (k * mean).max(E_SIGMAS * sigma_r);
        assert!(first < 0.7 * limit, "{first} {limit}");
        assert_eq!(run(1.05 * first, 250).1, Some((at + 1, Cause::Breakage)));
        let (armed, none) = run(0.95 * first, 250);
        assert_eq!(none, None);
        assert!(armed[at + 3].0 < plain.0, "{:?}", armed[at + 3]);
    }

    /// The record after the revolution that follows a moved window: its change from a
    /// revolution earlier is on the records, but the tooth before it had the odd period
    /// then, and its change is known only against its re-cut profile. That pair (a loss
    /// there, this tooth's gain) is taken as in the revolution before: raised past three
    /// times `E`'s threshold. Not without the loss (a gain alone is `R`'s, no pair).
    #[test]
    fn a_pair_across_a_move_is_taken_on_the_record_after_its_revolution() {
        let est = EstimatorConfig::default();
        let a = AlarmConfig::default().build(&est).unwrap();
        let f = forces(3.0, 42, &[]);
        let at = 40 * 4;
        let (bridge, before) = (at + 5, at + 4);
        // The first breakage raised, where the tooth before the bridging record lost
        // `loss` in its first period since the move (on its re-cut profile and its record
        // alike) and the bridging record's tooth gained `gain` on its record; and `E`'s
        // threshold there, three times over: `k` of the revolution mean (no estimate) or 5
        // of the pair's noise (two teeth's `R`), the wider.
        let run = |loss: f32, gain: f32| {
            let mut st = AlarmState::default();
            let (mut raised, mut limit) = (None, f32::NAN);
            for (i, &force) in f.iter().enumerate() {
                let change = match i {
                    _ if i == before => -loss,
                    _ if i == bridge => gain,
                    _ => 0.0,
                };
                let rec = record_across_move(i, at, force + change, 250);
                if i == bridge {
                    let mean = (1..4).map(|k| st.force(k - 1)).sum::<f32>() + rec.f2_n;
                    let var_r = 0.5 * a.decision_var(&st, mean / 4.0).unwrap();
                    let k = a.config().breakage.threshold_rel;
                    let floor = E_SIGMAS * libm::sqrtf(2.0 * var_r);
                    limit = SINGLE_EXCEEDANCE * (k * mean / 4.0).max(floor);
                }
                let recut = match i - at.min(i) {
                    1..=3 => 0.0,
                    4 => -loss,
                    _ => f32::NAN,
                };
                process_recut(&a, &mut st, (i, &rec), recut, &mut raised);
            }
            (raised, limit)
        };
        let limit = run(0.0, 0.0).1;
        assert!(limit.is_finite());
        let half = |share: f32| 0.5 * share * limit;
        assert_eq!(
            run(half(1.05), half(1.05)).0,
            Some((bridge, Cause::Breakage))
        );
        assert_ne!(
            run(half(0.95), half(0.95)).0,
            Some((bridge, Cause::Breakage))
        );
        assert_ne!(run(0.0, 1.1 * limit).0, Some((bridge, Cause::Breakage)));
    }

    /// A trip latches the output at once; the records after it name the cause: the next
    /// flute's gain a breakage (one empty window alone is not a lost tool), every tooth
    /// empty a lost tool.
    #[test]
    fn a_drop_trip_latches_at_once_and_is_named_by_the_records_after_it() {
        let broken = [0.0, -100.0, 100.0, 0.0];
        let f = forces(3.0, 40, &[broken, broken].concat());
        let (latched, event) = trip_then(&f, 161, usize::MAX);
        assert!(latched);
        let (i, cause) = event.unwrap();
        assert_eq!(cause, Cause::Breakage);
        assert!((161..=163).contains(&i), "{i}");
        // The flute's window empty and flagged not cutting (the monitor's test on the
        // revolution mean, under its floor before the next flute takes the chip: seed 8800
        // break 22): a breakage still, not a lost tool.
        let (latched, event) = trip_then(&f, 161, 161);
        assert!(latched);
        assert_eq!(event.map(|e| e.1), Some(Cause::Breakage));
        // The tool gone from tooth 1 of the revolution: the tripped period partly cut.
        let mut f = forces(3.0, 40, &[0.0; 8]);
        f[161] *= 0.5;
        for x in f.iter_mut().skip(162) {
            *x = 0.0;
        }
        let (latched, event) = trip_then(&f, 161, 161);
        assert!(latched);
        let (i, cause) = event.unwrap();
        assert_eq!(cause, Cause::ToolGone);
        assert!((161..=163).contains(&i), "{i}");
        // The drives swing as the load goes at once: the tooth after the tripped period
        // keeps a little over GONE_SHARE of its force (33 %), the next 8 % (over the not-cutting
        // floor; seed 8473 gone 29). Still a lost tool; a flute lost keeps the two together.
        let mut f = forces(3.0, 40, &[0.0; 8]);
        f[161] *= 0.6;
        f[162] *= GONE_SHARE + 0.03;
        for x in f.iter_mut().skip(163) {
            *x *= 0.08;
        }
        let (latched, event) = trip_then(&f, 161, usize::MAX);
        assert!(latched);
        assert_eq!(event.map(|e| e.1), Some(Cause::ToolGone));
    }

    /// A flute lost between its engagements: its next period loses its whole force (tooth
    /// 1: -100 N), the tooth after takes the chip (+100 N): decided on the gain, the drop
    /// alone is not (the first tooth of an exit through a face drops as much) unless it
    /// leaves the tooth empty at the steady feed, which latches the output at once (an
    /// exit takes a share of the arc a feed of travel reaches, far under the whole).
    /// Steady runout and noise, and an exit's fall, never latch.
    #[test]
    fn a_lost_flute_is_decided_on_the_tooth_that_takes_its_chip() {
        let steady = forces(3.0, 40, &[0.0; 16]);
        assert_eq!(first_latch(&steady, usize::MAX), (None, None));
        let broken = [0.0, -100.0, 100.0, 0.0];
        let f = forces(3.0, 40, &[broken, broken].concat());
        assert_eq!(
            first_latch(&f, usize::MAX),
            (Some(161), Some((162, 162, Cause::Breakage)))
        );
        // (Not empty, 90 N down: decided on the gain.)
        let broken = [0.0, -90.0, 90.0, 0.0];
        let f = forces(3.0, 40, &[broken, broken].concat());
        assert_eq!(
            first_latch(&f, usize::MAX),
            (Some(162), Some((162, 162, Cause::Breakage)))
        );
        // The hand-over first (the flute broke after its engagement in the period before
        // the sync pulse's): a tooth that gains a flute's chip alone is decided at once.
        let handed = [0.0, 100.0, -100.0, 0.0];
        let f = forces(3.0, 40, &[handed, handed].concat());
        assert_eq!(
            first_latch(&f, usize::MAX),
            (Some(161), Some((161, 161, Cause::Breakage)))
        );
        // The flute broke late in its period (tooth 1 lost a quarter), the next took the
        // chip: the hand-over decides on the rise.
        let late = [0.0, -25.0, 100.0, -75.0];
        let f = forces(3.0, 40, &[late, late].concat());
        assert_eq!(
            first_latch(&f, usize::MAX),
            (Some(162), Some((162, 162, Cause::Breakage)))
        );
        // An exit through a face square to the feed: the arc's far reach (the thickest
        // chip) leaves first, the force falls as the square root of the travel: a third
        // of it on the first tooth, every tooth after lower still.
        let mut f = forces(3.0, 40, &[0.0; 12]);
        for (j, x) in f.iter_mut().skip(161).enumerate() {
            *x *= 1.0 - 0.8 * libm::sqrtf(((j + 1) as f32 / 5.0).min(1.0));
        }
        assert_eq!(first_latch(&f, usize::MAX), (None, None));
    }

    /// E is there from the ninth record of a 4-flute cut: 16 values (the least the rules
    /// decide on, their floor widened by `sqrt(32 / 16)`) by record 24, the 32 of a settled
    /// spread only by record 40. A flute lost in between is the steady pattern by then.
    #[test]
    fn a_flute_lost_in_the_first_revolutions_of_a_cut_is_caught() {
        let broken = [0.0, -100.0, 100.0, 0.0];
        let f = forces(3.0, 7, &[broken, broken, broken, broken].concat());
        // (Its empty period latches the output: see the test above.)
        assert_eq!(
            first_latch(&f, usize::MAX),
            (Some(29), Some((30, 30, Cause::Breakage)))
        );
        let steady = forces(3.0, 11, &[]);
        assert_eq!(first_latch(&steady, usize::MAX), (None, None));
    }

    /// A steady cut whose window moved at record 160 (the period after it flagged for its
    /// length too), then, 7 teeth on, a tooth that lost `pair` N (its record flagged
    /// transient if `flagged`) and the next that gained as much, once. Each record's first
    /// event (index, cause) and the drop trip's floor after it.
    fn pair_after_move(pair: f32, flagged: bool) -> (Option<(usize, Cause)>, Vec<f32>) {
        // (Four flutes alike at 200 N and `k` at half of it: `E`'s rules, at three times
        // `k F` or both signs past it, and the first tooth's, at 35 % of the tooth, leave
        // the pair to its own rule.)
        let mut cfg = AlarmConfig::default();
        cfg.breakage.threshold_rel = 0.5;
        let a = cfg.build(&EstimatorConfig::default()).unwrap();
        let (forget, loss) = (160, 168);
        let mut f = forces_at([200.0; 4], 3.0, 40, &[0.0; 16]);
        f[loss] -= pair;
        f[loss + 1] += pair;
        let mut st = AlarmState::default();
        let (mut event, mut floors) = (None, Vec::new());
        for (i, &fx) in f.iter().enumerate() {
            let status = match i {
                _ if i == forget => Status::WINDOW_MOVED | Status::PERIOD_INVALID,
                _ if i == forget + 1 => Status::PERIOD_INVALID,
                _ if i == loss && flagged => Status::AMBIGUOUS | Status::TRANSIENT,
                _ => Status::AMBIGUOUS,
            };
            let out = a.process(&mut st, &record(i, fx, status));
            if let (None, Some(e)) = (event, out.event) {
                event = Some((i, e.cause));
            }
            floors.push(st.trip_floor_n());
        }
        (event, floors)
    }

    /// A hand-over pair right after a moved window: a flagged loss counts only out of a
    /// cut whose revolutions before it held, not armed yet there, so it raises where it is
    /// as far past the noise and the threshold `k F` as `pair_raises` asks (60 N each
    /// side, 120 against 100; seed 13375 break 9 waited for the trip on the broken flute's
    /// next pass), as an unflagged one does, and a flagged one under that arms nothing (40
    /// N each side: the plain trip's floor, 6 sigma_R, where the unflagged pair arms the
    /// evidence's 4 less the loss).
    #[test]
    fn a_flagged_pair_just_after_a_move_raises_only_far_past_the_noise() {
        for flagged in [false, true] {
            assert_eq!(
                pair_after_move(60.0, flagged).0,
                Some((169, Cause::Breakage)),
                "flagged {flagged}"
            );
        }
        let (event, plain) = pair_after_move(40.0, true);
        assert_eq!(event, None);
        let (event, evidence) = pair_after_move(40.0, false);
        assert_eq!(event, None);
        // The handed tooth's next period is armed by the record before it (171).
        assert!(
            evidence[171] < 0.8 * plain[171],
            "{} against {}",
            evidence[171],
            plain[171]
        );
    }

    /// A steady cut whose tooth history is forgotten at record `forget` (the window moved;
    /// the period after it flagged for its length too), then `f` goes on; records from
    /// `gone_from` on at or under 5 N are not cutting. The first event: index and cause.
    fn first_event_after_forget(
        f: &[f32],
        forget: usize,
        gone_from: usize,
    ) -> Option<(usize, Cause)> {
        let a = alarms_at_5n();
        let mut st = AlarmState::default();
        for (i, &fx) in f.iter().enumerate() {
            let status = match i {
                _ if i == forget => Status::WINDOW_MOVED | Status::PERIOD_INVALID,
                _ if i == forget + 1 => Status::PERIOD_INVALID,
                _ if i >= gone_from && fx <= 5.0 => Status::NOT_CUTTING,
                _ => Status::AMBIGUOUS,
            };
            if let Some(e) = a.process(&mut st, &record(i, fx, status)).event {
                return Some((i, e.cause));
            }
        }
        None
    }

    /// The first event of a steady cut (AMBIGUOUS: not a valid estimate, so the threshold
    /// is on the measured force, about 107 N) whose record `at` carries the hand-over
    /// `(z, newtons)`; the record before it transient if `transient_before`.
    fn first_event_with_handover(
        at: usize,
        handover: (f32, f32),
        transient_before: bool,
    ) -> Option<(usize, Cause)> {
        first_event_with_handover_at(at, handover, transient_before, 0, u8::MAX)
    }

    /// ... the spindle faster by `shorter` samples a tooth over the two revolutions that
    /// end at `at`, and `quiet` boundaries in a row (`Alarms::process_with`'s `lag_quiet`).
    fn first_event_with_handover_at(
        at: usize,
        handover: (f32, f32),
        transient_before: bool,
        shorter: u32,
        quiet: u8,
    ) -> Option<(usize, Cause)> {
        let a = AlarmConfig::default()
            .build(&EstimatorConfig::default())
            .unwrap();
        let mut st = AlarmState::default();
        for (i, &fx) in forces(3.0, 40, &[0.0; 16]).iter().enumerate() {
            let status = if transient_before && i + 1 == at {
                Status::TRANSIENT
            } else {
                Status::AMBIGUOUS
            };
            let mut rec = record(i, fx, status);
            if i == at {
                (rec.handover_z, rec.handover_n) = handover;
            }
            if i + 8 > at && i <= at {
                faster(&mut rec, shorter);
            }
            let c: (f32, f32, u8, &dyn Fn(usize) -> f32) = (f32::NAN, 0.0, quiet, &NOT_TOLD);
            if let Some(e) = a.process_with(&mut st, &rec, None, c, &mut NoProbe).event {
                return Some((i, e.cause));
            }
        }
        None
    }

    /// The hand-over inside a period (`crate::handover`) decides past HANDOVER_SIGMAS (4.5) and
    /// HANDOVER_SHARE of the breakage threshold (`0.2 * 0.2 * 107 N`, 4.3 N), out of a
    /// steady cut only; the tooth averages themselves unchanged (the rules on them see
    /// nothing).
    #[test]
    fn a_hand_over_inside_the_period_decides_out_of_a_steady_cut() {
        assert_eq!(first_event_with_handover(165, (0.0, 0.0), false), None);
        assert_eq!(
            first_event_with_handover(165, (4.6, 10.0), false),
            Some((165, Cause::Breakage))
        );
        // Within the noise (4.0-4.12 sigma in three normal cuts of seeds 673-864), too
        // small to matter, or after a transient record: none.
        assert_eq!(first_event_with_handover(165, (4.4, 10.0), false), None);
        assert_eq!(first_event_with_handover(165, (4.6, 4.0), false), None);
        assert_eq!(first_event_with_handover(165, (4.6, 10.0), true), None);
        // A speed change: the current loop's lag, a time, moves the force across the bins
        // (seed 306 break case 105, 2 flutes, before its damage: 11.98 N at 4.41 sigma as
        // the spindle sped up by 1-2 % a tooth). The newest two revolutions 0.4 % shorter
        // than the two before are as long (to 1 % and two samples: the pulses' jitter);
        // 1.2 % shorter, they are not.
        assert_eq!(
            first_event_with_handover_at(165, (4.6, 10.0), false, 1, u8::MAX),
            Some((165, Cause::Breakage))
        );
        assert_eq!(
            first_event_with_handover_at(165, (4.6, 10.0), false, 3, u8::MAX),
            None
        );
        // The lengths alike, but the boundaries' lag still moving after a ramp (seed 8345
        // normal 17: a hand-over of 4.9 sigma 7 teeth after the ramp, the lengths 202 and
        // 206 samples in turn): only once the boundaries of both periods (here 4 teeth:
        // past 4 in a row) lie where a revolution earlier.
        assert_eq!(
            first_event_with_handover_at(165, (4.6, 10.0), false, 0, 4),
            None
        );
        assert_eq!(
            first_event_with_handover_at(165, (4.6, 10.0), false, 0, 5),
            Some((165, Cause::Breakage))
        );
    }

    /// A flute lost just after the history was forgotten: by the time two revolutions are
    /// armed again its empty period is the steady pattern and no revolution-to-revolution
    /// rule can see it. The empty period, with the next tooth cutting, is decided in those
    /// two revolutions; steady runout (flute 0 at 130 %, the flute after it at 100 %) and a
    /// tool lost there are not breakages.
    #[test]
    fn a_flute_lost_while_the_history_is_forgotten_is_still_caught() {
        let steady = forces(3.0, 40, &[0.0; 32]);
        assert_eq!(first_event_after_forget(&steady, 160, usize::MAX), None);
        // Flute 2 lost at the move: tooth 2 empty from record 162 on, tooth 3 takes its chip;
        // or, with arcs wider than a pitch, tooth 2's window keeps the end of flute 1's cut
        // (40 N, 37 % of the mean).
        for lost in [100.0, 60.0] {
            let broken = [0.0, 0.0, -lost, lost];
            let f = forces(3.0, 40, &[broken; 8].concat());
            let (at, cause) = first_event_after_forget(&f, 160, usize::MAX).unwrap();
            assert_eq!(cause, Cause::Breakage);
            assert!((162..=160 + 2 * 4 + 2).contains(&at), "decided at {at}");
        }
        // The strongest runout of the evaluation: flute 1 at 65 % of the tooth (60 % of
        // the mean, flute 0 at 130 %).
        let runout = forces(3.0, 40, &[[0.0, -35.0, 0.0, 0.0]; 8].concat());
        let runout: Vec<f32> = runout
            .iter()
            .enumerate()
            .map(|(i, &f)| if i % 4 == 1 && i < 160 { f - 35.0 } else { f })
            .collect();
        assert_eq!(first_event_after_forget(&runout, 160, usize::MAX), None);
        // The whole tool lost after the move: tool gone, not a breakage (the newest tooth
        // alone empty is not decided).
        let mut f = forces(3.0, 40, &[0.0; 3]);
        f.extend([0.5; 8]);
        // (Forgotten at 156: armed again from 157, a revolution mean from 160, two from
        // 164; the tool lost at 163, and not cutting by the monitor's flag a revolution
        // later.)
        let gone = first_event_after_forget(&f, 156, 167);
        assert_eq!(gone.map(|e| e.1), Some(Cause::ToolGone));
    }

    /// The tool lost late in a tripped period in the revolutions after a forget (the
    /// window moved), that period left a share of its force just over the collapse's and
    /// the teeth after it nearly none: the trip named a lost tool, not a breakage by the
    /// rule for a resumed cut on the first empty tooth (seed 3731 gone 23: 31 %, then 1 %).
    #[test]
    fn a_tool_lost_inside_a_tripped_period_after_a_forget_is_a_lost_tool() {
        let a = alarms_at_5n();
        // (The flutes as the case's: 1 100, 590, 880 and 820 N; lost in the weak one's
        // period, the revolution mean stays a steady cut's.)
        for (lost_at, kept) in [161, 165, 169]
            .into_iter()
            .flat_map(|i| [(i, 0.31), (i, 0.4)])
        {
            let mut f = forces_at([130.0, 70.0, 104.0, 97.0], 3.0, 40, &[0.0; 16]);
            f[lost_at] *= kept;
            for x in f.iter_mut().skip(lost_at + 1) {
                *x *= 0.01;
            }
            let mut st = AlarmState::default();
            let mut event = None;
            for (i, &fx) in f.iter().enumerate() {
                if i == lost_at {
                    a.trip(&mut st, 100.0, 50.0, trip_sample(i));
                }
                let status = match i {
                    156 => Status::WINDOW_MOVED | Status::PERIOD_INVALID,
                    157 => Status::PERIOD_INVALID,
                    // (The monitor's not-cutting flag, on the revolution mean, a
                    // revolution later.)
                    _ if i > lost_at + 4 => Status::NOT_CUTTING,
                    _ => Status::AMBIGUOUS,
                };
                let out = a.process(&mut st, &record(i, fx, status));
                event = event.or(out.event.map(|e| (i, e.cause)));
            }
            let (i, cause) = event.unwrap();
            assert_eq!(
                cause,
                Cause::ToolGone,
                "lost at {lost_at} ({kept}), named at {i}"
            );
        }
    }

    /// Default alarms for a 2-flute tool, the not-cutting floor at `floor_n`.
    fn alarms_2_flutes(floor_n: f32) -> Alarms {
        alarms_flutes(2, floor_n)
    }

    /// ... for a tool of `flutes` flutes.
    fn alarms_flutes(flutes: u8, floor_n: f32) -> Alarms {
        let est = EstimatorConfig {
            force_floor_n: floor_n,
            tool: crate::Tool {
                flutes,
                ..EstimatorConfig::default().tool
            },
            ..EstimatorConfig::default()
        };
        AlarmConfig::default().build(&est).unwrap()
    }

    /// Feeds `len` (at most 120) records of a 2-flute cut to `a`, record `i` made by
    /// `make(i, e)` from its noise `e` (`sigma` N; drawn for every record: skipping one
    /// would shift the runout taken out of the noise by a tooth, and a 30 N pattern
    /// repeating every other revolution would make pairs), its tooth `i % 2`. The first
    /// event: its record and cause.
    fn first_event_2_flutes(
        a: &Alarms,
        sigma: f32,
        len: usize,
        make: impl FnMut(usize, f32) -> ToothRecord,
    ) -> Option<(usize, Cause)> {
        first_latch_2_flutes(a, sigma, len, make).map(|(_, named, cause)| (named, cause))
    }

    /// ... the record the output latched at, the one that named its cause, and the cause.
    fn first_latch_2_flutes(
        a: &Alarms,
        sigma: f32,
        len: usize,
        make: impl FnMut(usize, f32) -> ToothRecord,
    ) -> Option<(usize, usize, Cause)> {
        first_latch_flutes(a, 2, sigma, len, make)
    }

    /// ... of a cut with `flutes` flutes, record `i`'s tooth `i % flutes`.
    fn first_latch_flutes(
        a: &Alarms,
        flutes: usize,
        sigma: f32,
        len: usize,
        mut make: impl FnMut(usize, f32) -> ToothRecord,
    ) -> Option<(usize, usize, Cause)> {
        let mut noise = forces(sigma, 30, &[]).into_iter();
        let mut st = AlarmState::default();
        for i in 0..len {
            let e = noise.next().unwrap() - if i % 4 == 0 { 130.0 } else { 100.0 };
            let mut rec = make(i, e);
            rec.tooth = (i % flutes) as u8;
            if let Some(e) = a.process(&mut st, &rec).event {
                // (The record the output latched at, `record`'s 250 samples each: an
                // empty window's is named on a later one.)
                let latched = (e.latched_sample / 250) as usize;
                return Some((latched.saturating_sub(1), i, e.cause));
            }
        }
        None
    }

    /// A light flute of a 2-flute tool under runout broken inside its cut (seed 10573
    /// break 21's forces: 64 and 285 N, no estimate; 7 N of noise leaves `E` the case's
    /// spread, about 18 N): its window loses 23 N, then the rest, and the heavy flute
    /// gains 28 N, then 45 N more, so no revolution's `E` passes its floor (five of its
    /// sigma) and the monitor flags the record after as a change. Against three
    /// revolutions earlier the pair is past 9 sigma_R: a breakage on the second gain. The
    /// same forces with the spindle 4 % faster since the revolution before the break (the
    /// current loop's lag moves force between the windows) are not judged that way.
    #[test]
    fn a_light_flute_broken_inside_its_cut_is_a_pair_against_revolutions_earlier() {
        let a = alarms_2_flutes(10.0);
        let first = |samples: u32| {
            first_event_2_flutes(&a, 7.0, 110, |i, e| {
                let f = match i {
                    80 => 41.0,
                    81 => 313.0,
                    82 | 84.. if i % 2 == 0 => 5.0 + e,
                    83.. => 357.0 + e,
                    _ if i % 2 == 0 => 64.0 + e,
                    _ => 285.0 + e,
                };
                let status = match i {
                    84 => Status::TRANSIENT | Status::SETTLING,
                    85..=99 => Status::SETTLING,
                    _ => Status::TC_OUT_OF_RANGE,
                };
                let mut rec = record(i, f, status);
                rec.samples = if i >= 78 { samples } else { 250 };
                rec
            })
        };
        assert_eq!(first(250), Some((83, Cause::Breakage)));
        // (Its empty window at the steady feed latched the output a record earlier, and no
        // rule named it: a breakage three records on.)
        assert_eq!(first(240), Some((85, Cause::Breakage)));
        // The other order, a gain on the tooth before and a loss on the newest, is no
        // flute's chip handed on: two flutes of 310 N, one 62 N up by noise, then the tool
        // lost inside the other's window, 98 N down (seed 10632 gone 10, its pair 20 %
        // larger), is a lost tool.
        let lost = first_event_2_flutes(&a, 7.0, 110, |i, e| {
            let (f, status) = match i {
                82 => (372.0, Status::TC_OUT_OF_RANGE),
                83 => (212.0, Status::TC_OUT_OF_RANGE),
                84 => (-4.0 + e, Status::TRANSIENT | Status::SETTLING),
                85.. => (e, Status::NOT_CUTTING),
                _ => (310.0 + e, Status::TC_OUT_OF_RANGE),
            };
            record(i, f, status)
        });
        assert_eq!(lost.map(|(_, cause)| cause), Some(Cause::ToolGone));
    }

    /// A light flute of a 3-flute tool under runout broken inside its cut (seed 13076
    /// break 107 at noise seed 3347570: the trip's records from four revolutions before
    /// the break, its forces 37, 127 and 184 N, no estimate): its window keeps 15 N, then 8,
    /// then nothing, while the flute after it gains 36 N, so neither one revolution's
    /// change nor the two revolutions' means pass their floors. As a hand-over pair on the
    /// means it passes 9 sigma_R: a breakage. Not where the gain is on the tooth two after
    /// the loss (the chip goes to the flute right after the broken one), nor with the
    /// spindle 4 % faster since the revolution before (the current loop's lag moves force
    /// between windows).
    #[test]
    fn a_light_flute_of_three_broken_inside_its_cut_is_a_pair_on_the_means() {
        // Records 70.. as measured (tooth `i % 3`, 2 the light one), `[F_x, F_2]` [N];
        // before them the steady forces at the case's noise figure (`sigma_R` 6.2 N on
        // the means, as the monitor had it).
        const MEASURED: [(f32, f32); 34] = [
            (-60.4, 184.2),
            (-17.8, 34.1),
            (-44.4, 126.5),
            (-61.4, 171.6),
            (-8.2, 37.4),
            (-37.9, 122.9),
            (-60.9, 187.3),
            (-9.2, 28.8),
            (-39.6, 129.1),
            (-68.0, 184.3),
            (-13.0, 31.3),
            (-37.8, 126.3),
            (-66.8, 193.6),
            (-3.2, 14.6),
            (-55.5, 162.8),
            (-61.3, 178.6),
            (-7.5, 7.6),
            (-63.9, 157.5),
            (-63.7, 193.2),
            (1.9, 1.0),
            (-54.8, 163.3),
            (-60.2, 181.1),
            (-0.9, -9.0),
            (-53.5, 168.4),
            (-65.3, 185.4),
            (-1.6, 4.1),
            (-56.3, 158.4),
            (-71.0, 181.0),
            (2.6, 5.4),
            (-49.4, 164.6),
            (-62.8, 173.4),
            (-5.4, 5.6),
            (-61.0, 162.8),
            (-60.2, 187.1),
        ];
        let a = alarms_flutes(3, 2.0);
        // `skipped`: the gain on tooth 1, two after the loss, from the break on.
        let first = |skipped: bool, samples: u32| {
            first_latch_flutes(&a, 3, 4.0, 70 + MEASURED.len(), |i, e| {
                let steady = [(-40.0, 126.0 + e), (-63.0, 184.0 + e), (-11.0, 33.0 + e)][i % 3];
                let (fx, mut f2) = i
                    .checked_sub(70)
                    .and_then(|k| MEASURED.get(k).copied())
                    .unwrap_or(steady);
                if skipped && i >= 83 && i % 3 != 2 {
                    f2 += if i % 3 == 0 { -36.0 } else { 36.0 };
                }
                let mut rec = record(i, fx, Status::TC_OUT_OF_RANGE);
                rec.f2_n = f2;
                rec.samples = if i >= 78 { samples } else { 250 };
                rec
            })
        };
        let got = first(false, 250);
        assert!(matches!(got, Some((_, 87, Cause::Breakage))), "{got:?}");
        assert_eq!(first(true, 250), None);
        assert_eq!(first(false, 240), None);
    }

    /// A 2-flute tool lost a tooth after the window moved (seed 8572 gone 5, its forces):
    /// the move's odd period, a full period and a partly cut one (both flagged transient
    /// as the monitor flags them), one nearly empty, then not cutting, the fifth record
    /// since the last steady one. The odd period is the move's: the collapse is within two
    /// revolutions of the steady cut and the tool is lost, named on the nearly empty one
    /// (the tooth before it down on its own). The same cut going on raises nothing.
    #[test]
    fn a_tool_lost_just_after_a_moved_window_is_a_lost_tool() {
        let a = alarms_2_flutes(30.0);
        let first = |lost: bool| {
            first_event_2_flutes(&a, 3.0, 100, |i, e| {
                let level = if i % 2 == 0 { 230.0 } else { 290.0 };
                let f = match (lost, i) {
                    (_, 80) => 262.0,
                    (true, 81) => 202.0,
                    (true, 82) => 78.0,
                    (true, 83) => 2.6,
                    (true, 84..) => 0.0,
                    _ => level + e,
                };
                let status = match (lost, i) {
                    (_, 80) => Status::WINDOW_MOVED | Status::PERIOD_INVALID,
                    (true, 81..=83) => Status::TRANSIENT | Status::SETTLING,
                    (true, 84..) => Status::NOT_CUTTING,
                    _ => Status::AMBIGUOUS,
                };
                record(i, f, status)
            })
        };
        assert_eq!(first(false), None);
        assert_eq!(first(true), Some((83, Cause::ToolGone)));
    }

    /// A 2-flute tool lost inside a tooth's cut: that window keeps part of its force and
    /// the next one is empty (both flagged transient, as the monitor flags them). A lost
    /// tool on that first empty window, not a revolution later where the second comes
    /// (seeds 10018 gone 3 and 28: 49 % and 59 % left, then nothing). A window that lost
    /// under `GONE_BEFORE_SIGMAS` latches the output there too, named a lost tool on the
    /// second (seeds 13378 gone 7, 13381 gone 15 and 13387 gone 16 waited for it). The
    /// same empty window after the other flute's gain is a broken flute's, and after its
    /// unchanged window where the flute broke at its cut's start, 3 sigma_R down by noise
    /// (seed 10123 break 48), latched there and named on the gain; and a feed turned
    /// down, the light flute under runout idle and the heavy one lower, is no lost tool
    /// (the same forces at the steady feed would be one).
    #[test]
    fn with_two_flutes_a_tool_lost_inside_a_cut_is_named_on_the_first_empty_window() {
        let a = alarms_2_flutes(30.0);
        // `after(i, level)`: record i's force from record 79 on; `tc_mm` from 80 on.
        let first = |levels: [f32; 2], after: &dyn Fn(usize, f32) -> f32, tc_mm: f32| {
            let mut before = 0.0;
            first_latch_2_flutes(&a, 3.0, 100, |i, e| {
                let level = levels[i % 2];
                let f = if i < 79 {
                    level + e
                } else {
                    after(i, level) + e / 3.0
                };
                // (The monitor's not-cutting flag: on the revolution's mean.)
                let status = match i {
                    80..=82 => Status::TRANSIENT | Status::SETTLING,
                    _ if f + before < 60.0 => Status::NOT_CUTTING,
                    _ => Status::AMBIGUOUS,
                };
                before = f;
                let mut rec = record(i, f, status);
                if i >= 80 {
                    rec.tc_mm = tc_mm;
                }
                rec
            })
        };
        let levels = [230.0, 290.0];
        let lost = |kept: f32| {
            move |i: usize, level: f32| match i {
                79 => level,
                80 => kept * level,
                _ => 3.0,
            }
        };
        for kept in [0.5, 0.85] {
            assert_eq!(
                first(levels, &lost(kept), 0.2),
                Some((81, 81, Cause::ToolGone)),
                "{kept}"
            );
        }
        assert_eq!(
            first(levels, &lost(0.95), 0.2),
            Some((81, 82, Cause::ToolGone))
        );
        // Flute 0 broken half way through its cut: flute 1 takes the rest of its chip,
        // then the whole of it; flute 0's windows are empty. Or broken at its cut's start,
        // flute 1's window before 9 N down.
        let broken = |start: bool| {
            move |i: usize, level: f32| match i {
                79 if start => level - 9.0,
                79 => level,
                80 if !start => 0.5 * level,
                81 if !start => level + 115.0,
                _ if i % 2 == 0 => 3.0,
                _ => level + 230.0,
            }
        };
        // (Broken at its cut's start, its empty window at the steady feed latched the
        // output, named on the gain after it.)
        assert_eq!(
            first(levels, &broken(false), 0.2),
            Some((81, 81, Cause::Breakage))
        );
        assert_eq!(
            first(levels, &broken(true), 0.2),
            Some((80, 81, Cause::Breakage))
        );
        // The feed halved: the light flute (100 N) idle, the heavy one 40 % down (the
        // force the feed leaves still well over the floor).
        let halved = |i: usize, level: f32| match i {
            79 => level,
            _ if i % 2 == 1 => 3.0,
            _ => 0.6 * level,
        };
        assert_eq!(first([500.0, 100.0], &halved, 0.1), None);
        assert_eq!(
            first([500.0, 100.0], &halved, 0.2),
            Some((81, 81, Cause::ToolGone))
        );
    }

    /// A 2-flute tool whose flute breaks in the first period armed after a forget: that
    /// period is partly cut, and the flute's first empty one is the newest record (left out:
    /// the first of a lost tool) until the revolution mean has its change, when the rule
    /// for a resumed cut stopped deciding before. By then the empty period is the steady
    /// pattern: at seed 87, break case 9 (forces as here), caught 96 revolutions on.
    /// Decided now within the two revolutions (from the partly cut period on, 90 N of a
    /// 210 N mean, under `MISSING_SHARE`); steady runout there is not a breakage.
    #[test]
    fn a_2_flute_tool_broken_in_the_first_period_after_a_forget_is_caught() {
        let a = alarms_2_flutes(5.0);
        // Flute 0 at 195 N, flute 1 at 225 N, noise 14 N; the window moved at record 80.
        // `broken`: flute 1 breaks 40 % into its period at record 81, flute 0 cuts its
        // chip from then on.
        let first = |broken: bool, sigma: f32| {
            first_event_2_flutes(&a, sigma, 120, |i, e| {
                let level = if i % 2 == 0 { 195.0 } else { 225.0 };
                let lost = match (broken, i) {
                    (true, 81) => -135.0,
                    (true, 82) => 135.0,
                    (true, 83..) if i % 2 == 1 => -222.0,
                    (true, 83..) => 225.0,
                    _ => 0.0,
                };
                // (As the monitor flags them: the broken flute's periods transient, all
                // settling.)
                let status = match i {
                    80 => Status::WINDOW_MOVED | Status::PERIOD_INVALID,
                    81.. if broken && i % 2 == 1 => Status::TRANSIENT | Status::SETTLING,
                    81.. if broken => Status::SETTLING,
                    _ => Status::AMBIGUOUS,
                };
                record(i, level + lost + e, status)
            })
        };
        // (At 3 N the rules on `E` see it too; at the case's 14 N only this one.)
        for sigma in [3.0, 14.0] {
            assert_eq!(first(false, sigma), None);
            let (at, cause) = first(true, sigma).unwrap();
            assert_eq!(cause, Cause::Breakage);
            assert!((82..=80 + 2 * 2 + 2).contains(&at), "decided at {at}");
        }
    }

    /// A breakage whose redistribution settles over three revolutions (runout: the chips
    /// after a break are cut from the surface every flute before left): tooth 1 loses 12 N
    /// a revolution and tooth 2 gains them, under every threshold one revolution at a time
    /// (about 21 N; `E` swings 24 N against 27), caught against three revolutions earlier.
    /// An entry whose teeth grow by 10 % a revolution (with the runout's tooth 0 growing
    /// most), an exit that shrinks them as fast, and the redistribution while the speed
    /// changes are not.
    #[test]
    fn a_redistribution_over_revolutions_is_caught_against_three_earlier() {
        let steps = |per_rev: [f32; 4]| -> Vec<f32> {
            (1..=6)
                .flat_map(|r| per_rev.map(|x| x * r.min(4) as f32))
                .collect()
        };
        let slow = steps([0.0, -12.0, 12.0, 0.0]);
        // Three revolutions of 12 N: decided in the third (records 160-171).
        let at = first_breakage(&forces(3.0, 40, &slow));
        assert!(at.is_some_and(|i| (168..172).contains(&i)), "{at:?}");
        // One revolution of it, held: nothing.
        let once: Vec<f32> = (0..24).map(|k| [0.0, -12.0, 12.0, 0.0][k % 4]).collect();
        assert_eq!(first_breakage(&forces(3.0, 40, &once)), None);
        for sign in [1.0f32, -1.0] {
            let ramp = steps([13.0 * sign, 10.0 * sign, 10.0 * sign, 10.0 * sign]);
            assert_eq!(first_breakage(&forces(3.0, 40, &ramp)), None, "{sign}");
        }
        // The same redistribution while the spindle speeds up by 2 % a revolution (the
        // current loop's lag moves force across the boundaries): not judged against three
        // revolutions earlier.
        let a = AlarmConfig::default()
            .build(&EstimatorConfig::default())
            .unwrap();
        let mut st = AlarmState::default();
        for (i, &fx) in forces(3.0, 40, &slow).iter().enumerate() {
            let mut rec = record(i, fx, Status::TRANSIENT);
            let revs = i.saturating_sub(159) / 4;
            rec.samples = 250 - 5 * revs.min(4) as u32;
            let out = a.process(&mut st, &rec);
            assert!(out.event.is_none(), "record {i}");
        }
    }

    /// A light cut, whose noise is large against `k F` (30 N a tooth, `k F` 6 N, sigma_E
    /// 8 N): E's running spread is the spread of the E values themselves, computed here
    /// from the forces. Clipped at `k F` alone it came out at 0.61 of that, and every floor
    /// set in it with it: an exit's tail raised breakages on pairs of 4-sigma noise (seed
    /// 3642 normal 103).
    #[test]
    fn the_noise_figure_of_a_light_cut_is_its_noise() {
        let f = forces_at([30.0; 4], 4.0, 150, &[]);
        let a = alarms_at_5n();
        let mut st = AlarmState::default();
        let mut learned = Vec::new();
        for (i, &fx) in f.iter().enumerate() {
            let out = a.process(&mut st, &record(i, fx, Status::AMBIGUOUS));
            assert!(!out.latched, "record {i}");
            if i >= 200 {
                learned.push(st.e_var);
            }
        }
        // E_i = F_i - F_{i-1} - F_{i-4} + F_{i-5}, over the same records.
        let e: Vec<f32> = (200..f.len())
            .map(|i| f[i] - f[i - 1] - f[i - 4] + f[i - 5])
            .collect();
        let var = e.iter().map(|x| x * x).sum::<f32>() / e.len() as f32;
        let mean_learned = learned.iter().sum::<f32>() / learned.len() as f32;
        let ratio = (mean_learned / var).sqrt();
        assert!((ratio - 1.0).abs() < 0.1, "learned spread / spread {ratio}");
    }

    /// One tooth's force off by `x` in a steady cut: `E` swings both ways at once (`E_i =
    /// -x`, `E_{i+1} = +x`), a breakage's pattern from a single tooth's noise. Noise 3 N a
    /// tooth: sigma_E 6 N; the threshold `5 sigma_E` (30 N, over `k F` = 21 N) plus the
    /// revolution mean's change `x / 4`. `x` = 37 N stays under it (at a 4-sigma floor it
    /// raised); twice that, past the threshold alone, is decided. Under the threshold with
    /// the teeth on either side a little the other way, both `E` pass, but the second is
    /// the first's mirror: one exceedance, not decided, up or down. A broken flute's next
    /// tooth takes its chip (`R_0`), or the exceedance of the gain came first and the loss
    /// before it (`R_2`): past [`MIRROR_SHARE`] of the floor, decided.
    #[test]
    fn a_single_tooth_excursion_is_not_a_breakage() {
        // The first breakage with `after` (padded to 12 teeth) in `noise` N of noise.
        let first = |noise: f32, after: &[f32]| {
            let mut padded = [0.0; 12];
            padded[..after.len()].copy_from_slice(after);
            first_breakage(&forces(noise, 40, &padded))
        };
        assert_eq!(first(3.0, &[0.0, 0.0, 0.0, 0.0, 0.0, -37.0]), None);
        assert!(first(3.0, &[0.0, 0.0, 0.0, 0.0, 0.0, -74.0]).is_some());
        for x in [-1.0, 1.0] {
            let after = [0.0, 0.0, 0.0, 0.0, 10.0 * x, -26.0 * x, 10.0 * x];
            assert_eq!(first(3.0, &after), None, "{x}");
        }
        // The loss, then its gain.
        for (gain, decided) in [(10.0, false), (20.0, true)] {
            let after = [0.0, 0.0, 0.0, 0.0, 10.0, -26.0, gain];
            assert_eq!(first(3.0, &after).is_some(), decided, "gain {gain}");
        }
        // The gain first, its loss before it, each under the threshold, the tooth after the
        // gain down a little. Noise 1 N: the floor `k F` (21.5 N).
        for (loss, decided) in [(8.0, false), (14.0, true)] {
            let after = [0.0, 0.0, 0.0, -loss, 19.0, -8.0];
            assert_eq!(first(1.0, &after), decided.then_some(165), "loss {loss}");
        }
    }

    /// An exit under heavy runout (flute 0 at three times the others' force): each tooth
    /// loses 40 % of its force, the light teeth a revolution before the heavy one (as a
    /// face passes them). The heavy tooth's loss makes an exceedance of `E` and its mirror
    /// the next; the shared tooth `R_1` passes the threshold alone, but not its share of
    /// the revolution's change: no breakage (seed 4712 normal 100). A light flute broken in
    /// the same cut is one.
    #[test]
    fn an_exit_under_runout_is_not_a_breakage() {
        let levels = [300.0, 100.0, 100.0, 100.0];
        let exit: Vec<f32> = (0..12)
            .map(|k| match (k % 4, k < 4) {
                (0, true) => 0.0,
                (0, false) => -120.0,
                _ => -40.0,
            })
            .collect();
        assert_eq!(first_breakage(&forces_at(levels, 1.0, 40, &exit)), None);
        let broken: Vec<f32> = (0..12)
            .map(|k| match k % 4 {
                2 => -100.0,
                3 => 100.0,
                _ => 0.0,
            })
            .collect();
        assert!(first_breakage(&forces_at(levels, 1.0, 40, &broken)).is_some());
    }

    /// A tooth up by a first tooth's share out of quiet teeth is decided (the flute before
    /// broke after its cut, and this one took its chip); not where the quiet teeth rose
    /// together past 2.5 sigma of their sum, each under the quiet bound: an entry (seed 3279
    /// wear 5: 3 teeth up 1.3-2 sigma_R each, then a flute's step into the cut, 6.1
    /// sigma_R). Falling together they are no entry: decided.
    #[test]
    fn a_first_tooth_out_of_teeth_rising_together_is_an_entry() {
        let est = EstimatorConfig::default();
        let a = AlarmConfig::default().build(&est).unwrap();
        for (rise, entry) in [(0.0, false), (-8.0, false), (11.0, true)] {
            // Teeth 2, 3 and 0 (records 162-164) by `rise`, then tooth 1 up by 40 N.
            let f = forces(3.0, 40, &[0.0, 0.0, rise, rise, rise, 40.0]);
            let mut st = AlarmState::default();
            let mut first = None;
            for (i, &fx) in f.iter().enumerate() {
                if i == 165 {
                    // Each of the three within the quiet bound; together past the trend's
                    // or not.
                    let s = libm::sqrtf(0.5 * st.e_var);
                    let r: Vec<f32> = (162..165).map(|k| f[k] - f[k - 4]).collect();
                    let quiet = FIRST_TOOTH_QUIET_SIGMAS * s;
                    assert!(r.iter().all(|r| r.abs() <= quiet), "{rise}: {r:?} {s}");
                    let sum = r.iter().sum::<f32>() / (s * libm::sqrtf(3.0));
                    assert_eq!(sum > FIRST_TOOTH_TREND_SIGMAS, entry, "{rise}: {sum}");
                }
                let out = a.process(&mut st, &record(i, fx, Status::AMBIGUOUS));
                if first.is_none() && out.event.is_some_and(|e| e.cause == Cause::Breakage) {
                    first = Some(i);
                }
            }
            assert_eq!(first, (!entry).then_some(165), "{rise}");
        }
    }

    #[test]
    fn a_steep_ramp_is_not_a_first_tooth() {
        // Down by 12 % of the level a revolution, tooth by tooth (an exit in 8 revolutions).
        let ramp: Vec<f32> = (0..32).map(|k| -0.03 * 100.0 * (k + 1) as f32).collect();
        let f = forces(3.0, 40, &ramp);
        assert_eq!(first_latch(&f, usize::MAX).0, None);
    }

    #[test]
    fn a_loss_spread_over_two_periods_is_decided_when_the_gain_completes_it() {
        // Noise 6 N a tooth: sigma_E 12 N, the floor 5 sigma_E = 60 N is above k F (21 N),
        // 4.5 sigma_R = 38 N. Flute 1 breaks while several flutes are engaged: teeth 1 and 2
        // each lose 45 N (below the floor in E), tooth 3 gains the 90 N (the revolution
        // total stays). The revolution changes R = (-45, -45, +90) have both signs beyond
        // max(k F, 4.5 sigma_R) at tooth 3: decided there, one tooth before the first
        // differences have both signs (tooth 0 of the next revolution: E = -90).
        let steady = forces(6.0, 30, &[0.0; 12]);
        assert_eq!(first_breakage(&steady), None, "steady runout and noise");
        let broken = [0.0, -45.0, -45.0, 90.0];
        let f = forces(6.0, 30, &[broken, broken, broken].concat());
        assert_eq!(first_breakage(&f), Some(4 * 30 + 3));
        // A step of the engagement by 40 % (flute 0, out by 30 %, gains 30 % more): every
        // R one way, no alarm.
        let step = [52.0, 40.0, 40.0, 40.0];
        let f = forces(
            6.0,
            30,
            &[[0.0, 40.0, 40.0, 40.0], step, step, step].concat(),
        );
        assert_eq!(first_breakage(&f), None);
    }

    /// A flute's loss under the noise of single teeth (noise 6 N a tooth; sigma_R 9.4 N as
    /// the rules estimate it): tooth 1 loses 42 N for good and tooth 2 takes them. One
    /// revolution's `R` (-42, +42) stays under the floor of `4.5 sigma_R`, the changes
    /// from three revolutions earlier too, and `E` passes `5 sigma_E` only once, with one
    /// sign: without the means no rule decides it in 8 revolutions. Each tooth's mean over
    /// the newest two revolutions against its mean over the two three revolutions earlier
    /// has the noise of `R` over sqrt 2 (the floor 30 N): decided in the revolution after
    /// the break's, the first whose newest two are both past it. The same change on every
    /// tooth (an engagement step) is not.
    /// Flagged transient from the break on (the monitor's revolution means see it as one)
    /// it is decided as well; with the two earlier revolutions flagged too (a cut still
    /// changing before the loss, an exit's: seed 2906 normal 57), not.
    #[test]
    fn a_loss_under_single_teeths_noise_is_decided_on_two_revolutions_means() {
        let broken = [0.0, -42.0, 42.0, 0.0];
        let f = forces(6.0, 30, &[broken; 8].concat());
        let from = |first: usize| {
            let a = AlarmConfig::default()
                .build(&EstimatorConfig::default())
                .unwrap();
            let mut st = AlarmState::default();
            f.iter().enumerate().find_map(|(i, &fx)| {
                let status = if i >= first {
                    Status::TRANSIENT
                } else {
                    Status::AMBIGUOUS
                };
                let out = a.process(&mut st, &record(i, fx, status));
                out.event
                    .is_some_and(|e| e.cause == Cause::Breakage)
                    .then_some(i as i64 - (4 * 30 + 1))
            })
        };
        // (From the break's tooth: tooth 0 of the next revolution is 3.)
        for first in [usize::MAX, 4 * 30 + 1] {
            let at = from(first);
            assert!(at.is_some_and(|k| (3..7).contains(&k)), "{first}: {at:?}");
        }
        assert_eq!(from(4 * 30 - 8), None);
        let step = [42.0 * 1.3, 42.0, 42.0, 42.0];
        assert_eq!(first_breakage(&forces(6.0, 30, &[step; 8].concat())), None);
    }

    /// The same loss, its gain split between the next two teeth (an arc wider than a
    /// pitch: the next flute's cut spans two windows). Neither gain, 21 N, passes the
    /// means' floor of 30 N, and `E` passes `5 sigma_E` once, with one sign (+63 N): only
    /// the two neighbouring gains together decide it, in the revolution after the break's
    /// as above. Split over two teeth that are not neighbours, it is not decided; nor is a
    /// step on every tooth; nor the same pattern in records flagged transient (a cut
    /// changing its shape moves its teeth's shares in pairs: seed 2101 normal 90).
    #[test]
    fn a_gain_split_between_two_neighbouring_teeth_completes_a_loss() {
        let decided = |change: [f32; 4], status: Status| {
            let f = forces(6.0, 30, &[change; 8].concat());
            first_breakage_as(&f, status).map(|i| i as i64 - (4 * 30 + 1))
        };
        let at = decided([0.0, -42.0, 21.0, 21.0], Status::AMBIGUOUS);
        assert!(at.is_some_and(|k| (3..7).contains(&k)), "{at:?}");
        assert_eq!(decided([21.0, -42.0, 21.0, 0.0], Status::AMBIGUOUS), None);
        assert_eq!(decided([30.0, 30.0, 30.0, 30.0], Status::AMBIGUOUS), None);
        assert_eq!(decided([0.0, -42.0, 21.0, 21.0], Status::TRANSIENT), None);
    }

    /// The first event (index and cause) of the forces fed as records of a 5 N floor, each
    /// with the status `status(i, force)`.
    fn first_event(f: &[f32], status: impl Fn(usize, f32) -> Status) -> Option<(usize, Cause)> {
        let a = alarms_at_5n();
        let mut st = AlarmState::default();
        f.iter().enumerate().find_map(|(i, &fx)| {
            let out = a.process(&mut st, &record(i, fx, status(i, fx)));
            out.event.map(|e| (i, e.cause))
        })
    }

    #[test]
    fn a_fade_over_two_revolutions_is_not_a_lost_tool_and_a_loss_after_a_forget_is() {
        // A fast exit: the first tooth loses 10 % (the cut still steady), then every tooth
        // less, under the floor on the eighth, two revolutions after the last steady
        // record. Only the two empty teeth at the end look like a lost tool's.
        let share = [
            0.9, 0.55, 0.35, 0.22, 0.14, 0.09, 0.06, 0.02, 0.01, 0.0, 0.0, 0.0,
        ];
        let level = |k: usize| if k % 4 == 0 { 130.0 } else { 100.0 };
        let mut f = forces(1.0, 20, &[]);
        f.extend(share.iter().enumerate().map(|(j, s)| s * level(80 + j)));
        f.extend([0.0; 8]);
        let cut = |_: usize, fx: f32| {
            if fx > 5.0 {
                Status::AMBIGUOUS
            } else {
                Status::NOT_CUTTING
            }
        };
        assert_eq!(first_event(&f, cut), None);
        // The tool lost right after the window moved (two records with force but without
        // good data): caught on the first empty tooth.
        let mut f = forces(1.0, 20, &[]);
        f.extend([100.0, 100.0, 40.0]);
        f.extend([0.0; 8]);
        let moved = |i: usize, fx: f32| match i {
            80 => Status::WINDOW_MOVED,
            81 => Status::PERIOD_INVALID,
            _ => cut(i, fx),
        };
        assert_eq!(first_event(&f, moved), Some((83, Cause::ToolGone)));
    }

    /// The drop trip's share after a steady cut at feed `tc_mm` (radius 8 mm, no valid
    /// estimate: the worst `R_r`); `None` where not armed.
    fn trip_share_at(tc_mm: f32) -> Option<f32> {
        let est = EstimatorConfig::default();
        let a = AlarmConfig::default().build(&est).unwrap();
        let mut st = AlarmState::default();
        for (i, &fx) in forces(1.0, 20, &[]).iter().enumerate() {
            let rec = ToothRecord {
                tc_mm,
                ..record(i, fx, Status::AMBIGUOUS)
            };
            a.process(&mut st, &rec);
        }
        st.trip_floor_n().is_finite().then(|| st.trip_share())
    }

    #[test]
    fn the_drop_trip_asks_more_than_an_exit_can_take() {
        assert_eq!(EstimatorConfig::default().tool.radius_mm, 8.0);
        // 0.05 mm: an exit's second tooth loses at most 2q/(1+q) = 27 % (q = 0.16).
        assert_eq!(trip_share_at(0.05), Some(TRIP_SHARE));
        // 0.2 mm: 48 %, and 3 sigma_R of a 1 N noise on 100 N (about 4 %); 1 mm: 80 %.
        for (tc_mm, x) in [(0.2, 0.05), (1.0, 0.25)] {
            let share = trip_share_at(tc_mm).unwrap();
            let q = libm::sqrtf(x * (2.0 - x));
            let bound = 2.0 * q / (1.0 + q);
            assert!(
                share > bound + 0.03 && share < bound + 0.06,
                "{share} vs {bound}"
            );
        }
        // 2 mm: 93 %, not armed.
        assert_eq!(trip_share_at(2.0), None);
    }
}
