//! Eq. 7 (closed-form per-tooth averages) against a brute-force integration of the
//! instantaneous elemental forces (eq. 1-3) over helical flutes and a full revolution.
//!
//! The brute force knows nothing of arcs, `A_r`, `B_r`, `C_r`: it turns the cutter through
//! a revolution in small steps, cuts every flute into thin discs along its helix, asks each
//! disc whether it is inside the engaged arc and, if so, adds `dF_t = K_s t_c sin(phi) dz`
//! and friends in machine axes. Coefficients are held at `t_a` as eq. 7 does (method.md:
//! evaluating them at the instantaneous chip thickness is a different model).

use estimator_core::coefficients::{AL6061, TABLE2};
use estimator_core::geometry::{average_chip_thickness_mm, engaged_arc_rad, entry_exit_rad};
use estimator_core::{average_forces, average_forces_linear, Engagement, MillingMode, Tool};
use std::f64::consts::PI;

struct Brute {
    ft: f64,
    fx: f64,
    fy: f64,
    fz: f64,
}

/// How an element's force depends on its chip thickness `h` [mm] (per unit height):
/// returns `(dF_t, dF_r, dF_a)` per mm.
type Law<'a> = &'a dyn Fn(f64) -> (f64, f64, f64);

/// Revolution-averaged total forces, midpoint rule in rotation and height, with the
/// power-law coefficients held at `t_a` as eq. 7 does.
fn brute_force(tool: &Tool, mode: MillingMode, e: Engagement, n_rot: usize, n_z: usize) -> Brute {
    let t_a = average_chip_thickness_mm(e.tc_mm, e.rr, engaged_arc_rad(e.rr));
    let (ks, r1, r2) = (
        TABLE2.ks.at(t_a) as f64,
        TABLE2.r1.at(t_a) as f64,
        TABLE2.r2.at(t_a) as f64,
    );
    brute_force_law(tool, mode, e, n_rot, n_z, &|h| {
        (ks * h, r1 * ks * h, r2 * ks * h)
    })
}

/// Same integration for any elemental law.
fn brute_force_law(
    tool: &Tool,
    mode: MillingMode,
    e: Engagement,
    n_rot: usize,
    n_z: usize,
    law: Law,
) -> Brute {
    let r = tool.radius_mm as f64;
    let tan_b = (tool.helix_deg as f64).to_radians().tan();
    let (st, ex) = entry_exit_rad(mode, e.rr);
    let (st, ex) = (st as f64, ex as f64);
    let tc = e.tc_mm as f64;
    let da = e.ra as f64 * r;
    let dz = da / n_z as f64;
    let pitch = 2.0 * PI / tool.flutes as f64;
    let (mut ft, mut fx, mut fy, mut fz) = (0.0, 0.0, 0.0, 0.0);
    for i in 0..n_rot {
        let theta = (i as f64 + 0.5) * 2.0 * PI / n_rot as f64;
        for flute in 0..tool.flutes {
            for j in 0..n_z {
                let z = (j as f64 + 0.5) * dz;
                // Helix lag: higher discs trail the flute's tip.
                let phi = (theta + flute as f64 * pitch - z * tan_b / r).rem_euclid(2.0 * PI);
                if phi < st || phi > ex {
                    continue;
                }
                let (t, r, a) = law(tc * phi.sin());
                let (dft, dfr) = (t * dz, r * dz);
                ft += dft;
                fx += dft * phi.cos() + dfr * phi.sin();
                fy += -dft * phi.sin() + dfr * phi.cos();
                fz += a * dz;
            }
        }
    }
    let n = n_rot as f64;
    Brute {
        ft: ft / n,
        fx: fx / n,
        fy: fy / n,
        fz: fz / n,
    }
}

fn check(tool: Tool, mode: MillingMode, e: Engagement) -> f64 {
    let model = average_forces(&tool, &TABLE2, mode, e);
    // Straight flutes cut with a jump at entry/exit that the helix otherwise smears over the
    // rotation steps: give them a finer rotation grid (there is nothing to resolve in z).
    let (n_rot, n_z) = if tool.helix_deg == 0.0 {
        (400 * 2880, 1)
    } else {
        (2880, 400)
    };
    let b = brute_force(&tool, mode, e, n_rot, n_z);
    // Components can pass through zero (F_ax at moderate immersion): scale every error by
    // the tangential force, which never does.
    let scale = b.ft.abs();
    let mut worst = 0.0f64;
    for (name, m, bf) in [
        ("ft", model.ft_n, b.ft),
        ("fx", model.fx_n, b.fx),
        ("fy", model.fy_n, b.fy),
        ("fz", model.fz_n, b.fz),
    ] {
        let err = (m as f64 - bf).abs() / scale;
        assert!(
            err < 1e-3,
            "{mode:?} {tool:?} {e:?}: {name} eq.7 {m} vs brute force {bf} (rel. err {err:.2e})"
        );
        worst = worst.max(err);
    }
    worst
}

