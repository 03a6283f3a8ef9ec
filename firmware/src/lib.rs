//! The firmware's hardware-free part: the task graph around the core's [`Pipeline`], and
//! everything it needs that does not touch a peripheral.
//!
//! # Design
//!
//! ```text
//!  sampling ──SampleBlock──┐                       ┌──Message──▶ telemetry (frames, CRC)
//!                          ├─▶ monitor + alarms ───┤
//!  tooth timing ──edge────┘   (Pipeline::process) └──AlarmView─▶ alarm output (relay, LED)
//!                                   ▲
//!                        reset ─────┘
//! ```
//!
//! One concern per task, joined by embassy-sync channels ([`graph::Graph`]). The tasks are
//! `async fn`s generic over their sources and sinks ([`graph`]); the board (`src/main.rs`,
//! `src/board/`) and the QEMU variant (`src/qemu/`) only plug peripherals (or a trace in
//! flash and semihosting) into them. Every decision is made here or in estimator-core,
//! where host tests reach it:
//!
//! - [`config`]: board constants (sample clock, block size, queues, baud rate, watchdog) and
//!   the configuration the board runs: the core's [`MachineConfig`] (with the analog front
//!   end and the feed encoder in its `front_end`) plus the telemetry decimation, checked
//!   once;
//! - [`frontend`]: ADC codes to signal units, quadrature counts to feed velocity;
//! - [`sync`]: capture timestamps to sample indices, and their merge into the samples;
//! - [`stage`]: the monitor + alarm stage (gaps, late edges, decimation, counters);
//! - [`telemetry`]: the framed binary messages (magic, format, sequence, CRC-32) and their
//!   decoder, which host-sim uses;
//! - [`alarm_out`]: what the alarm output and the status LED show, and the liveness check
//!   that gates the watchdog.
//!
//! `no_std`, no heap, no `unsafe`, no embassy-stm32: it builds and is tested on the host.
//!
//! [`Pipeline`]: estimator_core::Pipeline
//! [`MachineConfig`]: estimator_core::MachineConfig
#![no_std]
#![forbid(unsafe_code)]

#[cfg(test)]
extern crate std;

pub mod alarm_out;
pub mod config;
pub mod frontend;
pub mod graph;
pub mod stage;
pub mod sync;
pub mod telemetry;
