//! The signal chain between the forces and the board's samples: current-loop lag, noise,
//! ADC quantisation and clipping, the CNC's spindle-load meter, the encoder's sync pulses.
//!
//! Each piece is a small state machine stepped once per sample; none allocates after
//! construction. Randomness comes from seeded [`Rng`] streams, one per purpose, so that
//! turning one effect on does not change the draws of another.
//!
//! [`Board`] puts the pieces together behind the drive models: feed-frame forces, feed
//! velocity and spindle speed in, the board's feed and spindle channels out. Both
//! simulators use it (the analytic one, [`super::simulate`], and the voxel one,
//! [`crate::voxel::trace`]), so their traces go through the same models and replay the
//! same way. [`sync_gen`] makes the matching encoder.

use super::scenario::SignalChain;
use estimator_core::drive::SpindleModel;
use estimator_core::monitor::Input;
use estimator_core::tooth::SyncMode;
use std::collections::VecDeque;
use std::f64::consts::TAU;

/// splitmix64's output step: a bijection of `u64` that scatters nearby inputs.
pub fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// xorshift64* with Box-Muller: deterministic, fast, good enough for sensor noise.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
    /// The second normal of the last Box-Muller pair.
    spare: Option<f64>,
}

impl Rng {
    /// Stream `stream` of seed `seed` (seeds mixed by splitmix64, so nearby seeds and
    /// streams are unrelated).
    pub fn new(seed: u64, stream: u64) -> Rng {
        Rng {
            state: splitmix64(seed ^ stream.wrapping_mul(0x9e37_79b9_7f4a_7c15)).max(1),
            spare: None,
        }
    }

