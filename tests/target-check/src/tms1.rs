//! Reader of the TMS1 sample blob: a raw trace in the binary form host-sim writes
//! (`host-sim trace-bin`, `host_sim::trace::encode_samples`), small enough to sit in flash.
//!
//! # Design
//!
//! ```text
//! offset  size        field
//! 0       4           magic b"TMS1"
//! 4       4           sample_rate_hz, f32 little-endian
//! 8       4           count, u32 little-endian
//! 12      24 * count  per sample, 6 x f32 LE: feed[0], feed[1], feed_velocity[0],
//!                     feed_velocity[1], spindle, sync (0.0 or 1.0)
//! ```
//!
//! No allocation, no alignment needed (`include_bytes!` data is byte-aligned): every field
//! is read with `from_le_bytes` from a byte slice. [`Tms1::parse`] checks the whole layout
//! once (magic, header, exact length), so iterating cannot fail afterwards; a blob that is
//! not exactly what the header says is refused rather than partly replayed. The sample rate
//! is not judged here: `MonitorConfig::build` does that and names it.

use estimator_core::Sample;

/// The four bytes every blob starts with.
pub const MAGIC: [u8; 4] = *b"TMS1";
/// Header length [bytes]: magic, sample rate, count.
pub const HEADER_LEN: usize = 12;
/// Bytes per sample: six f32.
pub const SAMPLE_LEN: usize = 24;

/// Why a blob cannot be read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tms1Error {
    /// Shorter than the 12-byte header.
    ShortHeader {
        /// Bytes present.
        len: usize,
    },
    /// The first four bytes are not `TMS1`.
    BadMagic([u8; 4]),
    /// The length differs from `12 + 24 * count`.
    Length {
        /// Samples the header announces.
        count: u32,
        /// Bytes after the header.
        body: usize,
    },
}

impl core::fmt::Display for Tms1Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::ShortHeader { len } => {
                write!(
                    f,
                    "TMS1 blob of {len} bytes is shorter than its {HEADER_LEN}-byte header"
                )
            }
            Self::BadMagic(m) => write!(f, "not a TMS1 blob: magic {m:02x?}"),
            Self::Length { count, body } => write!(
                f,
                "TMS1 header announces {count} samples ({} bytes), the body has {body} bytes",
                *count as u64 * SAMPLE_LEN as u64
            ),
        }
    }
}

/// A checked blob: header fields and the sample bytes.
#[derive(Clone, Copy, Debug)]
pub struct Tms1<'a> {
    sample_rate_hz: f32,
    body: &'a [u8],
}

/// Reads 4 bytes at `at` (callers have checked the length; a short read gives zeros).
fn word(bytes: &[u8], at: usize) -> [u8; 4] {
    let mut w = [0u8; 4];
    if let Some(src) = bytes.get(at..at + 4) {
        w.copy_from_slice(src);
    }
    w
}

impl<'a> Tms1<'a> {
    /// Checks magic and length.
    pub fn parse(bytes: &'a [u8]) -> Result<Self, Tms1Error> {
        let (header, body) = match (bytes.get(..HEADER_LEN), bytes.get(HEADER_LEN..)) {
            (Some(h), Some(b)) => (h, b),
            _ => return Err(Tms1Error::ShortHeader { len: bytes.len() }),
        };
        let magic = word(header, 0);
        if magic != MAGIC {
            return Err(Tms1Error::BadMagic(magic));
        }
        let sample_rate_hz = f32::from_le_bytes(word(header, 4));
        let count = u32::from_le_bytes(word(header, 8));
        // u64: a hostile count must not overflow the product on a 32-bit target.
        if count as u64 * SAMPLE_LEN as u64 != body.len() as u64 {
            return Err(Tms1Error::Length {
                count,
                body: body.len(),
            });
        }
        Ok(Tms1 {
            sample_rate_hz,
            body,
        })
    }

    /// Sample rate from the header [Hz] (not checked: the monitor's config does that).
    pub fn sample_rate_hz(&self) -> f32 {
        self.sample_rate_hz
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.body.len() / SAMPLE_LEN
    }

    /// No samples.
    pub fn is_empty(&self) -> bool {
        self.body.is_empty()
    }

    /// The samples, in order.
    pub fn samples(&self) -> impl Iterator<Item = Sample> + 'a {
        self.body.chunks_exact(SAMPLE_LEN).map(decode_sample)
    }
}

/// One 24-byte record as a monitor sample. `sync` is any value other than 0.0 (host-sim
/// writes exactly 0.0 or 1.0; a NaN reads as a pulse, like any non-zero value).
fn decode_sample(rec: &[u8]) -> Sample {
    let f = |k: usize| f32::from_le_bytes(word(rec, 4 * k));
    Sample {
        feed: [f(0), f(1)],
        feed_velocity_mm_min: [f(2), f(3)],
        spindle: f(4),
        sync: f(5) != 0.0,
    }
}

/// Writes a blob into `out` (for build scripts and tests on the host; host-sim has its own
/// writer, which is the reference). Returns the bytes written, or `None` if `out` is short.
pub fn encode_into(sample_rate_hz: f32, samples: &[Sample], out: &mut [u8]) -> Option<usize> {
    let need = HEADER_LEN + SAMPLE_LEN * samples.len();
    let out = out.get_mut(..need)?;
    let (header, body) = out.split_at_mut(HEADER_LEN);
    header[..4].copy_from_slice(&MAGIC);
    header[4..8].copy_from_slice(&sample_rate_hz.to_le_bytes());
    header[8..12].copy_from_slice(&u32::try_from(samples.len()).ok()?.to_le_bytes());
    for (rec, s) in body.chunks_exact_mut(SAMPLE_LEN).zip(samples) {
        let words = [
            s.feed[0],
            s.feed[1],
            s.feed_velocity_mm_min[0],
            s.feed_velocity_mm_min[1],
            s.spindle,
            if s.sync { 1.0 } else { 0.0 },
        ];
        for (dst, w) in rec.chunks_exact_mut(4).zip(words) {
            dst.copy_from_slice(&w.to_le_bytes());
        }
    }
    Some(need)
}
