//! The task graph: channels, and the tasks that do not touch a peripheral.
//!
//! # Design
//!
//! [`Graph`] holds every channel between the tasks; the board and the QEMU variant each
//! keep one in a `static`. The tasks here are `async fn`s generic over their sinks, so that
//! the board (UART, GPIO), QEMU (semihosting) and host tests (vectors) plug in the same
//! code; embassy's `#[task]` functions, which cannot be generic, are one-line wrappers in
//! the binaries.
//!
//! - **sampling** (board: ADC ring + feed encoder; QEMU: the trace) sends [`SampleBlock`]s
//!   on `samples`;
//! - **tooth timing** (board: TIM2 capture; QEMU: the trace's pulses) sends sample indices
//!   on `edges`, each before the block that holds its sample (see [`crate::sync`]);
//! - **monitor + alarms** ([`monitor_task`]) merges them, runs the core's pipeline, queues
//!   telemetry on `messages` without ever waiting for it (a full queue is counted), signals
//!   the alarm state on `alarm` and beats `heartbeat` once per block;
//! - **telemetry** ([`telemetry_task`]) encodes frames and writes them to a [`FrameSink`];
//! - **alarm output** ([`alarm_output_task`]) drives the relay and the LED through
//!   [`AlarmPins`]; the reset input signals `reset`.
//!
//! On the board, sampling and tooth timing run on a high-priority interrupt executor and
//! the rest in thread mode, so the monitor never starves the two tasks that empty hardware
//! buffers. Channels use a `RawMutex` chosen by the binary (`CriticalSectionRawMutex` across
//! priorities).

use core::sync::atomic::{AtomicU32, Ordering};

use embassy_futures::select::{select, Either};
use embassy_sync::blocking_mutex::raw::RawMutex;
use embassy_sync::channel::Channel;
use embassy_sync::signal::Signal;

use crate::alarm_out::AlarmView;
use crate::config::{EDGE_QUEUE, MESSAGE_QUEUE, SAMPLE_QUEUE};
pub use crate::stage::{MonitorStage, SampleBlock};
use crate::telemetry::RecordFrame;

/// What the monitor hands the telemetry task.
#[derive(Clone, Copy, Debug)]
#[allow(clippy::large_enum_variant)] // no heap; a queue of a few of them
pub enum Message {
    /// A record frame to send.
    Record(RecordFrame),
    /// The samples ended (QEMU only): flush and stop.
    End,
}

/// Every channel between the tasks.
pub struct Graph<M: RawMutex> {
    /// Sampling -> monitor.
    pub samples: Channel<M, SampleBlock, SAMPLE_QUEUE>,
    /// Tooth timing -> monitor: sample indices of sync edges.
    pub edges: Channel<M, u64, EDGE_QUEUE>,
    /// Monitor -> telemetry.
    pub messages: Channel<M, Message, MESSAGE_QUEUE>,
    /// Monitor -> alarm output: the latest state.
    pub alarm: Signal<M, AlarmView>,
    /// Reset input -> monitor: the operator's reset of a latched alarm.
    pub reset: Signal<M, ()>,
    /// Blocks the monitor has finished (the watchdog's liveness).
    pub heartbeat: AtomicU32,
    /// Sync edges the tooth-timing task could not deliver (overcapture, full queue).
    pub edges_lost: AtomicU32,
}

impl<M: RawMutex> Graph<M> {
    /// Empty channels.
    pub const fn new() -> Self {
        Graph {
            samples: Channel::new(),
            edges: Channel::new(),
            messages: Channel::new(),
            alarm: Signal::new(),
            reset: Signal::new(),
            heartbeat: AtomicU32::new(0),
            edges_lost: AtomicU32::new(0),
        }
    }
}

impl<M: RawMutex> Default for Graph<M> {
    fn default() -> Self {
        Self::new()
    }
}

/// Brackets the monitor's work on each block (instruction counts in QEMU; nothing on the
/// board).
pub trait BlockProbe {
    /// Before the block.
    fn begin(&mut self) {}
    /// After it: its samples and the records it closed.
    fn end(&mut self, _samples: u16, _records: u16) {}
}

/// No probe.
pub struct NoProbe;

impl BlockProbe for NoProbe {}