    fn next(&mut self) -> u64 {
        let x = &mut self.state;
        *x ^= *x >> 12;
        *x ^= *x << 25;
        *x ^= *x >> 27;
        x.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    /// Uniform in `(0, 1)`.
    pub fn uniform(&mut self) -> f64 {
        ((self.next() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// Standard normal.
    pub fn gauss(&mut self) -> f64 {
        if let Some(g) = self.spare.take() {
            return g;
        }
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let (s, c) = (TAU * u2).sin_cos();
        self.spare = Some(r * s);
        r * c
    }

    /// Uniform integer in `[-j, j]`.
    pub fn offset(&mut self, j: u32) -> i64 {
        let span = 2 * j as u64 + 1;
        (self.next() % span) as i64 - j as i64
    }
}

/// First-order lag `tau dy/dt = x - y`, discretised exactly for an input held over each
/// sample: `y[n] = a y[n-1] + (1 - a) x[n]`, `a = exp(-dt / tau)`. Starts settled on its
/// first input. Its steady-state mean equals the input's, so tooth averages of a steady
/// cut are unchanged.
#[derive(Clone, Debug)]
pub struct Lag {
    a: f64,
    y: Option<f64>,
}

impl Lag {
    /// `tau_s = 0`: no lag.
    pub fn new(tau_s: f64, dt_s: f64) -> Lag {
        let a = if tau_s > 0.0 {
            (-dt_s / tau_s).exp()
        } else {
            0.0
        };
        Lag { a, y: None }
    }

    /// One sample.
    pub fn step(&mut self, x: f64) -> f64 {
        let y = match self.y {
            Some(y) => self.a * y + (1.0 - self.a) * x,
            None => x,
        };
        self.y = Some(y);
        y
    }
}

/// An analog input's clipping and quantisation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adc {
    /// Reading per code (0: not quantised).
    pub lsb: f64,
    /// Lowest reading.
    pub min: f64,
    /// Highest reading.
    pub max: f64,
}

impl Adc {
    /// `full_scale` absent: an ideal channel. Otherwise clipping at `±full_scale`, and
    /// with `bits` codes from `-2^(bits-1)` to `2^(bits-1) - 1` of `full_scale /
    /// 2^(bits-1)` each.
    pub fn new(bits: Option<u8>, full_scale: Option<f64>) -> Adc {
        match (bits, full_scale) {
            (_, None) => Adc {
                lsb: 0.0,
                min: f64::NEG_INFINITY,
                max: f64::INFINITY,
            },
            (None, Some(fs)) => Adc {
                lsb: 0.0,
                min: -fs,
                max: fs,
            },
            (Some(b), Some(fs)) => {
                let half = (1u32 << (b - 1)) as f64;
                let lsb = fs / half;
                Adc {
                    lsb,
                    min: -half * lsb,
                    max: (half - 1.0) * lsb,
                }
            }
        }
    }

    /// The reading for `x`, and whether it sits on a rail (clipped).
    pub fn read(&self, x: f64) -> (f64, bool) {
        let q = if self.lsb > 0.0 {
            (x / self.lsb).round() * self.lsb
        } else {
            x
        };
        if q >= self.max {
            (self.max, true)
        } else if q <= self.min {
            (self.min, true)
        } else {
            (q, false)
        }
    }

    /// The level to give the monitor as `clip` for this channel: the largest reading in
    /// magnitude that is still a real one is below it (infinite for an ideal channel).
    pub fn clip_level(&self) -> f64 {
        self.max.min(-self.min)
    }
}

/// A CNC's spindle-load display (paper 003): the mean of the signal over each update
/// interval, rounded to the resolution, held until the next update. The first interval
/// reports its first sample.
#[derive(Clone, Debug)]
pub struct LoadMeter {
    /// Update interval [samples] (need not be whole).
    interval: f64,
    resolution: f64,
    /// Sample index of the next update.
    next_update: f64,
    sum: f64,
    count: u32,
    held: Option<f64>,
}

impl LoadMeter {
    /// `update_hz` in `(0, sample_rate_hz]`, `resolution` > 0.
    pub fn new(sample_rate_hz: f64, update_hz: f64, resolution: f64) -> LoadMeter {
        let interval = sample_rate_hz / update_hz;
        LoadMeter {
            interval,
            resolution,
            next_update: interval,
            sum: 0.0,
            count: 0,
            held: None,
        }
    }

    /// Sample `i` (counting from 0) of value `x`; returns the displayed value.
    pub fn step(&mut self, i: u64, x: f64) -> f64 {
        let round = |v: f64| (v / self.resolution).round() * self.resolution;
        if self.held.is_none() {
            self.held = Some(round(x));
        }
        // Note: a tolerance, so that an interval of a whole number of samples stays whole
        // however the running sum of fractional intervals rounds.
        let at = i as f64 + 1e-6;
        if at >= self.next_update && self.count > 0 {
            self.held = Some(round(self.sum / self.count as f64));
            self.sum = 0.0;
            self.count = 0;
            while self.next_update <= at {
                self.next_update += self.interval;
            }
        }
        self.sum += x;
        self.count += 1;
        self.held.unwrap_or(0.0)
    }
}

/// Encoder pulses: one each time flute 0's angle `theta` passes `phase + k spacing`
/// (spacing a tooth pitch or a revolution), at the first sample at or after the crossing,
/// then lost with probability `dropout` or moved by a uniform `[-J, J]` samples (all
/// pulses delayed by `J` so that early ones can be emitted in a stream).
#[derive(Clone, Debug)]
pub struct SyncGen {
    spacing: f64,
    next_boundary: f64,
    jitter: u32,
    dropout: f64,
    pending: VecDeque<u64>,
    rng_jitter: Rng,
    rng_drop: Rng,
    /// Pulses emitted.
    pub emitted: u64,
    /// Pulses lost.
    pub dropped: u64,
}

impl SyncGen {
    /// Pulses every `spacing_rad` of rotation, the first at `phase_rad` (reduced to
    /// `[0, spacing)`).
    pub fn new(spacing_rad: f64, phase_rad: f64, jitter: u32, dropout: f64, seed: u64) -> Self {
        SyncGen {
            spacing: spacing_rad,
            next_boundary: phase_rad.rem_euclid(spacing_rad),
            jitter,
            dropout,
            pending: VecDeque::with_capacity(16),
            rng_jitter: Rng::new(seed, 101),
            rng_drop: Rng::new(seed, 102),
            emitted: 0,
            dropped: 0,
        }
    }

    /// Sample `i` with flute 0 at `theta` (unwrapped, increasing): whether a pulse is at
    /// this sample.
    pub fn step(&mut self, i: u64, theta: f64) -> bool {
        while theta >= self.next_boundary {
            self.next_boundary += self.spacing;
            if self.dropout > 0.0 && self.rng_drop.uniform() < self.dropout {
                self.dropped += 1;
                continue;
            }
            let at = if self.jitter > 0 {
                let d = self.rng_jitter.offset(self.jitter);
                (i as i64 + self.jitter as i64 + d) as u64
            } else {
                i
            };
            self.pending.push_back(at);
        }
        let mut fire = false;
        while self.pending.front().is_some_and(|&p| p <= i) {
            self.pending.pop_front();
            fire = true;
        }
        if fire {
            self.emitted += 1;
        }
        fire
    }
}

/// What the board's drives see at one sample: the cutting forces in the feed frame, the
/// feed's direction, velocity and acceleration, the spindle's speed and acceleration.
///
/// Forces are on the **work** ([`estimator_core::geometry`]'s convention): `fx_n` is `F_ax`
/// along the feed, positive when it resists the feed; `fy_n` is `F_ay` along the feed
/// direction turned +90 deg (left of the path); `ft_n` is `F_at`, the spindle torque over
/// the tool radius.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BoardInput {
    /// `F_ax` [N].
    pub fx_n: f64,
    /// `F_ay` [N].
    pub fy_n: f64,
    /// `F_at` [N].
    pub ft_n: f64,
    /// Unit feed direction in machine axes X, Y (`[cos, sin]` of the feed angle). The
    /// loads are resolved on it even while the feed stands.
    pub dir: [f64; 2],
    /// Feed velocity X, Y [mm/min] (what the drives' friction models and the
    /// one-axis/two-axis inverses see).
    pub velocity_mm_min: [f64; 2],
    /// Feed acceleration along `dir` [m/s^2]: `m a` joins the feed load (motor input).
    pub accel_m_s2: f64,
    /// Spindle speed [rpm].
    pub rpm: f64,
    /// Spindle angular acceleration [rad/s^2]: `J alpha / R` joins the tangential force
    /// (motor input).
    pub alpha_rad_s2: f64,
}

/// The monitor board behind the machine's drives: per sample, feed-frame forces to motor
/// currents (or a dynamometer's forces) and the spindle signal, then lag, noise, ADC
/// quantisation and clipping or the CNC's spindle-load meter.
///
/// The currents come from the core's own inverses
/// ([`FeedDrive::currents_for_loads_a`](estimator_core::drive::FeedDrive::currents_for_loads_a),
/// [`SpindleModel::signal_for_force`]), so a replay through the forward models inverts
/// exactly what was simulated. The axis loads are the feed force along `dir` and the
/// normal force along `dir` turned +90 deg, `[fa ux - fy uy, fa uy + fy ux]` with
/// `fa = F_ax + m a`; a one-axis drive takes the X load only. A dynamometer reads
/// `F_ax`, `F_ay` themselves (no inertia) and has no spindle channel.
#[derive(Clone, Debug)]
pub struct Board {
    input: Input,
    radius_mm: f64,
    moving_mass_kg: f64,
    spindle_inertia_kg_m2: f64,
    lag: [Lag; 3],
    rng: [Rng; 3],
    noise: [f64; 3],
    load_model: bool,
    adc: [Adc; 3],
    meter: LoadMeter,
    clipped: [u64; 3],
}

/// Whether the spindle channel is the CNC's load % (paper 003).
fn is_load_model(input: &Input) -> bool {
    matches!(
        input,
        Input::Motor {
            spindle: SpindleModel::Load { .. },
            ..
        }
    )
}

/// The ADCs of feed X, feed Y and spindle (the load % is digital, a dynamometer has no
/// spindle channel: no ADC).
pub fn board_adcs(input: &Input, signal: &SignalChain) -> [Adc; 3] {
    let feed = Adc::new(signal.adc_bits, signal.feed_full_scale);
    let spindle = if is_load_model(input) || matches!(input, Input::Dynamometer) {
        Adc::new(None, None)
    } else {
        Adc::new(signal.adc_bits, signal.spindle_full_scale)
    };
    [feed, feed, spindle]
}

impl Board {
    /// The board for `input` (the drive and spindle models) and `signal` (its chain), at
    /// `sample_rate_hz`, for a tool of radius `radius_mm`; noise streams 1 to 3 of `seed`.
    /// The arguments are taken as valid (`Scenario::validate` checks them).
    pub fn new(
        input: &Input,
        signal: &SignalChain,
        sample_rate_hz: f64,
        radius_mm: f64,
        seed: u64,
    ) -> Board {
        let dt = 1.0 / sample_rate_hz;
        Board {
            input: input.clone(),
            radius_mm,
            moving_mass_kg: signal.moving_mass_kg,
            spindle_inertia_kg_m2: signal.spindle_inertia_kg_m2,
            lag: [
                Lag::new(signal.feed_lag_s, dt),
                Lag::new(signal.feed_lag_s, dt),
                Lag::new(signal.spindle_lag_s, dt),
            ],
            rng: [1, 2, 3].map(|s| Rng::new(seed, s)),
            noise: [signal.feed_noise, signal.feed_noise, signal.spindle_noise],
            load_model: is_load_model(input),
            adc: board_adcs(input, signal),
            meter: LoadMeter::new(
                sample_rate_hz,
                signal.load_update_hz,
                signal.load_resolution_pct,
            ),
            clipped: [0; 3],
        }
    }

    /// Sample `i` (counting from 0, one call per sample in order): the feed channels
    /// (currents [A], or `F_ax`, `F_ay` [N] for a dynamometer; the second 0 for a one-axis
    /// drive) and the spindle channel (current [A] or load [%]; 0 for a dynamometer).
    pub fn sample(&mut self, i: u64, s: &BoardInput) -> ([f32; 2], f32) {
        let [ux, uy] = s.dir;
        let r_mm = self.radius_mm;
        let (raw, spindle_raw) = match &self.input {
            Input::Motor {
                feed: drive,
                spindle,
            } => {
                let f_inertia = self.moving_mass_kg * s.accel_m_s2;
                let ft_inertia = self.spindle_inertia_kg_m2 * s.alpha_rad_s2 / (r_mm * 1e-3);
                // Load the drive supplies on each axis: the feed force along the feed
                // velocity, the normal force along it turned +90 deg.
                let fa = s.fx_n + f_inertia;
                let loads = [fa * ux - s.fy_n * uy, fa * uy + s.fy_n * ux];
                let i_axes = drive.currents_for_loads_a(
                    loads.map(|x| x as f32),
                    s.velocity_mm_min.map(|x| x as f32),
                );
                let second = if drive.two_axis {
                    i_axes[1] as f64
                } else {
                    0.0
                };
                let sig = spindle.signal_for_force(
                    (s.ft_n + ft_inertia) as f32,
                    s.rpm as f32,
                    r_mm as f32,
                );
                ([i_axes[0] as f64, second], sig as f64)
            }
            // No spindle column: rows carry 0, as the trace reader fills them.
            Input::Dynamometer => ([s.fx_n, s.fy_n], f64::NAN),
        };
        let mut chan = [raw[0], raw[1], spindle_raw];
        for (k, x) in chan.iter_mut().enumerate() {
            if x.is_nan() {
                continue;
            }
            let mut y = self.lag[k].step(*x);
            if self.noise[k] > 0.0 {
                y += self.noise[k] * self.rng[k].gauss();
            }
            if k == 2 && self.load_model {
                y = self.meter.step(i, y);
            } else {
                let (q, clipped) = self.adc[k].read(y);
                y = q;
                self.clipped[k] += clipped as u64;
            }
            *x = y;
        }
        let spindle = if chan[2].is_nan() {
            0.0
        } else {
            chan[2] as f32
        };
        ([chan[0] as f32, chan[1] as f32], spindle)
    }

    /// Samples at an ADC rail so far: feed X, feed Y, spindle.
    pub fn clipped(&self) -> [u64; 3] {
        self.clipped
    }

    /// Levels to give the monitor as `clip` (feed X, feed Y, spindle): the ADC rails,
    /// infinite for a channel that cannot clip.
    pub fn clip_levels(&self) -> [f64; 3] {
        self.adc.map(|a| a.clip_level())
    }
}

/// The encoder of a tool with `flutes` flutes: pulses per tooth or per revolution at the
/// chain's phase, with its jitter and dropouts (streams 101 and 102 of `seed`). Step it
/// with flute 0's rotation angle.
pub fn sync_gen(sync: SyncMode, flutes: u8, signal: &SignalChain, seed: u64) -> SyncGen {
    let spacing = match sync {
        SyncMode::PerTooth => TAU / f64::from(flutes),
        SyncMode::PerRevolution => TAU,
    };
    SyncGen::new(
        spacing,
        signal.sync_phase_deg.to_radians(),
        signal.sync_jitter_samples,
        signal.sync_dropout,
        seed,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_has_unit_variance() {
        let mut r = Rng::new(7, 0);
        let n = 200_000;
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let g = r.gauss();
            s += g;
            s2 += g * g;
        }
        let mean = s / n as f64;
        let var = s2 / n as f64 - mean * mean;
        assert!(
            mean.abs() < 0.01 && (var - 1.0).abs() < 0.01,
            "{mean} {var}"
        );
    }

    #[test]
    fn adc_codes_and_clipping() {
        let a = Adc::new(Some(12), Some(10.0));
        let lsb = 10.0 / 2048.0;
        assert_eq!(a.lsb, lsb);
        assert_eq!(a.read(1.0).0, (1.0 / lsb).round() * lsb);
        assert_eq!(a.read(20.0), (10.0 - lsb, true));
        assert_eq!(a.read(-20.0), (-10.0, true));
        assert_eq!(a.clip_level(), 10.0 - lsb);
        let ideal = Adc::new(None, None);
        assert_eq!(ideal.read(1e9), (1e9, false));
    }

    #[test]
    fn lag_is_exact_for_a_step() {
        let (tau, dt) = (1e-3, 1e-4);
        let mut l = Lag::new(tau, dt);
        l.step(0.0);
        let mut y = 0.0;
        for _ in 0..10 {
            y = l.step(1.0);
        }
        assert!((y - (1.0 - (-1.0f64).exp())).abs() < 1e-12, "{y}");
    }
}
