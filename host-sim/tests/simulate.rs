//! The trace simulator (`host_sim::sim`) against the core's physics: tooth averages of a
//! steady cut against eq. 7, instantaneous forces against a brute-force sum of disk
//! elements, the drive chain against the core's forward functions, damage, runout, the
//! encoder, the ADC, the load meter, the scenario file.

#![allow(clippy::unwrap_used)]

// One module, so that `cargo test -p host-sim sim` selects these tests too.
mod sim {

    use estimator_core::coefficients::AL6061;
    use estimator_core::drive::{FeedAxis, FeedDrive, SpindleModel};
    use estimator_core::monitor::Input;
    use estimator_core::status::Status;
    use estimator_core::table::{Segment as Line, Segments};
    use estimator_core::tooth::SyncMode;
    use estimator_core::{
        average_forces, average_forces_linear, Engagement, MillingMode, Monitor, MonitorConfig,
        MonitorState, Tool, TABLE2,
    };
    use host_sim::sim::{
        simulate, CoefficientsAt, Event, EventKind, Material, Profile, Scenario, SimSummary,
    };
    use host_sim::trace::TraceRow;
    use std::f64::consts::{PI, TAU};

    /// A steady dynamometer cut: paper tool, 600 rpm, 20 kS/s (500 samples per tooth), t_c
    /// 0.1, R_r 0.5, R_a 1. The sync phase is off the sample grid so that no boundary falls on
    /// a sample exactly.
    const BASE: &str = r#"
sample_rate_hz = 20000.0
input = "dynamometer"
[tool]
radius_mm = 8.0
flutes = 4
helix_deg = 30.0
[signal]
sync_phase_deg = 0.37
[[segment]]
duration_s = 0.4
rpm = 600.0
feed_mm_min = 240.0
dr_mm = 4.0
da_mm = 8.0
"#;

    fn base() -> Scenario {
        Scenario::from_toml(BASE, "BASE").unwrap()
    }

    fn run(sc: &Scenario) -> (Vec<TraceRow>, SimSummary) {
        let mut rows = Vec::new();
        let s = simulate(sc, |r| {
            rows.push(*r);
            Ok(())
        })
        .unwrap();
        (rows, s)
    }

    /// Sets the one segment's engagement.
    fn set_cut(sc: &mut Scenario, rr: f64, ra: f64, tc: f64, rpm: f64) {
        let r = sc.tool.radius_mm;
        let n = sc.tool.flutes as f64;
        let s = &mut sc.segments[0];
        s.rpm = Some(Profile::Constant(rpm));
        s.feed_mm_min = Some(Profile::Constant(tc * n * rpm));
        s.dr_mm = Some(Profile::Constant(rr * r));
        s.da_mm = Some(Profile::Constant(ra * r));
    }

    /// One complete period between two sync pulses: mean true forces, first sample.
    #[derive(Debug, Clone, Copy)]
    struct Tooth {
        start: usize,
        len: usize,
        ft: f64,
        fx: f64,
        fy: f64,
    }

    fn teeth(rows: &[TraceRow]) -> Vec<Tooth> {
        let pulses: Vec<usize> = (0..rows.len()).filter(|&i| rows[i].sync).collect();
        pulses
            .windows(2)
            .map(|w| {
                let seg = &rows[w[0]..w[1]];
                let m = |f: fn(&TraceRow) -> f32| {
                    seg.iter().map(|r| f(r) as f64).sum::<f64>() / seg.len() as f64
                };
                Tooth {
                    start: w[0],
                    len: seg.len(),
                    ft: m(|r| r.truth.ft_n),
                    fx: m(|r| r.truth.fx_n),
                    fy: m(|r| r.truth.fy_n),
                }
            })
            .collect()
    }

    /// Largest error of any tooth's averages against `want`, relative to `F_at`.
    fn worst_tooth_error(teeth: &[Tooth], want: (f64, f64, f64)) -> f64 {
        let (ft, fx, fy) = want;
        teeth
            .iter()
            .map(|t| {
                [(t.ft - ft).abs(), (t.fx - fx).abs(), (t.fy - fy).abs()]
                    .into_iter()
                    .fold(0.0, f64::max)
                    / ft.abs()
            })
            .fold(0.0, f64::max)
    }

    fn eq7(sc: &Scenario, rr: f64, ra: f64, tc: f64) -> (f64, f64, f64) {
        let e = Engagement {
            rr: rr as f32,
            ra: ra as f32,
            tc_mm: tc as f32,
        };
        let tool = sc.tool.core();
        let f = match sc.material {
            Material::Al6061 => average_forces_linear(&tool, &AL6061, sc.mode, e),
            _ => average_forces(&tool, &TABLE2, sc.mode, e),
        };
        (f.ft_n as f64, f.fx_n as f64, f.fy_n as f64)
    }

