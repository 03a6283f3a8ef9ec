//! Raw trace CSV: write -> read bit-exact, header and row errors named by line and column,
//! `to_sample`, binary samples.

use host_sim::trace::{
    columns, decode_samples, encode_samples, write_sample_bin, FeedSignal, SpindleSignal,
    TraceKind, TraceReader, TraceRow, TraceWriter, Truth, SAMPLE_BIN_MAGIC,
};
use std::io::Cursor;

/// Deterministic f32 bit patterns over the whole range (subnormals, huge, -0, inf), NaN
/// replaced by a plain value so equality can be by bits.
struct Bits(u64);

impl Bits {
    fn next_u32(&mut self) -> u32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 32) as u32
    }

    fn f32(&mut self) -> f32 {
        let v = f32::from_bits(self.next_u32());
        if v.is_nan() {
            1.5
        } else {
            v
        }
    }

    /// Mostly ordinary numbers, sometimes any bit pattern.
    fn value(&mut self) -> f32 {
        match self.next_u32() % 4 {
            0 => self.f32(),
            1 => (self.next_u32() as f32 / 4e8) - 5.0,
            2 => [
                0.0,
                -0.0,
                f32::INFINITY,
                f32::NEG_INFINITY,
                f32::MIN_POSITIVE / 3.0,
            ][(self.next_u32() % 5) as usize],
            _ => (self.next_u32() % 100_000) as f32 * 1e-4,
        }
    }
}

fn kinds() -> Vec<TraceKind> {
    let mut out = Vec::new();
    for feed in [FeedSignal::Current, FeedSignal::Force] {
        for two_axis in [false, true] {
            for has_velocity in [false, true] {
                for spindle in [
                    SpindleSignal::Current,
                    SpindleSignal::Load,
                    SpindleSignal::None,
                ] {
                    for has_truth in [false, true] {
                        let k = TraceKind {
                            feed,
                            two_axis,
                            has_velocity,
                            spindle,
                            has_truth,
                        };
                        if k.validate().is_ok() {
                            out.push(k);
                        }
                    }
                }
            }
        }
    }
    out
}

fn same(a: f32, b: f32) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

