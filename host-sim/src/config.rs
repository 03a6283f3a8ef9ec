//! TOML files on the desktop: the tool file of `estimate` and the coefficient file of
//! `gen-poly`.
//!
//! Both read into host-side mirrors with every field optional and unknown keys refused:
//! the core's own serde types would ignore a misspelt key (`radius = 6` instead of
//! `radius_mm = 6`) and silently keep the default, which here means a wrong depth of cut.
//! Key names are those of the core's serde derive, so a serialised `EstimatorConfig` (or
//! `CuttingCoefficients`) is a valid file.

use anyhow::{anyhow, Context, Result};
use estimator_core::{
    CuttingCoefficients, EstimatorConfig, MillingMode, PowerLaw, Solver, Tool, TABLE2,
};
use serde::Deserialize;
use std::path::Path;

/// A tool file using every key, shown by `estimate --help` (and parsed by a test, so the
/// help cannot drift from the format).
pub const TOOL_FILE_EXAMPLE: &str = r#"mode = "up"                  # or "down"
force_floor_n = 5.0          # N; below it: not cutting
solver = "inversion"         # auto | polynomial | table3 | inversion
[tool]
radius_mm = 6.0
flutes = 3
helix_deg = 35.0
[coeffs]                     # K_s, r1, r2 = k * t_a^p, t_a in mm
ks = { k = 646.08, p = -0.4362 }
r1 = { k = 0.2201, p = -0.2667 }
r2 = { k = 0.1244, p = 0.1702 }
tc_fit_mm = [0.1042, 0.4667]
"#;

/// `k * t_a^p`, both required.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PowerLawFile {
    /// Value at `t_a` = 1 mm.
    pub k: f32,
    /// Exponent.
    pub p: f32,
}

impl From<PowerLawFile> for PowerLaw {
    fn from(l: PowerLawFile) -> Self {
        PowerLaw { k: l.k, p: l.p }
    }
}

/// Cutting coefficients, any part of them (keys as in `CuttingCoefficients`).
#[derive(Clone, Copy, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoeffsFile {
    /// `K_s` [N/mm^2] against `t_a` [mm].
    pub ks: Option<PowerLawFile>,
    /// Radial / tangential.
    pub r1: Option<PowerLawFile>,
    /// Axial / tangential.
    pub r2: Option<PowerLawFile>,
    /// Calibration feed range [mm/tooth].
    pub tc_fit_mm: Option<(f32, f32)>,
}

impl CoeffsFile {
    /// `base` with the parts given here replaced.
    pub fn over(self, base: CuttingCoefficients) -> CuttingCoefficients {
        CuttingCoefficients {
            ks: self.ks.map_or(base.ks, Into::into),
            r1: self.r1.map_or(base.r1, Into::into),
            r2: self.r2.map_or(base.r2, Into::into),
            tc_fit_mm: self.tc_fit_mm.unwrap_or(base.tc_fit_mm),
        }
    }

    /// The complete set; names the first key missing.
    pub fn complete(self) -> Result<CuttingCoefficients> {
        let need = |v: Option<PowerLawFile>, key: &str| {
            v.map(PowerLaw::from)
                .ok_or_else(|| anyhow!("missing key `{key}`"))
        };
        Ok(CuttingCoefficients {
            ks: need(self.ks, "ks")?,
            r1: need(self.r1, "r1")?,
            r2: need(self.r2, "r2")?,
            tc_fit_mm: self
                .tc_fit_mm
                .ok_or_else(|| anyhow!("missing key `tc_fit_mm`"))?,
        })
    }
}

/// The cutter, any part of it.
#[derive(Clone, Copy, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToolPart {
    /// Tool radius [mm].
    pub radius_mm: Option<f32>,
    /// Number of flutes.
    pub flutes: Option<u8>,
    /// Helix angle [deg].
    pub helix_deg: Option<f32>,
}

/// The `--tool` file of `estimate`: overrides of [`EstimatorConfig::default`].
#[derive(Clone, Copy, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToolFile {
    /// `[tool]`: radius, flutes, helix.
    pub tool: Option<ToolPart>,
    /// `[coeffs]`: cutting coefficients.
    pub coeffs: Option<CoeffsFile>,
    /// `mode = "down"` or `"up"`.
    pub mode: Option<MillingMode>,
    /// Not-cutting threshold [N].
    pub force_floor_n: Option<f32>,
    /// `solver = "auto" | "polynomial" | "table3" | "inversion"`.
    pub solver: Option<Solver>,
}

