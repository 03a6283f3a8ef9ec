//! `gen-poly`: fits the `f_xt` polynomials of `estimator_core::poly` and writes them as
//! Rust constants (`estimator-core/src/fxt_poly.rs`).
//!
//! The paper publishes no polynomial for the motor-current ratio `f_xt = F_ax / F_at`, so
//! it is fitted here from the core's own forward model (`Operating::ratio_fxt`, in f32,
//! exactly what the estimator inverts; no physics is re-implemented on the host):
//!
//! 1. a grid of `(R_r, t_c)` slightly wider than the range the set will serve, so that
//!    the fit has no edge droop inside it;
//! 2. `x`, `y` scaled to `[-1, 1]` by the extremes over that grid, computed in f32 with
//!    the f32 scale constants, as `FxtPoly::eval_raw` will compute them;
//! 3. weighted least squares (weight `1 / R_r`: the goal is relative error) for the 36
//!    coefficients of `x^i y^k`, by Householder QR in f64 ([`crate::lstsq`]);
//! 4. the coefficients rounded to f32 and the result judged by `eval_raw` itself on a
//!    separate evaluation grid; a fit that misses [`GOAL`] is an error, not a file.
//!
//! Up milling fits only `R_r >= 0.5`: there `f_xt` peaks at light cuts (near `R_r`
//! 0.1-0.25 depending on `t_c`), so below the peak no function of `f_xt` exists, and the
//! estimator uses the exact inversion (which flags the ambiguity).
//!
//! The output is deterministic (fixed grids, fixed operation order) and formatted by hand:
//! the constant tables carry `#[rustfmt::skip]` so that `cargo fmt` leaves the generated
//! layout alone, and `--check` can compare text without running rustfmt.

use crate::lstsq::lstsq;
use anyhow::{bail, ensure, Context, Result};
use estimator_core::forward::Operating;
use estimator_core::poly::{FxtPoly, TERMS};
use estimator_core::{CuttingCoefficients, MillingMode, TABLE2};
use std::fmt::Write as _;

/// The command that writes the committed file, as the header and error messages quote it.
pub const COMMAND: &str = "cargo run -p host-sim -- gen-poly";

/// What one fitted set covers and what it is fitted on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FitSpec {
    /// Name of the constant (`DOWN`, `UP`).
    pub name: &'static str,
    /// Milling mode.
    pub mode: MillingMode,
    /// `R_r` range of the fit grid (linear, both ends included).
    pub fit_rr: (f64, f64),
    /// Points across `fit_rr`.
    pub n_rr: usize,
    /// `t_c` range of the fit grid [mm/tooth] (log-spaced, both ends included).
    pub fit_tc_mm: (f64, f64),
    /// Points across `fit_tc_mm`.
    pub n_tc: usize,
    /// `R_r` range the set is declared valid for (`FxtPoly::rr`).
    pub rr: (f32, f32),
    /// `t_c` range the set is declared valid for (`FxtPoly::tc_mm`).
    pub tc_mm: (f32, f32),
}

/// Down milling: `f_xt` rises with `R_r` over the whole range, so one set covers 0.1-2.
pub const DOWN: FitSpec = FitSpec {
    name: "DOWN",
    mode: MillingMode::Down,
    fit_rr: (0.095, 2.0),
    n_rr: 300,
    fit_tc_mm: (0.018, 0.55),
    n_tc: 80,
    rr: (0.1, 2.0),
    tc_mm: (0.02, 0.5),
};

/// Up milling: only the slot-side branch, where `f_xt` is monotonic (see module docs).
pub const UP: FitSpec = FitSpec {
    name: "UP",
    mode: MillingMode::Up,
    fit_rr: (0.475, 2.0),
    n_rr: 300,
    fit_tc_mm: (0.018, 0.55),
    n_tc: 80,
    rr: (0.5, 2.0),
    tc_mm: (0.02, 0.5),
};

/// Every set written, in file order.
pub const SPECS: [FitSpec; 2] = [DOWN, UP];

/// Accuracy goal: relative error of `R_r` on the evaluation grid, `(p95, max)`.
pub const GOAL: (f64, f64) = (0.005, 0.02);

