//! Alarms on the monitor's records, fed from synthetic cuts (tests/common): each detector
//! with cases that must fire and cases that must not.

#![allow(clippy::unwrap_used)]

mod common;

use common::*;
use estimator_core::alarm::{AlarmConfig, AlarmEvent, Cause, DriftReference, EnvelopeRecorder};
use estimator_core::{MillingMode, ToothRecord};

/// Runs the alarms over records; returns every event with the time it was raised, and
/// the wear multiplier at the end.
fn alarms(recs: &[(ToothRecord, Truth)], cfg: AlarmConfig) -> (Vec<AlarmEvent>, f32) {
    let est = config(MillingMode::Down, 10_000.0).estimator;
    let a = cfg.build(&est).unwrap();
    let mut st = Default::default();
    let mut events = Vec::new();
    let mut wear = 1.0;
    for (r, _) in recs {
        let out = a.process(&mut st, r);
        events.extend(out.event);
        wear = out.wear;
    }
    (events, wear)
}

fn alarm_causes(events: &[AlarmEvent]) -> Vec<Cause> {
    events
        .iter()
        .map(|e| e.cause)
        .filter(|c| *c != Cause::Wear)
        .collect()
}

/// A 4 s steady cut with a flute breaking (or chipping) at 2.013 s, 3 % noise, runout.
fn breaking(loss: f64, seed: u64) -> Scenario {
    let mut sc = paper(vec![seg(4.0, 3.0, 6.0, 500.0)], seed);
    sc.noise_rel = 0.03;
    sc.runout_mm = [0.015, 0.0, 0.0, 0.0];
    sc.break_at = Some((2.013, 2, loss));
    sc
}

#[test]
fn a_broken_flute_is_caught_within_one_revolution() {
    for seed in 1..=5 {
        let sc = breaking(1.0, seed);
        let recs = run(&sc, config(MillingMode::Down, 10_000.0));
        let (events, _) = alarms(&recs, AlarmConfig::default());
        let first = events
            .iter()
            .find(|e| e.cause != Cause::Wear)
            .expect("an alarm");
        assert_eq!(first.cause, Cause::Breakage, "{first:?}");
        let t = first.record.time_s(10_000.0);
        // One revolution at 600 rpm is 0.1 s.
        assert!(
            t > 2.013 && t <= 2.013 + 0.1,
            "seed {seed}: raised at {t:.4} s"
        );
    }
}

#[test]
fn steady_runout_and_noise_never_alarm() {
    for seed in 1..=3 {
        // One flute cutting 35 % more, 3 % noise, 10 s.
        let mut sc = paper(vec![seg(10.0, 3.0, 6.0, 500.0)], 100 + seed);
        sc.noise_rel = 0.03;
        sc.runout_mm = [0.35 * 500.0 / 2400.0, 0.0, 0.0, 0.0];
        let recs = run(&sc, config(MillingMode::Down, 10_000.0));
        let (events, _) = alarms(&recs, AlarmConfig::default());
        assert!(alarm_causes(&events).is_empty(), "seed {seed}: {events:?}");
    }
}

