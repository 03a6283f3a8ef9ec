//! Firmware for the STM32F405RG tool monitor (embassy): the board.
//!
//! # Design
//!
//! The task graph of `firmware::graph`, with the board's peripherals at its ends
//! (`board/`, one file per peripheral; the pin map is in `board/mod.rs`):
//!
//! | task | executor | does |
//! | --- | --- | --- |
//! | `sampling` | interrupt (UART4 line, P6) | ADC ring + feed encoder -> sample blocks (`board/adc.rs`) |
//! | `tooth_timing` | interrupt | TIM2 capture -> sample indices of sync edges (`board/tooth_capture.rs`) |
//! | `monitor` | thread | `firmware::graph::monitor_task`: the core's `Pipeline`, telemetry queued, alarm state |
//! | `telemetry` | thread | frames to USART3 (`board/telemetry_uart.rs`) |
//! | `alarm_output` | thread | relay and LED (`board/alarm_io.rs`) |
//! | `reset_input` | thread | debounced reset button -> `reset` signal |
//! | `watchdog` | thread | feeds the IWDG while the monitor's heartbeat moves |
//!
//! The two tasks that empty hardware buffers run on a higher-priority interrupt executor,
//! so a tooth update in the monitor (a few thousand instructions) never delays them, and a
//! sync edge is always queued before the block that holds its sample reaches the monitor
//! (`firmware::sync`). Everything they and the others decide is in the `firmware` library
//! and in estimator-core, where host tests reach it; this file only wires.
//!
//! The configuration is `BoardConfig::board_default()` (`src/config.rs`), built once here;
//! if it does not build, nothing is started but the alarm output (relay de-energised, LED
//! flashing the error) and the error is logged over defmt-RTT.
//!
//! On the host (any target with an OS) the binary is an empty `main`, so workspace-wide
//! `cargo test` / `cargo clippy` stay green without a cross toolchain; build it for real
//! with `cargo fw`, flash and run it with `cargo run --release -p firmware --target
//! thumbv7em-none-eabihf` (probe-rs, see README "Flashing").
#![cfg_attr(target_os = "none", no_std, no_main)]

#[cfg(target_os = "none")]
mod board;

#[cfg(target_os = "none")]
mod target {
    use core::sync::atomic::Ordering;

    use defmt::{error, info, warn};
    use embassy_executor::{Executor, InterruptExecutor, Spawner};
    use embassy_stm32::exti::ExtiInput;
    use embassy_stm32::interrupt;
    use embassy_stm32::interrupt::{InterruptExt, Priority};
    use embassy_stm32::mode::Async;
    use embassy_stm32::peripherals::IWDG;
    use embassy_stm32::wdg::IndependentWatchdog;
    use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
    use embassy_time::Timer;
    use firmware::alarm_out::Liveness;
    use firmware::config::{BoardConfig, SAMPLE_BLOCK, WATCHDOG_CHECK_MS};
    use firmware::frontend::{FeedVelocity, Frontend};
    use firmware::graph::{
        alarm_output_task, monitor_task, telemetry_task, Graph, MonitorStage, NoProbe, Sleep,
    };
    // Linked for their side effects: the RTT logger, the panic handler, the critical-section
    // implementation (cortex-m) and the vector table / reset handler (cortex-m-rt).
    use {cortex_m as _, cortex_m_rt as _, defmt_rtt as _, panic_probe as _};

    use crate::board::adc::{Sampler, DMA_LEN};
    use crate::board::alarm_io::{self, Outputs, RESET_DEBOUNCE_MS};
    use crate::board::feed_encoder::FeedEncoder;
    use crate::board::telemetry_uart::TelemetryUart;
    use crate::board::tooth_capture::{Event, ToothCapture};
    use crate::board::{self, Board};

    static GRAPH: Graph<CriticalSectionRawMutex> = Graph::new();

    /// Sampling and tooth timing: above thread mode, below the DMA and capture interrupts.
    static EXECUTOR_HIGH: InterruptExecutor = InterruptExecutor::new();

    // Note(unsafe): cortex-m-rt's interrupt handlers are `unsafe fn`; `on_interrupt` must
    // only be called from the interrupt `EXECUTOR_HIGH` was started on, which this is.
    #[allow(unsafe_code)]
    #[interrupt]
    unsafe fn UART4() {
        unsafe { EXECUTOR_HIGH.on_interrupt() }
    }

    /// Milliseconds between counter reads when no sync pulse comes.
    const CAPTURE_TICK_MS: u64 = 1000;

    #[embassy_executor::task]
    async fn sampling(mut sampler: Sampler, encoder: FeedEncoder, mut frontend: Frontend) {
        loop {
            let raw = sampler.next_block().await;
            let block = frontend.block(raw.first, &raw.codes, encoder.count());
            // A monitor that falls behind holds this up, the DMA ring then overruns, and
            // the overrun is counted (board/adc.rs): never a silent loss.
            GRAPH.samples.send(block).await;
        }
    }

