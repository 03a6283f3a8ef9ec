//! Instantaneous cutting forces of a helical end mill (paper 000 eq. 1-3, method.md
//! section 1), summed over every flute and integrated along its helix.
//!
//! # Design
//! Flute `j`'s edge at height `z` above the tip sits at immersion angle
//! `phi = theta - j 2pi/N - z tan(beta)/R` (helix lag: higher points trail the tip), so
//! flute `j + 1` passes every angle one tooth pitch after flute `j` and cuts the chip
//! flute `j` left. An edge point cuts while `phi` is inside the engaged set `A`: the arc of
//! the milling mode ([`estimator_core::geometry::entry_exit_rad`]) intersected, near a
//! face of the work, with the angles whose point `R sin(phi)` ahead of the centre lies
//! inside the material. Its chip is `h = t_cj sin(phi)` with `t_cj` the chip load of that
//! flute at that height:
//!
//! ```text
//! t_cj(z) = max(0, min over earlier flutes i that had an edge at z when they passed
//!                   of (d_ij t_c + r_j - r_i))
//! ```
//!
//! `d_ij` the pitches from flute `i` to `j` (1 for the flute just before, `N` for `j`
//! itself one revolution earlier) and `r` the radial runout offsets. Flute `i` passed the
//! point flute `j` is cutting `d_ij` pitches of rotation earlier, so it counts as it was
//! then. With every flute whole this is `t_c + r_j - r_(j-1)`; a broken flute is absent at
//! every height, so the next flute takes `2 t_c`, but only from the angles the broken one
//! had not reached when it broke (a flute breaks under load, in its cut: what it had cut
//! is not cut again); a flute chipped over `[0, L)` is absent there only.
//! Note: runout enters as a change of the flute's chip load (`h = t_cj sin(phi)`), the
//! usual simplification; the exact offset adds `r_j - r_i` radially. Both give the same
//! revolution sum as long as no chip vanishes, and this one keeps `h = 0` at the ends of
//! the arc as eq. 7 assumes.
//!
//! Elemental forces per unit height (eq. 1-3, or paper 004's shearing + edge law):
//! `dF_t = K_tc h + K_te`, `dF_r = K_rc h + K_re`, `dF_a = K_ac h + K_ae`, and
//! `dF_x = dF_t cos(phi) + dF_r sin(phi)`, `dF_y = -dF_t sin(phi) + dF_r cos(phi)`.
//! Eq. 9's power laws held at the nominal `t_a` are of this form (`K_tc = K_s(t_a)`,
//! `K_rc = r1 K_s`, `K_ac = r2 K_s`, no edge terms). Along a flute `dz = R/tan(beta) dphi`,
//! so the force of a stretch of edge is a closed-form integral over its angles of `1`,
//! `sin`, `cos`, `sin cos` and `sin^2`: the exact limit of paper 004's disk elements as
//! their height goes to zero, at the cost of a few `sin`/`cos` per engaged stretch instead
//! of one per element. With coefficients at the instantaneous chip
//! (`K_s(h) h = k_s h^(1 + p_s)`) there is no closed form: each stretch is integrated by
//! the midpoint rule with elements of at most `element_mm`. Straight flutes
//! (`beta = 0`) have every height at one angle.
//!
//! Sign conventions are [`estimator_core::geometry`]'s: `x` along the feed, `y` normal to
//! it, forces on the work, `F_ax > 0` resisting the feed.

use super::scenario::{Coefficients, CoefficientsAt, ToolSpec, MAX_FLUTES};
use estimator_core::MillingMode;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Total forces on the work [N] (feed frame; `ft` is torque / R).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Forces {
    /// Tangential, summed over the edge (spindle torque / R).
    pub ft: f64,
    /// Feed direction.
    pub fx: f64,
    /// Normal to the feed.
    pub fy: f64,
    /// Axial.
    pub fz: f64,
}

impl std::ops::AddAssign for Forces {
    fn add_assign(&mut self, o: Forces) {
        self.ft += o.ft;
        self.fx += o.fx;
        self.fy += o.fy;
        self.fz += o.fz;
    }
}