#[test]
fn write_read_round_trip_is_bit_exact_for_every_kind() {
    let ks = kinds();
    assert_eq!(
        ks.len(),
        2 * 2 * 2 * 2 + 2 * 3 * 2,
        "motor 16 kinds (a spindle column required), force 12 (always two axes)"
    );
    let mut g = Bits(7);
    for kind in ks {
        let rows: Vec<TraceRow> = (0..300)
            .map(|i| TraceRow {
                // An awkward but exact time base: shortest repr must bring every bit back.
                time_s: 3.0 + i as f64 / 30_000.0 + f64::from(g.next_u32()) * 1e-19,
                sync: g.next_u32() % 7 == 0,
                feed: [g.value(), g.value()],
                feed_velocity_mm_min: [g.value(), g.value()],
                spindle: g.value(),
                truth: Truth {
                    dr_mm: g.value(),
                    da_mm: g.value(),
                    tc_mm: g.value(),
                    rpm: g.value(),
                    flutes_intact: g.next_u32(),
                    fx_n: g.value(),
                    fy_n: g.value(),
                    ft_n: if i == 5 { f32::NAN } else { g.value() },
                },
            })
            .collect();
        let mut w = TraceWriter::new(Vec::new(), kind, 30_000.0).expect("writer");
        for r in &rows {
            w.write_row(r).expect("write");
        }
        let bytes = w.finish().expect("finish");
        let mut rd = TraceReader::new(Cursor::new(&bytes), "mem.csv").expect("header");
        assert_eq!(rd.kind(), kind);
        assert_eq!(rd.sample_rate_hz(), Some(30_000.0));
        for (i, want) in rows.iter().enumerate() {
            let got = rd.next_row().expect("row").expect("not at the end");
            let ctx = format!("{kind:?} row {i}");
            assert_eq!(got.time_s.to_bits(), want.time_s.to_bits(), "{ctx}");
            assert_eq!(got.sync, want.sync, "{ctx}");
            assert!(same(got.feed[0], want.feed[0]), "{ctx}");
            let feed1 = if kind.two_axis { want.feed[1] } else { 0.0 };
            assert!(same(got.feed[1], feed1), "{ctx}");
            let v = match (kind.has_velocity, kind.two_axis) {
                (false, _) => [f32::NAN; 2],
                (true, false) => [want.feed_velocity_mm_min[0], 0.0],
                (true, true) => want.feed_velocity_mm_min,
            };
            assert!(same(got.feed_velocity_mm_min[0], v[0]), "{ctx}");
            assert!(same(got.feed_velocity_mm_min[1], v[1]), "{ctx}");
            let spindle = if kind.spindle == SpindleSignal::None {
                0.0
            } else {
                want.spindle
            };
            assert!(same(got.spindle, spindle), "{ctx}");
            let t = if kind.has_truth {
                want.truth
            } else {
                Truth::default()
            };
            let (a, b) = (got.truth, t);
            for (x, y) in [
                (a.dr_mm, b.dr_mm),
                (a.da_mm, b.da_mm),
                (a.tc_mm, b.tc_mm),
                (a.rpm, b.rpm),
                (a.fx_n, b.fx_n),
                (a.fy_n, b.fy_n),
                (a.ft_n, b.ft_n),
            ] {
                assert!(same(x, y), "{ctx}: truth {x} vs {y}");
            }
            assert_eq!(a.flutes_intact, b.flutes_intact, "{ctx}");
        }
        assert!(rd.next_row().expect("end").is_none());
    }
}

#[test]
fn header_names_the_kind_and_metadata_the_rate() {
    let text = "# from a test\n# sample_rate_hz = 10000\n# operator = me\n\
                time_s,sync,fx_n,fy_n,extra_column\n0,1,1.5,-2.5,whatever\n";
    let mut rd = TraceReader::new(Cursor::new(text), "t.csv").expect("reads");
    let k = rd.kind();
    assert_eq!(k.feed, FeedSignal::Force);
    assert!(k.two_axis && !k.has_velocity && !k.has_truth);
    assert_eq!(k.spindle, SpindleSignal::None);
    assert_eq!(rd.sample_rate_hz(), Some(10_000.0));
    assert_eq!(rd.metadata()[1], ("operator".to_string(), "me".to_string()));
    let row = rd.next_row().expect("row").expect("one row");
    assert_eq!(row.feed, [1.5, -2.5]);
    assert!(row.sync);
    assert_eq!(row.spindle, 0.0);
}

#[test]
fn sample_rate_from_time_stamps_when_no_metadata() {
    let text = "time_s,sync,feed_x_a,spindle_load_pct\n2,0,1,5\n2.0001,0,1,5\n2.0002,1,1,5\n";
    let mut rd = TraceReader::new(Cursor::new(text), "t.csv").expect("reads");
    assert_eq!(rd.kind().spindle, SpindleSignal::Load);
    assert_eq!(rd.sample_rate_hz(), None, "nothing read yet");
    assert_eq!(
        rd.detect_sample_rate_hz().expect("reads ahead"),
        Some(10_000.0)
    );
    // The rows read ahead still come out, in order.
    let times: Vec<f64> = std::iter::from_fn(|| rd.next_row().expect("row"))
        .map(|r| r.time_s)
        .collect();
    assert_eq!(times, [2.0, 2.0001, 2.0002]);
    // A one-row trace cannot tell.
    let mut one =
        TraceReader::new(Cursor::new("time_s,sync,fx_n,fy_n\n0,0,1,1\n"), "o.csv").expect("reads");
    assert_eq!(one.detect_sample_rate_hz().expect("reads"), None);
}

