//! The monitor + alarm stage: sample blocks and sync edges in, telemetry frames and the
//! alarm state out. The core's [`Pipeline`] does the work; this stage only feeds it.
//!
//! # Design
//!
//! Per block: every sample gets its sync flag from the [`SyncMerger`] (by sample index) and
//! goes through `Pipeline::process`; every record that comes out is counted, and the ones
//! the decimation lets through become a [`RecordFrame`] with the next sequence number.
//!
//! - **Gaps.** A block whose first index is past the next expected one follows lost samples
//!   (an ADC ring overrun on the board). They are counted (`samples_lost`, in every frame)
//!   and bridged with NaN samples, up to [`GAP_FILL_MAX`]: the core leaves NaN out of its
//!   sums and flags the tooth periods they touch (`input_fault`), and the sample indices of
//!   later edges still line up with the samples the core counts. Beyond `GAP_FILL_MAX` the
//!   core's sample count (`end_sample`) falls behind the board's by the rest.
//! - **Decimation.** With `record_every = n`, one record in n is sent; a record that raises
//!   an event, or after which the latch or the wear warning changed, is always sent.
//! - **Drops.** The sender returns false when the telemetry queue is full: counted
//!   (`frames_dropped`), and the sequence number was used, so the host sees the gap.
//!
//! No `async`, no channel: the async task in [`crate::graph`] wraps it, and host tests
//! drive it directly.

use estimator_core::alarm::{AlarmOutput, Cause};
use estimator_core::{Pipeline, PipelineState, Sample, ToothRecord};

use crate::alarm_out::AlarmView;
use crate::config::{TelemetryConfig, EDGE_QUEUE, GAP_FILL_MAX, SAMPLE_BLOCK};
use crate::sync::SyncMerger;
use crate::telemetry::{AlarmFields, Counters, EventFields, RecordFrame};

/// One block of samples from the sampling task. `sync` of the samples is ignored: pulses
/// come from the tooth-timing task as edges.
#[derive(Clone, Copy, Debug)]
pub struct SampleBlock {
    /// Sample index (the board's sample clock) of `samples[0]`.
    pub first: u64,
    /// Samples used, `<= SAMPLE_BLOCK`.
    pub len: u16,
    /// The source has no more samples after these (the QEMU trace's end; never on the
    /// board).
    pub end: bool,
    /// The samples.
    pub samples: [Sample; SAMPLE_BLOCK],
}

impl SampleBlock {
    /// An empty block starting at `first`.
    pub const fn empty(first: u64) -> Self {
        const Z: Sample = Sample {
            feed: [0.0; 2],
            feed_velocity_mm_min: [0.0; 2],
            spindle: 0.0,
            sync: false,
        };
        SampleBlock {
            first,
            len: 0,
            end: false,
            samples: [Z; SAMPLE_BLOCK],
        }
    }

    /// The samples used.
    pub fn samples(&self) -> &[Sample] {
        let n = (self.len as usize).min(SAMPLE_BLOCK);
        self.samples.get(..n).unwrap_or(&[])
    }
}

/// The monitor + alarm stage.
#[derive(Clone, Debug)]
pub struct MonitorStage {
    pipeline: Pipeline,
    state: PipelineState,
    merger: SyncMerger<EDGE_QUEUE>,
    sample_rate_hz: f32,
    /// Index of the next sample expected.
    next: u64,
    records: u32,
    seq: u32,
    record_every: u16,
    since_sent: u16,
    samples_lost: u32,
    frames_dropped: u32,
    /// Edges lost before they reached the stage (reported by the tooth-timing task).
    edges_lost_upstream: u32,
    /// Latch and warning as last sent.
    sent_latched: bool,
    sent_wear: bool,
}

impl MonitorStage {
    /// A stage running `pipeline`, first sample index 0.
    pub fn new(pipeline: Pipeline, telemetry: TelemetryConfig) -> Self {
        MonitorStage {
            sample_rate_hz: pipeline.monitor().config().sample_rate_hz,
            pipeline,
            state: PipelineState::default(),
            merger: SyncMerger::new(),
            next: 0,
            records: 0,
            seq: 0,
            record_every: telemetry.record_every.max(1),
            since_sent: 0,
            samples_lost: 0,
            frames_dropped: 0,
            edges_lost_upstream: 0,
            sent_latched: false,
            sent_wear: false,
        }
    }

