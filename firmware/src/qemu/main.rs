//! The firmware's task graph in QEMU (netduinoplus2, the STM32F405 map of `memory.x`).
//!
//! # Design
//!
//! The same graph as the board (`firmware::graph`): the monitor + alarm task, the telemetry
//! task and the alarm-output task are the library's, unchanged; only the ends differ.
//!
//! - **Time**: a SysTick driver for embassy-time ([`time_driver`]): QEMU models neither the
//!   STM32's RCC (embassy-stm32's init hangs) nor its timers.
//! - **Sampling and tooth timing**: a TMS1 trace compiled into flash (`FIRMWARE_TRACE=path`
//!   at build time, see build.rs; a tiny built-in one otherwise) plays both: its samples
//!   go out in blocks of `SAMPLE_BLOCK`, paced by a `Ticker` at the trace's own rate, and
//!   its sync pulses as edges (sample indices), each before the block that holds it, as
//!   the board's capture does.
//! - **Configuration**: `BoardConfig::board_default()` at the trace's sample rate: the
//!   board's, i.e. `MachineConfig::default()` (what host-sim's replay runs without a
//!   machine file).
//! - **Telemetry**: every frame's bytes as one line of little-endian words on semihosting
//!   stdout, in target-check's framed report (`target-check begin`, `idx w0 w1 ...`,
//!   `target-check end N`); tests/firmware-qemu turns them back into bytes and decodes them
//!   with `firmware::telemetry::decode`, as host-sim does with a UART capture.
//! - **Alarm output**: relay changes as lines on semihosting stderr.
//! - **Executor**: all tasks on one interrupt executor, thread mode in `wfi` (see
//!   `EXECUTOR`: QEMU does not sleep on the thread executor's `wfe`). With one source task
//!   sending a block's edges before the block, the order the board gets from priorities
//!   holds by construction.
//! - At the end of the trace, a `firmware-qemu stats` line on stderr: counts, loss
//!   counters, the stack high-water mark (painted) and, per block, the SysTick cycles the
//!   monitor took (instructions under `-icount shift=0`, see [`time_driver`]); then QEMU
//!   exits with success.
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod time_driver;

#[cfg(target_os = "none")]
mod target {
    use core::fmt::Write as _;

    use embassy_executor::{InterruptExecutor, SendSpawner};
    use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
    use embassy_sync::signal::Signal;
    use embassy_time::{Duration, Ticker, Timer};
    use estimator_core::Sample;
    use firmware::config::{BoardConfig, SAMPLE_BLOCK};
    use firmware::graph::{
        alarm_output_task, monitor_task, telemetry_task, AlarmPins, BlockProbe, FrameSink, Graph,
        MonitorStage, SampleBlock, Sleep,
    };
    use firmware::telemetry::Counters;
    use stm32_metapac::interrupt;
    use target_check::semihosting::{eprint, exit, Buffered};
    use target_check::tms1::Tms1;
    use target_check::{write_case, BEGIN, END_PREFIX};
    // Linked for their side effects: the vector table (cortex-m-rt, and the device's
    // interrupt vectors from the PAC: no HAL), the defmt logger embassy's crates log to, the
    // panic handler (exits QEMU with a failure).
    use {cortex_m_rt as _, defmt_rtt as _, panic_semihosting as _};

    use super::time_driver;

    /// The trace, copied to OUT_DIR by build.rs.
    static TRACE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/trace.bin"));

    static GRAPH: Graph<CriticalSectionRawMutex> = Graph::new();

    /// What the monitor reports when the trace is over.
    #[derive(Clone, Copy, Default)]
    struct Stats {
        samples: u64,
        records: u32,
        frames: u32,
        counters: Counters,
        probe: Probe,
    }

    static STATS: Signal<CriticalSectionRawMutex, Stats> = Signal::new();

