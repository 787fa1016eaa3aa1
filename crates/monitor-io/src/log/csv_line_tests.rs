//! Tests of [`super`]: the number parser against `str::parse`, the block parser.

use super::*;

#[test]
fn blocks_pick_columns_and_skip_empty_lines() {
    let cols = Cols::new(&[0, 2], 3);
    let mut out = vec![];
    assert!(parse_block(
        b"1,2,3\n4, 5 ,6\r\n\n\r\n7,8,9",
        &cols,
        &mut out
    ));
    assert_eq!(out, vec![1.0, 3.0, 4.0, 6.0, 7.0, 9.0]);
    let mut out = vec![];
    assert!(!parse_block(b"1,2\n", &cols, &mut out));
    assert!(!parse_block(b"1,2,3,4\n", &cols, &mut out));
    assert!(!parse_block(b"1,x,y\n", &cols, &mut out));
    assert!(!parse_block(b"1,2,3x\n", &cols, &mut out));
    assert!(!parse_block(b"1,2,\"3\"\n", &cols, &mut out));
}

#[test]
fn line_ends_and_skipped_columns() {
    let cols = Cols::new(&[0, 1], 3);
    let mut out = vec![];
    assert!(parse_block(b"1,2,a\r\n3,4,b\n5,6,c\r", &cols, &mut out));
    assert_eq!(out, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    let cols = Cols::new(&[1, 2], 3);
    let mut out = vec![];
    assert!(parse_block(
        b"x,1,2\r\ny,3, 4 \r\n\r\nz,5,6",
        &cols,
        &mut out
    ));
    assert_eq!(out, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    assert!(!parse_block(b"x,1,2\rz,5,6", &cols, &mut out));
    assert!(!parse_block(b"x,1,2 3\n", &cols, &mut out));
    assert!(!parse_block(b"   \n", &cols, &mut out));
}

#[test]
fn eight_digits_at_a_time() {
    let word = |s: &[u8]| {
        let mut a = [b'x'; 8];
        a[..s.len()].copy_from_slice(s);
        u64::from_le_bytes(a)
    };
    assert_eq!(leading_digits(word(b"12345678")), 8);
    assert_eq!(leading_digits(word(b"1234,678")), 4);
    assert_eq!(leading_digits(word(b",2345678")), 0);
    assert_eq!(leading_digits(word(b"9/:0")), 1);
    assert_eq!(leading_digits(word(b"09.1")), 2);
    assert_eq!(digits_value(word(b"12345678"), 8), 12_345_678);
    assert_eq!(digits_value(word(b"90210,5"), 5), 90_210);
    assert_eq!(digits_value(word(b"7"), 1), 7);
    assert_eq!(digits_value(word(b"00000009"), 8), 9);
    let (mut w, mut n) = (0, 0);
    let s = b"1234567890123,5";
    assert_eq!(digit_run(s, 0, &mut w, &mut n), 13);
    assert_eq!((w, n), (1_234_567_890_123, 13));
}

#[test]
fn parses_like_std() {
    let cols = Cols::new(&[0], 1);
    for s in [
        "0",
        "-0",
        "1.5",
        "326.5986",
        "-163.2993",
        "5.072449e-09",
        "1e3",
        "+2.5E+2",
        "0.0001",
        "0.00030000000000000003",
        "12345678901234567890",
        "1.",
        ".5",
        "inf",
        "-infinity",
        " 2.5 \r",
    ] {
        let mut out = vec![];
        assert!(parse_block(s.as_bytes(), &cols, &mut out), "{s}");
        let b: f64 = s.trim().parse().unwrap();
        assert_eq!(out[0].to_bits(), b.to_bits(), "{s}");
    }
    for s in ["-", "abc", "1.2.3", "1e", "1,2", "1 2"] {
        let mut out = vec![];
        assert!(!parse_block(s.as_bytes(), &cols, &mut out), "{s}");
        assert!(s.parse::<f64>().is_err(), "{s}");
    }
}

/// The plain-decimal path gives `fast_float2`'s value and length, or leaves the text
/// to it: every printed f32 and f64 (shortest round trip, as the log writer prints),
/// fixed and scientific forms, and text around the path's limits.
#[test]
fn plain_decimals_parse_like_fast_float() {
    let same = |s: &str| {
        let want = fast_float2::parse_partial::<f64, _>(s.as_bytes()).ok();
        let got = parse_number(s.as_bytes());
        assert_eq!(
            got.map(|(v, k)| (v.to_bits(), k)),
            want.map(|(v, k)| (v.to_bits(), k)),
            "{s}"
        );
        if let Some((v, k)) = parse_plain(s.as_bytes()) {
            assert_eq!(
                (v.to_bits(), k),
                want.map(|(v, k)| (v.to_bits(), k)).unwrap(),
                "{s}"
            );
        }
    };
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut plain = 0;
    for k in 0..200_000 {
        // xorshift: bit patterns of every magnitude, then ordinary values.
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        let v = if k % 2 == 0 {
            f64::from_bits(x)
        } else {
            ((x >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 10f64.powi(k % 13 - 6)
        };
        if !v.is_finite() {
            continue;
        }
        let f = v as f32;
        for s in [
            format!("{v}"),
            format!("{v:e}"),
            format!("{f}"),
            format!("{f:e}"),
            format!("{f:E}"),
            format!("{:.3}", f),
            format!("{}", (v * 1e4).round() / 1e4),
        ] {
            same(&s);
            plain += usize::from(parse_plain(s.as_bytes()).is_some());
        }
    }
    assert!(plain > 500_000, "the plain path took only {plain} numbers");
    for s in [
        "0",
        "-0",
        "+0",
        "-0.0",
        "1.",
        ".5",
        "-.5",
        "+.5e1",
        "1e22",
        "1e23",
        "1e-22",
        "1e-23",
        "9007199254740992",
        "9007199254740993",
        "9007199254740992e-3",
        "1234567890123456789",
        "12345678901234567890",
        "0.00030000000000000003",
        "1e",
        "1e+",
        "1e-",
        "1E5",
        "1e0005",
        "1e00005",
        "1e99999",
        "2.5e-308",
        "-",
        "+",
        ".",
        "-.",
        "e5",
        ".e5",
        "inf",
        "-infinity",
        "NaN",
        "1.5x",
        "1..5",
        "1.5e3,2",
        "326.5986,1",
        "0.0001\r\n",
        "1,2",
        "1 2",
        "000000000000000000001",
        "0000000000000000001.5",
        "4.9406564584124654e-324",
        "1.7976931348623157e308",
        "6.408294e-9",
        "0.0000012402029",
        "-163.67188",
    ] {
        same(s);
    }
}
