//! The scenario file of `host-sim simulate`: tool, material, machine, signal chain and a
//! timeline of segments and events (TOML; see `host-sim/examples/cut.toml`).
//!
//! Every table refuses unknown keys (a misspelt key would otherwise keep a default and
//! simulate another cut than the one asked for); TOML errors name the line, validation
//! errors name the key path (`segment[2].rpm`).
//!
//! The machine sections have the shape of [`estimator_core::MonitorConfig`]'s: `input`
//! (the drive and spindle models, `estimator_core::monitor::Input`) and `sync`
//! (`estimator_core::tooth::SyncMode`) are the core's own types, so the `[input...]`
//! tables of a monitor configuration can be pasted here unchanged and the replay inverts
//! exactly the models that were simulated.

use anyhow::{anyhow, bail, Result};
use estimator_core::coefficients::{CuttingCoefficients, LinearCoefficients, PowerLaw};
use estimator_core::monitor::Input;
use estimator_core::tooth::SyncMode;
use estimator_core::{MillingMode, MonitorConfig, TABLE2};
use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::{Deserialize, Serialize, Serializer};
use std::fmt;

/// Most flutes a scenario may have (`true_flutes_intact` is a bit mask; the per-sample
/// work uses fixed arrays of this size).
pub const MAX_FLUTES: usize = 16;

/// A whole simulation: what is cut, with what, on which machine, and when.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// ADC sample rate [Hz]; one trace row per sample.
    pub sample_rate_hz: f64,
    /// Seed of every random stream (noise, jitter, dropouts): same seed, same bits.
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Milling mode of every segment that does not give its own.
    #[serde(default)]
    pub mode: MillingMode,
    /// Where the power-law coefficients are evaluated (ignored by the linear model).
    #[serde(default)]
    pub coefficients_at: CoefficientsAt,
    /// Axial quadrature step [mm] for `coefficients_at = "instantaneous"`, where the
    /// elemental force is not integrable in closed form (elements of this height along
    /// each engaged stretch of flute; at most this, the stretch is split evenly).
    #[serde(default = "default_element_mm")]
    pub element_mm: f64,
    /// The cutter.
    pub tool: ToolSpec,
    /// Cutting coefficients.
    #[serde(default)]
    pub material: Material,
    /// Analog inputs of the board (same type and TOML shape as `MonitorConfig::input`).
    #[serde(default = "default_input")]
    pub input: Input,
    /// Encoder pulses per tooth or per revolution (as `MonitorConfig::sync`).
    #[serde(default)]
    pub sync: SyncMode,
    /// What happens between the forces and the board's samples.
    #[serde(default)]
    pub signal: SignalChain,
    /// Faces of the work along the path (entry and exit); absent: material everywhere.
    #[serde(default)]
    pub workpiece: Option<Workpiece>,
    /// Which optional columns the trace carries.
    #[serde(default)]
    pub output: OutputSpec,
    /// The timeline, in order (`[[segment]]` tables).
    #[serde(rename = "segment")]
    pub segments: Vec<Segment>,
    /// Tool damage (`[[event]]` tables), at given times.
    #[serde(default, rename = "event")]
    pub events: Vec<Event>,
}

fn default_seed() -> u64 {
    1
}

fn default_element_mm() -> f64 {
    0.05
}

fn default_input() -> Input {
    MonitorConfig::default().input
}

/// Where `K_s`, `r1`, `r2` of the power laws are evaluated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CoefficientsAt {
    /// Once per sample at the nominal average chip thickness `t_a` of the scheduled cut,
    /// as eq. 7 does: the simulated tooth averages then equal eq. 7 (method.md section 1,
    /// "compare like with like").
    #[default]
    NominalTa,
    /// At every element's own chip thickness `h`: more realistic, and the tangential
    /// force comes out 4-5 % below eq. 7.
    Instantaneous,
}

/// The cutter: [`estimator_core::Tool`] plus runout.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToolSpec {
    /// Radius `R` [mm].
    pub radius_mm: f64,
    /// Number of flutes `N` (1 to [`MAX_FLUTES`]).
    pub flutes: u8,
    /// Helix angle [deg], 0 (straight flutes) to below 90.
    pub helix_deg: f64,
    /// Radial offset of each flute's edge [mm] (runout; positive sticks out and cuts
    /// more, and the flute after it less); empty: none.
    #[serde(default)]
    pub runout_mm: Vec<f64>,
}