    /// SysTick cycles of the monitor's work per block, split by the records a block closed.
    #[derive(Clone, Copy, Default)]
    struct Probe {
        t0: u64,
        /// Blocks that closed no record: count, samples, cycles.
        plain: (u32, u64, u64),
        /// Blocks that closed exactly one record: count, samples, cycles.
        one: (u32, u64, u64),
        /// Most cycles of any block.
        max: u64,
    }

    impl BlockProbe for Probe {
        fn begin(&mut self) {
            self.t0 = time_driver::cycles();
        }

        fn end(&mut self, samples: u16, records: u16) {
            let dt = time_driver::cycles().saturating_sub(self.t0);
            self.max = self.max.max(dt);
            let acc = match records {
                0 => &mut self.plain,
                1 => &mut self.one,
                _ => return,
            };
            acc.0 += 1;
            acc.1 += samples as u64;
            acc.2 += dt;
        }
    }

    /// Sampling and tooth timing from the trace.
    #[embassy_executor::task]
    async fn trace_source(trace: Tms1<'static>) {
        let fs = trace.sample_rate_hz() as f64;
        let block_us = (SAMPLE_BLOCK as f64 * 1e6 / fs) as u64;
        let mut ticker = Ticker::every(Duration::from_micros(block_us));
        let mut samples = trace.samples().peekable();
        let mut first = 0u64;
        loop {
            let mut b = SampleBlock::empty(first);
            for (j, slot) in b.samples.iter_mut().enumerate() {
                let Some(s) = samples.next() else { break };
                if s.sync {
                    GRAPH.edges.send(first + j as u64).await;
                }
                *slot = Sample { sync: false, ..s };
                b.len += 1;
            }
            b.end = samples.peek().is_none();
            // The block is there when its last sample is.
            ticker.next().await;
            first += b.len as u64;
            let end = b.end;
            GRAPH.samples.send(b).await;
            if end {
                return;
            }
        }
    }

    /// The monitor task; builds its configuration itself (at the trace's sample rate), so
    /// that the large values are made in place rather than moved through `main`'s stack.
    #[embassy_executor::task]
    async fn monitor(sample_rate_hz: f32) {
        let mut board = BoardConfig::board_default();
        board.machine.monitor.sample_rate_hz = sample_rate_hz;
        let mut stage = match board.build() {
            Ok(built) => MonitorStage::new(built.pipeline, built.telemetry),
            Err(e) => {
                eprint(format_args!("firmware-qemu: configuration: {e}\n"));
                exit(false)
            }
        };
        let mut probe = Probe::default();
        monitor_task(&GRAPH, &mut stage, &mut probe).await;
        STATS.signal(Stats {
            samples: stage.next_sample(),
            records: stage.records(),
            frames: stage.frames(),
            counters: stage.counters(),
            probe,
        });
    }

    /// Frames as report lines of little-endian words.
    struct SemihostingSink {
        out: Buffered,
        lines: u32,
        failed: bool,
    }

    impl FrameSink for SemihostingSink {
        async fn write_frame(&mut self, frame: &[u8]) {
            let mut words = [0u32; firmware::telemetry::RECORD_FRAME_WORDS];
            for (w, b) in words.iter_mut().zip(frame.chunks_exact(4)) {
                *w = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
            }
            let n = frame.len() / 4;
            if write_case(&mut self.out, self.lines, &words[..n.min(words.len())]).is_err() {
                self.failed = true;
            }
            self.lines += 1;
        }
    }