    #[test]
    fn steady_tooth_averages_match_eq7() {
        let mut worst = 0.0f64;
        let mut cases = 0;
        for material in [Material::Table2, Material::Al6061] {
            for mode in [MillingMode::Down, MillingMode::Up] {
                for (radius, flutes, helix) in [
                    (8.0, 4, 30.0),
                    (5.0, 2, 45.0),
                    (8.0, 3, 10.0),
                    (6.0, 4, 0.0),
                ] {
                    for (rr, ra, tc) in [
                        (0.1, 0.5, 0.1),
                        (0.5, 1.0, 0.2),
                        (1.0, 1.5, 0.1042),
                        (1.5, 0.25, 0.3),
                        (2.0, 1.0, 0.15),
                    ] {
                        let mut sc = base();
                        sc.material = material.clone();
                        sc.mode = mode;
                        sc.tool.radius_mm = radius;
                        sc.tool.flutes = flutes;
                        sc.tool.helix_deg = helix;
                        sc.segments[0].duration_s = 0.25;
                        set_cut(&mut sc, rr, ra, tc, 600.0);
                        let (rows, _) = run(&sc);
                        let t = teeth(&rows);
                        assert!(t.len() >= 2 * flutes as usize, "{} teeth", t.len());
                        let err = worst_tooth_error(&t, eq7(&sc, rr, ra, tc));
                        assert!(
                            err < 0.01,
                            "{material:?} {mode:?} R {radius} N {flutes} helix {helix} R_r {rr} \
                         R_a {ra} t_c {tc}: tooth average off eq. 7 by {:.3} % of F_at",
                            err * 100.0
                        );
                        worst = worst.max(err);
                        cases += 1;
                    }
                }
            }
        }
        println!("{cases} cases, worst tooth {:.4} % of F_at", worst * 100.0);
    }

    /// Brute force: every flute cut into `nz` disks, each adding its elemental force at its
    /// own angle; chip loads `tcs`; coefficients at `t_a` or at the disk's chip.
    #[allow(clippy::too_many_arguments)]
    fn brute_force(
        tool: &Tool,
        mode: MillingMode,
        rr: f64,
        da: f64,
        tc: f64,
        tcs: &[f64],
        theta: f64,
        instantaneous: bool,
        nz: usize,
    ) -> (f64, f64, f64) {
        let r = tool.radius_mm as f64;
        let tan_b = (tool.helix_deg as f64).to_radians().tan();
        let arc = (1.0 - rr).acos();
        let (st, ex) = match mode {
            MillingMode::Down => (PI - arc, PI),
            MillingMode::Up => (0.0, arc),
        };
        let t_a = tc * rr / arc;
        let law = |l: estimator_core::PowerLaw, t: f64| l.k as f64 * t.powf(l.p as f64);
        let n = tool.flutes as usize;
        let dz = da / nz as f64;
        let (mut ft, mut fx, mut fy) = (0.0, 0.0, 0.0);
        for (j, &tcj) in tcs.iter().enumerate().take(n) {
            for k in 0..nz {
                let z = (k as f64 + 0.5) * dz;
                let phi = (theta - j as f64 * TAU / n as f64 - z * tan_b / r).rem_euclid(TAU);
                if phi < st || phi > ex {
                    continue;
                }
                let h = tcj * phi.sin();
                let at = if instantaneous { h } else { t_a };
                if at <= 0.0 {
                    continue;
                }
                let dft = law(TABLE2.ks, at) * h * dz;
                let dfr = law(TABLE2.r1, at) * dft;
                ft += dft;
                fx += dft * phi.cos() + dfr * phi.sin();
                fy += -dft * phi.sin() + dfr * phi.cos();
            }
        }
        (ft, fx, fy)
    }

    #[test]
    fn instantaneous_forces_match_a_sum_of_disk_elements() {
        for instantaneous in [false, true] {
            for (mode, flutes, helix, rr, ra, runout) in [
                (
                    MillingMode::Down,
                    4,
                    30.0,
                    0.5,
                    1.0,
                    vec![0.01, 0.0, -0.004, 0.0],
                ),
                (MillingMode::Up, 3, 45.0, 1.2, 2.0, vec![]),
                (MillingMode::Down, 2, 10.0, 2.0, 0.5, vec![0.0, 0.02]),
            ] {
                let mut sc = base();
                sc.mode = mode;
                sc.tool.flutes = flutes;
                sc.tool.helix_deg = helix;
                sc.tool.runout_mm = runout.clone();
                sc.element_mm = 0.01;
                if instantaneous {
                    sc.coefficients_at = CoefficientsAt::Instantaneous;
                }
                sc.segments[0].duration_s = 0.1;
                let tc = 0.12;
                set_cut(&mut sc, rr, ra, tc, 600.0);
                let (rows, _) = run(&sc);
                let n = flutes as usize;
                let r = |j: usize| runout.get(j).copied().unwrap_or(0.0);
                let tcs: Vec<f64> = (0..n).map(|j| tc + r(j) - r((j + n - 1) % n)).collect();
                let tool = sc.tool.core();
                let peak = rows.iter().map(|r| r.truth.ft_n.abs()).fold(0.0, f32::max) as f64;
                let mut worst = 0.0f64;
                for i in (0..rows.len()).step_by(37) {
                    let theta = TAU * 600.0 / 60.0 * i as f64 / 20_000.0;
                    let (ft, fx, fy) = brute_force(
                        &tool,
                        mode,
                        rr,
                        ra * 8.0,
                        tc,
                        &tcs,
                        theta,
                        instantaneous,
                        4000,
                    );
                    let t = &rows[i].truth;
                    for (sim, bf) in [(t.ft_n, ft), (t.fx_n, fx), (t.fy_n, fy)] {
                        worst = worst.max((sim as f64 - bf).abs() / peak);
                    }
                }
                assert!(
                    worst < 2e-3,
                    "{mode:?} N {flutes} helix {helix} R_r {rr} instantaneous {instantaneous}: \
                 off the brute force by {:.3} % of the peak",
                    worst * 100.0
                );
            }
        }
    }