impl ToolSpec {
    /// The core's view of the tool.
    pub fn core(&self) -> estimator_core::Tool {
        estimator_core::Tool {
            radius_mm: self.radius_mm as f32,
            flutes: self.flutes,
            helix_deg: self.helix_deg as f32,
        }
    }
}

/// Cutting coefficients: a named set or one given in full.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Material {
    /// Paper 000's Table 2 power laws (SB40 steel), `estimator_core::TABLE2`.
    #[default]
    Table2,
    /// Paper 004's linear shearing + edge coefficients for Al6061.
    Al6061,
    /// Power laws `k t_a^p` (eq. 9) given in full.
    PowerLaw(PowerLawSpec),
    /// Linear shearing + edge coefficients given in full.
    Linear(LinearSpec),
}

/// One power law `k t^p`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LawSpec {
    /// Value at 1 mm.
    pub k: f32,
    /// Exponent.
    pub p: f32,
}

/// `[material.power_law]`: the fields of [`CuttingCoefficients`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PowerLawSpec {
    /// `K_s` [N/mm^2].
    pub ks: LawSpec,
    /// `r1`.
    pub r1: LawSpec,
    /// `r2`.
    pub r2: LawSpec,
    /// Feed range of the identification [mm/tooth] (informative here).
    #[serde(default = "default_tc_fit")]
    pub tc_fit_mm: (f32, f32),
}

fn default_tc_fit() -> (f32, f32) {
    TABLE2.tc_fit_mm
}

/// `[material.linear]`: the fields of [`LinearCoefficients`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinearSpec {
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

/// The coefficient model, resolved.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Coefficients {
    /// Power laws (eq. 9).
    PowerLaw(CuttingCoefficients),
    /// Linear shearing + edge.
    Linear(LinearCoefficients),
}

impl Material {
    /// The coefficient set this names.
    pub fn coefficients(&self) -> Coefficients {
        match self {
            Material::Table2 => Coefficients::PowerLaw(TABLE2),
            Material::Al6061 => Coefficients::Linear(estimator_core::coefficients::AL6061),
            Material::PowerLaw(s) => {
                let law = |l: LawSpec| PowerLaw { k: l.k, p: l.p };
                Coefficients::PowerLaw(CuttingCoefficients {
                    ks: law(s.ks),
                    r1: law(s.r1),
                    r2: law(s.r2),
                    tc_fit_mm: s.tc_fit_mm,
                })
            }
            Material::Linear(s) => Coefficients::Linear(LinearCoefficients {
                ktc: s.ktc,
                krc: s.krc,
                kac: s.kac,
                kte: s.kte,
                kre: s.kre,
                kae: s.kae,
            }),
        }
    }
}

/// `[signal]`: drive dynamics, sensor noise, ADC, spindle-load meter, encoder pulses.
/// Every field is optional; the defaults are an ideal board (no lag, noise, quantisation
/// or clipping, a perfect encoder) with a 20 Hz, 1 % spindle-load meter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SignalChain {
    /// Time constant of the feed current loop (or the dynamometer) [s]; 0: none.
    pub feed_lag_s: f64,
    /// Time constant of the spindle current (or load) signal [s]; 0: none.
    pub spindle_lag_s: f64,
    /// Gaussian noise on each feed channel, 1 sigma per sample [A, or N for a
    /// dynamometer].
    pub feed_noise: f64,
    /// Gaussian noise on the spindle channel, 1 sigma per sample [A, or % before the load
    /// meter averages and rounds].
    pub spindle_noise: f64,
    /// ADC resolution [bits] of the analog channels; absent: not quantised.
    pub adc_bits: Option<u8>,
    /// Feed channels' full scale [A or N]: readings clip at `±` this; absent: no clipping.
    /// With `adc_bits`, codes run from `-2^(bits-1)` to `2^(bits-1) - 1` of
    /// `full_scale / 2^(bits-1)`, so the largest positive reading is one LSB below.
    pub feed_full_scale: Option<f64>,
    /// Spindle current channel's full scale [A] (the load % is digital: not used there).
    pub spindle_full_scale: Option<f64>,
    /// Moving mass of the feed axes [kg]: `m a` joins the axis load while the feed
    /// ramps (steps are taken as instantaneous and add nothing).
    pub moving_mass_kg: f64,
    /// Spindle rotor and tool inertia [kg m^2]: `J alpha` joins the spindle torque while
    /// the speed ramps.
    pub spindle_inertia_kg_m2: f64,
    /// Update rate of the CNC's spindle load [Hz] (load model only): each update reports
    /// the mean over the interval since the last, rounded, held until the next.
    pub load_update_hz: f64,
    /// Step of the reported spindle load [%] (FANUC: whole percent).
    pub load_resolution_pct: f64,
    /// Angle of the sync pulse [deg]: per tooth, a pulse comes each time a flute's tip
    /// passes this immersion angle (the period after it is that flute's); per revolution,
    /// each time flute 0's tip does.
    pub sync_phase_deg: f64,
    /// Timing jitter of the sync pulses [samples]: each pulse lands a uniform random
    /// whole number of samples in `[-J, J]` from its true sample. To allow early pulses
    /// in a streamed trace, all pulses are delayed by `J` samples (a constant phase).
    pub sync_jitter_samples: u32,
    /// Probability that a sync pulse is lost, in `[0, 1)`.
    pub sync_dropout: f64,
}

