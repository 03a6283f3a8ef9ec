//! `calibrate cutting`: cutting coefficients from calibration cuts of known engagement.
//!
//! Each cut (a raw trace replayed through the Monitor, or a per-tooth CSV) gives its mean
//! per-tooth forces at one feed per tooth. Two models are fitted to them:
//!
//! - **Power laws of eq. 9** (what the estimator runs on), as paper 000 identified Table 2:
//!   each cut is inverted through eq. 7 at its known `R_r`, `R_a`, `t_c` for `K_s`, `r1`
//!   (and `r2` when the axial force is given) at its average chip thickness `t_a`, and
//!   `ln K_s = ln k + p ln t_a` is fitted by least squares (likewise `r1`, `r2`). With
//!   `s = R_a R t_c / phi_N` and the arc integrals `a, b, c` of the core
//!   (`estimator_core::geometry::ArcIntegrals`), eq. 7 reads `F_at = s K_s c`,
//!   `F_ax = s K_s (a + r1 b)`, `F_ay = s K_s (r1 a - b)`, `F_az = s K_s r2 c`, so
//!   - motor route (`F_ax`, `F_at`): `K_s = F_at / (s c)`, `r1 = (F_ax / (s K_s) - a) / b`;
//!   - dynamometer route (`F_ax`, `F_ay`): `s K_s = (a F_ax - b F_ay) / (a^2 + b^2)`,
//!     `s K_s r1 = (b F_ax + a F_ay) / (a^2 + b^2)`.
//! - **Linear shearing + edge coefficients** (paper 003 eq. 2, paper 004's model, the voxel
//!   simulator's material): the core's `average_forces_linear` is linear in
//!   `(K_tc, K_te, K_rc, K_re, K_ac, K_ae)`, so every measured mean force is one row of a
//!   least-squares system whose columns are that function at unit coefficients. For
//!   slotting cuts this is paper 003's `K_tc = 4 slope(F_ay vs t_c) / (N a)`.
//!
//! The per-tooth means come from the records the Monitor marks as steady cutting (replayed
//! here from a raw trace, or a records file from `replay` or the board's telemetry); its
//! estimation flags (`tc_out_of_range`, clamps) are ignored, since they judge the very
//! coefficients being identified.

use super::stats::{fit_linear, LinearFit};
use crate::config::parse_toml;
use crate::replay;
use crate::trace::TraceReader;
use anyhow::{anyhow, bail, Context, Result};
use estimator_core::coefficients::{CuttingCoefficients, LinearCoefficients, PowerLaw};
use estimator_core::forward::{average_forces_linear, Engagement};
use estimator_core::geometry::{average_chip_thickness_mm, ArcIntegrals};
use estimator_core::monitor::Input;
use estimator_core::{MillingMode, MonitorConfig, Status, Tool};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// Records that are not steady cutting.
const NOT_STEADY: Status = Status(
    Status::NOT_CUTTING.0
        | Status::NON_FINITE.0
        | Status::PERIOD_INVALID.0
        | Status::NO_SYNC.0
        | Status::INPUT_FAULT.0
        | Status::TRANSIENT.0
        | Status::FEED_CHANGE.0
        | Status::SETTLING.0,
);

/// Largest relative spread of `t_c` within one cut.
const TC_SPREAD: f64 = 0.03;

/// The plan file: the calibration cuts.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plan {
    /// Milling mode of cuts that do not give one; default: the machine file's.
    #[serde(default)]
    pub mode: Option<MillingMode>,
    /// The cuts (`[[cut]]`).
    #[serde(rename = "cut")]
    pub cuts: Vec<PlanCut>,
}

/// One calibration cut.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanCut {
    /// Raw trace (relative paths: from the plan file's directory).
    #[serde(default)]
    pub trace: Option<PathBuf>,
    /// Or a per-tooth CSV: `tc_mm`, `fx_n` and `ft_n` or `fy_n`, optionally `fz_n`; or a
    /// records file of `replay` or `decode-telemetry` (`f2_n`, and `status` picks the
    /// steady teeth).
    #[serde(default)]
    pub teeth: Option<PathBuf>,
    /// Radial depth [mm].
    pub dr_mm: f64,
    /// Axial depth [mm].
    pub da_mm: f64,
    /// Milling mode; default: the plan's.
    #[serde(default)]
    pub mode: Option<MillingMode>,
    /// Use records ending after this time [s] (traces only).
    #[serde(default)]
    pub from_s: Option<f64>,
    /// Use records ending before this time [s] (traces only).
    #[serde(default)]
    pub to_s: Option<f64>,
}