    #[test]
    fn instantaneous_coefficients_cut_lower_than_eq7() {
        // method.md: coefficients at the instantaneous chip give a tangential force 4-5 %
        // below eq. 7 (K_s grows as the chip thins; the thin ends weigh less than t_a says).
        let mut sc = base();
        sc.coefficients_at = CoefficientsAt::Instantaneous;
        set_cut(&mut sc, 0.5, 1.0, 0.2, 600.0);
        let (rows, _) = run(&sc);
        let t = teeth(&rows);
        let want = eq7(&sc, 0.5, 1.0, 0.2).0;
        let mean = t.iter().map(|t| t.ft).sum::<f64>() / t.len() as f64;
        let low = 1.0 - mean / want;
        println!(
            "instantaneous coefficients: F_at {:.2} % below eq. 7",
            low * 100.0
        );
        assert!(
            (0.02..0.08).contains(&low),
            "{:.2} % below eq. 7",
            low * 100.0
        );
    }

    fn feed_axis() -> FeedAxis {
        FeedAxis {
            torque_constant_nm_per_a: 1.2,
            screw_lead_mm: 10.0,
            efficiency: 0.9,
            current_offset_a: 0.05,
            coulomb_n: 40.0,
            viscous_n_per_mm_min: 0.02,
            stiction_band_mm_min: 1.0,
            sign: -1.0,
        }
    }

    fn current_spindle() -> SpindleModel {
        SpindleModel::Current {
            torque_constant_nm_per_a: 0.8,
            idle_current_a: Segments::new(&[Line {
                from_rpm: 0.0,
                slope: 1e-4,
                intercept: 0.5,
            }])
            .unwrap(),
        }
    }

    fn motor(two_axis: bool, spindle: SpindleModel) -> Input {
        Input::Motor {
            feed: FeedDrive {
                axes: [
                    feed_axis(),
                    FeedAxis {
                        sign: 1.0,
                        ..feed_axis()
                    },
                ],
                two_axis,
            },
            spindle,
        }
    }

    #[test]
    fn currents_invert_to_the_true_forces() {
        // No noise, lag, ADC: the core's forward functions give back the simulated forces at
        // every sample, along +X, -X and diagonally, for both spindle models.
        for (two_axis, angle, spindle) in [
            (false, 0.0, current_spindle()),
            (false, 180.0, current_spindle()),
            (true, 30.0, current_spindle()),
            (true, 225.0, SpindleModel::paper003()),
        ] {
            let mut sc = base();
            sc.input = motor(two_axis, spindle.clone());
            sc.segments[0].feed_angle_deg = Some(angle);
            sc.segments[0].duration_s = 0.1;
            if matches!(spindle, SpindleModel::Load { .. }) {
                // A meter that reports every sample, unrounded: it reports the interval that
                // just ended, one sample late.
                sc.signal.load_update_hz = sc.sample_rate_hz;
                sc.signal.load_resolution_pct = 1e-9;
            }
            let load = matches!(spindle, SpindleModel::Load { .. });
            let (rows, _) = run(&sc);
            let Input::Motor { feed, spindle } = &sc.input else {
                unreachable!()
            };
            let scale = rows.iter().map(|r| r.truth.ft_n.abs()).fold(0.0, f32::max);
            for (i, r) in rows.iter().enumerate().skip(1) {
                let fx = feed.feed_force_n(r.feed, r.feed_velocity_mm_min);
                let truth_sp = if load { &rows[i - 1].truth } else { &r.truth };
                let ft = spindle.tangential_force_n(r.spindle, 600.0, 8.0);
                assert!(
                    (fx - r.truth.fx_n).abs() < 2e-4 * scale,
                    "angle {angle} row {i}: feed force {fx} vs true {}",
                    r.truth.fx_n
                );
                assert!(
                    (ft - truth_sp.ft_n).abs() < 2e-4 * scale,
                    "angle {angle} row {i}: tangential force {ft} vs true {}",
                    truth_sp.ft_n
                );
            }
        }
        // A dynamometer reads the feed-frame forces themselves.
        let (rows, _) = run(&base());
        for r in &rows {
            assert_eq!(r.feed, [r.truth.fx_n, r.truth.fy_n]);
        }
    }

    #[test]
    fn inertia_joins_the_feed_load_while_the_feed_ramps() {
        let mut sc = base();
        sc.input = motor(false, current_spindle());
        sc.signal.moving_mass_kg = 200.0;
        sc.segments[0].duration_s = 0.1;
        // 240 -> 1440 mm/min in 0.1 s: 0.2 m/s^2, 40 N.
        sc.segments[0].feed_mm_min = Some(Profile::Ramp(240.0, 1440.0));
        let (rows, _) = run(&sc);
        let Input::Motor { feed, .. } = &sc.input else {
            unreachable!()
        };
        for r in &rows {
            let fx = feed.feed_force_n(r.feed, r.feed_velocity_mm_min);
            assert!(
                (fx - r.truth.fx_n - 40.0).abs() < 0.05,
                "{fx} {}",
                r.truth.fx_n
            );
        }
    }

    /// Which flute a tooth period belongs to: the pulse comes as flute `j`'s tip passes the
    /// sync phase, at `theta = phase + j pitch` (mod 2 pi).
    fn flute_of(t: &Tooth, sc: &Scenario) -> usize {
        let n = sc.tool.flutes as usize;
        let pitch = TAU / n as f64;
        let theta = TAU * 600.0 / 60.0 * t.start as f64 / sc.sample_rate_hz;
        let j = ((theta - sc.signal.sync_phase_deg.to_radians()) / pitch).round() as i64;
        j.rem_euclid(n as i64) as usize
    }