/// The monitor + alarm task. Returns only after a block marked `end` (QEMU), once
/// [`Message::End`] is queued.
pub async fn monitor_task<M: RawMutex, P: BlockProbe>(
    g: &Graph<M>,
    stage: &mut MonitorStage,
    probe: &mut P,
) {
    let mut view = stage.view();
    g.alarm.signal(view);
    loop {
        let block = match select(g.samples.receive(), g.reset.wait()).await {
            Either::First(b) => b,
            Either::Second(()) => {
                stage.reset_alarm();
                publish(g, stage, &mut view);
                continue;
            }
        };
        // Every edge captured before this block's last sample is queued by now.
        while let Ok(e) = g.edges.try_receive() {
            stage.push_edge(e);
        }
        stage.set_edges_lost_upstream(g.edges_lost.load(Ordering::Relaxed));
        probe.begin();
        let records = stage.process_block(&block, &mut |f| {
            g.messages.try_send(Message::Record(f)).is_ok()
        });
        probe.end(block.len, records);
        g.heartbeat.fetch_add(1, Ordering::Relaxed);
        publish(g, stage, &mut view);
        if block.end {
            g.messages.send(Message::End).await;
            return;
        }
    }
}

fn publish<M: RawMutex>(g: &Graph<M>, stage: &MonitorStage, view: &mut AlarmView) {
    let now = stage.view();
    if now != *view {
        *view = now;
        g.alarm.signal(now);
    }
}

/// Where telemetry frames go (the UART, semihosting, a test's vector).
#[allow(async_fn_in_trait)] // used with concrete types only, never as `dyn` or across threads
pub trait FrameSink {
    /// Writes one whole frame.
    async fn write_frame(&mut self, frame: &[u8]);
}

/// The telemetry task: encodes and writes every queued frame. Returns after
/// [`Message::End`] with the number of frames written.
pub async fn telemetry_task<M: RawMutex, S: FrameSink>(g: &Graph<M>, sink: &mut S) -> u32 {
    let mut n = 0u32;
    loop {
        match g.messages.receive().await {
            Message::Record(f) => {
                sink.write_frame(&f.encode()).await;
                n = n.wrapping_add(1);
            }
            Message::End => return n,
        }
    }
}

/// The alarm relay and the status LED.
pub trait AlarmPins {
    /// Energise (all well) or drop (alarm) the output to the CNC.
    fn set_relay(&mut self, energised: bool);
    /// LED on or off.
    fn set_led(&mut self, on: bool);
}

/// A delay (embassy-time on the target).
#[allow(async_fn_in_trait)] // used with concrete types only
pub trait Sleep {
    /// Waits `ms` milliseconds.
    async fn sleep_ms(&mut self, ms: u32);
}