/// The second force of a cut.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Second {
    /// Tangential `F_at` [N] (motor route).
    Tangential(f64),
    /// Normal `F_ay` [N] (dynamometer route).
    Normal(f64),
}

/// A cut's mean per-tooth forces.
#[derive(Clone, Debug, PartialEq)]
pub struct CutPoint {
    /// Where it came from (`file`, or `file [from..to s]`).
    pub source: String,
    /// Milling mode.
    pub mode: MillingMode,
    /// Radial immersion ratio.
    pub rr: f64,
    /// Axial immersion ratio.
    pub ra: f64,
    /// Mean feed per tooth [mm/tooth].
    pub tc_mm: f64,
    /// Mean `F_ax` [N].
    pub fx_n: f64,
    /// Mean second force.
    pub second: Second,
    /// Mean `F_az` [N], if measured.
    pub fz_n: Option<f64>,
    /// Teeth averaged.
    pub teeth: usize,
    /// Teeth left out (not steady cutting, outside the window, non-finite).
    pub left_out: usize,
}

/// One cut inverted through eq. 7.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inverted {
    /// Average chip thickness [mm].
    pub t_a_mm: f64,
    /// `K_s` [N/mm^2].
    pub ks: f64,
    /// `r1`.
    pub r1: f64,
    /// `r2`, if the axial force was measured.
    pub r2: Option<f64>,
}

/// A fitted power law with its uncertainty.
#[derive(Clone, Debug, PartialEq)]
pub struct LawFit {
    /// The law.
    pub law: PowerLaw,
    /// The log-linear fit `(ln k, p)`.
    pub fit: LinearFit,
}

impl LawFit {
    /// 95 % interval of `k` (asymmetric: the fit is of `ln k`).
    pub fn k_ci95(&self) -> (f64, f64) {
        let (lnk, h) = (self.fit.coef[0], self.fit.ci95[0]);
        ((lnk - h).exp(), (lnk + h).exp())
    }
}

/// The power-law result.
#[derive(Clone, Debug, PartialEq)]
pub struct PowerFit {
    /// Per cut.
    pub inverted: Vec<Inverted>,
    /// `K_s`.
    pub ks: LawFit,
    /// `r1`.
    pub r1: LawFit,
    /// `r2`; `None`: no cut measured the axial force (kept from the base).
    pub r2: Option<LawFit>,
    /// The coefficient set.
    pub coeffs: CuttingCoefficients,
}

/// The linear-model result.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearFitResult {
    /// `(K_tc, K_te, K_rc, K_re)`, then `(K_ac, K_ae)` if axial forces were given.
    pub fit: LinearFit,
    /// The set (axial terms 0 when not measured).
    pub coeffs: LinearCoefficients,
    /// Whether the axial terms were fitted.
    pub axial: bool,
}

/// Reads the plan and every cut's mean forces. Traces are replayed with `cfg` (friction
/// and spindle idle as calibrated before).
pub fn read_cuts(plan_path: &Path, cfg: &MonitorConfig) -> Result<Vec<CutPoint>> {
    let text = std::fs::read_to_string(plan_path)
        .with_context(|| format!("cannot read {}", plan_path.display()))?;
    let file = plan_path.display().to_string();
    let plan: Plan = parse_toml(&text, &file)?;
    if plan.cuts.is_empty() {
        bail!("{file}: no [[cut]]");
    }
    let dir = plan_path.parent().unwrap_or(Path::new("."));
    let radius = f64::from(cfg.estimator.tool.radius_mm);
    let mut out = Vec::new();
    for (i, cut) in plan.cuts.iter().enumerate() {
        let at = format!("{file}: cut[{i}]");
        let mode = cut.mode.or(plan.mode).unwrap_or(cfg.estimator.mode);
        let rr = cut.dr_mm / radius;
        let ra = cut.da_mm / radius;
        if !(rr > 0.0 && rr <= 2.0) {
            bail!(
                "{at}: dr_mm = {} must be in (0, 2 R] = (0, {}]",
                cut.dr_mm,
                2.0 * radius
            );
        }
        if !(ra.is_finite() && ra > 0.0) {
            bail!("{at}: da_mm = {} must be > 0", cut.da_mm);
        }
        let mut p = match (&cut.trace, &cut.teeth) {
            (Some(t), None) => from_trace(&dir.join(t), cfg, cut, &at)?,
            (None, Some(t)) => {
                if cut.from_s.is_some() || cut.to_s.is_some() {
                    bail!("{at}: from_s / to_s apply to traces, not to a per-tooth CSV");
                }
                from_teeth(&dir.join(t), cfg.input == Input::Dynamometer, &at)?
            }
            _ => bail!("{at}: give exactly one of `trace` and `teeth`"),
        };
        p.mode = mode;
        p.rr = rr;
        p.ra = ra;
        out.push(p);
    }
    Ok(out)
}