/// The engagement at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cut {
    /// Rotation of flute 0's tip [rad] (any value; reduced mod 2 pi here).
    pub theta: f64,
    /// Milling mode.
    pub mode: MillingMode,
    /// Radial immersion ratio `d_r / R`, in `[0, 2]`.
    pub rr: f64,
    /// Axial depth [mm].
    pub da_mm: f64,
    /// Nominal feed per tooth [mm/tooth].
    pub tc_mm: f64,
    /// Distance travelled by the tool centre along the path [mm] (for the faces).
    pub path_mm: f64,
}

/// Linear-in-`h` coefficients per unit height: `[K_tc, K_rc, K_ac, K_te, K_re, K_ae]`.
type Linear = [f64; 6];

#[derive(Clone, Copy, Debug)]
enum Law {
    /// Linear shearing + edge, constant.
    Linear(Linear),
    /// Power laws held at the nominal `t_a` of each instant: linear in `h` once `t_a` is
    /// known.
    NominalTa([(f64, f64); 3]),
    /// Power laws at the element's own chip: `(k, p)` of `K_s`, `r1`, `r2`.
    Instantaneous([(f64, f64); 3]),
}

/// The cutter with its coefficients, ready to evaluate forces; holds the per-call scratch
/// space so that evaluating allocates nothing.
#[derive(Clone, Debug)]
pub struct Cutter {
    r: f64,
    n: usize,
    pitch: f64,
    /// `tan(beta) / R` [rad/mm]: helix lag per unit height.
    lag_per_mm: f64,
    runout: [f64; MAX_FLUTES],
    law: Law,
    element_mm: f64,
    /// Scratch: the engaged set.
    arcs: Vec<(f64, f64)>,
    /// Last `(R_r, t_c)` the nominal-`t_a` coefficients were evaluated at, and the result
    /// (three `powf` per sample otherwise, a third of the run time).
    nominal_cache: Option<((f64, f64), Linear)>,
}

impl Cutter {
    /// Builds the evaluator; the inputs are assumed validated (`Scenario::validate`).
    pub fn new(
        tool: &ToolSpec,
        coeffs: Coefficients,
        at: CoefficientsAt,
        element_mm: f64,
    ) -> Cutter {
        let n = tool.flutes as usize;
        let mut runout = [0.0; MAX_FLUTES];
        for (d, s) in runout.iter_mut().zip(&tool.runout_mm) {
            *d = *s;
        }
        let law = match coeffs {
            Coefficients::Linear(k) => Law::Linear([
                k.ktc as f64,
                k.krc as f64,
                k.kac as f64,
                k.kte as f64,
                k.kre as f64,
                k.kae as f64,
            ]),
            Coefficients::PowerLaw(c) => {
                let laws = [c.ks, c.r1, c.r2].map(|l| (l.k as f64, l.p as f64));
                match at {
                    CoefficientsAt::NominalTa => Law::NominalTa(laws),
                    CoefficientsAt::Instantaneous => Law::Instantaneous(laws),
                }
            }
        };
        Cutter {
            r: tool.radius_mm,
            n,
            pitch: TAU / n as f64,
            lag_per_mm: tool.helix_deg.to_radians().tan() / tool.radius_mm,
            runout,
            law,
            element_mm,
            arcs: Vec::with_capacity(16),
            nominal_cache: None,
        }
    }