/// Evaluation grid size `(R_r, t_c)`: not a multiple of the fit grid, so that its points
/// fall between the fitted ones.
pub const EVAL_GRID: (usize, usize) = (391, 59);

/// How well a set reproduces the forward model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quality {
    /// 95th percentile of `|R_r fitted - R_r| / R_r`.
    pub p95: f64,
    /// Largest relative error.
    pub max: f64,
    /// `(R_r, t_c)` where the largest error occurs.
    pub worst_at: (f32, f32),
}

/// A fitted set with its measured quality.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fitted {
    /// Which spec it answers.
    pub spec: FitSpec,
    /// The constants, exactly as written to the file.
    pub poly: FxtPoly,
    /// Measured with `FxtPoly::eval_raw`.
    pub quality: Quality,
}

/// `n` points from `lo` to `hi`, ends exact.
fn linspace(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| match i {
            0 => lo,
            _ if i == n - 1 => hi,
            _ => lo + (hi - lo) * i as f64 / (n - 1) as f64,
        })
        .collect()
}

/// `n` log-spaced points from `lo` to `hi`, ends exact.
fn logspace(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let mut v: Vec<f64> = linspace(lo.ln(), hi.ln(), n)
        .into_iter()
        .map(f64::exp)
        .collect();
    // exp(ln(x)) need not give x back; the ends are the stated ranges.
    v[0] = lo;
    v[n - 1] = hi;
    v
}

/// `(mid, half)` of the range of `values`, rounded to the f32 the core stores.
fn mid_half(values: impl Iterator<Item = f64>) -> (f32, f32) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    (((hi + lo) / 2.0) as f32, ((hi - lo) / 2.0) as f32)
}

/// `f_xt` from the core's forward model.
fn fxt(coeffs: &CuttingCoefficients, mode: MillingMode, rr: f32, tc_mm: f32) -> f32 {
    Operating::new(coeffs, mode, rr, tc_mm).ratio_fxt()
}

/// Scaled coordinates as `FxtPoly::eval_raw` computes them (f32, libm).
fn scaled(poly: &FxtPoly, fxt: f32, tc_mm: f32) -> (f64, f64) {
    let x = (fxt - poly.x_scale.0) / poly.x_scale.1;
    let y = (libm::logf(tc_mm) - poly.y_scale.0) / poly.y_scale.1;
    (f64::from(x), f64::from(y))
}

/// Fits one set for `coeffs`.
pub fn fit(coeffs: &CuttingCoefficients, spec: &FitSpec) -> Result<FxtPoly> {
    ensure!(
        spec.n_rr >= 2 && spec.n_tc >= 2 && spec.n_rr * spec.n_tc >= TERMS * TERMS,
        "{}: fit grid {} x {} too small for {} coefficients",
        spec.name,
        spec.n_rr,
        spec.n_tc,
        TERMS * TERMS
    );
    // Grid points as the f32 values the core sees.
    let rrs: Vec<f32> = linspace(spec.fit_rr.0, spec.fit_rr.1, spec.n_rr)
        .into_iter()
        .map(|v| v as f32)
        .collect();
    let tcs: Vec<f32> = logspace(spec.fit_tc_mm.0, spec.fit_tc_mm.1, spec.n_tc)
        .into_iter()
        .map(|v| v as f32)
        .collect();
    let points: Vec<(f32, f32, f32)> = tcs
        .iter()
        .flat_map(|&tc| rrs.iter().map(move |&rr| (rr, tc)))
        .map(|(rr, tc)| (rr, tc, fxt(coeffs, spec.mode, rr, tc)))
        .collect();
    if let Some(&(rr, tc, _)) = points.iter().find(|p| !p.2.is_finite()) {
        bail!(
            "{}: forward model gives a non-finite f_xt at R_r {rr}, t_c {tc} mm",
            spec.name
        );
    }
    let mut poly = FxtPoly {
        coeffs: *coeffs,
        mode: spec.mode,
        x_scale: mid_half(points.iter().map(|p| f64::from(p.2))),
        y_scale: mid_half(tcs.iter().map(|&tc| f64::from(tc).ln())),
        tc_mm: spec.tc_mm,
        rr: spec.rr,
        c: [[0.0; TERMS]; TERMS],
    };
    ensure!(
        poly.x_scale.1 > 0.0 && poly.y_scale.1 > 0.0,
        "{}: f_xt or t_c does not vary over the fit grid",
        spec.name
    );
    let n = TERMS * TERMS;
    let mut a = Vec::with_capacity(points.len() * n);
    let mut b = Vec::with_capacity(points.len());
    for &(rr, tc, f) in &points {
        let (x, y) = scaled(&poly, f, tc);
        let w = 1.0 / f64::from(rr);
        let (xp, yp) = (powers(x), powers(y));
        a.extend(
            xp.iter()
                .flat_map(|xi| yp.iter().map(move |yk| w * xi * yk)),
        );
        b.push(w * f64::from(rr));
    }
    let c = lstsq(&a, n, &b).with_context(|| format!("fitting {}", spec.name))?;
    for (row, chunk) in poly.c.iter_mut().zip(c.chunks(TERMS)) {
        for (ci, v) in row.iter_mut().zip(chunk) {
            *ci = *v as f32;
        }
    }
    Ok(poly)
}

