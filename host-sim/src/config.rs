//! TOML files on the desktop: the tool file of `estimate` and the coefficient file of
//! `gen-poly`.
//!
//! Key names are those of the core's serde derive (a serialised `EstimatorConfig` or
//! `CuttingCoefficients` is a valid file). A file may give any part: it is laid over the
//! defaults serialised to TOML, key by key, and the result deserialised. Keys the defaults
//! do not have are refused: serde would ignore a misspelt key (`radius = 6` for
//! `radius_mm = 6`) and silently keep the default, which here means a wrong depth of cut.
//! Working on the serialised form keeps this in step with the core's types: a field the
//! core adds is accepted, and defaulted, without a change here.

use anyhow::{anyhow, bail, Context, Result};
use estimator_core::{CuttingCoefficients, EstimatorConfig, TABLE2};
use serde::{de::DeserializeOwned, Serialize};
use std::path::Path;

/// A tool file using every key, shown by `estimate --help` (and checked by a test against
/// the core's `EstimatorConfig`, so the help cannot drift from the format).
pub const TOOL_FILE_EXAMPLE: &str = r#"mode = "up"                  # or "down"
force_floor_n = 5.0          # N; below it: not cutting
solver = "inversion"         # auto | polynomial | table3 | inversion
gain_uncertainty = 0.02      # relative 1-sigma gain error of each force channel
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

/// `base` with every key of `patch` laid over it (tables merged key by key, other values
/// replaced, keys `base` lacks added: an optional field left at `None` is absent from the
/// serialised defaults).
fn overlay(base: &mut toml::Table, patch: &toml::Table) {
    for (key, value) in patch {
        match (base.get_mut(key), value) {
            (Some(toml::Value::Table(b)), toml::Value::Table(p)) => overlay(b, p),
            (Some(slot), v) => *slot = v.clone(),
            (None, v) => {
                base.insert(key.clone(), v.clone());
            }
        }
    }
}

/// Every key of `patch` must be in `result` (the merged configuration, deserialised and
/// serialised again): serde drops a key it does not know, so a key missing there was
/// misspelt (`radius = 6` for `radius_mm = 6`); the error names its dotted path and what
/// that table takes. `at` is the path of `patch` itself ("" at the top).
fn check_known(result: &toml::Table, patch: &toml::Table, at: &str) -> Result<()> {
    for (key, value) in patch {
        let path = if at.is_empty() {
            key.clone()
        } else {
            format!("{at}.{key}")
        };
        match (result.get(key), value) {
            (None, _) => {
                let known = result
                    .keys()
                    .map(String::as_str)
                    .collect::<Vec<_>>()
                    .join(", ");
                bail!("unknown key `{path}` (expected one of: {known})");
            }
            (Some(toml::Value::Table(r)), toml::Value::Table(p)) => check_known(r, p, &path)?,
            _ => {}
        }
    }
    Ok(())
}

/// `base` overridden by the TOML `text`; errors name `file` (and the line, for syntax).
pub fn override_from<T: Serialize + DeserializeOwned>(
    base: &T,
    text: &str,
    file: &str,
) -> Result<T> {
    let patch = parse_toml::<toml::Table>(text, file)?;
    let mut merged = toml::Table::try_from(base).context("serialising the defaults")?;
    overlay(&mut merged, &patch);
    let out: T = merged
        .try_into()
        .map_err(|e: toml::de::Error| anyhow!("{file}: {}", e.message().trim()))?;
    let result = toml::Table::try_from(&out).context("serialising the configuration")?;
    check_known(&result, &patch, "").with_context(|| file.to_string())?;
    Ok(out)
}

/// Reads a TOML file.
fn read(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))
}