fn err_of(text: &str) -> String {
    let r = TraceReader::new(Cursor::new(text.to_string()), "bad.csv").and_then(|mut rd| {
        while rd.next_row()?.is_some() {}
        Ok(())
    });
    format!("{:#}", r.expect_err("must fail"))
}

#[test]
fn missing_columns_are_all_named() {
    let msg = err_of("# sample_rate_hz = 1000\nsync,feed_y_a\n");
    assert!(msg.starts_with("bad.csv line 2: missing columns"), "{msg}");
    for c in [
        "`time_s`",
        "`feed_x_a`",
        "`spindle_a` or `spindle_load_pct`",
    ] {
        assert!(msg.contains(c), "{c} not named: {msg}");
    }
    let msg = err_of("time_s,sync,fx_n\n");
    assert!(msg.contains("`fy_n`") && msg.contains("line 1"), "{msg}");
    let msg = err_of("time_s,sync,feed_x_a,spindle_a,feed_vy_mm_min\n");
    assert!(msg.contains("`feed_vx_mm_min`"), "{msg}");
    let msg = err_of("time_s,sync,feed_x_a,fx_n,fy_n,spindle_a\n");
    assert!(msg.contains("both `feed_x_a` and `fx_n`"), "{msg}");
    let msg = err_of("time_s,sync,feed_x_a,spindle_a,sync\n");
    assert!(msg.contains("`sync` appears twice"), "{msg}");
    let msg = err_of("# only comments\n");
    assert!(msg.contains("no header"), "{msg}");
    let msg = err_of("# sample_rate_hz = fast\ntime_s,sync,fx_n,fy_n\n");
    assert!(
        msg.starts_with("bad.csv line 1: sample_rate_hz `fast`"),
        "{msg}"
    );
}

#[test]
fn row_errors_name_file_line_and_column() {
    let head = "# c\ntime_s,sync,feed_x_a,spindle_a,true_dr_mm,true_flutes_intact\n";
    let good = "0,0,1,2,3,15\n";
    let cases = [
        (
            "0,0,abc,2,3,15\n",
            "bad.csv line 4, column `feed_x_a`: `abc` is not a number",
        ),
        (
            "0,0,1,,3,15\n",
            "bad.csv line 4, column `spindle_a`: empty value",
        ),
        ("0,0,1,2\n", "bad.csv line 4: 4 fields, the header has 6"),
        (
            "0,0,1,2,3,15,9\n",
            "bad.csv line 4: 7 fields, the header has 6",
        ),
        (
            "0,2,1,2,3,15\n",
            "bad.csv line 4, column `sync`: `2` is not 0 or 1",
        ),
        (
            "x,0,1,2,3,15\n",
            "bad.csv line 4, column `time_s`: `x` is not a number",
        ),
        (
            "0,0,1,2,3,-1\n",
            "bad.csv line 4, column `true_flutes_intact`: `-1` is not a bitmask",
        ),
        (
            "0,0,1,2,1e,15\n",
            "bad.csv line 4, column `true_dr_mm`: `1e` is not a number",
        ),
    ];
    for (row, want) in cases {
        let msg = err_of(&format!("{head}{good}{row}"));
        assert!(msg.starts_with(want), "row {row:?}: {msg}");
    }
    // Blank lines and CRLF line ends are not errors; the line count still follows the file.
    let text = format!("{head}\r\n{good}\n0,0,1,2,3,15\r\n0,0,x,2,3,15\n");
    let msg = err_of(&text);
    assert!(
        msg.starts_with("bad.csv line 7, column `feed_x_a`"),
        "{msg}"
    );
}

