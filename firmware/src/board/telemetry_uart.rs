//! Telemetry out: USART3 TX with DMA.
//!
//! # Design
//!
//! USART3 at `firmware::config::UART_BAUD` (921 600, 8N1), TX only, on PB10; each frame
//! (144 bytes, `firmware::telemetry`) is one DMA write (DMA1 stream 3), awaited by the
//! telemetry task, all on the HAL. The task is the only writer, so frames never interleave.
//! A failed write is counted and logged (defmt); the frame is lost, and the host sees the
//! gap in the sequence numbers. When the UART is slower than the records, the monitor's
//! queue fills and the monitor counts the frames it drops (`frames_dropped`): the UART never
//! holds the monitor up.

use embassy_stm32::mode::Async;
use embassy_stm32::peripherals::{DMA1_CH3, PB10, USART3};
use embassy_stm32::usart::{Config, UartTx};
use embassy_stm32::Peri;
use firmware::config::UART_BAUD;
use firmware::graph::FrameSink;

use super::Irqs;

/// The peripherals of telemetry.
pub struct Parts {
    /// The UART.
    pub usart: Peri<'static, USART3>,
    /// TX pin.
    pub tx: Peri<'static, PB10>,
    /// TX DMA stream.
    pub dma: Peri<'static, DMA1_CH3>,
}

/// The UART as a frame sink.
pub struct TelemetryUart {
    tx: Option<UartTx<'static, Async>>,
    /// Writes that failed (or all of them, if the UART did not start).
    pub errors: u32,
}

impl TelemetryUart {
    /// Sets USART3 up; a configuration the UART refuses leaves it off (every write then
    /// counts as an error).
    pub fn new(p: Parts) -> Self {
        let mut cfg = Config::default();
        cfg.baudrate = UART_BAUD;
        let tx = UartTx::new(p.usart, p.tx, p.dma, Irqs, cfg).ok();
        if tx.is_none() {
            defmt::error!("telemetry UART: configuration refused");
        }
        TelemetryUart { tx, errors: 0 }
    }
}

impl FrameSink for TelemetryUart {
    async fn write_frame(&mut self, frame: &[u8]) {
        let ok = match &mut self.tx {
            Some(tx) => tx.write(frame).await.is_ok(),
            None => false,
        };
        if !ok {
            self.errors = self.errors.wrapping_add(1);
            defmt::warn!("telemetry UART: write failed ({} so far)", self.errors);
        }
    }
}