/// Mean of `xs`.
fn mean(xs: &[f64]) -> f64 {
    xs.iter().sum::<f64>() / xs.len() as f64
}

/// Checks a cut's feed is one feed.
fn check_tc(tcs: &[f64], at: &str) -> Result<f64> {
    let tc = mean(tcs);
    let (lo, hi) = tcs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    if tc.is_nan() || tc <= 0.0 {
        bail!("{at}: feed per tooth {tc} mm: the cut must feed");
    }
    if hi - lo > 2.0 * TC_SPREAD * tc {
        bail!(
            "{at}: t_c varies from {lo:.4} to {hi:.4} mm/tooth within the cut; one cut per feed \
             (split it with from_s / to_s)"
        );
    }
    Ok(tc)
}

fn from_trace(path: &Path, cfg: &MonitorConfig, cut: &PlanCut, at: &str) -> Result<CutPoint> {
    let mut reader = TraceReader::open(path)?;
    let mut c = cfg.clone();
    if let Some(rate) = reader.detect_sample_rate_hz()? {
        c.sample_rate_hz = rate as f32;
    }
    let rate = c.sample_rate_hz;
    let (from, to) = (
        cut.from_s.unwrap_or(f64::NEG_INFINITY),
        cut.to_s.unwrap_or(f64::INFINITY),
    );
    let (mut tc, mut fx, mut f2) = (Vec::new(), Vec::new(), Vec::new());
    let mut left_out = 0;
    replay::replay(&mut reader, &c, |rec, _| {
        let t = rec.time_s(rate);
        if rec.status.intersects(NOT_STEADY) || t < from || t > to {
            left_out += 1;
        } else {
            tc.push(f64::from(rec.tc_mm));
            fx.push(f64::from(rec.fx_n));
            f2.push(f64::from(rec.f2_n));
        }
    })
    .with_context(|| at.to_string())?;
    if tc.len() < 8 {
        bail!(
            "{at}: {} steady cutting teeth in {} ({left_out} left out: not cutting, entry, \
             feed change, bad input or outside from_s..to_s); a cut needs a few revolutions \
             at constant feed",
            tc.len(),
            path.display()
        );
    }
    let second = mean(&f2);
    Ok(CutPoint {
        source: path.display().to_string(),
        mode: MillingMode::Down,
        rr: f64::NAN,
        ra: f64::NAN,
        tc_mm: check_tc(&tc, at)?,
        fx_n: mean(&fx),
        second: match c.input {
            Input::Motor { .. } => Second::Tangential(second),
            Input::Dynamometer => Second::Normal(second),
        },
        fz_n: None,
        teeth: tc.len(),
        left_out,
    })
}

