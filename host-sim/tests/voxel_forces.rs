//! The voxel simulator against the closed-form per-tooth averages (method.md eq. 7 with the
//! linear shearing + edge model, `estimator_core::average_forces_linear`), signs included.
//!
//! `average_forces_linear` gives the force on the work in the feed frame; the simulator
//! gives the force on the tool in machine axes. For a straight cut along +X the
//! expected sample averages are `fx = -F_ax`, `fy = -F_ay`, `fz = -F_az`,
//! `torque = F_at R`, with the material on -Y for down milling and on +Y for up milling.

mod voxel_common;

use estimator_core::MillingMode::{Down, Up};
use host_sim::voxel::sim::EdgeRule;
use voxel_common::*;

fn report(c: &Cut, r: &CutResult) -> String {
    let a = analytic(c);
    let s = to_feed_frame(c, r);
    format!(
        "{:?} dr {} da {} tc {} m {} {:?}: sim (Fx Fy Fz Ft) = ({:.2} {:.2} {:.2} {:.2}), \
         eq.7 = ({:.2} {:.2} {:.2} {:.2}) over {} teeth",
        c.mode,
        c.dr,
        c.da,
        c.tc,
        c.voxel,
        c.feed,
        s[0],
        s[1],
        s[2],
        s[3],
        a.fx_n,
        a.fy_n,
        a.fz_n,
        a.ft_n,
        r.teeth
    )
}

/// Down and up milling along +X at 0.09 mm voxels: every average within 5 % of F_at, and
/// the signs of the machine-axis samples as the module doc states.
#[test]
fn straight_cut_matches_eq7_down_and_up() {
    for (mode, dr, tc) in [
        (Down, 2.5, 0.1),
        (Up, 2.5, 0.1),
        (Down, 10.0, 0.1),
        // Chips thinner than a voxel (the paper's regime, and the benchmark's).
        (Down, 2.5, 0.05),
        (Up, 2.5, 0.05),
    ] {
        let c = Cut::new(mode, dr, 2.7, tc, 0.09);
        let (r, _) = run(&c, false);
        assert!(r.teeth >= 40, "{}", report(&c, &r));
        let (worst, e) = errors(&c, &r);
        println!("{} -> errors {e:.4?}", report(&c, &r));
        assert!(worst < 0.05, "{} -> errors {e:.4?}", report(&c, &r));
        // Signs in machine axes, straight from the samples. Down milling with the material
        // on -Y: the work is pulled back (F_ax < 0), so the tool is pushed forward (+X) and
        // away from the wall (+Y). Up milling with the material on +Y: the tool is pushed
        // back (-X) and pulled into the wall (+Y), the shop-floor rule (conventional
        // milling over-cuts, climb milling leaves stock). Slot: pushed back, and to +Y.
        let a = analytic(&c);
        assert_eq!(
            r.fx.signum(),
            -f64::from(a.fx_n).signum(),
            "{}",
            report(&c, &r)
        );
        assert_eq!(
            r.fy.signum(),
            -f64::from(a.fy_n).signum(),
            "{}",
            report(&c, &r)
        );
        match (mode, dr < 10.0) {
            (Down, true) => assert!(r.fx > 0.0 && r.fy > 0.0, "{}", report(&c, &r)),
            (Up, true) => assert!(r.fx < 0.0 && r.fy > 0.0, "{}", report(&c, &r)),
            _ => assert!(r.fx < 0.0 && r.fy > 0.0, "{}", report(&c, &r)),
        }
        // K_ac > 0: the helix lifts the work (F_az > 0), so it pulls the tool down.
        assert!(r.torque_nm > 0.0 && r.fz < 0.0, "{}", report(&c, &r));
    }
}

/// The same cut fed along +Y: machine forces are the feed-frame ones rotated by +90 deg.
#[test]
fn feed_along_y_rotates_the_forces() {
    for mode in [Down, Up] {
        let mut c = Cut::new(mode, 3.0, 1.8, 0.1, 0.09);
        c.feed = Feed::PlusY;
        let (r, _) = run(&c, false);
        let (worst, e) = errors(&c, &r);
        assert!(worst < 0.05, "{} -> errors {e:.4?}", report(&c, &r));
    }
}

/// The measured engagement equals the programmed one within a voxel.
#[test]
fn measured_engagement_within_a_voxel() {
    for (mode, dr, da, m) in [
        (Down, 2.5, 2.7, 0.09),
        (Up, 4.0, 1.8, 0.09),
        (Down, 10.0, 2.4, 0.15),
    ] {
        let c = Cut::new(mode, dr, da, 0.1, m);
        let (r, _) = run(&c, false);
        assert!(!r.dr_meas.is_empty());
        for (&d, &a) in r.dr_meas.iter().zip(&r.da_meas) {
            assert!(
                (d - dr).abs() <= m,
                "{mode:?}: measured d_r {d} vs {dr} (m {m})"
            );
            assert!(
                (a - da).abs() <= m,
                "{mode:?}: measured d_a {a} vs {da} (m {m})"
            );
        }
    }
}

