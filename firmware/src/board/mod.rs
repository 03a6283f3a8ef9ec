//! The board: every pin and peripheral the firmware uses, named here and nowhere else.
//!
//! # Design
//!
//! | signal | pin | peripheral | file |
//! | --- | --- | --- | --- |
//! | feed-motor current (check terminal, via the front end) | PA4 | ADC1 IN4, DMA2 stream 0 | [`adc`] |
//! | spindle-motor current (check terminal, via the front end) | PA5 | ADC1 IN5 | [`adc`] |
//! | sample trigger (internal) | — | TIM3 update -> TRGO -> ADC1 | [`adc`] |
//! | tooth sync from the spindle encoder | PA0 | TIM2 CH1 input capture, TIM2 counting TIM3's updates | [`tooth_capture`] |
//! | feed-axis encoder A / B | PB6 / PB7 | TIM4 CH1 / CH2, encoder mode | [`feed_encoder`] |
//! | telemetry TX (921 600 8N1) | PB10 | USART3 TX, DMA1 stream 3 | [`telemetry_uart`] |
//! | alarm output to the CNC (relay driver, high = energised = OK) | PB12 | GPIO push-pull | [`alarm_io`] |
//! | status LED (high = on) | PC1 | GPIO | [`alarm_io`] |
//! | alarm reset input (to GND, internal pull-up) | PB13 | GPIO + EXTI13 | [`alarm_io`] |
//! | watchdog | — | IWDG (LSI) | [`watchdog`] |
//! | debug probe, defmt over RTT | PA13 / PA14 | SWD | — |
//!
//! Timers in use: TIM2 (tooth capture / sample counter), TIM3 (sample trigger), TIM4 (feed
//! encoder), TIM12 (embassy-time's driver, `time-driver-tim12`). PC1 is the user LED of an
//! Adafruit Feather STM32F405 Express, on which the rest of the pins are broken out too.
//!
//! Clocks ([`config`]): HSI 16 MHz -> PLL (/8, x168, /2) -> SYSCLK 168 MHz; APB1 42 MHz
//! (timers 84 MHz = `firmware::config::TIMER_CLOCK_HZ`), APB2 84 MHz (ADC clock 21 MHz).
//! HSI is 1 % accurate: the sample rate, and so the rpm the core reports, too; the feed per
//! tooth is a ratio of two rates on the same clock and does not see it. With a crystal,
//! set `hse` and `pll_src` here and keep the 84 MHz timer clock.

pub mod adc;
pub mod alarm_io;
pub mod feed_encoder;
pub mod telemetry_uart;
pub mod tooth_capture;
pub mod watchdog;

use embassy_stm32::{bind_interrupts, dma, peripherals, timer, Config, Peripherals};

bind_interrupts!(pub struct Irqs {
    DMA2_STREAM0 => dma::InterruptHandler<peripherals::DMA2_CH0>;
    DMA1_STREAM3 => dma::InterruptHandler<peripherals::DMA1_CH3>;
    TIM2 => timer::CaptureCompareInterruptHandler<peripherals::TIM2>;
    EXTI15_10 => embassy_stm32::exti::InterruptHandler<embassy_stm32::interrupt::typelevel::EXTI15_10>;
});

/// The clock tree of the module docs.
pub fn config() -> Config {
    use embassy_stm32::rcc::{
        AHBPrescaler, APBPrescaler, Pll, PllMul, PllPDiv, PllPreDiv, PllQDiv, PllSource, Sysclk,
    };
    let mut c = Config::default();
    c.rcc.hsi = true;
    c.rcc.pll_src = PllSource::HSI;
    c.rcc.pll = Some(Pll {
        prediv: PllPreDiv::DIV8,
        mul: PllMul::MUL168,
        divp: Some(PllPDiv::DIV2),
        divq: Some(PllQDiv::DIV7),
        divr: None,
    });
    c.rcc.sys = Sysclk::PLL1_P;
    c.rcc.ahb_pre = AHBPrescaler::DIV1;
    c.rcc.apb1_pre = APBPrescaler::DIV4;
    c.rcc.apb2_pre = APBPrescaler::DIV2;
    c
}

/// The peripherals, split by task.
pub struct Board {
    /// ADC1 + TIM3 + DMA2 stream 0 (sampling task).
    pub adc: adc::Parts,
    /// TIM2 (tooth-timing task).
    pub capture: tooth_capture::Parts,
    /// TIM4 (sampling task).
    pub encoder: feed_encoder::Parts,
    /// USART3 (telemetry task).
    pub uart: telemetry_uart::Parts,
    /// Relay, LED, reset input (alarm-output and reset tasks).
    pub io: alarm_io::Parts,
    /// IWDG (watchdog task).
    pub iwdg: watchdog::Parts,
}

impl Board {
    /// Splits the peripherals (pins as in the module docs).
    pub fn split(p: Peripherals) -> Board {
        Board {
            adc: adc::Parts {
                adc: p.ADC1,
                trigger: p.TIM3,
                dma: p.DMA2_CH0,
                feed: p.PA4,
                spindle: p.PA5,
            },
            capture: tooth_capture::Parts {
                tim: p.TIM2,
                pin: p.PA0,
            },
            encoder: feed_encoder::Parts {
                tim: p.TIM4,
                a: p.PB6,
                b: p.PB7,
            },
            uart: telemetry_uart::Parts {
                usart: p.USART3,
                tx: p.PB10,
                dma: p.DMA1_CH3,
            },
            io: alarm_io::Parts {
                relay: p.PB12,
                led: p.PC1,
                reset: p.PB13,
                reset_exti: p.EXTI13,
            },
            iwdg: watchdog::Parts { iwdg: p.IWDG },
        }
    }
}
