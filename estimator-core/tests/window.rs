//! Where the tooth windows begin (`estimator_core::window`), through the whole Monitor: a
//! cut whose flutes engage for 40 % of their pitch, with the encoder pulse in the middle
//! of each engagement. The per-tooth averages are checked against each flute's own cut,
//! summed sample by sample here.

#![allow(clippy::unwrap_used)]

use estimator_core::monitor::{Input, Sample, ToothRecord};
use estimator_core::tooth::SyncMode;
use estimator_core::{MonitorConfig, Status};

/// 10 kS/s, 4 flutes at 1500 rpm: 100 samples a tooth.
const FS: f32 = 10_000.0;
const PITCH: usize = 100;
const FLUTES: usize = 4;
/// Each flute cuts a half sine `WIDTH` samples long, centred on its encoder pulse.
const WIDTH: usize = 40;
/// Runout: the flutes' peak forces relative to the nominal.
const SHARE: [f32; FLUTES] = [1.3, 1.0, 0.9, 1.05];
const PEAK_N: f32 = 600.0;

/// Tangential-like force at sample `i` of a cut that starts at `start`: flute `k` cuts
/// samples `[k P - W/2, k P + W/2)` of each revolution (pulses at `k P`), or, `flat`,
/// every flute's force is spread evenly with a 5 % ripple at the tooth frequency.
fn force(i: usize, start: usize, flat: bool) -> f32 {
    if i < start {
        return 0.0;
    }
    if flat {
        let phase = (i % PITCH) as f32 / PITCH as f32;
        return 0.5 * PEAK_N * (1.0 + 0.05 * (core::f32::consts::TAU * phase).sin());
    }
    let shifted = i + WIDTH / 2;
    let (tooth, at) = (shifted / PITCH, shifted % PITCH);
    if at >= WIDTH {
        return 0.0;
    }
    let s = (core::f32::consts::PI * (at as f32 + 0.5) / WIDTH as f32).sin();
    SHARE[tooth % FLUTES] * PEAK_N * s
}

fn config(align: bool) -> MonitorConfig {
    let mut cfg = MonitorConfig {
        sample_rate_hz: FS,
        input: Input::Dynamometer,
        align_window: align,
        ..MonitorConfig::default()
    };
    cfg.estimator.tool.flutes = FLUTES as u8;
    cfg.estimator.force_floor_n = 5.0;
    cfg
}

/// Records of `revs` revolutions, the cut starting after ten.
fn run(align: bool, flat: bool, revs: usize) -> Vec<ToothRecord> {
    run_with(align, revs, |i| force(i, 10 * FLUTES * PITCH, flat))
}

/// Records of `revs` revolutions of the force `f(sample)`.
fn run_with(align: bool, revs: usize, f: impl Fn(usize) -> f32) -> Vec<ToothRecord> {
    let m = config(align).build().unwrap();
    let mut st = Default::default();
    let mut out = Vec::new();
    for i in 0..revs * FLUTES * PITCH {
        let f = f(i);
        let s = Sample {
            feed: [-0.5 * f, f],
            feed_velocity_mm_min: [600.0, 0.0],
            spindle: 0.0,
            sync: i % PITCH == 0,
        };
        out.extend(m.process(&mut st, &s));
    }
    assert_eq!(
        m.config().sync,
        SyncMode::PerTooth,
        "the test places pulses per tooth"
    );
    out
}

/// Each flute's own cut averaged over a tooth period, `F_ay` [N], summed sample by sample.
fn flute_means() -> [f32; FLUTES] {
    let start = 0;
    let mut sums = [0.0f64; FLUTES];
    // The cut of flute k around pulse (FLUTES + k) P: whole, away from the start.
    for (k, sum) in sums.iter_mut().enumerate() {
        let centre = (FLUTES + k) * PITCH;
        for i in centre - WIDTH / 2..centre + WIDTH / 2 {
            *sum += f64::from(force(i, start, false));
        }
    }
    sums.map(|s| (s / PITCH as f64) as f32)
}

/// Whether `f` is one flute's own mean (to 1e-4 of it), and which.
fn which_flute(f: f32) -> Option<usize> {
    flute_means().iter().position(|m| (f - m).abs() <= 1e-4 * m)
}