impl Default for SignalChain {
    fn default() -> Self {
        SignalChain {
            feed_lag_s: 0.0,
            spindle_lag_s: 0.0,
            feed_noise: 0.0,
            spindle_noise: 0.0,
            adc_bits: None,
            feed_full_scale: None,
            spindle_full_scale: None,
            moving_mass_kg: 0.0,
            spindle_inertia_kg_m2: 0.0,
            load_update_hz: 20.0,
            load_resolution_pct: 1.0,
            sync_phase_deg: 0.0,
            sync_jitter_samples: 0,
            sync_dropout: 0.0,
        }
    }
}

/// `[workpiece]`: where the work is along the path.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Workpiece {
    /// Stretches of material `[entry, exit]` along the path [mm], sorted, not
    /// overlapping. The path coordinate is the distance the tool centre has travelled
    /// since `t = 0` (whatever the direction). A flute element at immersion angle `phi`
    /// reaches `R sin(phi)` ahead of the centre and cuts only inside a stretch, so the
    /// engaged arc grows over about one radius of travel at entry and shrinks at exit.
    pub spans_mm: Vec<[f64; 2]>,
}

/// `[output]`: optional trace columns.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OutputSpec {
    /// Write `feed_vx_mm_min` (and `feed_vy_mm_min` with two axes).
    pub velocity: bool,
    /// Write the `true_*` columns.
    pub truth: bool,
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec {
            velocity: true,
            truth: true,
        }
    }
}

/// A value that is constant over a segment or ramps linearly across it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Profile {
    /// The same all along (TOML: a number).
    Constant(f64),
    /// From the first value at the segment's start to the second at its end
    /// (TOML: `[from, to]`).
    Ramp(f64, f64),
}

impl Profile {
    /// `(start, end)` values.
    pub fn ends(&self) -> (f64, f64) {
        match *self {
            Profile::Constant(v) => (v, v),
            Profile::Ramp(a, b) => (a, b),
        }
    }
}