/// `[1, v, v^2, ..]`, `TERMS` of them.
fn powers(v: f64) -> [f64; TERMS] {
    let mut p = [1.0; TERMS];
    for i in 1..TERMS {
        p[i] = p[i - 1] * v;
    }
    p
}

/// Relative error of `poly.eval_raw` against the forward model on the evaluation grid,
/// which spans the declared ranges `poly.rr` x `poly.tc_mm`.
pub fn quality(poly: &FxtPoly) -> Quality {
    let rrs = linspace(f64::from(poly.rr.0), f64::from(poly.rr.1), EVAL_GRID.0);
    let tcs = logspace(
        f64::from(poly.tc_mm.0),
        f64::from(poly.tc_mm.1),
        EVAL_GRID.1,
    );
    let mut errs = Vec::with_capacity(rrs.len() * tcs.len());
    let mut worst = (0.0, (0.0, 0.0));
    for &tc in &tcs {
        for &rr in &rrs {
            let (rr, tc) = (rr as f32, tc as f32);
            let got = poly.eval_raw(fxt(&poly.coeffs, poly.mode, rr, tc), tc);
            let rel = (f64::from(got) - f64::from(rr)).abs() / f64::from(rr);
            // NaN must not hide: it sorts last and becomes the worst case.
            let rel = if rel.is_nan() { f64::INFINITY } else { rel };
            if rel > worst.0 {
                worst = (rel, (rr, tc));
            }
            errs.push(rel);
        }
    }
    errs.sort_by(f64::total_cmp);
    // Nearest-rank percentile.
    let rank = ((0.95 * errs.len() as f64).ceil() as usize).clamp(1, errs.len());
    Quality {
        p95: errs[rank - 1],
        max: worst.0,
        worst_at: worst.1,
    }
}

/// Fits every set in [`SPECS`] for `coeffs` and checks it against [`GOAL`].
pub fn fit_all(coeffs: &CuttingCoefficients) -> Result<Vec<Fitted>> {
    SPECS
        .iter()
        .map(|spec| {
            let poly = fit(coeffs, spec)?;
            let quality = quality(&poly);
            ensure!(
                quality.p95 < GOAL.0 && quality.max < GOAL.1,
                "{} fit misses the accuracy goal (p95 < {} %, max < {} %): p95 {:.3} %, \
                 max {:.3} % at R_r {}, t_c {} mm; the coefficients may not suit a fixed \
                 polynomial (the estimator's exact inversion still works without one)",
                spec.name,
                GOAL.0 * 100.0,
                GOAL.1 * 100.0,
                quality.p95 * 100.0,
                quality.max * 100.0,
                quality.worst_at.0,
                quality.worst_at.1,
            );
            Ok(Fitted {
                spec: *spec,
                poly,
                quality,
            })
        })
        .collect()
}

/// The complete `fxt_poly.rs` for `coeffs`. `command` is quoted in the header as the way to
/// regenerate it.
pub fn generate(coeffs: &CuttingCoefficients, command: &str) -> Result<(String, Vec<Fitted>)> {
    let fits = fit_all(coeffs)?;
    let text = render(&fits, command)?;
    Ok((text, fits))
}