fn from_teeth(path: &Path, dynamometer: bool, at: &str) -> Result<CutPoint> {
    let name = path.display().to_string();
    let mut r = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_path(path)
        .with_context(|| format!("cannot read {name}"))?;
    let headers = r.headers().with_context(|| name.clone())?.clone();
    let col = |c: &str| headers.iter().position(|h| h.trim() == c);
    let (Some(itc), Some(ifx)) = (col("tc_mm"), col("fx_n")) else {
        bail!("{name}: needs columns `tc_mm` and `fx_n` (and `ft_n` or `fy_n`)");
    };
    let (ift, ify, if2, ifz) = (col("ft_n"), col("fy_n"), col("f2_n"), col("fz_n"));
    // A records file (`replay`, `decode-telemetry`): `f2_n` is what the machine's input
    // gives, and its `status` says which teeth are steady cutting.
    let istatus = if2.and(col("status"));
    let (i2, tangential) = match (ift, ify, if2) {
        (Some(i), None, None) => (i, true),
        (None, Some(i), None) => (i, false),
        (None, None, Some(i)) => (i, !dynamometer),
        (None, None, None) => bail!(
            "{name}: needs `ft_n` (motor route), `fy_n` (dynamometer) or `f2_n` (a records file)"
        ),
        _ => bail!("{name}: more than one of `ft_n`, `fy_n`, `f2_n`: give one route per cut"),
    };
    let (mut tc, mut fx, mut f2, mut fz) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut left_out = 0;
    for (k, rec) in r.records().enumerate() {
        let rec = rec.with_context(|| name.clone())?;
        let line = rec.position().map_or(k as u64 + 2, |p| p.line());
        let num = |i: usize, c: &str| -> Result<f64> {
            let s = rec.get(i).unwrap_or("").trim();
            s.parse::<f64>()
                .map_err(|_| anyhow!("{name} line {line}: `{c}` is not a number: {s:?}"))
        };
        let v = [
            num(itc, "tc_mm")?,
            num(ifx, "fx_n")?,
            num(i2, "second force")?,
        ];
        let z = ifz.map(|i| num(i, "fz_n")).transpose()?;
        let steady = match istatus {
            None => true,
            Some(i) => {
                let s = rec.get(i).unwrap_or("");
                let st = Status::parse(s)
                    .ok_or_else(|| anyhow!("{name} line {line}: unknown status {s:?}"))?;
                !st.intersects(NOT_STEADY)
            }
        };
        if steady && v.iter().chain(&z).all(|x| x.is_finite()) {
            tc.push(v[0]);
            fx.push(v[1]);
            f2.push(v[2]);
            fz.extend(z);
        } else {
            left_out += 1;
        }
    }
    if tc.is_empty() {
        bail!("{at}: {name} has no finite rows");
    }
    let second = mean(&f2);
    Ok(CutPoint {
        source: name,
        mode: MillingMode::Down,
        rr: f64::NAN,
        ra: f64::NAN,
        tc_mm: check_tc(&tc, at)?,
        fx_n: mean(&fx),
        second: if tangential {
            Second::Tangential(second)
        } else {
            Second::Normal(second)
        },
        fz_n: (!fz.is_empty()).then(|| mean(&fz)),
        teeth: tc.len(),
        left_out,
    })
}

/// Inverts one cut through eq. 7 (see the module docs).
pub fn invert(tool: &Tool, p: &CutPoint) -> Inverted {
    let arc = ArcIntegrals::new(p.mode, p.rr as f32);
    let (a, b, c) = (f64::from(arc.a), f64::from(arc.b), f64::from(arc.c));
    let t_a = f64::from(average_chip_thickness_mm(p.tc_mm as f32, arc.c, arc.arc));
    let s = p.ra * f64::from(tool.radius_mm) * p.tc_mm / f64::from(tool.tooth_pitch_rad());
    let (ks, r1) = match p.second {
        Second::Tangential(ft) => {
            let ks = ft / (s * c);
            (ks, (p.fx_n / (s * ks) - a) / b)
        }
        Second::Normal(fy) => {
            let q = a * a + b * b;
            let sks = (a * p.fx_n - b * fy) / q;
            let sks_r1 = (b * p.fx_n + a * fy) / q;
            (sks / s, sks_r1 / sks)
        }
    };
    Inverted {
        t_a_mm: t_a,
        ks,
        r1,
        r2: p.fz_n.map(|fz| fz / (s * ks * c)),
    }
}

/// `ln y = ln k + p ln t_a` over the cuts.
fn fit_law(name: &str, pts: &[(f64, f64, &str)]) -> Result<LawFit> {
    if let Some((_, y, src)) = pts.iter().find(|p| !(p.1 > 0.0 && p.1.is_finite())) {
        bail!(
            "{name} = {y:.4} <= 0 in {src}: no power law through it (for r1: the feed force \
             is below what any radial force gives; check the feed friction calibration, the \
             axis sign and the cut's mode)"
        );
    }
    let a: Vec<f64> = pts.iter().flat_map(|p| [1.0, p.0.ln()]).collect();
    let y: Vec<f64> = pts.iter().map(|p| p.1.ln()).collect();
    let fit = fit_linear(&a, 2, &y).with_context(|| {
        format!("{name}: the cuts must span at least two average chip thicknesses")
    })?;
    Ok(LawFit {
        law: PowerLaw {
            k: fit.coef[0].exp() as f32,
            p: fit.coef[1] as f32,
        },
        fit,
    })
}