/// Parses TOML text; errors name `file` and the line.
pub fn parse_toml<T: DeserializeOwned>(text: &str, file: &str) -> Result<T> {
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
/// A machine file (replay's `--config`, what `calibrate` writes) serves as a tool file too:
/// its `[estimator]` table is used and the rest (drives, alarms) ignored.
pub fn load_estimator_config(tool_file: Option<&Path>) -> Result<EstimatorConfig> {
    let base = EstimatorConfig::default();
    let Some(path) = tool_file else {
        return Ok(base);
    };
    let text = read(path)?;
    let file = path.display().to_string();
    let table: toml::Table = parse_toml(&text, &file)?;
    match table.get("estimator") {
        Some(toml::Value::Table(est)) => {
            let sub = toml::to_string(est).map_err(|e| anyhow!("{file}: {e}"))?;
            override_from(&base, &sub, &format!("{file} [estimator]"))
        }
        _ => override_from(&base, &text, &file),
    }
}

/// A coefficient set from a `--coeffs` file (every key required), or Table 2 without one.
pub fn load_coeffs(path: Option<&Path>) -> Result<CuttingCoefficients> {
    let Some(path) = path else {
        return Ok(TABLE2);
    };
    let file = path.display().to_string();
    let text = read(path)?;
    // Overlaying on TABLE2 checks the key names; the plain parse then insists on all of
    // them: a fit for a half-replaced set would be a fit for nobody's tool.
    override_from(&TABLE2, &text, &file)?;
    let coeffs: CuttingCoefficients = parse_toml(&text, &file)?;
    coeffs.validate().map_err(|e| anyhow!("{file}: {e}"))?;
    Ok(coeffs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use estimator_core::{MillingMode, PowerLaw, Solver, Tool};

    fn keys(t: &toml::Table, at: &str, out: &mut Vec<String>) {
        for (k, v) in t {
            let path = if at.is_empty() {
                k.clone()
            } else {
                format!("{at}.{k}")
            };
            match v {
                toml::Value::Table(sub) => keys(sub, &path, out),
                _ => out.push(path),
            }
        }
    }

    #[test]
    fn help_example_parses_and_covers_every_key() {
        let base = EstimatorConfig::default();
        let cfg = override_from(&base, TOOL_FILE_EXAMPLE, "example").expect("example parses");
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
        // A field added to EstimatorConfig must be documented in the example.
        let (mut all, mut shown) = (Vec::new(), Vec::new());
        keys(
            &toml::Table::try_from(base).expect("serialise"),
            "",
            &mut all,
        );
        keys(
            &parse_toml(TOOL_FILE_EXAMPLE, "example").expect("parse"),
            "",
            &mut shown,
        );
        let missing: Vec<_> = all.iter().filter(|k| !shown.contains(k)).collect();
        assert!(missing.is_empty(), "TOOL_FILE_EXAMPLE lacks {missing:?}");
    }

    #[test]
    fn partial_file_keeps_the_rest() {
        let base = EstimatorConfig::default();
        let cfg = override_from(&base, "[coeffs]\nr1 = { k = 0.3 }\n", "t").expect("parses");
        assert_eq!(
            cfg.coeffs.r1,
            PowerLaw {
                k: 0.3,
                p: base.coeffs.r1.p
            }
        );
        assert_eq!(
            EstimatorConfig {
                coeffs: base.coeffs,
                ..cfg
            },
            base
        );
    }

    #[test]
    fn unknown_keys_and_bad_values_are_named() {
        let base = EstimatorConfig::default();
        let e = override_from(&base, "mode = \"down\"\n[tool]\nradius = 6.0\n", "t.toml")
            .expect_err("typo accepted");
        let msg = format!("{e:#}");
        assert!(
            msg.starts_with("t.toml: unknown key `tool.radius`"),
            "{msg}"
        );
        assert!(msg.contains("radius_mm"), "{msg}");
        let e = override_from(&base, "mode = \"sideways\"\n", "t.toml").expect_err("bad mode");
        let msg = format!("{e:#}");
        assert!(
            msg.starts_with("t.toml: ") && msg.contains("sideways"),
            "{msg}"
        );
        let e = override_from(&base, "mode = \n", "t.toml").expect_err("bad syntax");
        let msg = format!("{e:#}");
        assert!(
            msg.starts_with("t.toml line 1: ") && !msg.contains('\n'),
            "{msg}"
        );
    }
}
