//! Telemetry frames: what the board sends on its UART, and the decoder host-sim uses.
//!
//! # Design
//!
//! A frame is a whole number of little-endian 32-bit words:
//!
//! ```text
//! word        field
//! 0           magic 0x4E4F4D54 (the bytes "TMON")
//! 1           format (bits 0-7, = FORMAT) | kind (bits 8-15) | payload words (bits 16-31)
//! 2           sequence number: +1 per frame the monitor queued, so a gap is a lost frame
//! 3..3+P      payload
//! 3+P         CRC-32 (IEEE 802.3: reflected 0x04C11DB7, init and xorout 0xFFFFFFFF) of
//!             the bytes of words 0..3+P
//! ```
//!
//! One kind for now, [`KIND_RECORD`]: one tooth record and the alarm state after it,
//! P = [`RECORD_PAYLOAD_WORDS`] = 32, 144 bytes a frame:
//!
//! ```text
//! 0..21   ToothRecord::to_words(): every field's bits (end_sample lo/hi, tooth, samples,
//!         rpm, tc_mm, fx_n, f2_n, fx_filt_n, f2_filt_n, tc_filt_mm, rr, ra, dr_mm, da_mm,
//!         dr_sigma_mm, da_sigma_mm, status, method, handover_z, handover_n)
//! 21      record index: records produced since start, sent or not (decimation shows here)
//! 22      sample rate [Hz], f32 bits (end_sample / rate is the record's time)
//! 23      alarm: bit 0 latched (the output to the CNC is dropped), bit 1 wear warning,
//!         bit 2 this record raised an event, bits 8-15 its cause (1 breakage, 2 tool gone,
//!         3 overload, 4 teach-in excursion, 5 wear)
//! 24, 25  the event's value and threshold, f32 bits (0 without an event)
//! 26      wear multiplier, f32 bits
//! 27..31  counters since start: samples lost (ADC ring overruns), sync edges late, sync
//!         edges dropped, frames dropped (telemetry queue full)
//! 31      the event's latch lead: samples from the output's latch to the record's last
//!         sample (a drop trip latches inside an earlier period; 0 without an event)
//!
//! Format 3 (this one) added the latch lead; format 2 added `handover_z`, `handover_n` to
//! the record. Frames of other formats are skipped and counted as another format.
//! ```
//!
//! The words are the record's exact bits, so a decoded stream equals host-sim's replay bit
//! for bit. The decoder resynchronises on the magic word after garbage or a bad CRC and
//! counts what it skipped, the frames that failed their CRC and the sequence gaps: nothing
//! lost on the wire goes unseen. CRC-32 by a 16-entry table, a nibble at a time (64 bytes
//! of flash, about 12 instructions per byte), rather than a 256-entry one (1 KiB, about
//! 7) or bit by bit (about 40): the flash budget is the tight one.

use estimator_core::alarm::{AlarmEvent, Cause};
use estimator_core::monitor::RECORD_WORDS;
use estimator_core::{Method, Status, ToothRecord};

/// First word of every frame: the bytes `TMON`.
pub const MAGIC: u32 = u32::from_le_bytes(*b"TMON");
/// Format of this layout; a decoder skips (and counts) frames of another format.
pub const FORMAT: u8 = 3;
/// Frame kind: a tooth record with the alarm state.
pub const KIND_RECORD: u8 = 1;
/// Words before the payload: magic, format/kind/length, sequence.
pub const HEADER_WORDS: usize = 3;
/// Payload words of a record frame.
pub const RECORD_PAYLOAD_WORDS: usize = RECORD_WORDS + 11;
/// Words of a record frame, CRC included.
pub const RECORD_FRAME_WORDS: usize = HEADER_WORDS + RECORD_PAYLOAD_WORDS + 1;
/// Bytes of a record frame.
pub const RECORD_FRAME_BYTES: usize = 4 * RECORD_FRAME_WORDS;
/// Largest payload a decoder accepts (a corrupt length must not swallow the stream).
pub const MAX_PAYLOAD_WORDS: usize = 256;

/// Counters that make losses visible, carried by every frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Counters {
    /// Samples lost to ADC ring overruns (bridged with NaN samples, see `stage`).
    pub samples_lost: u32,
    /// Sync edges that reached the monitor after their sample.
    pub edges_late: u32,
    /// Sync edges lost: overcaptured, or dropped on a full queue.
    pub edges_dropped: u32,
    /// Telemetry messages dropped on a full queue.
    pub frames_dropped: u32,
}