#[test]
fn the_windows_move_to_where_no_flute_cuts() {
    let recs = run(true, false, 60);
    let moved: Vec<usize> = recs
        .iter()
        .enumerate()
        .filter(|(_, r)| r.status.contains(Status::WINDOW_MOVED))
        .map(|(k, _)| k)
        .collect();
    assert_eq!(moved.len(), 1, "moves once: {moved:?}");
    // The cut had settled before the move.
    assert!(!recs[moved[0] - 1].status.contains(Status::SETTLING));
    // Before the move every average mixes two flutes' cuts; from the period after it (the
    // period of the move is of odd length; the next one is judged against the length
    // before it, and is good), each holds one flute's whole cut, the flutes in turn, and
    // none is a transient.
    let cutting_before: Vec<&ToothRecord> =
        recs[..moved[0]].iter().filter(|r| r.f2_n > 0.0).collect();
    assert!(cutting_before.len() > 8, "{}", cutting_before.len());
    assert!(
        cutting_before.iter().all(|r| which_flute(r.f2_n).is_none()),
        "at the pulse, no average is one flute's cut"
    );
    let after = &recs[moved[0] + 1..];
    assert!(after.len() > 100);
    let first = which_flute(after[0].f2_n).expect("one flute's cut");
    let mut transient = Vec::new();
    for (k, r) in after.iter().enumerate() {
        assert_eq!(
            which_flute(r.f2_n),
            Some((first + k) % FLUTES),
            "record {k} after the move: {} N against {:?}",
            r.f2_n,
            flute_means()
        );
        assert!(!r
            .status
            .intersects(Status(Status::PERIOD_INVALID.0 | Status::WINDOW_MOVED.0)));
        if r.status.contains(Status::TRANSIENT) {
            transient.push(k);
        }
    }
    // The cut does not change at the move. The revolution means over it hold each flute
    // once (the teeth of the move's own period stand in as they were a revolution
    // earlier); a mean that holds teeth of both alignments is off by the runout's share
    // of the boundary's shift (one record here; three with the move's period left out).
    assert!(
        transient.len() <= 1,
        "transient after the move: {transient:?}"
    );
    // Nor does the move restart the filter's settling: the cut was steady before it, and
    // the records after it are not flagged settling up to that transient.
    let until = transient.first().copied().unwrap_or(after.len());
    assert!(until > 0);
    assert!(
        after[..until]
            .iter()
            .all(|r| !r.status.contains(Status::SETTLING)),
        "{:?}",
        after[..until].iter().map(|r| r.status).collect::<Vec<_>>()
    );
}

#[test]
fn without_alignment_the_windows_stay_at_the_pulse() {
    let recs = run(false, false, 60);
    assert!(recs
        .iter()
        .all(|r| !r.status.contains(Status::WINDOW_MOVED) && which_flute(r.f2_n).is_none()));
}

#[test]
fn a_cut_without_a_gap_leaves_the_windows_where_they_are() {
    let recs = run(true, true, 200);
    assert!(recs.iter().filter(|r| r.f2_n > 0.0).count() > 700);
    assert!(recs
        .iter()
        .all(|r| !r.status.contains(Status::WINDOW_MOVED)));
}

/// The boundary is reviewed once a cut. A cut whose flutes are always engaged passes its
/// review; when its flutes later leave gaps (a profile that would move the boundary, as a
/// flute breaking inside its period shifts one near the margin), the boundary stays: a
/// move makes the detectors forget their history. A new cut, after air, is reviewed again.
#[test]
fn the_boundary_is_reviewed_once_a_cut() {
    let rev = FLUTES * PITCH;
    let profile = |i: usize| match i / rev {
        0..10 | 90..100 => 0.0,
        10..40 => force(i, 0, true),
        _ => force(i, 0, false),
    };
    let recs = run_with(true, 160, profile);
    let moved: Vec<usize> = recs
        .iter()
        .filter(|r| r.status.contains(Status::WINDOW_MOVED))
        .map(|r| r.end_sample as usize / rev)
        .collect();
    assert_eq!(moved.len(), 1, "moves once, in the second cut: {moved:?}");
    assert!(moved[0] > 100, "{moved:?}");
}