#[test]
fn entry_exit_feed_and_speed_changes_and_air_never_alarm() {
    let mut segs = vec![seg(0.5, 0.0, 6.0, 500.0)];
    for k in 1..=20 {
        segs.push(seg(0.05, 3.0 * k as f64 / 20.0, 6.0, 500.0)); // entry over 10 revs
    }
    segs.push(seg(1.5, 3.0, 6.0, 500.0));
    segs.push(seg(1.5, 3.0, 6.0, 800.0)); // feed step
                                          // Axial step, entered over a tool radius of travel (8 mm: 0.6 s at 800 mm/min).
    segs.extend(travel(
        &seg(0.0, 3.0, 6.0, 800.0),
        &seg(0.0, 3.0, 11.0, 800.0),
        8.0,
        12,
    ));
    segs.push(seg(1.0, 3.0, 11.0, 800.0));
    segs.push(Seg {
        dur_s: 1.5,
        dr_mm: 3.0,
        da_mm: 11.0,
        feed_mm_min: 800.0,
        rpm: 700.0,
    }); // speed
    for k in (0..20).rev() {
        segs.push(Seg {
            dur_s: 0.05,
            dr_mm: 3.0 * k as f64 / 20.0,
            da_mm: 11.0,
            feed_mm_min: 800.0,
            rpm: 700.0,
        });
    }
    segs.push(seg(0.5, 0.0, 6.0, 500.0));
    for seed in 1..=3 {
        let mut sc = paper(segs.clone(), 200 + seed);
        sc.noise_rel = 0.03;
        sc.runout_mm = [0.02, 0.0, 0.0, 0.0];
        let recs = run(&sc, config(MillingMode::Down, 10_000.0));
        let (events, _) = alarms(&recs, AlarmConfig::default());
        assert!(alarm_causes(&events).is_empty(), "seed {seed}: {events:?}");
    }
}

#[test]
fn a_chipped_flute_is_caught_and_a_small_chip_is_not_an_alarm() {
    // 60 % of a flute's edge lost: caught; 5 %: below any sensible threshold at 3 % noise.
    let recs = run(&breaking(0.6, 7), config(MillingMode::Down, 10_000.0));
    let (events, _) = alarms(&recs, AlarmConfig::default());
    assert_eq!(alarm_causes(&events), vec![Cause::Breakage]);
    let recs = run(&breaking(0.05, 7), config(MillingMode::Down, 10_000.0));
    let (events, _) = alarms(&recs, AlarmConfig::default());
    assert!(alarm_causes(&events).is_empty(), "{events:?}");
}

#[test]
fn tool_gone_fires_on_a_collapse_not_on_an_exit() {
    // The cutter vanishes mid-cut while the feed goes on.
    let sc = paper(
        vec![seg(2.0, 3.0, 6.0, 500.0), seg(1.0, 0.0, 6.0, 500.0)],
        3,
    );
    let recs = run(&sc, config(MillingMode::Down, 10_000.0));
    let (events, _) = alarms(&recs, AlarmConfig::default());
    let causes = alarm_causes(&events);
    assert_eq!(causes, vec![Cause::ToolGone], "{events:?}");
    let t = events[0].record.time_s(10_000.0);
    // Two tooth periods with nothing above the not-cutting floor after the one the tool
    // was lost in: within a revolution (0.1 s), before the monitor's not-cutting flag (on
    // the revolution mean) would say so.
    assert!((2.0..2.1).contains(&t), "raised at {t}");
    // An exit ramp over several revolutions, then air: no alarm.
    let mut segs = vec![seg(2.0, 3.0, 6.0, 500.0)];
    for k in (0..10).rev() {
        segs.push(seg(0.05, 3.0 * k as f64 / 10.0, 6.0, 500.0));
    }
    segs.push(seg(1.0, 0.0, 6.0, 500.0));
    let recs = run(&paper(segs, 4), config(MillingMode::Down, 10_000.0));
    let (events, _) = alarms(&recs, AlarmConfig::default());
    assert!(alarm_causes(&events).is_empty(), "{events:?}");
}

#[test]
fn overload_follows_the_allowed_engagement() {
    let mut cfg = AlarmConfig::default();
    cfg.overload.max_rr = 0.5; // 4 mm radial
    cfg.overload.max_ra = 1.0; // 8 mm axial
    let recs = run(
        &paper(vec![seg(2.0, 3.0, 6.0, 500.0)], 5),
        config(MillingMode::Down, 10_000.0),
    );
    assert!(alarm_causes(&alarms(&recs, cfg).0).is_empty());
    let recs = run(
        &paper(vec![seg(2.0, 6.0, 10.0, 500.0)], 5),
        config(MillingMode::Down, 10_000.0),
    );
    assert_eq!(alarm_causes(&alarms(&recs, cfg).0), vec![Cause::Overload]);
    // The limit scales with the feed: the same engagement at twice the feed is allowed
    // (the limit is the force the maximum engagement gives at this feed).
    let recs = run(
        &paper(vec![seg(2.0, 3.0, 6.0, 1000.0)], 5),
        config(MillingMode::Down, 10_000.0),
    );
    assert!(alarm_causes(&alarms(&recs, cfg).0).is_empty());
    // A plain force cap.
    let mut capped = AlarmConfig::default();
    capped.overload.force_limit_n = 300.0;
    let recs = run(
        &paper(vec![seg(2.0, 3.0, 6.0, 500.0)], 5),
        config(MillingMode::Down, 10_000.0),
    );
    assert_eq!(
        alarm_causes(&alarms(&recs, capped).0),
        vec![Cause::Overload]
    );
}