    /// Chip loads [mm/tooth] of every flute at one height. `present[d]` (bit `i` for flute
    /// `i`): the flutes that had an edge there `d` pitches ago (`d = 0`: now; one entry
    /// per `d` in `0..=N`, a missing entry counts as `present[0]`). Flute `j` cuts what the
    /// last flute to pass the same point of the work left: flute `j - d` passed it `d`
    /// pitches ago, so it is that flute's edge *then* that counts (a flute broken in the
    /// middle of its pass has cut the angles before the break; the next flute takes its
    /// chip only past them). 0 for flutes without an edge now.
    pub fn chip_loads(&self, tc_mm: f64, present: &[u32]) -> [f64; MAX_FLUTES] {
        let n = self.n;
        let now = present.first().copied().unwrap_or(0);
        let mut out = [0.0; MAX_FLUTES];
        for (j, o) in out.iter_mut().enumerate().take(n) {
            if now & (1 << j) == 0 {
                continue;
            }
            let mut best = f64::INFINITY;
            for d in 1..=n {
                let i = (j + n - d) % n;
                if present.get(d).copied().unwrap_or(now) & (1 << i) != 0 {
                    best = best.min(d as f64 * tc_mm + self.runout[j] - self.runout[i]);
                }
            }
            *o = best.max(0.0);
        }
        out
    }

    /// Total forces at one instant. `missing_mm[d][j]`: flute `j` had no edge below this
    /// height `d` pitches of rotation ago (0 whole, infinite broken; `d = 0`: now, one row
    /// per `d` in `0..=N`, see [`Self::chip_loads`]). `spans`: stretches of work along the
    /// path, or `None` for material everywhere.
    pub fn forces(
        &mut self,
        cut: &Cut,
        missing_mm: &[[f64; MAX_FLUTES]],
        spans: Option<&[[f64; 2]]>,
    ) -> Forces {
        let mut total = Forces::default();
        if !(cut.rr > 0.0 && cut.da_mm > 0.0 && cut.tc_mm > 0.0) {
            return total;
        }
        self.engaged_set(cut, spans);
        if self.arcs.is_empty() {
            return total;
        }
        let lin = match self.law {
            Law::Linear(k) => Some(k),
            Law::NominalTa([ks, r1, r2]) => {
                let key = (cut.rr, cut.tc_mm);
                match self.nominal_cache {
                    Some((k, c)) if k == key => Some(c),
                    _ => {
                        let arc = (1.0 - cut.rr).clamp(-1.0, 1.0).acos();
                        let t_a = cut.tc_mm * cut.rr / arc;
                        let ks = ks.0 * t_a.powf(ks.1);
                        let c = [
                            ks,
                            r1.0 * t_a.powf(r1.1) * ks,
                            r2.0 * t_a.powf(r2.1) * ks,
                            0.0,
                            0.0,
                            0.0,
                        ];
                        self.nominal_cache = Some((key, c));
                        Some(c)
                    }
                }
            }
            Law::Instantaneous(_) => None,
        };
        // Height bands between the flutes' missing lengths (now and at every lag): the
        // sets of flutes with an edge, and so every chip load, are constant inside a band.
        let n = self.n;
        let rows = missing_mm.len().min(n + 1);
        let mut cuts = [0.0f64; (MAX_FLUTES + 1) * MAX_FLUTES + 1];
        let mut nb = 0;
        for row in &missing_mm[..rows] {
            for &m in row.iter().take(n) {
                if m > 0.0 && m < cut.da_mm {
                    cuts[nb] = m;
                    nb += 1;
                }
            }
        }
        cuts[..nb].sort_by(f64::total_cmp);
        cuts[nb] = cut.da_mm;
        let theta = cut.theta.rem_euclid(TAU);
        let mut z0 = 0.0;
        for &z1 in &cuts[..=nb] {
            if z1 <= z0 {
                continue;
            }
            let mut present = [0u32; MAX_FLUTES + 1];
            for (p, row) in present.iter_mut().zip(&missing_mm[..rows]) {
                for (j, &m) in row.iter().enumerate().take(n) {
                    if m <= z0 {
                        *p |= 1 << j;
                    }
                }
            }
            let chips = self.chip_loads(cut.tc_mm, &present[..rows]);
            for (j, &tc) in chips.iter().enumerate().take(n) {
                if tc > 0.0 {
                    let tip = theta - j as f64 * self.pitch;
                    total += self.stretch(tip, z0, z1, tc, lin);
                }
            }
            z0 = z1;
        }
        total
    }