/// The alarm-output task: the relay follows [`AlarmView::relay_energised`] at once, the LED
/// blinks [`AlarmView::led`]. Starts de-energised until the monitor says it runs.
pub async fn alarm_output_task<M: RawMutex, P: AlarmPins, S: Sleep>(
    g: &Graph<M>,
    pins: &mut P,
    sleep: &mut S,
) -> ! {
    let mut view = AlarmView::default();
    loop {
        pins.set_relay(view.relay_energised());
        let blink = view.led();
        pins.set_led(true);
        if let Either::First(v) = select(g.alarm.wait(), sleep.sleep_ms(blink.on_ms)).await {
            view = v;
            continue;
        }
        if blink.off_ms > 0 {
            pins.set_led(false);
            if let Either::First(v) = select(g.alarm.wait(), sleep.sleep_ms(blink.off_ms)).await {
                view = v;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{BoardConfig, SAMPLE_BLOCK};
    use crate::telemetry::decode;
    use embassy_futures::block_on;
    use embassy_futures::join::join3;
    use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
    use estimator_core::Sample;
    use std::vec::Vec;

    #[test]
    fn alarm_output_follows_the_monitor_and_starts_dropped() {
        use crate::alarm_out::AlarmView;
        use core::cell::Cell;
        use embassy_futures::select::select;
        use embassy_futures::yield_now;
        use estimator_core::alarm::Cause;

        struct Pins<'a>(&'a Cell<Option<bool>>);
        impl AlarmPins for Pins<'_> {
            fn set_relay(&mut self, energised: bool) {
                self.0.set(Some(energised));
            }
            fn set_led(&mut self, _on: bool) {}
        }
        /// Never wakes: only the monitor's changes move the task.
        struct Never;
        impl Sleep for Never {
            async fn sleep_ms(&mut self, _ms: u32) {
                core::future::pending::<()>().await
            }
        }

        let g: Graph<CriticalSectionRawMutex> = Graph::new();
        let relay = Cell::new(None);
        let mut pins = Pins(&relay);
        let seen = Cell::new(std::vec::Vec::new());
        let driver = async {
            let mut log = std::vec::Vec::new();
            for view in [
                None,
                Some(AlarmView {
                    running: true,
                    latched: None,
                    wear_warning: false,
                }),
                Some(AlarmView {
                    running: true,
                    latched: None,
                    wear_warning: true,
                }),
                Some(AlarmView {
                    running: true,
                    latched: Some(Cause::Breakage),
                    wear_warning: true,
                }),
                Some(AlarmView {
                    running: true,
                    latched: None,
                    wear_warning: false,
                }),
            ] {
                if let Some(v) = view {
                    g.alarm.signal(v);
                }
                for _ in 0..3 {
                    yield_now().await;
                }
                log.push(relay.get());
            }
            seen.set(log);
        };
        block_on(select(alarm_output_task(&g, &mut pins, &mut Never), driver));
        assert_eq!(
            seen.take(),
            [Some(false), Some(true), Some(true), Some(false), Some(true)]
        );
    }

    struct VecSink(Vec<u8>);

    impl FrameSink for VecSink {
        async fn write_frame(&mut self, frame: &[u8]) {
            self.0.extend_from_slice(frame);
        }
    }

    /// The whole graph on the host: a source task sends edges then blocks (as QEMU's does),
    /// the monitor and telemetry tasks run as on the board; the decoded stream holds every
    /// record, identical to the core's pipeline run directly on the same samples.
    #[test]
    fn graph_delivers_the_pipelines_records_bit_for_bit() {
        let g: Graph<CriticalSectionRawMutex> = Graph::new();
        let cfg = BoardConfig::board_default().build().expect("builds");
        let samples: Vec<Sample> = (0..20_000u32)
            .map(|i| Sample {
                feed: [0.5 + 0.1 * ((i % 100) as f32 / 100.0), 0.0],
                feed_velocity_mm_min: [1200.0, 0.0],
                spindle: 0.3 + 0.05 * ((i % 37) as f32 / 37.0),
                sync: i % 100 == 7,
            })
            .collect();
        let source = async {
            for (k, chunk) in samples.chunks(SAMPLE_BLOCK).enumerate() {
                let first = (k * SAMPLE_BLOCK) as u64;
                let mut b = SampleBlock::empty(first);
                b.len = chunk.len() as u16;
                b.end = first as usize + chunk.len() == samples.len();
                for (j, s) in chunk.iter().enumerate() {
                    if s.sync {
                        g.edges.send(first + j as u64).await;
                    }
                    b.samples[j] = Sample { sync: false, ..*s };
                }
                g.samples.send(b).await;
            }
        };
        let mut stage = MonitorStage::new(cfg.pipeline.clone(), cfg.telemetry);
        let mut sink = VecSink(Vec::new());
        let ((), (), frames) = block_on(join3(
            source,
            monitor_task(&g, &mut stage, &mut NoProbe),
            telemetry_task(&g, &mut sink),
        ));

        let pipeline = cfg.pipeline.clone();
        let mut st = estimator_core::PipelineState::default();
        let expect: Vec<_> = samples
            .iter()
            .filter_map(|s| pipeline.process(&mut st, s))
            .map(|(r, _)| r.to_words())
            .collect();
        let mut got = Vec::new();
        let stats = decode(&sink.0, |f| got.push(f.record.to_words()));
        assert_eq!(frames as usize, expect.len());
        assert_eq!(stats.frames as usize, expect.len());
        assert_eq!(
            (stats.missing, stats.bad_crc, stats.skipped_bytes),
            (0, 0, 0)
        );
        assert!(expect.len() > 190, "{}", expect.len());
        assert_eq!(got, expect);
        assert_eq!(g.heartbeat.load(Ordering::Relaxed), 625);
    }
}