    /// R_r 0.5 down milling, d_a 4 mm: a flute's tip cuts from 120 to 197 deg, so with the
    /// pulse at 115 deg each tooth period holds one flute's whole cut and nothing else.
    fn one_flute_per_period() -> Scenario {
        let mut sc = base();
        sc.signal.sync_phase_deg = 115.0;
        sc.segments[0].duration_s = 1.0;
        set_cut(&mut sc, 0.5, 0.5, 0.1, 600.0);
        sc
    }

    /// Mean tooth force per flute over the teeth starting in `[from_s, to_s)`.
    fn per_flute(sc: &Scenario, teeth: &[Tooth], from_s: f64, to_s: f64) -> Vec<f64> {
        let n = sc.tool.flutes as usize;
        let (mut sum, mut count) = (vec![0.0; n], vec![0; n]);
        for t in teeth {
            let time = t.start as f64 / sc.sample_rate_hz;
            if time >= from_s && time < to_s {
                let j = flute_of(t, sc);
                sum[j] += t.ft;
                count[j] += 1;
            }
        }
        sum.iter().zip(&count).map(|(s, &c)| s / c as f64).collect()
    }

    fn assert_ratios(got: &[f64], want: &[f64], unit: f64, what: &str) {
        for (j, (g, w)) in got.iter().zip(want).enumerate() {
            assert!(
                (g / unit - w).abs() < 0.01,
                "{what}: flute {j} at {:.4} of eq. 7, expected {w}",
                g / unit
            );
        }
        let total: f64 = got.iter().sum::<f64>() / unit;
        let want_total: f64 = want.iter().sum();
        assert!(
            (total - want_total).abs() < 0.01 * want_total,
            "{what}: revolution sum {total} vs {want_total}"
        );
    }

    #[test]
    fn a_broken_flute_cuts_nothing_and_the_next_one_takes_its_chip() {
        let mut sc = one_flute_per_period();
        sc.events.push(Event {
            time_s: 0.5,
            flute: 2,
            kind: EventKind::Break,
            fraction: None,
            length_mm: None,
        });
        let (rows, _) = run(&sc);
        let unit = eq7(&sc, 0.5, 0.5, 0.1).0;
        let t = teeth(&rows);
        assert!(t.iter().all(|t| t.len == 500));
        assert_ratios(&per_flute(&sc, &t, 0.0, 0.45), &[1.0; 4], unit, "before");
        assert_ratios(
            &per_flute(&sc, &t, 0.6, 1.0),
            &[1.0, 1.0, 0.0, 2.0],
            unit,
            "after",
        );
        assert_eq!(rows[0].truth.flutes_intact, 0b1111);
        assert_eq!(rows.last().unwrap().truth.flutes_intact, 0b1011);
    }

    #[test]
    fn a_flute_broken_in_its_cut_leaves_the_next_one_only_what_it_had_not_cut() {
        // Flute 2 breaks with its tip at 140 deg, in the middle of the down-milling arc
        // 120..180 deg. What it had cut is gone; the rest of its chip goes to flute 3, a
        // pitch later. No material is cut twice: with the (linear) nominal-t_a law the force
        // the cut loses and the force flute 3 gains integrate to the same impulse. (Flute 3
        // taking `2 t_c` from the break on would cut 120..140 deg a second time: half a
        // tooth's impulse too much.)
        let clean = one_flute_per_period();
        let tip = 140f64.to_radians();
        let t_b = host_sim::sim::time_at_angle(&clean, 0.5, 2, tip)
            .unwrap()
            .expect("in the run");
        assert!((0.5..0.6).contains(&t_b), "{t_b}");
        let mut sc = clean.clone();
        sc.events.push(Event {
            time_s: t_b,
            flute: 2,
            kind: EventKind::Break,
            fraction: None,
            length_mm: None,
        });
        let (a, _) = run(&clean);
        let (b, _) = run(&sc);
        let dt = 1.0 / sc.sample_rate_hz;
        let tooth_s = 60.0 / (600.0 * 4.0);
        let unit = eq7(&sc, 0.5, 0.5, 0.1).0 * tooth_s;
        let impulse = |from: f64, to: f64| -> f64 {
            a.iter()
                .zip(&b)
                .filter(|(r, _)| r.time_s >= from && r.time_s < to)
                .map(|(r, s)| f64::from(s.truth.ft_n - r.truth.ft_n) * dt)
                .sum()
        };
        // The rest of flute 2's cut, from 140 deg to the arc's end (and its trailing
        // helix), is lost at once, and nothing is gained before flute 3 reaches 140 deg a
        // pitch later.
        let lost = -impulse(t_b, t_b + tooth_s) / unit;
        assert!(lost > 0.2 && lost < 0.8, "lost {lost} of a tooth");
        let early = impulse(t_b + 0.75 * tooth_s, t_b + tooth_s) / unit;
        assert!(early.abs() < 1e-3, "{early}");
        // Flute 3 then takes exactly that, and no more until flute 2 comes round: no
        // material is cut twice.
        let gained = impulse(t_b + tooth_s, t_b + 2.0 * tooth_s) / unit;
        assert!(
            (gained - lost).abs() < 0.01 * lost,
            "gained {gained}, lost {lost}"
        );
        let rest = impulse(t_b + 2.0 * tooth_s, t_b + 3.0 * tooth_s) / unit;
        assert!(rest.abs() < 1e-3, "{rest}");
        // From then on every revolution loses flute 2's chip and gains it on flute 3.
        let rev = impulse(t_b + 4.0 * tooth_s, t_b + 8.0 * tooth_s) / unit;
        assert!(rev.abs() < 0.01, "net {rev} of a tooth a revolution");
        // And after it, flute 2 cuts nothing, flute 3 twice the chip.
        let all = 0b1111u32;
        assert_eq!(b.last().unwrap().truth.flutes_intact, all & !(1 << 2));
    }

