//! The report framing: a truncated or padded report must not parse as a valid one.

use target_check::{parse_report, write_case, ReportError, BEGIN, END_PREFIX};

fn parse(output: &str) -> Result<Vec<&str>, ReportError> {
    let mut lines = Vec::new();
    parse_report(output, |l| lines.push(l)).map(|n| {
        assert_eq!(n, lines.len());
        lines
    })
}

#[test]
fn case_line_format() {
    let mut s = String::new();
    write_case(&mut s, 12, &[0x3f80_0000, 0x0000_0001]).expect("String");
    assert_eq!(s, "12 3f800000 00000001\n");
}

#[test]
fn framed_report_with_noise_around_it() {
    let out = format!(
        "qemu: warning\r\n{BEGIN}\r\n0 00000000\r\n1 ffffffff\r\n{END_PREFIX}2\r\ntrailing\n"
    );
    assert_eq!(parse(&out), Ok(vec!["0 00000000", "1 ffffffff"]));
}

#[test]
fn truncated_or_miscounted_reports_fail() {
    assert_eq!(parse("0 00000000\n"), Err(ReportError::MissingBegin));
    assert_eq!(
        parse(&format!("{BEGIN}\n0 00000000\n")),
        Err(ReportError::MissingEnd)
    );
    assert_eq!(
        parse(&format!("{BEGIN}\n0 00000000\n{END_PREFIX}2\n")),
        Err(ReportError::CountMismatch {
            announced: 2,
            seen: 1
        })
    );
    assert_eq!(
        parse(&format!("{BEGIN}\n{END_PREFIX}x\n")),
        Err(ReportError::BadEnd)
    );
}

#[test]
fn host_report_is_well_formed() {
    let mut s = String::new();
    target_check::write_report(&mut s).expect("String");
    let lines = parse(&s).expect("own report parses");
    assert!(!lines.is_empty());
}