#[test]
fn teach_in_accepts_the_taught_cut_and_flags_a_different_one() {
    let job = |da: f64, seed| {
        let mut segs = vec![seg(0.3, 0.0, da, 500.0)];
        segs.push(seg(1.5, 2.0, da, 500.0));
        // A radial step, entered over a tool radius of travel.
        segs.extend(travel(
            &seg(0.0, 2.0, da, 500.0),
            &seg(0.0, 4.0, da, 500.0),
            8.0,
            10,
        ));
        segs.push(seg(1.5, 4.0, da, 500.0));
        run(&paper(segs, seed), config(MillingMode::Down, 10_000.0))
    };
    let mut rec = EnvelopeRecorder::new(4, 2);
    for (r, _) in job(6.0, 1) {
        rec.push(&r);
    }
    let mut cfg = AlarmConfig::default();
    cfg.teach.envelope = Some(rec.finish());
    assert!(alarm_causes(&alarms(&job(6.0, 2), cfg).0).is_empty());
    assert_eq!(
        alarm_causes(&alarms(&job(9.0, 2), cfg).0),
        vec![Cause::TeachExcursion]
    );
}

/// The same job run again on a blank whose face is a little proud (a 0.03 mm skim for
/// three revolutions before the entry), with other noise: where the cut is first seen
/// moves, where it reaches a quarter of its force does not; no excursion. The job on deeper
/// stock still flags.
#[test]
fn teach_in_aligns_the_cut_where_its_force_builds_up() {
    let job = |skim_s: f64, da: f64, seed| {
        let mut segs = vec![seg(0.3, 0.0, da, 500.0)];
        if skim_s > 0.0 {
            segs.push(seg(skim_s, 0.03, da, 500.0));
        }
        // A slow entry: the radial depth grows over a tool radius of travel.
        segs.extend(travel(
            &seg(0.0, 0.0, da, 500.0),
            &seg(0.0, 4.0, da, 500.0),
            8.0,
            16,
        ));
        segs.push(seg(2.0, 4.0, da, 500.0));
        let mut sc = paper(segs, seed);
        sc.noise_rel = 0.03;
        run(&sc, config(MillingMode::Down, 10_000.0))
    };
    let mut rec = EnvelopeRecorder::new(4, 2);
    for (r, _) in job(0.0, 6.0, 11) {
        rec.push(&r);
    }
    let env = rec.finish();
    assert!(env.start_n > 0.0 && env.len > 10, "{} bins", env.len);
    let mut cfg = AlarmConfig::default();
    cfg.teach.envelope = Some(env);
    for seed in 12..=14 {
        let (ev, _) = alarms(&job(0.3, 6.0, seed), cfg);
        assert!(
            alarm_causes(&ev).is_empty(),
            "seed {seed}: {:?}",
            ev.iter()
                .map(|e| (e.cause, e.value, e.threshold, e.record.time_s(10_000.0)))
                .collect::<Vec<_>>()
        );
    }
    assert_eq!(
        alarm_causes(&alarms(&job(0.3, 9.0, 12), cfg).0),
        vec![Cause::TeachExcursion]
    );
}