    #[test]
    fn a_chipped_flute_loses_its_tip_to_the_next_one() {
        // Half the axial depth lost on flute 1, then 1 mm of flute 3's tip: the following
        // flute takes the lost part's chip at that height on top of its own.
        let mut sc = one_flute_per_period();
        for (t, flute, fraction, length_mm) in
            [(0.3, 1, Some(0.5), None), (0.6, 3, None, Some(1.0))]
        {
            sc.events.push(Event {
                time_s: t,
                flute,
                kind: EventKind::Chip,
                fraction,
                length_mm,
            });
        }
        let (rows, _) = run(&sc);
        let unit = eq7(&sc, 0.5, 0.5, 0.1).0;
        let t = teeth(&rows);
        assert_ratios(&per_flute(&sc, &t, 0.0, 0.25), &[1.0; 4], unit, "whole");
        assert_ratios(
            &per_flute(&sc, &t, 0.4, 0.55),
            &[1.0, 0.5, 1.5, 1.0],
            unit,
            "flute 1 chipped",
        );
        // d_a 4 mm: flute 3 loses a quarter, flute 0 gains it.
        assert_ratios(
            &per_flute(&sc, &t, 0.7, 1.0),
            &[1.25, 0.5, 1.5, 0.75],
            unit,
            "flutes 1 and 3 chipped",
        );
        assert_eq!(rows.last().unwrap().truth.flutes_intact, 0b0101);
    }

    #[test]
    fn runout_makes_flutes_unequal_but_not_the_revolution() {
        let mut sc = one_flute_per_period();
        sc.tool.runout_mm = vec![0.01, 0.0, -0.005, 0.0];
        let (rows, _) = run(&sc);
        let unit = eq7(&sc, 0.5, 0.5, 0.1).0;
        let t = teeth(&rows);
        // t_cj = t_c + r_j - r_(j-1): 0.11, 0.09, 0.095, 0.105.
        assert_ratios(
            &per_flute(&sc, &t, 0.0, 1.0),
            &[1.1, 0.9, 0.95, 1.05],
            unit,
            "runout",
        );
    }

    #[test]
    fn sync_pulses_per_tooth_and_per_revolution() {
        let mut sc = base();
        sc.segments[0].duration_s = 1.0;
        let (rows, s) = run(&sc);
        let pulses: Vec<usize> = (0..rows.len()).filter(|&i| rows[i].sync).collect();
        assert_eq!(pulses.len() as u64, s.sync_pulses);
        assert_eq!(pulses.len(), 40);
        assert!(pulses.windows(2).all(|w| w[1] - w[0] == 500));
        // The pulse after the 0.37 deg crossing: 0.37 / 360 / 10 rev/s * 20 kS/s = 2.06.
        assert_eq!(pulses[0], 3);

        sc.sync = SyncMode::PerRevolution;
        let (rows, _) = run(&sc);
        let pulses: Vec<usize> = (0..rows.len()).filter(|&i| rows[i].sync).collect();
        assert_eq!(pulses.len(), 10);
        assert!(pulses.windows(2).all(|w| w[1] - w[0] == 2000));
    }

    #[test]
    fn sync_pulses_follow_a_speed_ramp() {
        // 600 -> 1200 rpm in 1 s: 15 revolutions, 60 teeth; periods shrink from 500 samples
        // to 250 as the speed at each period says.
        let mut sc = base();
        sc.segments[0].duration_s = 1.0;
        sc.segments[0].rpm = Some(Profile::Ramp(600.0, 1200.0));
        sc.segments[0].dr_mm = Some(Profile::Constant(0.0));
        let (rows, s) = run(&sc);
        assert_eq!(s.sync_pulses, 60);
        let pulses: Vec<usize> = (0..rows.len()).filter(|&i| rows[i].sync).collect();
        for w in pulses.windows(2) {
            let mid = (w[0] + w[1]) as f64 / 2.0 / 20_000.0;
            let rpm = 600.0 + 600.0 * mid;
            let want = 20_000.0 * 60.0 / (rpm * 4.0);
            assert!(((w[1] - w[0]) as f64 - want).abs() <= 1.0, "{w:?}: {want}");
        }
        assert_eq!(rows[10_000].truth.rpm, 900.0);
    }

