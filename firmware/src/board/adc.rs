//! Sampling: ADC1 scanning the two check-terminal inputs on every TIM3 update, into a
//! circular DMA buffer.
//!
//! # Design
//!
//! TIM3 counts the 84 MHz timer clock with period `TIMER_CLOCK_HZ / sample_rate_hz` (4 200
//! at 20 kS/s) and puts its update event on TRGO. ADC1 (21 MHz, 12 bit, 56-cycle sampling:
//! 68 cycles, 3.2 us a conversion) converts IN4 (feed) then IN5 (spindle) on each rising
//! TRGO edge, and DMA2 stream 0 writes the pairs into a circular buffer of two blocks
//! (`2 x SAMPLE_BLOCK` pairs) with half- and full-transfer interrupts: embassy-stm32's
//! `RingBufferedAdc` with a regular trigger, all on the HAL. The two channels of a sample
//! are 3.2 us apart, a scan, not a simultaneous dual-ADC conversion (which the HAL does not
//! offer): against tooth periods of 0.6 ms and more, and averaged per tooth, the skew does
//! not matter.
//!
//! Sample index: TIM2 counts TIM3's updates (see `tooth_capture.rs`), so the number of
//! samples triggered is in TIM2's counter. Samples are numbered from the first update
//! after start-up; each block's first index is the running count.
//!
//! Overruns are counted here, not trusted to the HAL (embassy's F4 ring ADC has its
//! hardware-overrun check commented out): a ring overrun (this task too slow: the DMA
//! lapped the reader) comes back from `read` as an error, and an ADC overrun (the DMA too
//! slow, `SR.OVR`, which also stops the DMA requests: a read that has waited 50 ms is
//! taken for one) is read from the register (PAC). Either way the task stops TIM3, lets the
//! last conversion land, empties the ring, takes the exact sample count from TIM2, clears
//! `OVR` and re-arms DMA requests if needed (PAC), and restarts TIM3; the next block's first
//! index jumps by the samples lost, which the monitor counts and bridges (`firmware::stage`).
//!
//! Note: `RingBufferedAdc::start` sets `SWSTART`. With an external trigger that may start
//! one conversion at once; the ring is therefore cleared after arming and before TIM3
//! starts, so the first sample read is TIM3's first.

use embassy_stm32::adc::{Adc, AdcChannel, Exten, RingBufferedAdc, SampleTime};
use embassy_stm32::peripherals::{ADC1, DMA2_CH0, PA4, PA5, TIM3};
use embassy_stm32::timer::low_level::{MasterMode, Timer};
use embassy_stm32::{pac, triggers, Peri};
use embassy_time::{with_timeout, Duration};
use firmware::config::SAMPLE_BLOCK;
use firmware::frontend::AdcCode;

use super::Irqs;

/// u16 entries of the DMA buffer: two blocks of two channels.
pub const DMA_LEN: usize = 2 * 2 * SAMPLE_BLOCK;

/// No block for this long is a stalled ADC or DMA (an `OVR` stops the DMA requests): the
/// sampler recovers. Well under the watchdog's 100 ms, far over a block (1.6 ms at 20 kS/s).
const STALL: Duration = Duration::from_millis(50);

/// The peripherals of sampling.
pub struct Parts {
    /// ADC1.
    pub adc: Peri<'static, ADC1>,
    /// The sample trigger.
    pub trigger: Peri<'static, TIM3>,
    /// ADC1's DMA stream.
    pub dma: Peri<'static, DMA2_CH0>,
    /// Feed current input.
    pub feed: Peri<'static, PA4>,
    /// Spindle current input.
    pub spindle: Peri<'static, PA5>,
}

/// A block of raw readings: `(feed, spindle)` per sample, and the index of the first.
pub struct RawBlock {
    /// Sample index of `codes[0]`.
    pub first: u64,
    /// Readings.
    pub codes: [(AdcCode, AdcCode); SAMPLE_BLOCK],
}

/// The running sampler.
pub struct Sampler {
    ring: RingBufferedAdc<'static, ADC1>,
    trigger: Timer<'static, TIM3>,
    buf: [u16; DMA_LEN / 2],
    next: u64,
    /// Ring or ADC overruns so far (logged; the samples lost reach telemetry through the
    /// monitor, `samples_lost`).
    overruns: u32,
}

impl Sampler {
    /// Sets up TIM3 (`period_ticks` timer clocks per sample), ADC1 and its DMA ring, and
    /// starts sampling. `dma_buf` is the circular buffer.
    pub fn start(p: Parts, dma_buf: &'static mut [u16; DMA_LEN], period_ticks: u32) -> Self {
        let trigger = Timer::new(p.trigger);
        trigger.stop();
        let r = trigger.regs_core();
        r.psc().write_value(0);
        r.arr().write(|w| w.set_arr((period_ticks - 1) as u16));
        trigger.set_master_mode(MasterMode::UPDATE);
        trigger.generate_update_event();

        let adc = Adc::new(p.adc);
        let mut ring = adc.into_ring_buffered(
            p.dma,
            dma_buf,
            Irqs,
            [
                (p.feed.degrade_adc(), SampleTime::CYCLES56),
                (p.spindle.degrade_adc(), SampleTime::CYCLES56),
            ]
            .into_iter(),
            triggers::TIM3_TRGO,
            Exten::RISING_EDGE,
        );
        ring.start();
        // See the module's note on SWSTART.
        cortex_m::asm::delay(2_000);
        ring.clear();
        trigger.start();
        Sampler {
            ring,
            trigger,
            buf: [0; DMA_LEN / 2],
            next: 0,
            overruns: 0,
        }
    }

    /// Waits for the next block. After an overrun the block's first index has jumped.
    pub async fn next_block(&mut self) -> RawBlock {
        loop {
            let read = with_timeout(STALL, self.ring.read(&mut self.buf)).await;
            // An ADC overrun stops the DMA requests: the read then times out, or, if it
            // happened after the block was full, the block is dropped with what follows.
            let hw_overrun = pac::ADC1.sr().read().ovr();
            match read {
                Ok(Ok(_)) if !hw_overrun => {
                    let mut b = RawBlock {
                        first: self.next,
                        codes: [(AdcCode(0), AdcCode(0)); SAMPLE_BLOCK],
                    };
                    for (dst, pair) in b.codes.iter_mut().zip(self.buf.chunks_exact(2)) {
                        *dst = (AdcCode(pair[0]), AdcCode(pair[1]));
                    }
                    self.next += SAMPLE_BLOCK as u64;
                    return b;
                }
                _ => self.recover(),
            }
        }
    }

    /// Restarts after an overrun at the exact sample count (module docs).
    fn recover(&mut self) {
        self.overruns = self.overruns.wrapping_add(1);
        self.trigger.stop();
        // The last triggered conversion (3.2 us of each channel) and its DMA transfer.
        cortex_m::asm::delay(2_000);
        let adc = pac::ADC1;
        if adc.sr().read().ovr() {
            adc.sr().modify(|w| w.set_ovr(false));
            adc.cr2().modify(|w| w.set_dma(false));
            adc.cr2().modify(|w| w.set_dma(true));
        }
        self.ring.clear();
        // Every sample triggered so far is either delivered or lost: the next one read is
        // the next one triggered. (32-bit counter: the forward difference from `next`.)
        let triggered = super::tooth_capture::sample_count();
        self.next += u64::from(triggered.wrapping_sub(self.next as u32));
        self.trigger.start();
        defmt::warn!(
            "ADC overrun #{}: resynchronised at sample {}",
            self.overruns,
            self.next
        );
    }
}