#[test]
fn wear_multiplier_tracks_force_against_a_known_engagement() {
    let recs = run(
        &paper(vec![seg(4.0, 3.0, 6.0, 500.0)], 6),
        config(MillingMode::Down, 10_000.0),
    );
    let mut cfg = AlarmConfig::default();
    cfg.drift.reference = DriftReference::Known {
        rr: 3.0 / 8.0,
        ra: 6.0 / 8.0,
    };
    let (events, theta) = alarms(&recs, cfg);
    assert!((theta - 1.0).abs() < 0.03, "as new: {theta}");
    assert!(events.iter().all(|e| e.cause != Cause::Wear));
    // The same forces against an engagement that should need 40 % less: theta ~ 1.4.
    cfg.drift.reference = DriftReference::Known {
        rr: 3.0 / 8.0,
        ra: 6.0 / 8.0 / 1.4,
    };
    let (events, theta) = alarms(&recs, cfg);
    assert!((theta - 1.4).abs() < 0.05, "worn: {theta}");
    assert!(events.iter().any(|e| e.cause == Cause::Wear));
    // Against a known engagement the estimate's own flags do not matter: at a feed below
    // the coefficients' fitted range (every estimate flagged tc_out_of_range) it tracks
    // the same.
    let slow = run(
        &paper(vec![seg(4.0, 3.0, 6.0, 200.0)], 6),
        config(MillingMode::Down, 10_000.0),
    );
    assert!(slow.iter().skip(100).all(|(r, _)| !r.status.is_valid()));
    let (events, theta) = alarms(&slow, cfg);
    assert!((theta - 1.4).abs() < 0.05, "worn, slow feed: {theta}");
    assert!(events.iter().any(|e| e.cause == Cause::Wear));
}

#[test]
fn alarms_latch_until_reset() {
    let recs = run(&breaking(1.0, 9), config(MillingMode::Down, 10_000.0));
    let est = config(MillingMode::Down, 10_000.0).estimator;
    let a = AlarmConfig::default().build(&est).unwrap();
    let mut st = Default::default();
    let mut raised_at = None;
    for (i, (r, _)) in recs.iter().enumerate() {
        let out = a.process(&mut st, r);
        if out.event.is_some_and(|e| e.cause == Cause::Breakage) {
            raised_at = Some(i);
        }
        if let Some(at) = raised_at {
            assert!(out.latched, "latched from {at} on, not at {i}");
        }
    }
    assert!(raised_at.is_some());
    a.reset(&mut st);
    assert!(st.latched().is_none());
}

/// First non-wear alarm and its time.
fn first_alarm(recs: &[(ToothRecord, Truth)]) -> Option<(Cause, f64)> {
    let (events, _) = alarms(recs, AlarmConfig::default());
    events
        .iter()
        .find(|e| e.cause != Cause::Wear)
        .map(|e| (e.cause, e.record.time_s(10_000.0)))
}

#[test]
fn a_quick_exit_is_not_a_lost_tool() {
    // Out of the part over three revolutions (a short exit at a high feed): the force
    // passes through "strong" on its way down and reaches the floor within two
    // revolutions of it, but it fell over the revolutions before: no tool-gone alarm.
    for seed in 1..=3 {
        let mut segs = vec![seg(2.0, 3.0, 6.0, 500.0)];
        for k in (0..6).rev() {
            segs.push(seg(0.05, 3.0 * k as f64 / 6.0, 6.0, 500.0));
        }
        segs.push(seg(1.0, 0.0, 6.0, 500.0));
        let mut sc = paper(segs, 40 + seed);
        sc.noise_rel = 0.03;
        let recs = run(&sc, config(MillingMode::Down, 10_000.0));
        assert_eq!(first_alarm(&recs), None, "seed {seed}");
    }
}

/// First non-wear alarm and its time, with the not-cutting floor at `floor_n` in the
/// monitor and the alarms (a machine's calibrated idle level, over the noise).
fn first_alarm_floor(sc: &Scenario, floor_n: f32) -> Option<(Cause, f64)> {
    let mut cfg = config(MillingMode::Down, 10_000.0);
    cfg.estimator.force_floor_n = floor_n;
    let a = AlarmConfig::default().build(&cfg.estimator).unwrap();
    let mut st = Default::default();
    run(sc, cfg).iter().find_map(|(r, _)| {
        let e = a.process(&mut st, r).event?;
        (e.cause != Cause::Wear).then(|| (e.cause, e.record.time_s(10_000.0)))
    })
}

