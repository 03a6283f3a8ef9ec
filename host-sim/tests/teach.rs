//! `teach` end to end: a good run of a simulated job taught from its raw trace (and from
//! its per-tooth records), then the job replayed with the taught machine file: run again
//! with other noise it raises nothing, on deeper stock it raises a teach-in excursion.

use estimator_core::alarm::{AlarmConfig, Cause};
use estimator_core::{MachineConfig, PipelineState};
use host_sim::records::RecordWriter;
use host_sim::replay::load_monitor_config;
use host_sim::sim::{self, scenario::Scenario};
use host_sim::teach::{run, TeachArgs};
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("teach");
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// The job: air, an entry over a tool radius of travel, a steady cut, a feed change.
fn job(da_mm: f64, seed: u64) -> Scenario {
    let text = format!(
        "sample_rate_hz = 10000.0\nseed = {seed}\n[tool]\nradius_mm = 8.0\nflutes = 4\n\
         helix_deg = 30.0\nrunout_mm = [0.01, 0.0, 0.0, 0.0]\n[signal]\nfeed_noise = 0.01\n\
         spindle_noise = 0.05\n\
         [[segment]]\nduration_s = 0.3\nrpm = 600.0\nfeed_mm_min = 500.0\ndr_mm = 0.0\nda_mm = {da_mm}\n\
         [[segment]]\nduration_s = 1.0\ndr_mm = [0.0, 6.0]\n\
         [[segment]]\nduration_s = 2.0\n\
         [[segment]]\nduration_s = 1.5\nfeed_mm_min = 700.0\n"
    );
    Scenario::from_toml(&text, "job").expect("scenario")
}

/// First alarm of the job through the machine file's pipeline.
fn first_alarm(machine: &Path, sc: &Scenario) -> Option<Cause> {
    let m = load_monitor_config(Some(machine), Some(sc.sample_rate_hz)).expect("machine file");
    let p = MachineConfig {
        monitor: m.config,
        alarms: m.alarms,
        front_end: m.front_end,
    }
    .build()
    .expect("builds");
    let mut st = PipelineState::default();
    let mut first = None;
    sim::simulate(sc, |row| {
        if let Some((_, out)) = p.process(&mut st, &row.to_sample()) {
            if first.is_none() {
                first = out.event.map(|e| e.cause).filter(|c| *c != Cause::Wear);
            }
        }
        Ok(())
    })
    .expect("simulate");
    first
}

#[test]
fn a_taught_job_passes_and_deeper_stock_is_flagged() {
    let d = dir();
    let good = job(6.0, 1);
    // The board the job is simulated with, as the base machine file (motor input of the
    // scenario, default estimator and alarms).
    let base = d.join("base.toml");
    std::fs::write(
        &base,
        "[estimator.tool]\nradius_mm = 8.0\nflutes = 4\nhelix_deg = 30.0\n",
    )
    .expect("base");
    let trace = d.join("good.csv");
    let f = std::io::BufWriter::new(std::fs::File::create(&trace).expect("trace"));
    sim::write_trace(&good, f).expect("simulate");
    run(&TeachArgs {
        config: Some(base.clone()),
        output: d.join("taught.toml"),
        trace: Some(trace.clone()),
        records: None,
        revs_per_bin: 2,
    })
    .expect("teach from the trace");
    let taught = d.join("taught.toml");
    let m = load_monitor_config(Some(&taught), Some(10_000.0)).expect("taught file");
    let env = m.alarms.teach.envelope.expect("an envelope");
    assert!(env.len >= 20 && env.start_n > 0.0, "{} bins", env.len);
    // Without the envelope nothing of the kind can be raised; with it, the same job again
    // passes and the deeper one does not.
    assert_eq!(AlarmConfig::default().teach.envelope, None);
    for seed in [2, 3] {
        assert_eq!(first_alarm(&taught, &job(6.0, seed)), None, "seed {seed}");
    }
    assert_eq!(
        first_alarm(&taught, &job(8.5, 2)),
        Some(Cause::TeachExcursion)
    );

    // The same from the board's per-tooth records of the good run.
    let m0 = load_monitor_config(Some(&base), Some(10_000.0)).expect("base");
    let p = MachineConfig {
        monitor: m0.config,
        alarms: m0.alarms,
        front_end: m0.front_end,
    }
    .build()
    .expect("builds");
    let records = d.join("good_records.csv");
    let mut w = RecordWriter::new(
        std::io::BufWriter::new(std::fs::File::create(&records).expect("records")),
        false,
    )
    .expect("writer");
    let mut st = PipelineState::default();
    sim::simulate(&good, |row| {
        if let Some((r, _)) = p.process(&mut st, &row.to_sample()) {
            w.write(r.time_s(10_000.0), &r, &row.truth)?;
        }
        Ok(())
    })
    .expect("simulate");
    w.finish().expect("flush");
    run(&TeachArgs {
        config: Some(base),
        output: d.join("taught_records.toml"),
        trace: None,
        records: Some(records),
        revs_per_bin: 2,
    })
    .expect("teach from the records");
    let m2 = load_monitor_config(Some(&d.join("taught_records.toml")), Some(10_000.0))
        .expect("taught file");
    assert_eq!(
        m2.alarms.teach.envelope,
        Some(env),
        "the same envelope both ways"
    );
}