#[test]
fn non_finite_values_pass_through() {
    let text =
        "time_s,sync,feed_x_a,feed_vx_mm_min,spindle_a\n0,1,NaN,inf,-inf\n0.1,0,nan,-INF,1\n";
    let mut rd = TraceReader::new(Cursor::new(text), "t.csv").expect("reads");
    let r = rd.next_row().expect("row").expect("row");
    assert!(r.feed[0].is_nan());
    assert_eq!(r.feed_velocity_mm_min, [f32::INFINITY, 0.0]);
    assert_eq!(r.spindle, f32::NEG_INFINITY);
    let r = rd.next_row().expect("row").expect("row");
    assert!(r.feed[0].is_nan() && r.feed_velocity_mm_min[0] == f32::NEG_INFINITY);
}

#[test]
fn to_sample_carries_every_channel() {
    let text = "time_s,sync,feed_x_a,feed_y_a,spindle_a\n0.5,1,1.25,-0.5,3\n";
    let mut rd = TraceReader::new(Cursor::new(text), "t.csv").expect("reads");
    let s = rd.next_row().expect("row").expect("row").to_sample();
    assert_eq!(s.feed, [1.25, -0.5]);
    assert!(s.sync);
    assert_eq!(s.spindle, 3.0);
    // No velocity columns: NaN, for a nominal-feed config to ignore.
    assert!(s.feed_velocity_mm_min.iter().all(|v| v.is_nan()));
}

#[test]
fn writer_refuses_kinds_the_reader_would() {
    let k = TraceKind {
        feed: FeedSignal::Current,
        two_axis: false,
        has_velocity: true,
        spindle: SpindleSignal::None,
        has_truth: false,
    };
    assert!(TraceWriter::new(Vec::new(), k, 1000.0).is_err());
    let k = TraceKind {
        feed: FeedSignal::Force,
        two_axis: false,
        spindle: SpindleSignal::Current,
        ..k
    };
    assert!(TraceWriter::new(Vec::new(), k, 1000.0).is_err());
    let k = TraceKind {
        two_axis: true,
        ..k
    };
    assert!(TraceWriter::new(Vec::new(), k, f64::NAN).is_err());
    let w = TraceWriter::new(Vec::new(), k, 1000.0).expect("valid");
    let text = String::from_utf8(w.finish().expect("finish")).expect("utf8");
    let header = text.lines().last().expect("header");
    assert_eq!(
        header,
        [
            columns::TIME,
            columns::SYNC,
            columns::FX_N,
            columns::FY_N,
            columns::FEED_VX,
            columns::FEED_VY,
            columns::SPINDLE_A
        ]
        .join(",")
    );
}

#[test]
fn binary_samples_round_trip_and_layout() {
    let text = "# sample_rate_hz = 20000\ntime_s,sync,feed_x_a,feed_vx_mm_min,spindle_a\n\
                0,1,1.5,600,2.25\n0.00005,0,-1,600,NaN\n";
    let mut rd = TraceReader::new(Cursor::new(text), "t.csv").expect("reads");
    let mut out = Vec::new();
    assert_eq!(write_sample_bin(&mut rd, &mut out).expect("writes"), 2);
    assert_eq!(out.len(), 12 + 2 * 24);
    assert_eq!(&out[..4], &SAMPLE_BIN_MAGIC);
    assert_eq!(&out[4..8], &20_000f32.to_le_bytes());
    assert_eq!(&out[8..12], &2u32.to_le_bytes());
    // First sample: feed X, feed Y (0: one axis), vx, vy (0), spindle, sync 1.0.
    let words: Vec<f32> = out[12..36]
        .chunks(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    assert_eq!(words, [1.5, 0.0, 600.0, 0.0, 2.25, 1.0]);
    let (rate, samples) = decode_samples(&out).expect("decodes");
    assert_eq!(rate, 20_000.0);
    assert!(!samples[1].sync && samples[1].spindle.is_nan());
    let again = encode_samples(rate, &samples).expect("encodes");
    assert_eq!(again, out);
    assert!(decode_samples(&out[..out.len() - 1]).is_err());
    assert!(decode_samples(b"TMS2\0\0\0\0\0\0\0\0").is_err());
}
