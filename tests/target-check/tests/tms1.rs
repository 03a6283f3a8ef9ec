//! The TMS1 blob reader: round trip, and every malformed blob refused with its reason.

use estimator_core::Sample;
use target_check::tms1::{encode_into, Tms1, Tms1Error, HEADER_LEN, SAMPLE_LEN};

fn samples() -> Vec<Sample> {
    (0..5)
        .map(|i| Sample {
            feed: [i as f32, -0.0],
            feed_velocity_mm_min: [f32::NAN, f32::INFINITY],
            spindle: 1e-40, // subnormal: bits must survive
            sync: i % 2 == 0,
        })
        .collect()
}

fn blob(s: &[Sample]) -> Vec<u8> {
    let mut b = vec![0u8; HEADER_LEN + SAMPLE_LEN * s.len()];
    let n = encode_into(5000.0, s, &mut b).expect("sized");
    assert_eq!(n, b.len());
    b
}

fn bits(s: &Sample) -> [u32; 6] {
    [
        s.feed[0].to_bits(),
        s.feed[1].to_bits(),
        s.feed_velocity_mm_min[0].to_bits(),
        s.feed_velocity_mm_min[1].to_bits(),
        s.spindle.to_bits(),
        s.sync as u32,
    ]
}

#[test]
fn round_trip_is_bit_exact() {
    let s = samples();
    let b = blob(&s);
    let t = Tms1::parse(&b).expect("valid");
    assert_eq!(t.sample_rate_hz(), 5000.0);
    assert_eq!(t.len(), s.len());
    let back: Vec<Sample> = t.samples().collect();
    for (a, b) in s.iter().zip(&back) {
        assert_eq!(bits(a), bits(b));
    }
}

#[test]
fn matches_host_sims_encoder() {
    let s = samples();
    let theirs = host_sim::trace::encode_samples(5000.0, &s).expect("encode");
    assert_eq!(theirs, blob(&s));
}

#[test]
fn empty_blob_is_valid() {
    let b = blob(&[]);
    let t = Tms1::parse(&b).expect("valid");
    assert!(t.is_empty());
    assert_eq!(t.samples().count(), 0);
}

#[test]
fn malformed_blobs_are_refused() {
    let good = blob(&samples());
    assert_eq!(
        Tms1::parse(&good[..7]).err(),
        Some(Tms1Error::ShortHeader { len: 7 })
    );
    let mut bad = good.clone();
    bad[0] = b'X';
    assert_eq!(Tms1::parse(&bad).err(), Some(Tms1Error::BadMagic(*b"XMS1")));
    assert_eq!(
        Tms1::parse(&good[..good.len() - 1]).err(),
        Some(Tms1Error::Length {
            count: 5,
            body: 5 * 24 - 1
        })
    );
    let mut long = good.clone();
    long.push(0);
    assert!(matches!(Tms1::parse(&long), Err(Tms1Error::Length { .. })));
    // A count whose byte length overflows 32 bits.
    let mut hostile = good.clone();
    hostile[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
    assert!(matches!(
        Tms1::parse(&hostile),
        Err(Tms1Error::Length {
            count: u32::MAX,
            ..
        })
    ));
}

#[test]
fn replay_refuses_bad_blob_and_bad_rate_without_writing() {
    use target_check::{write_replay_report, ReplayError};
    let mut out = String::new();
    assert_eq!(
        write_replay_report(&mut out, b"nope"),
        Err(ReplayError::Blob(Tms1Error::ShortHeader { len: 4 }))
    );
    let mut b = blob(&samples());
    b[4..8].copy_from_slice(&(-1.0f32).to_le_bytes());
    assert!(matches!(
        write_replay_report(&mut out, &b),
        Err(ReplayError::Config(_))
    ));
    assert!(out.is_empty());
}