/// The removed volume is the programmed one; nothing is left inside the swept slot; the
/// annulus shortcut changes nothing at all (same voxels, same forces).
#[test]
fn removal_is_complete_and_the_shortcut_is_exact() {
    let mut c = Cut::new(Down, 3.0, 1.8, 0.1, 0.12);
    let (fast, sim_fast) = run(&c, true);
    c.skip_cleared = false;
    let (slow, sim_slow) = run(&c, true);
    assert!(
        fast.stats.column_visits * 4 < slow.stats.column_visits,
        "{:?} vs {:?}",
        fast.stats,
        slow.stats
    );
    assert_eq!(fast.samples, slow.samples);
    assert_eq!(
        sim_fast.stock().count_voxels(),
        sim_slow.stock().count_voxels()
    );
    // Volume: the strip dr x da along the path (entry from outside to x = 8, plus the
    // half disk at the end).
    let m = c.voxel;
    let removed = fast.removed_voxels as f64 * m * m * m;
    let stock = sim_fast.stock();
    let o = stock.origin();
    let [nx, ny, _] = stock.dims();
    // No material voxel centre left within R - m of the path, between tip and top.
    let k0 = stock.z_index(-c.da);
    for iy in 0..ny {
        for ix in 0..nx {
            let x = o[0] + (ix as f64 + 0.5) * m;
            let y = o[1] + (iy as f64 + 0.5) * m;
            let dx = if x > 8.0 { x - 8.0 } else { 0.0 };
            if dx.hypot(y) < R - m {
                assert!(stock.top(ix, iy) <= k0, "debris at ({x:.2}, {y:.2})");
            }
        }
    }
    let strip = c.dr * c.da * 8.0;
    let end_cap = {
        // Material of the half disk beyond x = 8 (segment of the circle below y = -R + dr).
        let h = c.dr;
        let seg = R * R * ((R - h) / R).acos() - (R - h) * (2.0 * R * h - h * h).sqrt();
        0.5 * seg * c.da
    };
    let want = strip + end_cap;
    assert!(
        (removed - want).abs() < 0.03 * want,
        "removed {removed:.2} mm^3, want {want:.2}"
    );
}

/// Paper 004's edge rule (edge force for the whole step whenever anything was removed)
/// overstates the edge force by about one step per engagement: visible at light radial
/// immersion, where the arc is short.
#[test]
fn any_removal_edge_rule_overstates_the_edge_force() {
    let mut c = Cut::new(Down, 1.0, 1.8, 0.1, 0.09);
    let (span, _) = run(&c, false);
    c.edge = EdgeRule::AnyRemoval;
    let (any, _) = run(&c, false);
    let ft = |r: &CutResult| r.torque_nm * 1e3 / R;
    let a = f64::from(analytic(&c).ft_n);
    println!(
        "F_at: eq.7 {a:.2}, span rule {:.2}, any-removal rule {:.2}",
        ft(&span),
        ft(&any)
    );
    assert!(ft(&any) > ft(&span));
    assert!((ft(&span) - a).abs() < (ft(&any) - a).abs());
}

/// Convergence with the voxel size (prints the table of docs/voxel.md). Heavy: run with
/// `cargo test --release -p host-sim --test voxel_forces -- --ignored --nocapture`.
#[test]
#[ignore]
fn convergence_table() {
    println!("| cut | m [mm] | F_x err | F_y err | F_z err | F_t err |");
    println!("| --- | --- | --- | --- | --- | --- |");
    for (name, mode, dr, tc) in [
        ("down R_r 0.5, t_c 0.1", Down, 2.5, 0.1),
        ("up R_r 0.5, t_c 0.1", Up, 2.5, 0.1),
        ("down R_r 0.5, t_c 0.05", Down, 2.5, 0.05),
        ("up R_r 0.5, t_c 0.05", Up, 2.5, 0.05),
        ("down R_r 0.2, t_c 0.05", Down, 1.0, 0.05),
        ("slot, t_c 0.05", Down, 10.0, 0.05),
    ] {
        for m in [0.3, 0.15, 0.09, 0.06, 0.045] {
            for edge in [EdgeRule::Span, EdgeRule::AnyRemoval] {
                let mut c = Cut::new(mode, dr, 2.7, tc, m);
                c.edge = edge;
                let (r, _) = run(&c, false);
                let (_, e) = errors(&c, &r);
                let rule = if edge == EdgeRule::Span {
                    ""
                } else {
                    " (paper rule)"
                };
                println!(
                    "| {name}{rule} | {m} | {:+.1} % | {:+.1} % | {:+.1} % | {:+.1} % |",
                    e[0] * 100.0,
                    e[1] * 100.0,
                    e[2] * 100.0,
                    e[3] * 100.0
                );
            }
        }
    }
}