impl Serialize for Profile {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match *self {
            Profile::Constant(v) => s.serialize_f64(v),
            Profile::Ramp(a, b) => [a, b].serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for Profile {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Profile;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number, or [from, to] for a ramp across the segment")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Profile, E> {
                Ok(Profile::Constant(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Profile, E> {
                Ok(Profile::Constant(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Profile, E> {
                Ok(Profile::Constant(v as f64))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Profile, A::Error> {
                let a: f64 = seq
                    .next_element()?
                    .ok_or_else(|| de::Error::invalid_length(0, &self))?;
                let b: f64 = seq
                    .next_element()?
                    .ok_or_else(|| de::Error::invalid_length(1, &self))?;
                if seq.next_element::<f64>()?.is_some() {
                    return Err(de::Error::invalid_length(3, &self));
                }
                Ok(Profile::Ramp(a, b))
            }
        }
        d.deserialize_any(V)
    }
}

/// `[[segment]]`: a stretch of the timeline. A value left out keeps the previous
/// segment's end value (the first segment must give `rpm`, `feed_mm_min`, `dr_mm` and
/// `da_mm`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Segment {
    /// Length [s].
    pub duration_s: f64,
    /// Spindle speed [rpm] (> 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rpm: Option<Profile>,
    /// Feed speed along the path [mm/min] (>= 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feed_mm_min: Option<Profile>,
    /// Radial depth of cut `d_r` [mm], 0 (air) to `2 R` (slot).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dr_mm: Option<Profile>,
    /// Axial depth of cut `d_a` [mm] (>= 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub da_mm: Option<Profile>,
    /// Direction of the feed in the machine's XY plane [deg, counter-clockwise from +X]:
    /// 0 is +X, 180 is -X; anything else needs a two-axis feed drive. Default: previous
    /// segment's, else 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feed_angle_deg: Option<f64>,
    /// Milling mode of this segment; default: previous segment's, else the scenario's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mode: Option<MillingMode>,
    /// A name for messages and plots (not used otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
}

/// What happens to a flute.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EventKind {
    /// The flute breaks off: from then on it cuts nothing, and the next intact flute takes
    /// its chip (where it passes after the broken one would have: the part of the cut the
    /// flute made before it broke is not cut again).
    Break,
    /// The flute's edge chips at the tool tip (the corner, where chipping starts): over
    /// `length_mm` from the tip, or the lower `fraction` of the current axial depth, it
    /// cuts nothing and the next flute cutting at that height takes its chip; above, it
    /// cuts as before. Chipping an already chipped flute keeps the larger damage.
    Chip,
}

/// `[[event]]`: tool damage at a given time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Event {
    /// When [s].
    pub time_s: f64,
    /// Which flute (0-based; flute `j + 1` follows flute `j` through the cut).
    pub flute: u8,
    /// Break or chip.
    pub kind: EventKind,
    /// Chip: lost edge as a fraction of the axial depth, in `(0, 1]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fraction: Option<f64>,
    /// Chip: lost edge length from the tip [mm] (> 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length_mm: Option<f64>,
}

/// A segment with every value filled in (previous values carried over).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Resolved {
    /// Start time [s].
    pub t0: f64,
    /// End time [s].
    pub t1: f64,
    /// Spindle speed ends [rpm].
    pub rpm: (f64, f64),
    /// Feed ends [mm/min].
    pub feed: (f64, f64),
    /// Radial depth ends [mm].
    pub dr: (f64, f64),
    /// Axial depth ends [mm].
    pub da: (f64, f64),
    /// Feed direction [rad].
    pub angle_rad: f64,
    /// Milling mode.
    pub mode: MillingMode,
}

impl Scenario {
    /// Parses and validates a scenario; errors name `file` and the line (TOML) or the key
    /// path (validation).
    pub fn from_toml(text: &str, file: &str) -> Result<Scenario> {
        let sc: Scenario = crate::config::parse_toml(text, file)?;
        sc.validate().map_err(|e| anyhow!("{file}: {e:#}"))?;
        Ok(sc)
    }

    /// Total length of the timeline [s].
    pub fn duration_s(&self) -> f64 {
        self.segments.iter().map(|s| s.duration_s).sum()
    }

    /// Number of trace rows: `round(duration * sample_rate)`.
    pub fn samples(&self) -> u64 {
        (self.duration_s() * self.sample_rate_hz).round() as u64
    }

    /// Whether the feed drive has two axes (motor input only).
    pub fn two_axis(&self) -> bool {
        match &self.input {
            Input::Motor { feed, .. } => feed.two_axis,
            Input::Dynamometer => false,
        }
    }

    /// The segments with carried-over values filled in; errors name the segment.
    pub fn resolve(&self) -> Result<Vec<Resolved>> {
        let mut out: Vec<Resolved> = Vec::with_capacity(self.segments.len());
        let mut t = 0.0;
        for (i, s) in self.segments.iter().enumerate() {
            let prev = out.last().copied();
            let pick = |v: Option<Profile>, prev_end: Option<f64>, key: &str| match (v, prev_end) {
                (Some(p), _) => Ok(p.ends()),
                (None, Some(e)) => Ok((e, e)),
                (None, None) => Err(anyhow!("segment[{i}].{key}: required in the first segment")),
            };
            let r = Resolved {
                t0: t,
                t1: t + s.duration_s,
                rpm: pick(s.rpm, prev.map(|p| p.rpm.1), "rpm")?,
                feed: pick(s.feed_mm_min, prev.map(|p| p.feed.1), "feed_mm_min")?,
                dr: pick(s.dr_mm, prev.map(|p| p.dr.1), "dr_mm")?,
                da: pick(s.da_mm, prev.map(|p| p.da.1), "da_mm")?,
                angle_rad: s
                    .feed_angle_deg
                    .map(f64::to_radians)
                    .or(prev.map(|p| p.angle_rad))
                    .unwrap_or(0.0),
                mode: s.mode.or(prev.map(|p| p.mode)).unwrap_or(self.mode),
            };
            t = r.t1;
            out.push(r);
        }
        Ok(out)
    }

