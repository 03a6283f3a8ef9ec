//! Tooth timing: capture timestamps to sample indices, and their merge into the samples.
//!
//! # Design
//!
//! On the board the sample counter is a timer: TIM2 counts the update events of TIM3, the
//! timer whose update triggers each ADC scan, so TIM2's count is the number of samples
//! triggered so far, and its input capture latches it at the encoder's edge. A capture of
//! `c` means the edge came after the trigger of sample `c - 1` and before that of sample
//! `c`: the pulse belongs to sample `c`, the first one after it (the core's convention: the
//! sample that carries the pulse opens the new period). No clock conversion, no rounding:
//! the timestamp *is* a sample index, in the samples' own time base.
//!
//! [`CaptureClock`] extends the 32-bit counter to 64 bits (2.5 days of samples at 20 kS/s
//! before it wraps); the tooth-timing task also feeds it the free-running count at least
//! once a second, so a long pause without edges cannot alias.
//!
//! [`SyncMerger`] holds the edges between the tooth-timing task and the monitor and says,
//! sample by sample, whether a pulse belongs there. An edge normally reaches the merger
//! before the block that holds its sample (the capture interrupt precedes that block's DMA
//! interrupt by at least one conversion, and the tooth-timing task runs at a higher
//! priority than the monitor). An edge that arrives after its sample was processed is
//! *late*: it is applied to the next sample, which shifts that tooth boundary (the core
//! then sees a period-length jump and flags it), and counted. An edge that finds the queue
//! full is dropped and counted: the core sees a lost pulse. Both counts go out with every
//! telemetry frame.

use heapless::Deque;

/// Extends a 32-bit sample counter to 64 bits.
#[derive(Clone, Copy, Debug, Default)]
pub struct CaptureClock {
    last: u64,
}

impl CaptureClock {
    /// Takes a counter reading (a capture or the free-running count) and returns it as a
    /// 64-bit index. Readings must come within 2^31 samples of each other (about 30 h at
    /// 20 kS/s); one slightly older than the last (a capture read after the counter) is
    /// placed before it, not 2^32 samples later.
    pub fn extend(&mut self, counter: u32) -> u64 {
        let delta = counter.wrapping_sub(self.last as u32) as i32 as i64;
        let index = (self.last as i64).wrapping_add(delta).max(0) as u64;
        self.last = self.last.max(index);
        index
    }
}

/// Edges waiting to be merged into the samples, with the late and dropped counts.
#[derive(Clone, Debug, Default)]
pub struct SyncMerger<const N: usize> {
    pending: Deque<u64, N>,
    /// Edges that arrived after their sample (applied to a later one).
    pub late: u32,
    /// Edges dropped on a full queue.
    pub dropped: u32,
}

impl<const N: usize> SyncMerger<N> {
    /// An empty merger.
    pub fn new() -> Self {
        SyncMerger {
            pending: Deque::new(),
            late: 0,
            dropped: 0,
        }
    }

    /// Queues the edge of sample `index` (edges arrive in order).
    pub fn push(&mut self, index: u64) {
        if self.pending.push_back(index).is_err() {
            self.dropped = self.dropped.saturating_add(1);
        }
    }

    /// Whether a pulse belongs to sample `index` (samples are asked for in order). Edges of
    /// earlier samples still queued are late: they count, and they land here.
    pub fn take(&mut self, index: u64) -> bool {
        let mut sync = false;
        while let Some(&e) = self.pending.front() {
            if e > index {
                break;
            }
            if e < index {
                self.late = self.late.saturating_add(1);
            }
            self.pending.pop_front();
            sync = true;
        }
        sync
    }

    /// Edges queued.
    pub fn len(&self) -> usize {
        self.pending.len()
    }

    /// No edge queued.
    pub fn is_empty(&self) -> bool {
        self.pending.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn capture_clock_unwraps_the_counter() {
        let mut c = CaptureClock::default();
        assert_eq!(c.extend(5), 5);
        // 7 samples before 5 would be before the start: clamped to 0.
        assert_eq!(c.extend(u32::MAX - 1), 0);
        let mut c = CaptureClock::default();
        let mut expect = 0u64;
        let mut raw = 0u32;
        for _ in 0..10 {
            raw = raw.wrapping_add(1 << 30);
            expect += 1 << 30;
            assert_eq!(c.extend(raw), expect);
        }
        assert!(expect > 1 << 32);
        // A capture a few samples older than the last counter reading stays before it.
        assert_eq!(c.extend(raw.wrapping_sub(3)), expect - 3);
        assert_eq!(c.extend(raw.wrapping_add(1)), expect + 1);
    }

    #[test]
    fn edges_land_on_their_samples() {
        let mut m = SyncMerger::<4>::new();
        m.push(3);
        m.push(7);
        let pulses: std::vec::Vec<u64> = (0..10).filter(|&i| m.take(i)).collect();
        assert_eq!(pulses, [3, 7]);
        assert_eq!((m.late, m.dropped), (0, 0));
    }

    #[test]
    fn late_and_dropped_edges_are_counted() {
        let mut m = SyncMerger::<2>::new();
        for i in 0..5 {
            assert!(!m.take(i));
        }
        // Edge of sample 3 arrives after sample 4 was processed: lands on 5.
        m.push(3);
        assert!(m.take(5));
        assert_eq!(m.late, 1);
        m.push(10);
        m.push(11);
        m.push(12);
        assert_eq!(m.dropped, 1);
        assert!(m.take(10) && m.take(11) && !m.take(12));
    }
}