    /// Queues a sync edge (sample index) from the tooth-timing task.
    pub fn push_edge(&mut self, index: u64) {
        self.merger.push(index);
    }

    /// The tooth-timing task's count of edges it could not deliver (overcapture, full
    /// queue); reported in `edges_dropped` with the stage's own.
    pub fn set_edges_lost_upstream(&mut self, n: u32) {
        self.edges_lost_upstream = n;
    }

    /// Runs a block; `send` queues a frame and says whether it fit. Returns the number of
    /// records the block closed.
    pub fn process_block(
        &mut self,
        block: &SampleBlock,
        send: &mut impl FnMut(RecordFrame) -> bool,
    ) -> u16 {
        let mut records = 0u16;
        if block.first > self.next {
            let gap = block.first - self.next;
            self.samples_lost = self
                .samples_lost
                .saturating_add(u32::try_from(gap).unwrap_or(u32::MAX));
            for k in 0..gap.min(GAP_FILL_MAX) {
                let s = Sample {
                    feed: [f32::NAN, 0.0],
                    feed_velocity_mm_min: [0.0; 2],
                    spindle: f32::NAN,
                    sync: self.merger.take(self.next + k),
                };
                records += self.sample(&s, send) as u16;
            }
        }
        // A block that starts before the expected index (a source that restarted) is taken
        // at its word: its indices are the board's.
        self.next = block.first;
        for s in block.samples() {
            let s = Sample {
                sync: self.merger.take(self.next),
                ..*s
            };
            records += self.sample(&s, send) as u16;
            self.next += 1;
        }
        records
    }

    fn sample(&mut self, s: &Sample, send: &mut impl FnMut(RecordFrame) -> bool) -> bool {
        match self.pipeline.process(&mut self.state, s) {
            Some((rec, out)) => {
                self.record(&rec, &out, send);
                true
            }
            None => false,
        }
    }

    fn record(
        &mut self,
        rec: &ToothRecord,
        out: &AlarmOutput,
        send: &mut impl FnMut(RecordFrame) -> bool,
    ) {
        let index = self.records;
        self.records = self.records.wrapping_add(1);
        self.since_sent = self.since_sent.saturating_add(1);
        let changed = out.latched != self.sent_latched || out.wear_warning != self.sent_wear;
        if self.since_sent < self.record_every && out.event.is_none() && !changed {
            return;
        }
        self.since_sent = 0;
        self.sent_latched = out.latched;
        self.sent_wear = out.wear_warning;
        let frame = RecordFrame {
            seq: self.seq,
            index,
            sample_rate_hz: self.sample_rate_hz,
            record: *rec,
            alarm: AlarmFields {
                latched: out.latched,
                wear_warning: out.wear_warning,
                event: out.event.as_ref().map(EventFields::from),
                wear: out.wear,
            },
            counters: self.counters(),
        };
        self.seq = self.seq.wrapping_add(1);
        if !send(frame) {
            self.frames_dropped = self.frames_dropped.saturating_add(1);
        }
    }

    /// The operator's reset of a latched alarm.
    pub fn reset_alarm(&mut self) {
        self.pipeline.reset_alarm(&mut self.state);
    }

    /// What the alarm output should show.
    pub fn view(&self) -> AlarmView {
        AlarmView {
            running: true,
            latched: self.latched_cause(),
            wear_warning: self.sent_wear,
        }
    }

    /// Cause of the latched alarm, if any.
    pub fn latched_cause(&self) -> Option<Cause> {
        self.state.alarms.output_cause()
    }

    /// Loss counters so far.
    pub fn counters(&self) -> Counters {
        Counters {
            samples_lost: self.samples_lost,
            edges_late: self.merger.late,
            edges_dropped: self.merger.dropped.saturating_add(self.edges_lost_upstream),
            frames_dropped: self.frames_dropped,
        }
    }

    /// Records produced so far.
    pub fn records(&self) -> u32 {
        self.records
    }

    /// Frames queued or dropped so far (the next sequence number).
    pub fn frames(&self) -> u32 {
        self.seq
    }

