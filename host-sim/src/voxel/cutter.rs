//! The cutter (flat end mill) and the work material of the voxel simulator.
//!
//! The tool is given on the command line as `key=value` pairs
//! (`radius=5,flutes=3,helix=30,length=20,runout=0.01/0/0`) or as a TOML file with the
//! keys `radius_mm`, `flutes`, `helix_deg`, `length_mm`, `runout_mm` (a list, one per
//! flute). The material is `al6061` (paper 004's coefficients, the core's
//! [`estimator_core::coefficients::AL6061`]) or a TOML file with all six linear
//! coefficients `ktc, krc, kac` [N/mm^2] and `kte, kre, kae` [N/mm].

use anyhow::{anyhow, bail, Context, Result};
use estimator_core::coefficients::{LinearCoefficients, AL6061};
use serde::Deserialize;
use std::path::Path;

/// Most flutes a cutter may have: `VoxelSample::flutes_intact` is a `u8` bitmask.
pub const MAX_FLUTES: u8 = 8;

/// A flat end mill.
#[derive(Clone, Debug, PartialEq)]
pub struct Cutter {
    /// Nominal radius `R` [mm].
    pub radius_mm: f64,
    /// Number of flutes `N` (1 to 8).
    pub flutes: u8,
    /// Helix angle `beta` [deg], right-hand helix (higher disks trail the tip).
    pub helix_deg: f64,
    /// Flute length [mm]: disk elements cover `[tip, tip + length)`; material above it is
    /// not cut (the shank would rub it; not modelled).
    pub length_mm: f64,
    /// Radial offset of each flute's cutting edge from `R` [mm] (runout), one per flute.
    pub runout_mm: Vec<f64>,
}

impl Default for Cutter {
    /// Paper 004's 10 mm 3-flute, 30 deg helix end mill, 20 mm of flute, no runout.
    fn default() -> Self {
        Cutter {
            radius_mm: 5.0,
            flutes: 3,
            helix_deg: 30.0,
            length_mm: 20.0,
            runout_mm: vec![0.0; 3],
        }
    }
}

/// The TOML form of a tool file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CutterFile {
    radius_mm: Option<f64>,
    flutes: Option<u8>,
    helix_deg: Option<f64>,
    length_mm: Option<f64>,
    runout_mm: Option<Vec<f64>>,
}

impl Cutter {
    /// Radius of flute `j`'s cutting edge [mm].
    #[inline]
    pub fn flute_radius_mm(&self, j: usize) -> f64 {
        self.radius_mm + self.runout_mm.get(j).copied().unwrap_or(0.0)
    }

    /// The core's tool description (for `average_forces_linear`).
    pub fn core_tool(&self) -> estimator_core::Tool {
        estimator_core::Tool {
            radius_mm: self.radius_mm as f32,
            flutes: self.flutes,
            helix_deg: self.helix_deg as f32,
        }
    }

    /// Checks every parameter once; errors name it.
    pub fn validate(&self) -> Result<()> {
        let finite_pos = |v: f64| v.is_finite() && v > 0.0;
        if !finite_pos(self.radius_mm) {
            bail!("tool radius must be > 0 mm, got {}", self.radius_mm);
        }
        if self.flutes == 0 || self.flutes > MAX_FLUTES {
            bail!("tool flutes must be 1 to {MAX_FLUTES}, got {}", self.flutes);
        }
        if !(self.helix_deg.is_finite() && (0.0..80.0).contains(&self.helix_deg)) {
            bail!(
                "tool helix must be 0 to 80 deg (right-hand), got {}",
                self.helix_deg
            );
        }
        if !finite_pos(self.length_mm) {
            bail!("tool length must be > 0 mm, got {}", self.length_mm);
        }
        if self.runout_mm.len() != self.flutes as usize {
            bail!(
                "tool runout needs one value per flute ({}), got {}",
                self.flutes,
                self.runout_mm.len()
            );
        }
        for (j, &r) in self.runout_mm.iter().enumerate() {
            if !(r.is_finite() && r.abs() < 0.25 * self.radius_mm) {
                bail!("tool runout of flute {j} must be finite and below R/4, got {r}");
            }
        }
        Ok(())
    }