    #[test]
    fn sync_jitter_and_dropouts_as_configured() {
        let mut sc = base();
        sc.segments[0].duration_s = 20.0;
        sc.segments[0].dr_mm = Some(Profile::Constant(0.0)); // air: fast
        let (clean, _) = run(&sc);
        let at = |rows: &[TraceRow]| -> Vec<usize> {
            (0..rows.len()).filter(|&i| rows[i].sync).collect()
        };
        let clean = at(&clean);
        sc.signal.sync_jitter_samples = 3;
        sc.signal.sync_dropout = 0.1;
        let (rows, s) = run(&sc);
        let jittered = at(&rows);
        assert_eq!(s.sync_pulses + s.sync_dropped, clean.len() as u64);
        let lost = s.sync_dropped as f64 / clean.len() as f64;
        // 800 pulses: 10 % +- 1.1 % (1 sigma).
        assert!((0.065..0.135).contains(&lost), "{lost}");
        // Every surviving pulse lies 0..=6 samples after a clean one (delay 3, +-3), and
        // every offset occurs.
        let mut seen = [0u32; 7];
        for p in &jittered {
            let c = clean.iter().rev().find(|&&c| c <= *p).unwrap();
            let d = p - c;
            assert!(d <= 6, "pulse {p} is {d} after {c}");
            seen[d] += 1;
        }
        assert!(seen.iter().all(|&k| k > 50), "{seen:?}");
    }

    #[test]
    fn adc_quantises_and_clips() {
        let mut sc = base();
        sc.input = motor(false, current_spindle());
        sc.segments[0].duration_s = 0.1;
        sc.signal.adc_bits = Some(8);
        sc.signal.feed_full_scale = Some(0.25); // the feed current swings beyond
        sc.signal.spindle_full_scale = Some(50.0);
        let (rows, s) = run(&sc);
        let lsb = 0.25 / 128.0;
        let mut rails = 0;
        for r in &rows {
            let x = r.feed[0] as f64;
            assert_eq!((x / lsb).round() * lsb, x, "{x} is not a code");
            assert!((-0.25..=0.25 - lsb).contains(&x));
            rails += (x == 0.25 - lsb || x == -0.25) as u64;
            let y = r.spindle as f64;
            assert_eq!((y / (50.0 / 128.0)).round() * (50.0 / 128.0), y);
        }
        assert!(rails > 100, "{rails}");
        assert_eq!(s.clipped[0], rails);
        assert_eq!(s.clipped[2], 0);
        assert_eq!(s.clip_levels[0], 0.25 - lsb);
        assert_eq!(s.clip_levels[1], 0.25 - lsb);
    }

    #[test]
    fn spindle_load_is_whole_percent_at_a_low_rate() {
        // Paper 003's spindle at 5400 rpm, 12 mm 2-flute tool in Al6061.
        let mut sc = base();
        sc.input = motor(false, SpindleModel::paper003());
        sc.material = Material::Al6061;
        sc.tool.radius_mm = 6.0;
        sc.tool.flutes = 2;
        sc.segments[0].duration_s = 1.0;
        set_cut(&mut sc, 1.0, 1.0, 0.1, 5400.0);
        let (rows, _) = run(&sc);
        let fs = sc.sample_rate_hz;
        let mut changes = 0;
        for (i, w) in rows.windows(2).enumerate() {
            assert_eq!(w[1].spindle.fract(), 0.0, "{}", w[1].spindle);
            if w[1].spindle != w[0].spindle {
                changes += 1;
                // Updates come every 50 ms (1000 samples).
                assert_eq!((i + 1) % (fs / 20.0) as usize, 0, "change at {}", i + 1);
            }
        }
        assert!(changes >= 1);
        // The displayed load is the mean cutting power's, rounded.
        let mean_ft = rows.iter().map(|r| r.truth.ft_n as f64).sum::<f64>() / rows.len() as f64;
        let Input::Motor { spindle, .. } = &sc.input else {
            unreachable!()
        };
        let want = spindle.signal_for_force(mean_ft as f32, 5400.0, 6.0);
        let last = rows.last().unwrap().spindle;
        assert!((last - want).abs() <= 0.5 + 1e-3, "{last} vs {want}");
    }

    #[test]
    fn entry_and_exit_through_the_faces() {
        // 240 mm/min = 4 mm/s; the work spans 4 to 12 mm of path. Down milling at R_r 0.5
        // engages phi in [120, 180] deg, R sin(phi) in [0, 6.93] mm ahead of the centre: first
        // contact at s = 4 - 6.93 < 0, so from the start; full arc from s = 4 (1 s) to
        // s = 12 - 6.93 = 5.07 (1.27 s); nothing after s = 12 (3 s).
        let mut sc = base();
        sc.segments[0].duration_s = 3.5;
        sc.workpiece = Some(host_sim::sim::Workpiece {
            spans_mm: vec![[4.0, 12.0]],
        });
        set_cut(&mut sc, 0.5, 1.0, 0.1, 600.0);
        // 4 mm/s: feed 240 mm/min, t_c = 240 / (4 * 600) = 0.1.
        let (rows, _) = run(&sc);
        let unit = eq7(&sc, 0.5, 1.0, 0.1).0;
        let t = teeth(&rows);
        let time = |t: &Tooth| t.start as f64 / sc.sample_rate_hz;
        let mut last = 0.0;
        for tooth in &t {
            let (s, f) = (time(tooth), tooth.ft / unit);
            if s < 1.0 - 0.026 {
                // Entering: grows.
                assert!(f <= 1.0 + 1e-3 && f >= last - 1e-3, "{s} s: {f}");
                last = f;
            } else if (1.0..1.25).contains(&s) {
                assert!((f - 1.0).abs() < 0.01, "{s} s: {f}");
            } else if s > 3.0 {
                assert_eq!(f, 0.0, "{s} s");
            }
        }
        // Truth: the cutter touches the work until the centre passes the exit face.
        assert_eq!(rows[0].truth.dr_mm, 4.0);
        assert_eq!(rows.last().unwrap().truth.dr_mm, 0.0);
    }