/// An alarm event as sent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EventFields {
    /// Why.
    pub cause: Cause,
    /// The quantity that crossed its threshold.
    pub value: f32,
    /// The threshold.
    pub threshold: f32,
    /// Samples from the output's latch to the record's last sample (a drop trip latches
    /// inside an earlier period; see `AlarmEvent::latched_sample`).
    pub latch_lead: u32,
}

impl From<&AlarmEvent> for EventFields {
    fn from(e: &AlarmEvent) -> Self {
        EventFields {
            cause: e.cause,
            value: e.value,
            threshold: e.threshold,
            latch_lead: u32::try_from(e.record.end_sample.saturating_sub(e.latched_sample))
                .unwrap_or(u32::MAX),
        }
    }
}

/// The alarm state after a record.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct AlarmFields {
    /// An alarm is latched: the output to the CNC is dropped.
    pub latched: bool,
    /// Wear multiplier above its warning level.
    pub wear_warning: bool,
    /// Raised by this record.
    pub event: Option<EventFields>,
    /// Wear multiplier.
    pub wear: f32,
}

/// One record frame's content.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RecordFrame {
    /// Sequence number.
    pub seq: u32,
    /// Records produced since start before this one (its index).
    pub index: u32,
    /// Sample rate [Hz].
    pub sample_rate_hz: f32,
    /// The record.
    pub record: ToothRecord,
    /// Alarm state after it.
    pub alarm: AlarmFields,
    /// Loss counters.
    pub counters: Counters,
}

/// Wire code of a cause (0 is "none").
pub fn cause_code(c: Cause) -> u8 {
    match c {
        Cause::Breakage => 1,
        Cause::ToolGone => 2,
        Cause::Overload => 3,
        Cause::TeachExcursion => 4,
        Cause::Wear => 5,
    }
}

/// Inverse of [`cause_code`].
pub fn cause_from_code(code: u8) -> Option<Cause> {
    Some(match code {
        1 => Cause::Breakage,
        2 => Cause::ToolGone,
        3 => Cause::Overload,
        4 => Cause::TeachExcursion,
        5 => Cause::Wear,
        _ => return None,
    })
}

/// Inverse of `ToothRecord::to_words`; `None` for an unknown method code.
pub fn record_from_words(w: &[u32; RECORD_WORDS]) -> Option<ToothRecord> {
    let f = |i: usize| f32::from_bits(w[i]);
    let method = match w[18] {
        0 => Method::None,
        1 => Method::Polynomial,
        2 => Method::Table3,
        3 => Method::Inversion,
        _ => return None,
    };
    Some(ToothRecord {
        end_sample: w[0] as u64 | (w[1] as u64) << 32,
        tooth: w[2] as u8,
        samples: w[3],
        rpm: f(4),
        tc_mm: f(5),
        fx_n: f(6),
        f2_n: f(7),
        fx_filt_n: f(8),
        f2_filt_n: f(9),
        tc_filt_mm: f(10),
        rr: f(11),
        ra: f(12),
        dr_mm: f(13),
        da_mm: f(14),
        dr_sigma_mm: f(15),
        da_sigma_mm: f(16),
        status: Status(w[17] as u16),
        method,
        handover_z: f(19),
        handover_n: f(20),
    })
}

impl RecordFrame {
    /// The sample at which the event's output latched (see [`EventFields::latch_lead`]).
    pub fn latched_sample(&self) -> Option<u64> {
        let e = self.alarm.event?;
        Some(
            self.record
                .end_sample
                .saturating_sub(u64::from(e.latch_lead)),
        )
    }

    /// The payload words (layout in the module docs).
    pub fn payload(&self) -> [u32; RECORD_PAYLOAD_WORDS] {
        let mut p = [0u32; RECORD_PAYLOAD_WORDS];
        p[..RECORD_WORDS].copy_from_slice(&self.record.to_words());
        let a = &self.alarm;
        let (present, cause, value, threshold, lead) = match a.event {
            Some(e) => (1, cause_code(e.cause), e.value, e.threshold, e.latch_lead),
            None => (0, 0, 0.0, 0.0, 0),
        };
        let c = &self.counters;
        let rest = [
            self.index,
            self.sample_rate_hz.to_bits(),
            a.latched as u32 | (a.wear_warning as u32) << 1 | present << 2 | (cause as u32) << 8,
            value.to_bits(),
            threshold.to_bits(),
            a.wear.to_bits(),
            c.samples_lost,
            c.edges_late,
            c.edges_dropped,
            c.frames_dropped,
            lead,
        ];
        p[RECORD_WORDS..].copy_from_slice(&rest);
        p
    }