    #[embassy_executor::task]
    async fn telemetry() {
        let Ok(out) = Buffered::stdout() else {
            eprint(format_args!("firmware-qemu: no semihosting stdout\n"));
            exit(false)
        };
        let mut sink = SemihostingSink {
            out,
            lines: 0,
            failed: false,
        };
        let begun = writeln!(sink.out, "{BEGIN}").is_ok();
        let frames = telemetry_task(&GRAPH, &mut sink).await;
        let ended = writeln!(sink.out, "{END_PREFIX}{frames}").is_ok();
        let flushed = sink.out.flush().is_ok();
        let s = STATS.wait().await;
        let p = s.probe;
        eprint(format_args!(
            "firmware-qemu stats samples={} records={} frames={} samples_lost={} \
             edges_late={} edges_dropped={} frames_dropped={} stack_peak_bytes={} \
             plain_blocks={} plain_samples={} plain_cycles={} one_record_blocks={} \
             one_record_samples={} one_record_cycles={} max_block_cycles={} \
             encode_cycles_per_frame={} frontend_cycles_per_block={}\n",
            s.samples,
            s.records,
            s.frames,
            s.counters.samples_lost,
            s.counters.edges_late,
            s.counters.edges_dropped,
            s.counters.frames_dropped,
            stack::peak(),
            p.plain.0,
            p.plain.1,
            p.plain.2,
            p.one.0,
            p.one.1,
            p.one.2,
            p.max,
            encode_cycles(),
            frontend_cycles(),
        ));
        exit(begun && ended && flushed && !sink.failed);
    }

    /// SysTick cycles to encode one record frame (header, payload, CRC-32), mean of 64.
    fn encode_cycles() -> u64 {
        let f = firmware::telemetry::RecordFrame {
            seq: 1,
            index: 1,
            sample_rate_hz: 20_000.0,
            record: Default::default(),
            alarm: Default::default(),
            counters: Default::default(),
        };
        let t0 = time_driver::cycles();
        let mut x = 0u32;
        for k in 0..64u32 {
            let g = firmware::telemetry::RecordFrame {
                seq: core::hint::black_box(k),
                ..f
            };
            x ^= core::hint::black_box(g.encode())[131] as u32;
        }
        core::hint::black_box(x);
        (time_driver::cycles() - t0) / 64
    }

    /// SysTick cycles of the board's sampling arithmetic for one block (ADC codes to
    /// samples, encoder to velocity: `Frontend::block`), mean of 64 blocks.
    fn frontend_cycles() -> u64 {
        use firmware::config::AnalogInput;
        use firmware::frontend::{AdcCode, FeedVelocity, Frontend, Scale};
        let mut fe = Frontend {
            feed: Scale::new(&AnalogInput::bipolar_10v(3.0)),
            spindle: Scale::new(&AnalogInput::bipolar_10v(5.0)),
            velocity: FeedVelocity::new(1000.0, 64, 0.0016, 0),
        };
        let mut codes = [(AdcCode(0), AdcCode(0)); SAMPLE_BLOCK];
        for (k, c) in codes.iter_mut().enumerate() {
            *c = (AdcCode(1000 + k as u16), AdcCode(3000 - k as u16));
        }
        let t0 = time_driver::cycles();
        let mut x = 0.0f32;
        for k in 0..64u16 {
            let b = fe.block(k as u64 * 32, core::hint::black_box(&codes), k * 10);
            x += core::hint::black_box(b).samples[31].feed[0];
        }
        core::hint::black_box(x);
        (time_driver::cycles() - t0) / 64
    }

    /// The relay and LED as stderr lines (relay changes only).
    struct QemuPins {
        relay: Option<bool>,
    }

    impl AlarmPins for QemuPins {
        fn set_relay(&mut self, energised: bool) {
            if self.relay != Some(energised) {
                self.relay = Some(energised);
                let what = if energised { "energised" } else { "dropped" };
                eprint(format_args!("firmware-qemu relay {what}\n"));
            }
        }

        fn set_led(&mut self, _on: bool) {}
    }

    struct EmbassySleep;

    impl Sleep for EmbassySleep {
        async fn sleep_ms(&mut self, ms: u32) {
            Timer::after_millis(ms as u64).await;
        }
    }

    #[embassy_executor::task]
    async fn alarm_output() {
        alarm_output_task(&GRAPH, &mut QemuPins { relay: None }, &mut EmbassySleep).await
    }