    #[embassy_executor::task]
    async fn tooth_timing(mut capture: ToothCapture) {
        loop {
            if let Event::Edge { index, lost } = capture.next(CAPTURE_TICK_MS).await {
                let full = GRAPH.edges.try_send(index).is_err() as u32;
                if lost + full > 0 {
                    GRAPH.edges_lost.fetch_add(lost + full, Ordering::Relaxed);
                }
            }
        }
    }

    /// The stage lives in a static of its own (`singleton!`), not in the task's future:
    /// moved in as an argument it would sit there twice.
    #[embassy_executor::task]
    async fn monitor(stage: &'static mut MonitorStage) {
        monitor_task(&GRAPH, stage, &mut NoProbe).await;
        // Only a finite source ends the monitor; the board's does not.
        error!("monitor: the sample source ended");
    }

    #[embassy_executor::task]
    async fn telemetry(mut uart: TelemetryUart) {
        telemetry_task(&GRAPH, &mut uart).await;
    }

    struct EmbassySleep;

    impl Sleep for EmbassySleep {
        async fn sleep_ms(&mut self, ms: u32) {
            Timer::after_millis(ms as u64).await;
        }
    }

    #[embassy_executor::task]
    async fn alarm_output(mut outputs: Outputs) {
        alarm_output_task(&GRAPH, &mut outputs, &mut EmbassySleep).await
    }

    #[embassy_executor::task]
    async fn reset_input(mut pin: ExtiInput<'static, Async>) {
        loop {
            pin.wait_for_falling_edge().await;
            Timer::after_millis(RESET_DEBOUNCE_MS).await;
            if pin.is_low() {
                info!("alarm reset");
                GRAPH.reset.signal(());
                pin.wait_for_high().await;
            }
        }
    }

    #[embassy_executor::task]
    async fn watchdog(mut wdg: IndependentWatchdog<'static, IWDG>) {
        let mut live = Liveness::default();
        loop {
            Timer::after_millis(WATCHDOG_CHECK_MS).await;
            if live.alive(GRAPH.heartbeat.load(Ordering::Relaxed)) {
                wdg.pet();
            } else {
                warn!("watchdog: the monitor is stalled; not feeding the IWDG");
            }
        }
    }

    fn start(spawner: Spawner, b: Board) {
        let (outputs, reset_pin) = alarm_io::split(b.io);
        // First, so that the relay is held de-energised whatever happens next.
        match alarm_output(outputs) {
            Ok(t) => spawner.spawn(t),
            Err(_) => error!("alarm output task not spawned"),
        }
        let cfg = match BoardConfig::board_default().build() {
            Ok(c) => c,
            Err(e) => {
                error!("configuration refused: parameter `{=str}`", e.parameter());
                return;
            }
        };
        info!(
            "tool monitor {}: {} S/s, {} timer clocks per sample",
            env!("CARGO_PKG_VERSION"),
            cfg.sample_rate_hz,
            cfg.trigger_period_ticks
        );
        let Some(dma_buf) = cortex_m::singleton!(: [u16; DMA_LEN] = [0; DMA_LEN]) else {
            error!("ADC buffer taken");
            return;
        };
        // The sample counter must run before the trigger starts.
        let capture = ToothCapture::new(b.capture);
        let encoder = FeedEncoder::new(b.encoder);
        let block_s = SAMPLE_BLOCK as f32 / cfg.sample_rate_hz;
        let frontend = Frontend {
            feed: cfg.feed_scale,
            spindle: cfg.spindle_scale,
            velocity: FeedVelocity::new(
                cfg.feed_encoder.counts_per_mm,
                cfg.feed_encoder.window_blocks,
                block_s,
                encoder.count(),
            ),
        };
        let Some(stage) = cortex_m::singleton!(
            : MonitorStage = MonitorStage::new(cfg.pipeline, cfg.telemetry)
        ) else {
            error!("monitor stage taken");
            return;
        };
        let uart = TelemetryUart::new(b.uart);
        // Consumers before producers.
        let spawned = [
            telemetry(uart).map(|t| spawner.spawn(t)),
            monitor(stage).map(|t| spawner.spawn(t)),
            reset_input(reset_pin).map(|t| spawner.spawn(t)),
        ];
        interrupt::UART4.set_priority(Priority::P6);
        let high = EXECUTOR_HIGH.start(interrupt::UART4);
        let sampler = Sampler::start(b.adc, dma_buf, cfg.trigger_period_ticks);
        let spawned_high = [
            tooth_timing(capture).map(|t| high.spawn(t)),
            sampling(sampler, encoder, frontend).map(|t| high.spawn(t)),
        ];
        if spawned.iter().chain(&spawned_high).any(|r| r.is_err()) {
            error!("a task was not spawned: the watchdog stays off, the relay de-energised");
            return;
        }
        match watchdog(board::watchdog::start(b.iwdg)) {
            Ok(t) => spawner.spawn(t),
            Err(_) => error!("watchdog task not spawned"),
        }
    }

    #[cortex_m_rt::entry]
    fn main() -> ! {
        let p = embassy_stm32::init(board::config());
        let b = Board::split(p);
        let Some(executor) = cortex_m::singleton!(: Executor = Executor::new()) else {
            panic!("executor taken");
        };
        executor.run(|spawner| start(spawner, b))
    }
}

#[cfg(not(target_os = "none"))]
fn main() {}