    /// Parses `--tool`: a TOML file if `spec` names one (ends in `.toml` or is an existing
    /// file), else `key=value` pairs separated by commas.
    pub fn parse(spec: &str) -> Result<Cutter> {
        let p = Path::new(spec);
        if spec.ends_with(".toml") || p.is_file() {
            let text = std::fs::read_to_string(p)
                .with_context(|| format!("cannot read tool file {spec}"))?;
            return Self::from_toml(&text, spec);
        }
        let mut c = Cutter::default();
        let mut runout: Option<Vec<f64>> = None;
        for pair in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let (key, value) = pair
                .split_once('=')
                .ok_or_else(|| anyhow!("--tool: `{pair}` is not key=value"))?;
            let num = |v: &str| -> Result<f64> {
                v.trim()
                    .parse::<f64>()
                    .map_err(|_| anyhow!("--tool: {key}: `{v}` is not a number"))
            };
            match key.trim() {
                "radius" | "radius_mm" => c.radius_mm = num(value)?,
                "diameter" => c.radius_mm = 0.5 * num(value)?,
                "flutes" => {
                    c.flutes = value
                        .trim()
                        .parse()
                        .map_err(|_| anyhow!("--tool: flutes: `{value}` is not a count"))?
                }
                "helix" | "helix_deg" => c.helix_deg = num(value)?,
                "length" | "length_mm" => c.length_mm = num(value)?,
                "runout" | "runout_mm" => {
                    runout = Some(value.split('/').map(num).collect::<Result<Vec<_>>>()?)
                }
                other => bail!(
                    "--tool: unknown key `{other}` (expected radius, diameter, flutes, helix, \
                     length, runout)"
                ),
            }
        }
        c.runout_mm = runout.unwrap_or_else(|| vec![0.0; c.flutes as usize]);
        c.validate().context("--tool")?;
        Ok(c)
    }

    /// Parses a tool TOML file (every key optional, defaults as [`Cutter::default`]).
    pub fn from_toml(text: &str, file: &str) -> Result<Cutter> {
        let f: CutterFile = toml::from_str(text).map_err(|e| toml_error(e, text, file))?;
        let mut c = Cutter::default();
        if let Some(v) = f.radius_mm {
            c.radius_mm = v;
        }
        if let Some(v) = f.flutes {
            c.flutes = v;
        }
        if let Some(v) = f.helix_deg {
            c.helix_deg = v;
        }
        if let Some(v) = f.length_mm {
            c.length_mm = v;
        }
        c.runout_mm = f.runout_mm.unwrap_or_else(|| vec![0.0; c.flutes as usize]);
        c.validate().with_context(|| file.to_string())?;
        Ok(c)
    }
}

/// The TOML form of a material file: all six coefficients.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialFile {
    ktc: f32,
    krc: f32,
    kac: f32,
    kte: f32,
    kre: f32,
    kae: f32,
}

/// Parses `--material`: `al6061` or a TOML file with `ktc, krc, kac, kte, kre, kae`.
pub fn parse_material(spec: &str) -> Result<LinearCoefficients> {
    if spec.eq_ignore_ascii_case("al6061") {
        return Ok(AL6061);
    }
    let text = std::fs::read_to_string(spec).with_context(|| {
        format!("--material: `{spec}` is neither `al6061` nor a readable TOML file")
    })?;
    material_from_toml(&text, spec)
}

/// Parses a material TOML text (all six keys required).
pub fn material_from_toml(text: &str, file: &str) -> Result<LinearCoefficients> {
    let m: MaterialFile = toml::from_str(text).map_err(|e| toml_error(e, text, file))?;
    let k = LinearCoefficients {
        ktc: m.ktc,
        krc: m.krc,
        kac: m.kac,
        kte: m.kte,
        kre: m.kre,
        kae: m.kae,
    };
    for (name, v) in [
        ("ktc", k.ktc),
        ("krc", k.krc),
        ("kac", k.kac),
        ("kte", k.kte),
        ("kre", k.kre),
        ("kae", k.kae),
    ] {
        if !v.is_finite() {
            bail!("{file}: `{name}` is not finite");
        }
    }
    if k.ktc <= 0.0 {
        bail!("{file}: `ktc` must be > 0");
    }
    Ok(k)
}

/// A toml error as one line naming the file and line.
fn toml_error(e: toml::de::Error, text: &str, file: &str) -> anyhow::Error {
    let msg = e.message().trim().to_string();
    match e.span() {
        Some(span) => {
            let line = text[..span.start.min(text.len())].matches('\n').count() + 1;
            anyhow!("{file} line {line}: {msg}")
        }
        None => anyhow!("{file}: {msg}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tool_string_and_toml() {
        let c = Cutter::parse("radius=6, flutes=2,helix=35,length=25,runout=0.01/-0.01")
            .expect("parses");
        assert_eq!(c.radius_mm, 6.0);
        assert_eq!(c.flutes, 2);
        assert_eq!(c.runout_mm, vec![0.01, -0.01]);
        assert_eq!(c.flute_radius_mm(1), 5.99);
        let t = Cutter::from_toml("radius_mm = 4.0\nflutes = 4\n", "t.toml").expect("toml");
        assert_eq!(t.flutes, 4);
        assert_eq!(t.runout_mm.len(), 4);
        assert_eq!(Cutter::parse("").expect("defaults"), Cutter::default());
    }

    #[test]
    fn tool_errors_name_the_problem() {
        let e = |s: &str| format!("{:#}", Cutter::parse(s).expect_err(s));
        assert!(e("radius=abc").contains("radius"));
        assert!(e("flutes=3,runout=0.1/0").contains("one value per flute"));
        assert!(e("flutes=9").contains("flutes"));
        assert!(e("diam=3").contains("unknown key `diam`"));
        let t = format!(
            "{:#}",
            Cutter::from_toml("radius_mm = 4.0\nradius = 3\n", "t.toml").expect_err("typo")
        );
        assert!(t.contains("t.toml line 2"), "{t}");
    }

    #[test]
    fn material_builtin_and_file() {
        assert_eq!(parse_material("AL6061").expect("builtin"), AL6061);
        let k = material_from_toml(
            "ktc = 700\nkrc = 200\nkac = 100\nkte = 15\nkre = 10\nkae = -1\n",
            "m.toml",
        )
        .expect("parses");
        assert_eq!(k.ktc, 700.0);
        let e = material_from_toml("ktc = 700\n", "m.toml").expect_err("incomplete");
        assert!(format!("{e:#}").contains("m.toml"));
    }
}