    /// Index of the next sample expected.
    pub fn next_sample(&self) -> u64 {
        self.next
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::BoardConfig;
    use estimator_core::window::TRACK_DELAY_SAMPLES;
    use estimator_core::Status;
    use std::vec::Vec;

    /// Steady cut signals at 20 kS/s, a pulse every 100 samples (3000 rpm, 4 flutes).
    fn block(first: u64) -> SampleBlock {
        let mut b = SampleBlock::empty(first);
        b.len = SAMPLE_BLOCK as u16;
        for s in b.samples.iter_mut() {
            *s = Sample {
                feed: [0.5, 0.0],
                feed_velocity_mm_min: [1200.0, 0.0],
                spindle: 0.3,
                sync: false,
            };
        }
        b
    }

    fn run(stage: &mut MonitorStage, blocks: u64, drop_from: u64) -> Vec<RecordFrame> {
        let mut out = Vec::new();
        let n = SAMPLE_BLOCK as u64;
        let mut k = 0;
        while k < blocks {
            let first = k * n;
            for e in (first..first + n).filter(|i| i % 100 == 0) {
                stage.push_edge(e);
            }
            if k == drop_from {
                // This block and the next three are lost; their edges still arrive (the
                // capture is separate).
                for e in (first + n..first + 4 * n).filter(|i| i % 100 == 0) {
                    stage.push_edge(e);
                }
                k += 4;
                stage.process_block(&block(k * n), &mut |f| {
                    out.push(f);
                    true
                });
                k += 1;
                continue;
            }
            stage.process_block(&block(first), &mut |f| {
                out.push(f);
                true
            });
            k += 1;
        }
        out
    }

    #[test]
    fn every_record_is_sent_in_sequence() {
        let cfg = BoardConfig::board_default().build().expect("builds");
        let mut st = MonitorStage::new(cfg.pipeline, cfg.telemetry);
        let frames = run(&mut st, 100, u64::MAX);
        // 3200 samples, pulses every 100: 31 closed periods, each boundary the window
        // stage's delay after its pulse.
        assert_eq!(frames.len(), 31);
        assert_eq!(st.records(), 31);
        let delay = TRACK_DELAY_SAMPLES as u64;
        for (i, f) in frames.iter().enumerate() {
            assert_eq!((f.seq, f.index), (i as u32, i as u32));
            assert_eq!(f.record.samples, 100);
            assert_eq!(f.record.end_sample, 100 * i as u64 + 99 + delay);
            assert_eq!(f.counters, Counters::default());
        }
    }

    #[test]
    fn lost_samples_are_counted_bridged_and_flagged() {
        let cfg = BoardConfig::board_default().build().expect("builds");
        let mut st = MonitorStage::new(cfg.pipeline, cfg.telemetry);
        let frames = run(&mut st, 100, 50);
        let c = st.counters();
        assert_eq!(c.samples_lost, 4 * SAMPLE_BLOCK as u32);
        assert_eq!((c.edges_late, c.edges_dropped), (0, 0));
        // Same sample count as without the loss: every later period keeps its length.
        assert_eq!(st.next_sample(), 100 * SAMPLE_BLOCK as u64);
        let faulted: Vec<_> = frames
            .iter()
            .filter(|f| f.record.status.contains(Status::INPUT_FAULT))
            .map(|f| f.record.end_sample)
            .collect();
        // Samples 1600..1728 are NaN: the periods from the pulses at 1500, 1600 and 1700
        // hold them (each boundary the window stage's delay after its pulse).
        let delay = TRACK_DELAY_SAMPLES as u64;
        assert_eq!(faulted, [1599 + delay, 1699 + delay, 1799 + delay]);
        assert_eq!(frames.last().map(|f| f.counters.samples_lost), Some(128));
    }

    #[test]
    fn decimation_and_drops_are_visible() {
        let mut board = BoardConfig::board_default();
        board.telemetry.record_every = 4;
        let cfg = board.build().expect("builds");
        let mut st = MonitorStage::new(cfg.pipeline, cfg.telemetry);
        let mut frames = Vec::new();
        for k in 0..100u64 {
            let first = k * SAMPLE_BLOCK as u64;
            for e in (first..first + SAMPLE_BLOCK as u64).filter(|i| i % 100 == 0) {
                st.push_edge(e);
            }
            // The queue takes every other frame.
            st.process_block(&block(first), &mut |f| {
                let fits = f.seq % 2 == 0;
                if fits {
                    frames.push(f);
                }
                fits
            });
        }
        assert_eq!(st.frames(), 7, "31 records, one in 4");
        let idx: Vec<u32> = frames.iter().map(|f| f.index).collect();
        assert_eq!(idx, [3, 11, 19, 27]);
        assert_eq!(st.counters().frames_dropped, 3);
        assert_eq!(frames[3].counters.frames_dropped, 3);
    }
}