    fn bits(rows: &[TraceRow]) -> Vec<u64> {
        rows.iter()
            .flat_map(|r| {
                let t = &r.truth;
                [
                    r.time_s.to_bits(),
                    r.sync as u64,
                    r.feed[0].to_bits() as u64,
                    r.feed[1].to_bits() as u64,
                    r.spindle.to_bits() as u64,
                    t.fx_n.to_bits() as u64,
                    t.ft_n.to_bits() as u64,
                ]
            })
            .collect()
    }

    #[test]
    fn same_seed_same_bits() {
        let mut sc = base();
        sc.input = motor(false, current_spindle());
        sc.segments[0].duration_s = 0.2;
        sc.signal.feed_noise = 0.05;
        sc.signal.spindle_noise = 0.05;
        sc.signal.sync_jitter_samples = 2;
        sc.signal.sync_dropout = 0.2;
        let a = bits(&run(&sc).0);
        assert_eq!(a, bits(&run(&sc).0));
        sc.seed = 2;
        assert_ne!(a, bits(&run(&sc).0));
    }

    #[test]
    fn noisy_lagged_trace_through_the_monitor() {
        // The whole chain: currents with lag, noise and a 12-bit ADC, read by the core's
        // Monitor configured with the same input; valid estimates near the truth.
        let mut sc = base();
        sc.input = motor(false, current_spindle());
        sc.tool.runout_mm = vec![0.005, 0.0, 0.0, 0.0];
        sc.segments[0].duration_s = 3.0;
        set_cut(&mut sc, 0.5, 1.0, 0.15, 600.0);
        sc.signal.feed_lag_s = 5e-4;
        sc.signal.spindle_lag_s = 2e-3;
        sc.signal.feed_noise = 0.02;
        sc.signal.spindle_noise = 0.05;
        sc.signal.adc_bits = Some(12);
        sc.signal.feed_full_scale = Some(20.0);
        sc.signal.spindle_full_scale = Some(60.0);
        let cfg = MonitorConfig {
            sample_rate_hz: sc.sample_rate_hz as f32,
            input: sc.input.clone(),
            ..MonitorConfig::default()
        };
        let mon: Monitor = cfg.build().unwrap();
        let mut st = MonitorState::default();
        let mut valid = Vec::new();
        simulate(&sc, |r| {
            if let Some(rec) = mon.process(&mut st, &r.to_sample()) {
                if rec.status.is_valid() {
                    valid.push(rec.dr_mm);
                }
            }
            Ok(())
        })
        .unwrap();
        assert!(valid.len() > 50, "{} valid teeth", valid.len());
        for dr in valid {
            assert!((dr - 4.0).abs() < 0.2, "d_r {dr}");
        }
    }

    #[test]
    fn scenario_errors_name_the_key() {
        let err = |text: &str| format!("{:#}", Scenario::from_toml(text, "s.toml").unwrap_err());
        let with = |from: &str, to: &str| {
            assert!(BASE.contains(from));
            err(&BASE.replace(from, to))
        };
        // TOML: the line and the key.
        let m = with("radius_mm = 8.0", "radius = 8.0");
        assert!(
            m.starts_with("s.toml line 5") && m.contains("radius"),
            "{m}"
        );
        let m = with("rpm = 600.0", "rpmm = 600.0");
        assert!(m.contains("line 12") && m.contains("rpmm"), "{m}");
        let m = with("dr_mm = 4.0", "dr_mm = [1.0, 2.0, 3.0]");
        assert!(m.contains("line 14") && m.contains("[from, to]"), "{m}");
        let m = with("input = \"dynamometer\"", "input = \"strain_gauge\"");
        assert!(m.contains("line 3") && m.contains("strain_gauge"), "{m}");
        // Validation: the key path.
        let m = with("rpm = 600.0", "rpm = -600.0");
        assert!(m.contains("segment[0].rpm"), "{m}");
        let m = with("da_mm = 8.0", "");
        assert!(m.contains("segment[0].da_mm: required"), "{m}");
        let m = with("dr_mm = 4.0", "dr_mm = 17.0");
        assert!(m.contains("segment[0].dr_mm"), "{m}");
        let m = err(&format!(
        "{BASE}[[segment]]\nduration_s = 0.0\n[[event]]\ntime_s = 1.0\nflute = 0\nkind = \"break\"\n"
    ));
        assert!(m.contains("segment[1].duration_s"), "{m}");
        let m = err(&format!(
            "{BASE}[[event]]\ntime_s = 1.0\nflute = 4\nkind = \"break\"\n"
        ));
        assert!(m.contains("event[0].flute"), "{m}");
        let m = err(&format!(
            "{BASE}[[event]]\ntime_s = 1.0\nflute = 1\nkind = \"chip\"\n"
        ));
        assert!(m.contains("event[0]") && m.contains("fraction"), "{m}");
        let m = with("sync_phase_deg = 0.37", "sync_jitter_samples = 200");
        assert!(m.contains("signal.sync_jitter_samples"), "{m}");
        // One feed axis cannot move diagonally.
        let mut sc = base();
        sc.input = motor(false, current_spindle());
        sc.segments[0].feed_angle_deg = Some(45.0);
        let m = format!("{:#}", sc.validate().unwrap_err());
        assert!(
            m.contains("segment[0].feed_angle_deg") && m.contains("two_axis"),
            "{m}"
        );
        // The core's own checks, with the section named.
        let mut sc = base();
        sc.input = motor(false, current_spindle());
        if let Input::Motor { feed, .. } = &mut sc.input {
            feed.axes[0].efficiency = 1.5;
        }
        let m = format!("{:#}", sc.validate().unwrap_err());
        assert!(
            m.contains("input.motor.feed") && m.contains("efficiency"),
            "{m}"
        );
    }