    /// Fills `self.arcs` with the engaged set `A` inside `[0, pi]`.
    fn engaged_set(&mut self, cut: &Cut, spans: Option<&[[f64; 2]]>) {
        self.arcs.clear();
        let arc = (1.0 - cut.rr).clamp(-1.0, 1.0).acos();
        let (st, ex) = match cut.mode {
            MillingMode::Down => (PI - arc, PI),
            MillingMode::Up => (0.0, arc),
        };
        let Some(spans) = spans else {
            self.arcs.push((st, ex));
            return;
        };
        // An edge point at phi is R sin(phi) ahead of the centre; it is in a stretch
        // [p, q] of work when lo <= sin(phi) <= hi.
        for &[p, q] in spans {
            let lo = (p - cut.path_mm) / self.r;
            let hi = (q - cut.path_mm) / self.r;
            if hi < 0.0 || lo > 1.0 {
                continue;
            }
            // sin(phi) >= lo on [a, pi - a]; sin(phi) <= hi on [0, b] and [pi - b, pi].
            let a = lo.max(0.0).asin();
            let b = if hi >= 1.0 { FRAC_PI_2 } else { hi.asin() };
            if b <= a {
                continue;
            }
            for (l, h) in [(a, b), (PI - b, PI - a)] {
                let (l, h) = (l.max(st), h.min(ex));
                if h > l {
                    self.arcs.push((l, h));
                }
            }
        }
    }

    /// Force of flute stretch `[z0, z1]` whose tip is at angle `tip`, chip load `tc`.
    fn stretch(&self, tip: f64, z0: f64, z1: f64, tc: f64, lin: Option<Linear>) -> Forces {
        let mut f = Forces::default();
        let k = self.lag_per_mm;
        if k == 0.0 {
            let phi = tip.rem_euclid(TAU);
            if self.arcs.iter().any(|&(a, b)| phi >= a && phi <= b) {
                let d = self.density(phi, tc, lin);
                let w = z1 - z0;
                f.ft = d.ft * w;
                f.fx = d.fx * w;
                f.fy = d.fy * w;
                f.fz = d.fz * w;
            }
            return f;
        }
        // Angles of the stretch: higher points trail, so z1 maps to the lower end.
        let (lo, hi) = (tip - z1 * k, tip - z0 * k);
        let m0 = (lo / TAU).floor() as i64;
        let m1 = (hi / TAU).floor() as i64;
        for m in m0..=m1 {
            let shift = m as f64 * TAU;
            for &(a, b) in &self.arcs {
                let l = lo.max(a + shift);
                let h = hi.min(b + shift);
                if h > l {
                    f += match lin {
                        Some(c) => integrate_linear(l, h, tc, &c, k),
                        None => self.integrate_midpoint(l, h, tc, k),
                    };
                }
            }
        }
        f
    }

    /// Force per unit height at angle `phi` (straight flutes and the quadrature).
    fn density(&self, phi: f64, tc: f64, lin: Option<Linear>) -> Forces {
        let (s, c) = phi.sin_cos();
        let h = tc * s;
        let (ft, fr, fa) = match (lin, self.law) {
            (Some(k), _) => (k[0] * h + k[3], k[1] * h + k[4], k[2] * h + k[5]),
            (None, Law::Instantaneous([ks, r1, r2])) => {
                if h <= 0.0 {
                    return Forces::default();
                }
                let ln_h = h.ln();
                let ft = ks.0 * ((1.0 + ks.1) * ln_h).exp();
                (
                    ft,
                    r1.0 * (r1.1 * ln_h).exp() * ft,
                    r2.0 * (r2.1 * ln_h).exp() * ft,
                )
            }
            (None, _) => (0.0, 0.0, 0.0),
        };
        Forces {
            ft,
            fx: ft * c + fr * s,
            fy: -ft * s + fr * c,
            fz: fa,
        }
    }