#[test]
fn eq7_matches_brute_force_down_and_up() {
    let mut worst = 0.0f64;
    let mut cases = 0;
    for mode in [MillingMode::Down, MillingMode::Up] {
        for (radius, flutes, helix) in [
            (8.0, 4, 30.0),
            (5.0, 2, 45.0),
            (8.0, 3, 10.0),
            (6.0, 4, 0.0),
        ] {
            let tool = Tool {
                radius_mm: radius,
                flutes,
                helix_deg: helix,
            };
            for rr in [0.05, 0.125, 0.5, 1.0, 1.5, 1.9, 2.0] {
                for (tc, ra) in [(0.02, 0.25), (0.1042, 1.0), (0.4167, 2.0)] {
                    worst = worst.max(check(tool, mode, Engagement { rr, ra, tc_mm: tc }));
                    cases += 1;
                }
            }
        }
    }
    println!("eq. 7 vs brute force: {cases} cases, worst error {worst:.2e} of F_at");
}

#[test]
fn averages_do_not_depend_on_helix() {
    // method.md: tan(beta) cancels. The brute force sees the helix; the averages must not.
    let e = Engagement {
        rr: 0.7,
        ra: 1.5,
        tc_mm: 0.2,
    };
    let base = brute_force(
        &Tool {
            helix_deg: 5.0,
            ..Tool::PAPER
        },
        MillingMode::Down,
        e,
        2880,
        400,
    );
    for helix in [20.0, 40.0, 60.0] {
        let b = brute_force(
            &Tool {
                helix_deg: helix,
                ..Tool::PAPER
            },
            MillingMode::Down,
            e,
            2880,
            400,
        );
        assert!(
            (b.fx - base.fx).abs() < 1e-3 * base.ft,
            "helix {helix}: {} vs {}",
            b.fx,
            base.fx
        );
        assert!((b.ft - base.ft).abs() < 1e-3 * base.ft);
    }
}

#[test]
fn brute_force_resolves_the_down_milling_sign_convention() {
    // The convention in geometry.rs: F_ax < 0 for a light down-milling cut, > 0 in a slot,
    // and up milling pushes (F_ax > 0) at any immersion.
    let tool = Tool::PAPER;
    let light = Engagement {
        rr: 0.25,
        ra: 1.0,
        tc_mm: 0.1,
    };
    let slot = Engagement { rr: 2.0, ..light };
    assert!(brute_force(&tool, MillingMode::Down, light, 720, 100).fx < 0.0);
    assert!(brute_force(&tool, MillingMode::Down, slot, 720, 100).fx > 0.0);
    assert!(brute_force(&tool, MillingMode::Up, light, 720, 100).fx > 0.0);
}

#[test]
fn linear_edge_model_matches_brute_force() {
    // Paper 004's shearing + edge model, the voxel simulator's reference.
    let k = AL6061;
    let law = |h: f64| {
        (
            k.ktc as f64 * h + k.kte as f64,
            k.krc as f64 * h + k.kre as f64,
            k.kac as f64 * h + k.kae as f64,
        )
    };
    for mode in [MillingMode::Down, MillingMode::Up] {
        for rr in [0.1, 0.5, 1.0, 1.6, 2.0] {
            for tc in [0.03, 0.1, 0.25] {
                let tool = Tool {
                    radius_mm: 5.0,
                    flutes: 3,
                    helix_deg: 35.0,
                };
                let e = Engagement {
                    rr,
                    ra: 0.8,
                    tc_mm: tc,
                };
                let m = average_forces_linear(&tool, &k, mode, e);
                let b = brute_force_law(&tool, mode, e, 2880, 400, &law);
                for (name, m, bf) in [
                    ("ft", m.ft_n, b.ft),
                    ("fx", m.fx_n, b.fx),
                    ("fy", m.fy_n, b.fy),
                    ("fz", m.fz_n, b.fz),
                ] {
                    let err = (m as f64 - bf).abs() / b.ft.abs();
                    assert!(
                        err < 1e-3,
                        "{mode:?} rr {rr} tc {tc}: {name} {m} vs {bf} ({err:.2e})"
                    );
                }
            }
        }
    }
}
