//! embassy-time driver on SysTick, for QEMU (which does not model the STM32's timers and
//! RCC that embassy-stm32's driver needs).
//!
//! # Design
//!
//! SysTick runs from the core clock, which netduinoplus2 models at 168 MHz, and interrupts
//! every millisecond (reload 168 000). `now()` is `ms * 1000 + (cycles into the ms) / 168`
//! in embassy-time's 1 MHz ticks; the pending-SysTick bit covers a reload that happened
//! inside the critical section before its interrupt ran. Wake-ups are checked once per
//! millisecond by the interrupt, and at once when scheduled (an expired deadline fires
//! immediately): 1 ms resolution, plenty for pacing blocks of samples.
//!
//! Under `-icount shift=0` one instruction is one nanosecond of virtual time, so
//! [`cycles`] (168 per microsecond) counts instructions in units of 1e9 / 168e6 = 5.95;
//! the QEMU variant brackets the monitor's work with it.

use core::cell::{Cell, RefCell};

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::{SCB, SYST};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::blocking_mutex::Mutex;
use embassy_time_queue_utils::Queue;

/// Core clock of netduinoplus2 [Hz].
pub const CORE_HZ: u32 = 168_000_000;
/// SysTick reload: one interrupt per millisecond.
const RELOAD: u32 = CORE_HZ / 1000 - 1;
/// Core cycles per embassy-time tick (1 MHz).
const CYCLES_PER_TICK: u64 = CORE_HZ as u64 / embassy_time_driver::TICK_HZ;

struct SysTickDriver {
    /// Milliseconds since start.
    ms: Mutex<CriticalSectionRawMutex, Cell<u64>>,
    /// Next deadline [ticks].
    alarm: Mutex<CriticalSectionRawMutex, Cell<u64>>,
    queue: Mutex<CriticalSectionRawMutex, RefCell<Queue>>,
}

embassy_time_driver::time_driver_impl!(static DRIVER: SysTickDriver = SysTickDriver {
    ms: Mutex::const_new(CriticalSectionRawMutex::new(), Cell::new(0)),
    alarm: Mutex::const_new(CriticalSectionRawMutex::new(), Cell::new(u64::MAX)),
    queue: Mutex::new(RefCell::new(Queue::new())),
});

/// Starts SysTick; call once, before anything waits on time.
pub fn init(mut syst: SYST) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(RELOAD);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();
}

/// Core cycles since start (168 per microsecond).
pub fn cycles() -> u64 {
    critical_section::with(|cs| {
        let mut ms = DRIVER.ms.borrow(cs).get();
        let mut val = SYST::get_current();
        if SCB::is_pendst_pending() {
            // Reloaded, interrupt not yet run: that millisecond is over.
            ms += 1;
            val = SYST::get_current();
        }
        ms * (RELOAD as u64 + 1) + (RELOAD - val) as u64
    })
}

impl embassy_time_driver::Driver for SysTickDriver {
    fn now(&self) -> u64 {
        cycles() / CYCLES_PER_TICK
    }

    fn schedule_wake(&self, at: u64, waker: &core::task::Waker) {
        critical_section::with(|cs| {
            let mut q = self.queue.borrow(cs).borrow_mut();
            if q.schedule_wake(at, waker) {
                // Wakes what is already due, returns the next deadline.
                let next = q.next_expiration(self.now());
                self.alarm.borrow(cs).set(next);
            }
        });
    }
}

impl SysTickDriver {
    fn on_tick(&self) {
        critical_section::with(|cs| {
            let ms = self.ms.borrow(cs);
            ms.set(ms.get() + 1);
            let alarm = self.alarm.borrow(cs);
            let now = ms.get() * 1000;
            if now >= alarm.get() {
                let next = self.queue.borrow(cs).borrow_mut().next_expiration(now);
                alarm.set(next);
            }
        });
    }
}

#[cortex_m_rt::exception]
fn SysTick() {
    DRIVER.on_tick();
}