#[test]
fn a_feed_override_turned_down_in_one_step_is_not_a_lost_tool() {
    // Mid-cut, the feed to a tenth within a tooth period; the tool stays in. With a runout
    // larger than the new chip two flutes in a row cut nothing, every revolution (six
    // seconds: the recent peak decays until the light cut counts as steady); in a light cut
    // every tooth's force falls to near the not-cutting floor (40 N here, over the noise as
    // a calibrated machine's).
    let floor_n = 40.0;
    let cases = [
        (3.0, [0.05, 0.02, -0.01, 0.0]), // two idle flutes in a row
        (0.5, [0.01, 0.0, 0.0, 0.0]),    // a light cut
    ];
    for (dr_mm, runout_mm) in cases {
        for seed in 1..=3 {
            let segs = vec![seg(2.0, dr_mm, 6.0, 500.0), seg(6.0, dr_mm, 6.0, 50.0)];
            let mut sc = paper(segs, 60 + seed);
            sc.noise_rel = 0.03;
            sc.runout_mm = runout_mm;
            let first = first_alarm_floor(&sc, floor_n);
            assert_eq!(first, None, "d_r {dr_mm} seed {seed}");
        }
    }
    // The tool lost after a step to half the feed: still a lost tool, within a revolution.
    let segs = vec![
        seg(2.0, 3.0, 6.0, 500.0),
        seg(2.0, 3.0, 6.0, 250.0),
        seg(1.0, 0.0, 6.0, 250.0),
    ];
    let (cause, t) = first_alarm_floor(&paper(segs, 70), floor_n).unwrap();
    assert_eq!(cause, Cause::ToolGone);
    assert!((4.0..4.1).contains(&t), "raised at {t}");
}

/// Moves the sync pulse closest after `at_s` by `shift` samples (later), or drops it.
fn move_pulse(at_s: f64, shift: Option<usize>) -> impl FnMut(usize, &mut estimator_core::Sample) {
    let from = (at_s * 10_000.0) as usize;
    let mut pending: Option<usize> = None;
    let mut done = false;
    move |i, s| {
        if !done && i >= from && s.sync {
            s.sync = false;
            done = true;
            pending = shift.map(|d| i + d);
        }
        if pending == Some(i) {
            s.sync = true;
            pending = None;
        }
    }
}

#[test]
fn a_jittered_period_keeps_the_history_and_a_lost_pulse_does_not() {
    let est_cfg = || config(MillingMode::Down, 10_000.0);
    let mut sc = breaking(1.0, 21);
    // A pulse 30 samples late (12 % of the 250-sample period: flagged PERIOD_INVALID, in
    // order and within a quarter of the length) two tooth periods before the break.
    let t_break = 2.013;
    let recs = run_with(&sc, est_cfg(), move_pulse(t_break - 0.05, Some(30)));
    let jittered = recs
        .iter()
        .filter(|(r, _)| r.status.contains(estimator_core::Status::PERIOD_INVALID))
        .count();
    assert!(jittered >= 1, "the late pulse is flagged");
    let (cause, t) = first_alarm(&recs).expect("an alarm");
    assert_eq!(cause, Cause::Breakage);
    assert!(t > t_break && t <= t_break + 0.1, "raised at {t:.4} s");
    // A lost pulse (two teeth in one period) breaks the tooth alignment: the history is
    // forgotten and nothing alarms on the misaligned teeth (no break in this cut).
    sc.break_at = None;
    for at in [1.0, 1.5, 2.2] {
        let recs = run_with(&sc, est_cfg(), move_pulse(at, None));
        assert_eq!(first_alarm(&recs), None, "pulse lost at {at} s");
    }
}