/// f32 written so that it parses back to the same bits (shortest round-trip digits).
fn lit(v: f32) -> String {
    format!("{v:?}")
}

/// Same, scientific, for the coefficient table.
fn lit_e(v: f32) -> String {
    format!("{v:e}")
}

/// Source text of the module.
pub fn render(fits: &[Fitted], command: &str) -> Result<String> {
    let Some(first) = fits.first() else {
        bail!("nothing to write: no fitted set");
    };
    let coeffs = first.poly.coeffs;
    let which = if coeffs == TABLE2 {
        "the paper's Table 2 coefficients (`TABLE2`)"
    } else {
        "the coefficient set in `coeffs` below"
    };
    let mut s = String::new();
    let o = &mut s;
    // `write!` into a String cannot fail; the `?`s only satisfy the types.
    writeln!(
        o,
        "//! Fitted `f_xt` polynomials ([`crate::poly::FxtPoly`]) for"
    )?;
    writeln!(o, "//! {which}.")?;
    writeln!(o, "//!")?;
    writeln!(o, "//! GENERATED by `{command}`: do not edit by hand.")?;
    writeln!(
        o,
        "//! Regenerate after changing the forward model, the coefficients or the"
    )?;
    writeln!(
        o,
        "//! generator; host-sim's tests fail while this file is stale."
    )?;
    writeln!(o, "//!")?;
    writeln!(
        o,
        "//! Fit: least squares weighted by 1/R_r on a grid of the core's `ratio_fxt`"
    )?;
    writeln!(
        o,
        "//! (R_r linear, t_c log-spaced). Quality: relative error of R_r from"
    )?;
    writeln!(
        o,
        "//! `FxtPoly::eval_raw` (f32), on a {}x{} grid",
        EVAL_GRID.0, EVAL_GRID.1
    )?;
    writeln!(
        o,
        "//! (R_r linear, t_c log-spaced) over each set's declared range:"
    )?;
    writeln!(o, "//!")?;
    writeln!(
        o,
        "//! | set | fit R_r | fit t_c [mm] | valid R_r | valid t_c [mm] | p95 | max |"
    )?;
    writeln!(o, "//! | --- | --- | --- | --- | --- | --- | --- |")?;
    for f in fits {
        let sp = &f.spec;
        writeln!(
            o,
            "//! | {} | {}-{} | {}-{} | {}-{} | {}-{} | {:.3} % | {:.3} % |",
            sp.name,
            sp.fit_rr.0,
            sp.fit_rr.1,
            sp.fit_tc_mm.0,
            sp.fit_tc_mm.1,
            sp.rr.0,
            sp.rr.1,
            sp.tc_mm.0,
            sp.tc_mm.1,
            f.quality.p95 * 100.0,
            f.quality.max * 100.0,
        )?;
    }
    writeln!(o, "//!")?;
    writeln!(
        o,
        "//! Up milling covers R_r >= 0.5 only: below, f_xt is not monotonic in R_r."
    )?;
    writeln!(o)?;
    writeln!(
        o,
        "use crate::coefficients::{{CuttingCoefficients, PowerLaw}};"
    )?;
    writeln!(o, "use crate::geometry::MillingMode;")?;
    writeln!(o, "use crate::poly::FxtPoly;")?;
    for f in fits {
        writeln!(o)?;
        render_poly(o, f)?;
    }
    writeln!(o)?;
    writeln!(
        o,
        "/// Every fitted set; the estimator picks the one matching its coefficients and mode."
    )?;
    let names: Vec<&str> = fits.iter().map(|f| f.spec.name).collect();
    writeln!(o, "pub const ALL: &[FxtPoly] = &[{}];", names.join(", "))?;
    check_round_trip(&s, fits)?;
    Ok(s)
}