/// Fits the power laws of eq. 9; `r2` from the base when no cut measured `F_az`.
pub fn fit_power(tool: &Tool, cuts: &[CutPoint], base: &CuttingCoefficients) -> Result<PowerFit> {
    let inverted: Vec<Inverted> = cuts.iter().map(|p| invert(tool, p)).collect();
    let pts = |f: &dyn Fn(&Inverted) -> Option<f64>| -> Vec<(f64, f64, &str)> {
        inverted
            .iter()
            .zip(cuts)
            .filter_map(|(i, c)| f(i).map(|v| (i.t_a_mm, v, c.source.as_str())))
            .collect()
    };
    let ks = fit_law("K_s", &pts(&|i| Some(i.ks)))?;
    let r1 = fit_law("r1", &pts(&|i| Some(i.r1)))?;
    let r2_pts = pts(&|i| i.r2);
    let r2 = match r2_pts.len() {
        0 => None,
        n if n == cuts.len() => Some(fit_law("r2", &r2_pts)?),
        n => bail!(
            "fz_n is given for {n} of {} cuts: for all or none",
            cuts.len()
        ),
    };
    let tc = cuts
        .iter()
        .map(|c| c.tc_mm)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(v), h.max(v))
        });
    let coeffs = CuttingCoefficients {
        ks: ks.law,
        r1: r1.law,
        r2: r2.as_ref().map_or(base.r2, |f| f.law),
        tc_fit_mm: (tc.0 as f32, tc.1 as f32),
    };
    coeffs
        .validate()
        .map_err(|e| anyhow!("fitted power laws refused: {e}"))?;
    Ok(PowerFit {
        inverted,
        ks,
        r1,
        r2,
        coeffs,
    })
}

/// How far the cuts' mean forces lie from eq. 7 with `coeffs`: the root mean square over
/// the cuts and both measured channels of `(measured - model) / F_at model` (the feed
/// force, near zero in some cuts, is taken relative to the tangential one). What the fitted
/// laws leave unexplained, as a relative error of a force channel: the estimator's
/// `gain_uncertainty`, the calibration's share of each estimate's uncertainty.
pub fn relative_force_rms(tool: &Tool, cuts: &[CutPoint], coeffs: &CuttingCoefficients) -> f64 {
    let mut sum = 0.0;
    let mut n = 0usize;
    for c in cuts {
        let e = Engagement {
            rr: c.rr as f32,
            ra: c.ra as f32,
            tc_mm: c.tc_mm as f32,
        };
        let m = estimator_core::average_forces(tool, coeffs, c.mode, e);
        let scale = f64::from(m.ft_n).abs();
        let (second, model2) = match c.second {
            Second::Tangential(f) => (f, m.ft_n),
            Second::Normal(f) => (f, m.fy_n),
        };
        for (meas, model) in [(c.fx_n, m.fx_n), (second, model2)] {
            sum += ((meas - f64::from(model)) / scale).powi(2);
            n += 1;
        }
    }
    (sum / n.max(1) as f64).sqrt()
}