    /// Checks everything once, so that the per-sample code need not; errors name the key.
    pub fn validate(&self) -> Result<()> {
        let finite_pos = |v: f64, key: &str| -> Result<()> {
            if !(v.is_finite() && v > 0.0) {
                bail!("{key}: must be a finite number > 0 (got {v})");
            }
            Ok(())
        };
        let finite_nonneg = |v: f64, key: &str| -> Result<()> {
            if !(v.is_finite() && v >= 0.0) {
                bail!("{key}: must be a finite number >= 0 (got {v})");
            }
            Ok(())
        };
        finite_pos(self.sample_rate_hz, "sample_rate_hz")?;
        finite_pos(self.element_mm, "element_mm")?;
        // Tool.
        let t = &self.tool;
        finite_pos(t.radius_mm, "tool.radius_mm")?;
        let n = t.flutes as usize;
        if n == 0 || n > MAX_FLUTES {
            bail!("tool.flutes: must be 1 to {MAX_FLUTES} (got {n})");
        }
        if !(t.helix_deg.is_finite() && (0.0..89.0).contains(&t.helix_deg)) {
            bail!("tool.helix_deg: must be in [0, 89) (got {})", t.helix_deg);
        }
        if !t.runout_mm.is_empty() && t.runout_mm.len() != n {
            bail!(
                "tool.runout_mm: one offset per flute ({n}), or none (got {})",
                t.runout_mm.len()
            );
        }
        for (j, r) in t.runout_mm.iter().enumerate() {
            if !r.is_finite() || r.abs() > 0.5 * t.radius_mm {
                bail!("tool.runout_mm[{j}]: must be finite and below R/2 (got {r})");
            }
        }
        // Material.
        match self.material.coefficients() {
            Coefficients::PowerLaw(c) => c
                .validate()
                .map_err(|e| anyhow!("material.power_law: {e}"))?,
            Coefficients::Linear(k) => {
                for (v, name) in [
                    (k.ktc, "ktc"),
                    (k.krc, "krc"),
                    (k.kac, "kac"),
                    (k.kte, "kte"),
                    (k.kre, "kre"),
                    (k.kae, "kae"),
                ] {
                    if !v.is_finite() {
                        bail!("material.linear.{name}: must be finite (got {v})");
                    }
                }
            }
        }
        // Machine.
        if let Input::Motor { feed, spindle } = &self.input {
            feed.validate()
                .map_err(|e| anyhow!("input.motor.feed: {e}"))?;
            spindle
                .validate()
                .map_err(|e| anyhow!("input.motor.spindle: {e}"))?;
        }
        // Signal chain.
        let s = &self.signal;
        for (v, key) in [
            (s.feed_lag_s, "signal.feed_lag_s"),
            (s.spindle_lag_s, "signal.spindle_lag_s"),
            (s.feed_noise, "signal.feed_noise"),
            (s.spindle_noise, "signal.spindle_noise"),
            (s.moving_mass_kg, "signal.moving_mass_kg"),
            (s.spindle_inertia_kg_m2, "signal.spindle_inertia_kg_m2"),
        ] {
            finite_nonneg(v, key)?;
        }
        if let Some(b) = s.adc_bits {
            if !(2..=24).contains(&b) {
                bail!("signal.adc_bits: must be 2 to 24 (got {b})");
            }
            if s.feed_full_scale.is_none() {
                bail!("signal.feed_full_scale: required with signal.adc_bits");
            }
            if s.spindle_full_scale.is_none() && self.spindle_is_current() {
                bail!("signal.spindle_full_scale: required with signal.adc_bits");
            }
        }
        if let Some(v) = s.feed_full_scale {
            finite_pos(v, "signal.feed_full_scale")?;
        }
        if let Some(v) = s.spindle_full_scale {
            finite_pos(v, "signal.spindle_full_scale")?;
        }
        finite_pos(s.load_update_hz, "signal.load_update_hz")?;
        if s.load_update_hz > self.sample_rate_hz {
            bail!(
                "signal.load_update_hz: must not exceed sample_rate_hz ({})",
                self.sample_rate_hz
            );
        }
        finite_pos(s.load_resolution_pct, "signal.load_resolution_pct")?;
        if !s.sync_phase_deg.is_finite() {
            bail!("signal.sync_phase_deg: must be finite");
        }
        if !(s.sync_dropout.is_finite() && (0.0..1.0).contains(&s.sync_dropout)) {
            bail!(
                "signal.sync_dropout: must be in [0, 1) (got {})",
                s.sync_dropout
            );
        }
        // Workpiece.
        if let Some(w) = &self.workpiece {
            let mut last = f64::NEG_INFINITY;
            for (i, [a, b]) in w.spans_mm.iter().copied().enumerate() {
                if !(a.is_finite() && b.is_finite() && a < b && a >= last) {
                    bail!(
                        "workpiece.spans_mm[{i}]: need finite [entry, exit] with entry < exit, \
                         sorted and not overlapping (got [{a}, {b}])"
                    );
                }
                last = b;
            }
        }
        // Timeline.
        if self.segments.is_empty() {
            bail!("segment: at least one [[segment]] is needed");
        }
        let resolved = self.resolve()?;
        let mut min_tooth_period_s = f64::INFINITY;
        for (i, (seg, r)) in self.segments.iter().zip(&resolved).enumerate() {
            finite_pos(seg.duration_s, &format!("segment[{i}].duration_s"))?;
            for (key, (a, b)) in [("rpm", r.rpm), ("feed_mm_min", r.feed)] {
                let k = format!("segment[{i}].{key}");
                if key == "rpm" {
                    finite_pos(a, &k)?;
                    finite_pos(b, &k)?;
                } else {
                    finite_nonneg(a, &k)?;
                    finite_nonneg(b, &k)?;
                }
            }
            for (a, b) in [r.dr] {
                for v in [a, b] {
                    if !(v.is_finite() && (0.0..=2.0 * t.radius_mm).contains(&v)) {
                        bail!(
                            "segment[{i}].dr_mm: must be in [0, 2 R] = [0, {}] (got {v})",
                            2.0 * t.radius_mm
                        );
                    }
                }
            }
            finite_nonneg(r.da.0, &format!("segment[{i}].da_mm"))?;
            finite_nonneg(r.da.1, &format!("segment[{i}].da_mm"))?;
            if let Some(a) = seg.feed_angle_deg {
                if !a.is_finite() {
                    bail!("segment[{i}].feed_angle_deg: must be finite");
                }
            }
            if matches!(self.input, Input::Motor { .. })
                && !self.two_axis()
                && r.angle_rad.sin().abs() > 1e-9
            {
                bail!(
                    "segment[{i}].feed_angle_deg: {} deg moves the Y axis, but \
                     input.motor.feed.two_axis is false (one-axis feeds go along 0 or 180 deg)",
                    r.angle_rad.to_degrees()
                );
            }
            let rpm_max = r.rpm.0.max(r.rpm.1);
            min_tooth_period_s = min_tooth_period_s.min(60.0 / (rpm_max * n as f64));
        }
        let j = s.sync_jitter_samples as f64;
        if j > 0.0 && 4.0 * j >= min_tooth_period_s * self.sample_rate_hz {
            bail!(
                "signal.sync_jitter_samples: {j} is not below a quarter of the shortest tooth \
                 period ({:.1} samples)",
                min_tooth_period_s * self.sample_rate_hz
            );
        }
        // Events.
        for (i, e) in self.events.iter().enumerate() {
            finite_nonneg(e.time_s, &format!("event[{i}].time_s"))?;
            if e.flute as usize >= n {
                bail!(
                    "event[{i}].flute: flutes are numbered 0 to {} (got {})",
                    n - 1,
                    e.flute
                );
            }
            match e.kind {
                EventKind::Break => {
                    if e.fraction.is_some() || e.length_mm.is_some() {
                        bail!("event[{i}]: a break takes neither `fraction` nor `length_mm`");
                    }
                }
                EventKind::Chip => match (e.fraction, e.length_mm) {
                    (Some(f), None) => {
                        if !(f.is_finite() && f > 0.0 && f <= 1.0) {
                            bail!("event[{i}].fraction: must be in (0, 1] (got {f})");
                        }
                    }
                    (None, Some(l)) => finite_pos(l, &format!("event[{i}].length_mm"))?,
                    _ => bail!("event[{i}]: a chip takes one of `fraction` or `length_mm`"),
                },
            }
        }
        Ok(())
    }

    /// Whether the spindle channel is an analog current (it has an ADC then).
    pub fn spindle_is_current(&self) -> bool {
        matches!(
            self.input,
            Input::Motor {
                spindle: estimator_core::drive::SpindleModel::Current { .. },
                ..
            }
        )
    }
}