/// One `pub const NAME: FxtPoly = ...;`, its table aligned by hand.
fn render_poly(o: &mut String, f: &Fitted) -> std::fmt::Result {
    let p = &f.poly;
    let law =
        |l: estimator_core::PowerLaw| format!("PowerLaw {{ k: {}, p: {} }}", lit(l.k), lit(l.p));
    let mode = match p.mode {
        MillingMode::Down => "Down",
        MillingMode::Up => "Up",
    };
    writeln!(
        o,
        "/// {} milling: R_r {}-{}, t_c {}-{} mm/tooth.",
        mode, p.rr.0, p.rr.1, p.tc_mm.0, p.tc_mm.1
    )?;
    writeln!(o, "#[rustfmt::skip]")?;
    writeln!(o, "pub const {}: FxtPoly = FxtPoly {{", f.spec.name)?;
    writeln!(o, "    coeffs: CuttingCoefficients {{")?;
    writeln!(o, "        ks: {},", law(p.coeffs.ks))?;
    writeln!(o, "        r1: {},", law(p.coeffs.r1))?;
    writeln!(o, "        r2: {},", law(p.coeffs.r2))?;
    let (a, b) = p.coeffs.tc_fit_mm;
    writeln!(o, "        tc_fit_mm: ({}, {}),", lit(a), lit(b))?;
    writeln!(o, "    }},")?;
    writeln!(o, "    mode: MillingMode::{mode},")?;
    let pair = |(a, b): (f32, f32)| format!("({}, {})", lit(a), lit(b));
    writeln!(o, "    x_scale: {},", pair(p.x_scale))?;
    writeln!(o, "    y_scale: {},", pair(p.y_scale))?;
    writeln!(o, "    tc_mm: {},", pair(p.tc_mm))?;
    writeln!(o, "    rr: {},", pair(p.rr))?;
    writeln!(
        o,
        "    // c[i][k] multiplies x^i y^k: one row per power of x."
    )?;
    writeln!(o, "    c: [")?;
    let cells: Vec<Vec<String>> =
        p.c.iter()
            .map(|row| row.iter().map(|&v| lit_e(v)).collect())
            .collect();
    let width = cells.iter().flatten().map(String::len).max().unwrap_or(0);
    for row in &cells {
        let padded: Vec<String> = row.iter().map(|c| format!("{c:>width$}")).collect();
        writeln!(o, "        [{}],", padded.join(", "))?;
    }
    writeln!(o, "    ],")?;
    writeln!(o, "}};")
}

/// Every number written must parse back to the f32 it came from (the estimator matches a
/// set to its coefficients by exact equality). Rust's shortest-digit formatting promises
/// this; the check makes a formatting change fail here rather than in the estimator.
fn check_round_trip(text: &str, fits: &[Fitted]) -> Result<()> {
    for f in fits {
        let p = &f.poly;
        let mut want: Vec<f32> = vec![
            p.coeffs.ks.k,
            p.coeffs.ks.p,
            p.coeffs.r1.k,
            p.coeffs.r1.p,
            p.coeffs.r2.k,
            p.coeffs.r2.p,
            p.coeffs.tc_fit_mm.0,
            p.coeffs.tc_fit_mm.1,
        ];
        want.extend(
            [p.x_scale, p.y_scale, p.tc_mm, p.rr]
                .iter()
                .flat_map(|&(a, b)| [a, b]),
        );
        want.extend(p.c.iter().flatten());
        for v in want {
            for s in [lit(v), lit_e(v)] {
                let back: f32 = s.parse().with_context(|| format!("literal `{s}`"))?;
                ensure!(
                    back.to_bits() == v.to_bits(),
                    "literal `{s}` does not round-trip ({v:?})"
                );
            }
        }
    }
    ensure!(
        text.ends_with('\n'),
        "generated text must end with a newline"
    );
    Ok(())
}

/// `None` if the generated `text` equals `on_disk`, else the first differing line (1-based)
/// with both versions, for a message that says where a stale file differs.
pub fn first_difference(text: &str, on_disk: &str) -> Option<(usize, String, String)> {
    if text == on_disk {
        return None;
    }
    let mut a = text.lines();
    let mut b = on_disk.lines();
    let mut line = 1;
    loop {
        match (a.next(), b.next()) {
            (Some(x), Some(y)) if x == y => line += 1,
            // Same lines, different line endings or final newline.
            (None, None) => return Some((line, "<line ending>".into(), "<line ending>".into())),
            (x, y) => {
                let show = |s: Option<&str>| s.map_or("<end of file>".to_string(), str::to_string);
                return Some((line, show(x), show(y)));
            }
        }
    }
}