    /// Parses a record payload; `None` if the method or cause code is unknown.
    pub fn from_payload(seq: u32, p: &[u32; RECORD_PAYLOAD_WORDS]) -> Option<RecordFrame> {
        let mut rw = [0u32; RECORD_WORDS];
        rw.copy_from_slice(&p[..RECORD_WORDS]);
        let record = record_from_words(&rw)?;
        let r = &p[RECORD_WORDS..];
        let flags = r[2];
        let event = if flags & 4 != 0 {
            Some(EventFields {
                cause: cause_from_code((flags >> 8) as u8)?,
                value: f32::from_bits(r[3]),
                threshold: f32::from_bits(r[4]),
                latch_lead: r[10],
            })
        } else {
            None
        };
        Some(RecordFrame {
            seq,
            index: r[0],
            sample_rate_hz: f32::from_bits(r[1]),
            record,
            alarm: AlarmFields {
                latched: flags & 1 != 0,
                wear_warning: flags & 2 != 0,
                event,
                wear: f32::from_bits(r[5]),
            },
            counters: Counters {
                samples_lost: r[6],
                edges_late: r[7],
                edges_dropped: r[8],
                frames_dropped: r[9],
            },
        })
    }

    /// The whole frame, ready for the UART.
    pub fn encode(&self) -> [u8; RECORD_FRAME_BYTES] {
        let mut out = [0u8; RECORD_FRAME_BYTES];
        let header = [
            MAGIC,
            FORMAT as u32 | (KIND_RECORD as u32) << 8 | (RECORD_PAYLOAD_WORDS as u32) << 16,
            self.seq,
        ];
        let words = header.into_iter().chain(self.payload());
        for (dst, w) in out.chunks_exact_mut(4).zip(words) {
            dst.copy_from_slice(&w.to_le_bytes());
        }
        let body = RECORD_FRAME_BYTES - 4;
        let crc = crc32(&out[..body]);
        out[body..].copy_from_slice(&crc.to_le_bytes());
        out
    }
}

/// The CRC of each nibble: 64 bytes of flash where a byte table takes 1 KiB (the board's
/// flash is the tighter budget; the telemetry task has time to spare).
const CRC_TABLE: [u32; 16] = {
    let mut t = [0u32; 16];
    let mut i = 0;
    while i < 16 {
        let mut c = i as u32;
        let mut k = 0;
        while k < 4 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
            k += 1;
        }
        t[i] = c;
        i += 1;
    }
    t
};

/// CRC-32 (IEEE 802.3, as zlib's `crc32`), a nibble at a time.
pub fn crc32(bytes: &[u8]) -> u32 {
    let mut c = 0xFFFF_FFFFu32;
    for &b in bytes {
        c ^= b as u32;
        c = CRC_TABLE[(c & 0xF) as usize] ^ (c >> 4);
        c = CRC_TABLE[(c & 0xF) as usize] ^ (c >> 4);
    }
    !c
}

/// What a decoder saw besides the frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct DecodeStats {
    /// Record frames decoded.
    pub frames: u64,
    /// Bytes skipped while looking for a frame (garbage, or the rest of a bad frame).
    pub skipped_bytes: u64,
    /// Frames whose CRC failed.
    pub bad_crc: u64,
    /// Well-formed frames of another format or kind, or with an unknown code, skipped.
    pub unsupported: u64,
    /// Frames missing by their sequence numbers.
    pub missing: u64,
    /// The stream ends inside a frame.
    pub truncated: bool,
}