    #[test]
    fn example_scenario_runs() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/cut.toml");
        let text = std::fs::read_to_string(path).unwrap();
        let sc = Scenario::from_toml(&text, path).unwrap();
        assert_eq!(sc.segments.len(), 7);
        // Through the writer and back: the reader sees the same rows.
        let (summary, bytes) = host_sim::sim::write_trace(&sc, Vec::new()).unwrap();
        assert_eq!(summary.rows, 270_000);
        assert_eq!(summary.clipped, [0, 0, 0]);
        let mut reader = host_sim::trace::TraceReader::new(&bytes[..], "cut.csv").unwrap();
        let mut rows = Vec::new();
        while let Some(r) = reader.next_row().unwrap() {
            rows.push(r);
        }
        assert_eq!(rows.len(), 270_000);
        let at = |t: f64| &rows[(t * 20_000.0) as usize].truth;
        // Before the face is met (8 mm at 0.67 s) nothing cuts; after the exit (13 s) neither.
        assert_eq!(at(0.5).ft_n, 0.0);
        assert!(at(3.0).ft_n > 0.0);
        assert_eq!(at(13.2).ft_n, 0.0);
        // The ramp, the step (met from 7.5 s over 8 mm of travel), the feed change, the
        // break.
        assert_eq!(at(5.0).dr_mm, 6.0);
        assert!((at(8.1667).da_mm - 5.0).abs() < 1e-3);
        assert_eq!(at(9.0).da_mm, 6.0);
        assert!((at(11.0).tc_mm - 0.225).abs() < 1e-6);
        assert_eq!(at(11.4).flutes_intact, 0b1111);
        assert_eq!(at(11.6).flutes_intact, 0b1011);
    }

    /// Throughput of the example scenario without the CSV writer; run in release:
    /// `cargo test --release -p host-sim --test simulate -- --ignored --nocapture throughput`.
    #[test]
    #[ignore]
    fn throughput() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/cut.toml");
        let sc = Scenario::from_toml(&std::fs::read_to_string(path).unwrap(), path).unwrap();
        let t0 = std::time::Instant::now();
        let mut acc = 0.0f64;
        let s = simulate(&sc, |r| {
            acc += r.feed[0] as f64;
            Ok(())
        })
        .unwrap();
        let secs = t0.elapsed().as_secs_f64();
        println!(
        "{} rows, {:.1} s of trace in {secs:.3} s: {:.0}x real time, {:.0} ns/sample ({acc:.0})",
        s.rows,
        s.duration_s,
        s.duration_s / secs,
        secs * 1e9 / s.rows as f64
    );
    }

    #[test]
    fn example_through_the_monitor() {
        // The demo's path: the example trace into the core's Monitor, configured with the
        // scenario's machine and the ADC's clip levels. In the steady stretches (after the
        // filter has settled) the estimates are valid and follow the truth.
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/cut.toml");
        let sc = Scenario::from_toml(&std::fs::read_to_string(path).unwrap(), path).unwrap();
        let mut cfg = MonitorConfig {
            sample_rate_hz: sc.sample_rate_hz as f32,
            input: sc.input.clone(),
            ..MonitorConfig::default()
        };
        cfg.clip = host_sim::sim::clip_levels(&sc).map(|c| c as f32);
        let mon = cfg.build().unwrap();
        let mut st = MonitorState::default();
        // (The first two stretches hold a move of the tooth windows each: at 2.38 s to
        // where no flute cuts, at 6.45 s again as the radial ramp's grown cut asks,
        // `window::REGROWN`. The moved period's record alone is flagged; the estimates
        // before and after it are valid.)
        let steady = [(2.33, 4.0), (6.41, 7.5), (9.3, 10.0), (11.0, 11.5)];
        let mut valid = [0; 4];
        let mut moved = [0; 4];
        simulate(&sc, |r| {
            if let Some(rec) = mon.process(&mut st, &r.to_sample()) {
                let t = &r.truth;
                let at = steady.iter().position(|&(a, b)| (a..b).contains(&r.time_s));
                if let Some(k) = at.filter(|_| rec.status.contains(Status::WINDOW_MOVED)) {
                    moved[k] += 1;
                } else if let Some(k) = at {
                    assert!(rec.status.is_valid(), "{:.3} s: {:?}", r.time_s, rec.status);
                    valid[k] += 1;
                    let (edr, eda) = (rec.dr_mm / t.dr_mm - 1.0, rec.da_mm / t.da_mm - 1.0);
                    assert!(
                        edr.abs() < 0.05 && eda.abs() < 0.05,
                        "{:.3} s: d_r {} vs {}, d_a {} vs {}",
                        r.time_s,
                        rec.dr_mm,
                        t.dr_mm,
                        rec.da_mm,
                        t.da_mm
                    );
                }
            }
            Ok(())
        })
        .unwrap();
        assert!(valid.iter().all(|&v| v >= 15), "{valid:?}");
        assert_eq!(moved, [1, 1, 0, 0]);
    }
}