impl ToolFile {
    /// `base` with the parts given here replaced.
    pub fn over(self, base: EstimatorConfig) -> EstimatorConfig {
        let t = self.tool.unwrap_or_default();
        EstimatorConfig {
            tool: Tool {
                radius_mm: t.radius_mm.unwrap_or(base.tool.radius_mm),
                flutes: t.flutes.unwrap_or(base.tool.flutes),
                helix_deg: t.helix_deg.unwrap_or(base.tool.helix_deg),
            },
            coeffs: self.coeffs.unwrap_or_default().over(base.coeffs),
            mode: self.mode.unwrap_or(base.mode),
            force_floor_n: self.force_floor_n.unwrap_or(base.force_floor_n),
            solver: self.solver.unwrap_or(base.solver),
        }
    }
}

/// Reads and parses a TOML file; errors name the file.
fn read_toml<T: for<'de> Deserialize<'de>>(path: &Path) -> Result<T> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    parse_toml(&text, &path.display().to_string())
}

/// Parses TOML text; errors name `file` and the line.
pub fn parse_toml<T: for<'de> Deserialize<'de>>(text: &str, file: &str) -> Result<T> {
    // toml's messages span several lines (a source excerpt); keep ours to one.
    toml::from_str(text).map_err(|e| {
        let msg = e.message().trim();
        match e.span().map(|s| line_of(text, s.start)) {
            Some(line) => anyhow!("{file} line {line}: {msg}"),
            None => anyhow!("{file}: {msg}"),
        }
    })
}

/// 1-based line number of byte `offset` in `text`.
fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The estimator configuration: defaults, overridden by the tool file if one is given.
pub fn load_estimator_config(tool_file: Option<&Path>) -> Result<EstimatorConfig> {
    let base = EstimatorConfig::default();
    match tool_file {
        None => Ok(base),
        Some(path) => Ok(read_toml::<ToolFile>(path)?.over(base)),
    }
}

/// A complete coefficient set from a `--coeffs` file, or Table 2 without one.
pub fn load_coeffs(path: Option<&Path>) -> Result<CuttingCoefficients> {
    let Some(path) = path else {
        return Ok(TABLE2);
    };
    let coeffs = read_toml::<CoeffsFile>(path)?
        .complete()
        .with_context(|| format!("{}", path.display()))?;
    coeffs
        .validate()
        .map_err(|e| anyhow!("{}: {e}", path.display()))?;
    Ok(coeffs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn help_example_parses_and_sets_every_part() {
        let f: ToolFile = parse_toml(TOOL_FILE_EXAMPLE, "example").expect("example parses");
        let cfg = f.over(EstimatorConfig::default());
        assert_eq!(cfg.mode, MillingMode::Up);
        assert_eq!(cfg.solver, Solver::Inversion);
        assert_eq!(cfg.force_floor_n, 5.0);
        assert_eq!(
            cfg.tool,
            Tool {
                radius_mm: 6.0,
                flutes: 3,
                helix_deg: 35.0
            }
        );
        assert_eq!(cfg.coeffs, TABLE2);
    }

    #[test]
    fn partial_file_keeps_the_rest() {
        let f: ToolFile =
            parse_toml("[coeffs]\nr1 = { k = 0.3, p = -0.2 }\n", "t").expect("parses");
        let base = EstimatorConfig::default();
        let cfg = f.over(base);
        assert_eq!(cfg.coeffs.r1, PowerLaw { k: 0.3, p: -0.2 });
        assert_eq!(cfg.coeffs.ks, base.coeffs.ks);
        assert_eq!(cfg.tool, base.tool);
        assert_eq!(cfg.mode, base.mode);
    }

    #[test]
    fn unknown_keys_are_errors_with_the_line() {
        let e = parse_toml::<ToolFile>("mode = \"down\"\n[tool]\nradius = 6.0\n", "t.toml")
            .expect_err("typo accepted");
        let msg = e.to_string();
        assert!(
            msg.starts_with("t.toml line 3: ") && msg.contains("radius"),
            "{msg}"
        );
        assert!(!msg.contains('\n'), "{msg}");
    }
}