/// Fits the linear shearing + edge coefficients (see the module docs).
pub fn fit_linear_model(tool: &Tool, cuts: &[CutPoint]) -> Result<LinearFitResult> {
    let axial = cuts.iter().all(|c| c.fz_n.is_some());
    let cols = if axial { 6 } else { 4 };
    let unit = |j: usize| {
        let mut v = [0.0f32; 6];
        v[j] = 1.0;
        LinearCoefficients {
            ktc: v[0],
            kte: v[1],
            krc: v[2],
            kre: v[3],
            kac: v[4],
            kae: v[5],
        }
    };
    let (mut a, mut y) = (Vec::new(), Vec::new());
    for c in cuts {
        let e = Engagement {
            rr: c.rr as f32,
            ra: c.ra as f32,
            tc_mm: c.tc_mm as f32,
        };
        let basis: Vec<_> = (0..cols)
            .map(|j| average_forces_linear(tool, &unit(j), c.mode, e))
            .collect();
        let (second, pick): (f64, fn(&estimator_core::AverageForces) -> f32) = match c.second {
            Second::Tangential(f) => (f, |f| f.ft_n),
            Second::Normal(f) => (f, |f| f.fy_n),
        };
        // Rows scaled by the cut's force level: a light cut counts as much as a slot.
        let w = 1.0 / (c.fx_n.abs().max(second.abs())).max(1e-9);
        for (meas, get) in [
            (
                c.fx_n,
                (|f: &estimator_core::AverageForces| f.fx_n) as fn(&_) -> f32,
            ),
            (second, pick),
        ] {
            a.extend(basis.iter().map(|f| f64::from(get(f)) * w));
            y.push(meas * w);
        }
        if let (true, Some(fz)) = (axial, c.fz_n) {
            a.extend(basis.iter().map(|f| f64::from(f.fz_n) * w));
            y.push(fz * w);
        }
    }
    let fit = fit_linear(&a, cols, &y).context(
        "linear model: the cuts must span at least two feeds per tooth (slotting at several \
         t_c, as paper 003)",
    )?;
    let k = |j: usize| fit.coef.get(j).copied().unwrap_or(0.0) as f32;
    Ok(LinearFitResult {
        coeffs: LinearCoefficients {
            ktc: k(0),
            kte: k(1),
            krc: k(2),
            kre: k(3),
            kac: k(4),
            kae: k(5),
        },
        fit,
        axial,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use estimator_core::coefficients::AL6061;
    use estimator_core::TABLE2;
    use std::f64::consts::PI;

    /// Per-tooth average forces `(F_at, F_ax, F_ay, F_az)` by brute-force integration of the
    /// elemental forces (method.md eq. 3) over the engaged arc, independent of the core's
    /// closed forms: `F = N d_a / (2 pi) int dF(phi) dphi`, the elemental law given as
    /// `(dF_t, dF_r, dF_a)` per unit height at chip thickness `h`.
    fn brute(
        tool: &Tool,
        mode: MillingMode,
        rr: f64,
        da_mm: f64,
        law: &dyn Fn(f64) -> (f64, f64, f64),
    ) -> [f64; 4] {
        let arc = (1.0 - rr).acos();
        let (st, ex) = match mode {
            MillingMode::Down => (PI - arc, PI),
            MillingMode::Up => (0.0, arc),
        };
        let n = 20_000;
        let dphi = (ex - st) / n as f64;
        let mut f = [0.0; 4];
        for k in 0..n {
            let phi = st + (k as f64 + 0.5) * dphi;
            let (t, r, a) = law(phi);
            f[0] += t;
            f[1] += t * phi.cos() + r * phi.sin();
            f[2] += -t * phi.sin() + r * phi.cos();
            f[3] += a;
        }
        let scale = f64::from(tool.flutes) * da_mm / (2.0 * PI) * dphi;
        f.map(|v| v * scale)
    }

    fn point(mode: MillingMode, rr: f64, ra: f64, tc: f64, f: [f64; 4], motor: bool) -> CutPoint {
        CutPoint {
            source: format!("rr {rr} tc {tc}"),
            mode,
            rr,
            ra,
            tc_mm: tc,
            fx_n: f[1],
            second: if motor {
                Second::Tangential(f[0])
            } else {
                Second::Normal(f[2])
            },
            fz_n: Some(f[3]),
            teeth: 1,
            left_out: 0,
        }
    }

    /// Paper 000's calibration: Table 2 back from forces generated with it, at feeds
    /// across its range, by both routes.
    #[test]
    fn table2_is_recovered_from_its_own_forces() {
        let tool = Tool::PAPER;
        let r = f64::from(tool.radius_mm);
        for motor in [true, false] {
            for mode in [MillingMode::Down, MillingMode::Up] {
                let mut cuts = Vec::new();
                for rr in [0.5f64, 1.0, 2.0] {
                    for &tc in &[0.1042, 0.2, 0.3, 0.4667] {
                        let arc = (1.0 - rr).acos();
                        let ta = tc * rr / arc;
                        let at = |l: PowerLaw| f64::from(l.k) * ta.powf(f64::from(l.p));
                        let (ks, r1, r2) = (at(TABLE2.ks), at(TABLE2.r1), at(TABLE2.r2));
                        let f = brute(&tool, mode, rr, 0.5 * r, &|phi| {
                            let dft = ks * tc * phi.sin();
                            (dft, r1 * dft, r2 * dft)
                        });
                        cuts.push(point(mode, rr, 0.5, tc, f, motor));
                    }
                }
                let fit = fit_power(&tool, &cuts, &TABLE2).unwrap();
                for (name, got, want) in [
                    ("ks", fit.coeffs.ks, TABLE2.ks),
                    ("r1", fit.coeffs.r1, TABLE2.r1),
                    ("r2", fit.coeffs.r2, TABLE2.r2),
                ] {
                    assert!(
                        (got.k / want.k - 1.0).abs() < 1e-4 && (got.p - want.p).abs() < 1e-4,
                        "{mode:?} motor {motor}: {name} {got:?} vs {want:?}"
                    );
                }
                assert!(fit.r2.is_some());
                // Eq. 7 with the laws it came from explains the cuts; one tangential force
                // 3 % off is 3 % over sqrt(2 cuts) of the rms.
                assert!(relative_force_rms(&tool, &cuts, &TABLE2) < 1e-4);
                if motor {
                    let mut off = cuts.clone();
                    if let Second::Tangential(f) = off[0].second {
                        off[0].second = Second::Tangential(1.03 * f);
                    }
                    let want = 0.03 / (2.0 * off.len() as f64).sqrt();
                    let got = relative_force_rms(&tool, &off, &TABLE2);
                    assert!((got / want - 1.0).abs() < 1e-3, "{got} vs {want}");
                }
                assert_eq!(fit.coeffs.tc_fit_mm, (0.1042, 0.4667));
                // Exact data: the residuals are rounding.
                assert!(fit.ks.fit.rms < 1e-5, "{}", fit.ks.fit.rms);
            }
        }
    }

    /// Paper 003 eq. 2 from slotting at several feeds: `K_tc = 4 slope(F_ay) / (N a)`, and
    /// the general fit gives the same; every coefficient of the Al6061 set comes back.
    #[test]
    fn slotting_gives_the_linear_coefficients() {
        let tool = Tool::PAPER;
        let k = AL6061;
        let da = 3.0;
        let tcs = [0.05, 0.1, 0.15, 0.2];
        let cuts: Vec<CutPoint> = tcs
            .iter()
            .map(|&tc| {
                let f = brute(&tool, MillingMode::Down, 2.0, da, &|phi| {
                    let h = tc * phi.sin();
                    (
                        f64::from(k.ktc) * h + f64::from(k.kte),
                        f64::from(k.krc) * h + f64::from(k.kre),
                        f64::from(k.kac) * h + f64::from(k.kae),
                    )
                });
                point(MillingMode::Down, 2.0, da / 8.0, tc, f, false)
            })
            .collect();
        // Paper 003's slope formula on F_ay (its F_normal), by hand.
        let ys: Vec<f64> = cuts
            .iter()
            .map(|c| match c.second {
                Second::Normal(f) => f,
                _ => unreachable!(),
            })
            .collect();
        let slope = (ys[3] - ys[0]) / (tcs[3] - tcs[0]);
        let ktc_paper = 4.0 * slope.abs() / (f64::from(tool.flutes) * da);
        assert!(
            (ktc_paper / f64::from(k.ktc) - 1.0).abs() < 1e-6,
            "{ktc_paper}"
        );
        let fit = fit_linear_model(&tool, &cuts).unwrap();
        assert!(fit.axial);
        let got = fit.coeffs;
        for (name, g, w) in [
            ("ktc", got.ktc, k.ktc),
            ("kte", got.kte, k.kte),
            ("krc", got.krc, k.krc),
            ("kre", got.kre, k.kre),
            ("kac", got.kac, k.kac),
            ("kae", got.kae, k.kae),
        ] {
            assert!(
                (g - w).abs() < 1e-3 * w.abs().max(1.0),
                "{name}: {g} vs {w}"
            );
        }
        // The motor route (F_at instead of F_ay) identifies the same four plane terms.
        let motor: Vec<CutPoint> = cuts
            .iter()
            .zip(&tcs)
            .map(|(c, &tc)| {
                let f = brute(&tool, MillingMode::Down, 2.0, da, &|phi| {
                    let h = tc * phi.sin();
                    (
                        f64::from(k.ktc) * h + f64::from(k.kte),
                        f64::from(k.krc) * h + f64::from(k.kre),
                        0.0,
                    )
                });
                CutPoint {
                    second: Second::Tangential(f[0]),
                    fz_n: None,
                    ..c.clone()
                }
            })
            .collect();
        let fit = fit_linear_model(&tool, &motor).unwrap();
        assert!(!fit.axial);
        assert!((fit.coeffs.ktc - k.ktc).abs() < 1e-3 * k.ktc);
        assert!((fit.coeffs.kre - k.kre).abs() < 1e-3 * k.kre);
    }

    #[test]
    fn one_feed_or_a_negative_r1_is_an_error_that_says_why() {
        let tool = Tool::PAPER;
        let f = brute(&tool, MillingMode::Down, 1.0, 4.0, &|phi| {
            let dft = 1000.0 * 0.2 * phi.sin();
            (dft, 0.3 * dft, 0.1 * dft)
        });
        let one = vec![point(MillingMode::Down, 1.0, 0.5, 0.2, f, true); 3];
        let e = fit_power(&tool, &one, &TABLE2).unwrap_err();
        assert!(
            format!("{e:#}").contains("two average chip thicknesses"),
            "{e:#}"
        );
        let mut neg = one.clone();
        neg[1].tc_mm = 0.3;
        neg[1].fx_n = -1e4;
        let e = fit_power(&tool, &neg, &TABLE2).unwrap_err();
        assert!(format!("{e:#}").contains("r1 = "), "{e:#}");
    }

    fn tmp(name: &str, text: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("cal-cut-{}", std::process::id()));
        std::fs::create_dir_all(&d).expect("temp dir");
        let p = d.join(name);
        std::fs::write(&p, text).expect("write");
        p
    }

    #[test]
    fn records_files_average_the_steady_teeth_only() {
        let p = tmp(
            "rec.csv",
            "time_s,tc_mm,fx_n,f2_n,status\n0.1,0.1,10,100,transient\n0.2,0.1,20,200,valid\n\
             0.3,0.1,30,300,tc_out_of_range|rr_clamped\n0.4,0.1,NaN,1,valid\n0.5,0.1,1,1,settling\n",
        );
        let c = from_teeth(&p, false, "t").expect("reads");
        assert_eq!((c.teeth, c.left_out), (2, 3));
        assert_eq!(c.fx_n, 25.0);
        assert_eq!(c.second, Second::Tangential(250.0));
        let c = from_teeth(&p, true, "t").expect("reads");
        assert_eq!(c.second, Second::Normal(250.0));
    }

    #[test]
    fn bad_plans_and_files_are_named() {
        let cfg = MonitorConfig::default();
        let bad = tmp("bad.csv", "tc_mm,fx_n,ft_n\n0.1,1,2\n0.1,x,2\n");
        let e = from_teeth(&bad, false, "t").expect_err("text accepted");
        assert!(
            format!("{e:#}").contains("bad.csv line 3: `fx_n` is not a number"),
            "{e:#}"
        );
        let plan = tmp(
            "plan.toml",
            "[[cut]]\ntrace = \"a.csv\"\nteeth = \"b.csv\"\ndr_mm = 4.0\nda_mm = 4.0\n",
        );
        let e = read_cuts(&plan, &cfg).expect_err("two sources accepted");
        assert!(
            format!("{e:#}").contains("cut[0]: give exactly one of"),
            "{e:#}"
        );
        let plan = tmp(
            "plan2.toml",
            "[[cut]]\nteeth = \"none.csv\"\ndr_mm = 4.0\nda_m = 4.0\n",
        );
        let e = read_cuts(&plan, &cfg).expect_err("typo accepted");
        assert!(format!("{e:#}").contains("plan2.toml line"), "{e:#}");
        let plan = tmp(
            "plan3.toml",
            "[[cut]]\nteeth = \"none.csv\"\ndr_mm = 4.0\nda_mm = 4.0\n",
        );
        let e = read_cuts(&plan, &cfg).expect_err("missing file accepted");
        assert!(format!("{e:#}").contains("none.csv"), "{e:#}");
        let plan = tmp(
            "plan4.toml",
            "[[cut]]\nteeth = \"bad.csv\"\ndr_mm = 17.0\nda_mm = 4.0\n",
        );
        let e = read_cuts(&plan, &cfg).expect_err("dr > 2R accepted");
        assert!(format!("{e:#}").contains("dr_mm = 17"), "{e:#}");
    }
}