fn word_at(bytes: &[u8], at: usize) -> Option<u32> {
    let b = bytes.get(at..at + 4)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// Decodes a captured byte stream: every good record frame goes to `on_frame`, in order.
pub fn decode(bytes: &[u8], mut on_frame: impl FnMut(&RecordFrame)) -> DecodeStats {
    let mut st = DecodeStats::default();
    let mut last_seq: Option<u32> = None;
    let mut i = 0usize;
    while i + 4 * HEADER_WORDS <= bytes.len() {
        let (Some(magic), Some(h), Some(seq)) = (
            word_at(bytes, i),
            word_at(bytes, i + 4),
            word_at(bytes, i + 8),
        ) else {
            break;
        };
        if magic != MAGIC {
            i += 1;
            st.skipped_bytes += 1;
            continue;
        }
        let p = (h >> 16) as usize;
        if p > MAX_PAYLOAD_WORDS {
            i += 1;
            st.skipped_bytes += 1;
            continue;
        }
        let body = 4 * (HEADER_WORDS + p);
        let Some(crc) = word_at(bytes, i + body) else {
            st.truncated = true;
            st.skipped_bytes += (bytes.len() - i) as u64;
            i = bytes.len();
            break;
        };
        if crc32(&bytes[i..i + body]) != crc {
            st.bad_crc += 1;
            i += 1;
            st.skipped_bytes += 1;
            continue;
        }
        if let Some(last) = last_seq {
            st.missing += u64::from(seq.wrapping_sub(last).wrapping_sub(1));
        }
        last_seq = Some(seq);
        let (format, kind) = (h as u8, (h >> 8) as u8);
        let mut parsed = None;
        if format == FORMAT && kind == KIND_RECORD && p == RECORD_PAYLOAD_WORDS {
            let mut w = [0u32; RECORD_PAYLOAD_WORDS];
            for (k, slot) in w.iter_mut().enumerate() {
                *slot = word_at(bytes, i + 4 * (HEADER_WORDS + k)).unwrap_or(0);
            }
            parsed = RecordFrame::from_payload(seq, &w);
        }
        match parsed {
            Some(f) => {
                st.frames += 1;
                on_frame(&f);
            }
            None => st.unsupported += 1,
        }
        i += body + 4;
    }
    st.skipped_bytes += (bytes.len() - i) as u64;
    st.truncated |= i < bytes.len();
    st
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::vec::Vec;

    fn frame(seq: u32) -> RecordFrame {
        RecordFrame {
            seq,
            index: seq * 2,
            sample_rate_hz: 20_000.0,
            record: ToothRecord {
                end_sample: (7u64 << 32) + seq as u64,
                tooth: 3,
                samples: 125,
                rpm: 600.5,
                tc_mm: 0.15,
                fx_n: -12.25,
                f2_n: f32::from_bits(0x4321_1234),
                dr_mm: 4.0,
                status: Status::TRANSIENT | Status::SETTLING,
                method: Method::Inversion,
                handover_z: 4.5,
                handover_n: f32::from_bits(0x4120_0001),
                ..ToothRecord::default()
            },
            alarm: AlarmFields {
                latched: true,
                wear_warning: false,
                event: Some(EventFields {
                    cause: Cause::Breakage,
                    value: 55.0,
                    threshold: 40.0,
                    latch_lead: 77,
                }),
                wear: 1.01,
            },
            counters: Counters {
                samples_lost: 1,
                edges_late: 2,
                edges_dropped: 3,
                frames_dropped: 4,
            },
        }
    }

    #[test]
    fn crc_is_the_ieee_one() {
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
        assert_eq!(crc32(b""), 0);
    }

    #[test]
    fn frames_round_trip_bit_for_bit() {
        let f = frame(5);
        let bytes = f.encode();
        assert_eq!(&bytes[..4], b"TMON");
        let mut got = Vec::new();
        let st = decode(&bytes, |g| got.push(*g));
        assert_eq!(st.frames, 1);
        assert_eq!(got[0].record.to_words(), f.record.to_words());
        assert_eq!(got[0], f);
    }

    #[test]
    fn decoder_resyncs_and_counts_what_it_lost() {
        let mut s: Vec<u8> = b"noise".to_vec();
        s.extend(frame(1).encode());
        let mut bad = frame(2).encode();
        bad[40] ^= 0x10;
        s.extend(bad);
        s.extend(frame(3).encode());
        s.extend(frame(6).encode());
        s.extend(&frame(7).encode()[..50]);
        let mut seqs = Vec::new();
        let st = decode(&s, |f| seqs.push(f.seq));
        assert_eq!(seqs, [1, 3, 6]);
        assert_eq!(st.bad_crc, 1);
        // 2 by the bad CRC, 4 and 5 never sent.
        assert_eq!(st.missing, 1 + 2);
        assert!(st.truncated);
        assert_eq!(st.skipped_bytes, 5 + RECORD_FRAME_BYTES as u64 + 50);
    }

    #[test]
    fn unknown_codes_are_skipped_not_misread() {
        let mut f = frame(1);
        f.record.method = Method::Polynomial;
        let mut p = f.payload();
        p[18] = 9;
        assert!(RecordFrame::from_payload(1, &p).is_none());
        for c in [
            Cause::Breakage,
            Cause::ToolGone,
            Cause::Overload,
            Cause::TeachExcursion,
            Cause::Wear,
        ] {
            assert_eq!(cause_from_code(cause_code(c)), Some(c));
        }
        assert_eq!(cause_from_code(0), None);
    }
}