    fn start(spawner: SendSpawner) -> Result<(), &'static str> {
        let trace = Tms1::parse(TRACE).map_err(|_| "the embedded trace is not TMS1")?;
        // Consumers first, the source last.
        spawner.spawn(alarm_output().map_err(|_| "alarm output task")?);
        spawner.spawn(telemetry().map_err(|_| "telemetry task")?);
        spawner.spawn(monitor(trace.sample_rate_hz()).map_err(|_| "monitor task")?);
        spawner.spawn(trace_source(trace).map_err(|_| "trace task")?);
        Ok(())
    }

    /// Every task runs on this executor, in the UART4 interrupt (unused: QEMU's
    /// netduinoplus2 has no UART4 device, its NVIC line is free).
    ///
    /// Note: not a thread-mode executor as on the board. That one sleeps with `wfe`, which
    /// QEMU treats as a yield: idle time would be spent spinning, and under `-icount` every
    /// virtual second would cost about 30 s of real time. Thread mode here sleeps with
    /// `wfi`, which QEMU does halt on.
    static EXECUTOR: InterruptExecutor = InterruptExecutor::new();

    // Note(unsafe): cortex-m-rt's interrupt handlers are `unsafe fn`; `on_interrupt` is
    // unsafe because it must only be called from the interrupt `EXECUTOR` was started on,
    // which this is.
    #[allow(unsafe_code)]
    #[interrupt]
    unsafe fn UART4() {
        unsafe { EXECUTOR.on_interrupt() }
    }

    #[cortex_m_rt::entry]
    fn main() -> ! {
        stack::paint();
        let Some(p) = cortex_m::Peripherals::take() else {
            eprint(format_args!("firmware-qemu: core peripherals taken\n"));
            exit(false)
        };
        time_driver::init(p.SYST);
        let spawner = EXECUTOR.start(interrupt::UART4);
        if let Err(e) = start(spawner) {
            eprint(format_args!("firmware-qemu: {e}\n"));
            exit(false);
        }
        loop {
            cortex_m::asm::wfi();
        }
    }

    target_check::hardfault_exits!();

    /// Stack high-water mark by painting.
    mod stack {
        /// Painting pattern.
        const PAINT: u32 = 0xA5A5_A5A5;

        // Linker symbols of cortex-m-rt: end of static RAM, top of the stack.
        extern "C" {
            static __sheap: u32;
            static _stack_start: u32;
        }

        /// `(lowest free address, top of stack)`: only the symbols' addresses are taken.
        fn bounds() -> (usize, usize) {
            (
                core::ptr::addr_of!(__sheap) as usize,
                core::ptr::addr_of!(_stack_start) as usize,
            )
        }

        /// Fills the free RAM below the live stack (up to 256 bytes under SP) with PAINT.
        #[inline(never)]
        pub fn paint() {
            let (lo, _) = bounds();
            let sp = cortex_m::register::msp::read() as usize;
            let mut a = lo;
            while a + 4 <= sp.saturating_sub(256) {
                // Note(unsafe): `lo..sp - 256` is RAM between the statics and the live
                // stack, used by nothing (no heap); word-aligned (`__sheap` is).
                #[allow(unsafe_code)]
                unsafe {
                    core::ptr::write_volatile(a as *mut u32, PAINT);
                }
                a += 4;
            }
        }

        /// Deepest stack use since [`paint`] [bytes].
        pub fn peak() -> usize {
            let (lo, top) = bounds();
            let mut a = lo;
            // Note(unsafe): reads back the words `paint` wrote (or the stack since).
            #[allow(unsafe_code)]
            while a < top && unsafe { core::ptr::read_volatile(a as *const u32) } == PAINT {
                a += 4;
            }
            top - a
        }
    }
}

#[cfg(not(target_os = "none"))]
fn main() {}