    /// Midpoint rule over `[l, h]` (angles) with elements of at most `element_mm`.
    fn integrate_midpoint(&self, l: f64, h: f64, tc: f64, k: f64) -> Forces {
        let height = (h - l) / k;
        let n = (height / self.element_mm).ceil().max(1.0);
        let dphi = (h - l) / n;
        let w = height / n;
        let mut f = Forces::default();
        for i in 0..n as usize {
            let d = self.density(l + (i as f64 + 0.5) * dphi, tc, None);
            f.ft += d.ft * w;
            f.fx += d.fx * w;
            f.fy += d.fy * w;
            f.fz += d.fz * w;
        }
        f
    }
}

/// Exact integral over angles `[l, h]` of the linear law, `dz = dphi / k`.
fn integrate_linear(l: f64, h: f64, tc: f64, c: &Linear, k: f64) -> Forces {
    let (sl, cl) = l.sin_cos();
    let (sh, ch) = h.sin_cos();
    let len = h - l;
    let int_sin = cl - ch;
    let int_cos = sh - sl;
    let int_sc = 0.5 * (sh * sh - sl * sl);
    // int sin^2 = (len - (sin 2h - sin 2l)/2) / 2, sin 2x = 2 sin x cos x.
    let int_ss = 0.5 * (len - (sh * ch - sl * cl));
    let [ktc, krc, kac, kte, kre, kae] = *c;
    let inv = 1.0 / k;
    Forces {
        ft: inv * (ktc * tc * int_sin + kte * len),
        fx: inv * (ktc * tc * int_sc + kte * int_cos + krc * tc * int_ss + kre * int_sin),
        fy: inv * (-ktc * tc * int_ss - kte * int_sin + krc * tc * int_sc + kre * int_cos),
        fz: inv * (kac * tc * int_sin + kae * len),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use estimator_core::TABLE2;

    fn tool(n: u8, helix: f64, runout: Vec<f64>) -> ToolSpec {
        ToolSpec {
            radius_mm: 8.0,
            flutes: n,
            helix_deg: helix,
            runout_mm: runout,
        }
    }

    #[test]
    fn chip_loads_follow_the_cutting_order() {
        let c = Cutter::new(
            &tool(4, 30.0, vec![0.02, 0.0, 0.0, 0.0]),
            Coefficients::PowerLaw(TABLE2),
            CoefficientsAt::NominalTa,
            0.05,
        );
        let all = 0b1111;
        let t = c.chip_loads(0.1, &[all]);
        // Flute 0 sticks out 0.02: it cuts 0.02 more, flute 1 (after it) 0.02 less.
        for (j, want) in [0.12, 0.08, 0.1, 0.1].iter().enumerate() {
            assert!((t[j] - want).abs() < 1e-12, "{j}: {}", t[j]);
        }
        // Flute 2 gone: flute 3 cuts what flute 1 left, two pitches of feed.
        let t = c.chip_loads(0.1, &[all & !(1 << 2)]);
        assert_eq!(t[2], 0.0);
        assert!((t[3] - 0.2).abs() < 1e-12);
        // ... but only where flute 2 was already gone when it would have passed, a pitch
        // before flute 3: where it cut before it broke, flute 3 takes the usual chip.
        let gone = all & !(1 << 2);
        let t = c.chip_loads(0.1, &[gone, all, all, all, all]);
        assert_eq!(t[2], 0.0);
        assert!((t[3] - 0.1).abs() < 1e-12, "{}", t[3]);
        let t = c.chip_loads(0.1, &[gone, gone, all, all, all]);
        assert!((t[3] - 0.2).abs() < 1e-12, "{}", t[3]);
        // Large runout: flute 0 sticks out 3.5 feeds; it cuts the whole revolution's
        // material (N t_c) and the others cut nothing.
        let c = Cutter::new(
            &tool(4, 30.0, vec![0.35, 0.0, 0.0, 0.0]),
            Coefficients::PowerLaw(TABLE2),
            CoefficientsAt::NominalTa,
            0.05,
        );
        let t = c.chip_loads(0.1, &[all]);
        assert!((t[0] - 0.4).abs() < 1e-12, "{}", t[0]);
        assert_eq!(&t[1..4], &[0.0; 3]);
    }
}
