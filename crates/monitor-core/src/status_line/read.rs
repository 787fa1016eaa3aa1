//! The status line read back: [`parse`] of one line of the decoder's output.

use crate::verdict::Verdict;
use crate::{Fault, Phase};

/// The fields of one status line as read; `None` where the line does not have the field
/// (an older firmware's line) or it does not read.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StatusReading<'a> {
    /// The decoder's timestamp [s], when it printed one (the line's first word).
    pub timestamp_s: Option<f64>,
    /// `r=`: the normalised residuals r1..r4.
    pub residuals: [f32; 4],
    /// `lamps=`: the residual lamps.
    pub lamps: [bool; 4],
    /// `fault=`: a lamp or a sensor fault.
    pub fault: bool,
    /// `call=`: the decision table's verdict on the board (older firmware's `clear` and
    /// `not-commissioned` read as healthy and could not judge).
    pub call: Option<Verdict>,
    /// `top=`, `2nd=`: the two most probable candidates (`none` or a probability of 0: `None`).
    pub candidates: [Option<(Fault, f32)>; 2],
    /// `wm=`: the shaft speed [rad/s].
    pub speed_rad_s: Option<f32>,
    /// `zc_locked=`: the zero-crossing detector's lock (`Some(None)`: other angle sources).
    pub zero_crossing_locked: Option<Option<bool>>,
    /// `mode=`: the panel's mode.
    pub mode: Option<&'a str>,
    /// `run=`: the latest commissioning run's id, blocks learned and needed.
    pub run: Option<(u16, u32, u32)>,
    /// `overruns=`.
    pub overruns: Option<u32>,
    /// `restarts=`.
    pub restarts: Option<u32>,
    /// `samples=`.
    pub samples: Option<u32>,
    /// `max_cyc=` [CPU cycles].
    pub max_update_cycles: Option<u32>,
    /// `iqs=` [A].
    pub iqs_a: Option<f32>,
    /// `ids=` [A].
    pub ids_a: Option<f32>,
    /// `vqs=` [V].
    pub vqs_v: Option<f32>,
    /// `f=`: the frame (supply) frequency [Hz].
    pub frame_hz: Option<f32>,
    /// `steady=`.
    pub quasi_steady: Option<bool>,
    /// `eval=`.
    pub evaluating: Option<bool>,
    /// `sens=`: current, voltage, speed.
    pub sensors: Option<[bool; 3]>,
    /// `mid=` and `half=`: the threshold bands' centres and half-widths.
    pub band: Option<([f32; 4], [f32; 4])>,
    /// `iso=` with `iso_change=` and `iso_p=` (0 where absent): the name the isolation
    /// gives, its change and its probability.
    pub isolation: Option<(&'a str, f32, f32)>,
    /// `wind=` with `wind_i2=` (0 where absent): the phase of shorted turns and the
    /// winding's part of |I2/I1|; `None` for `wind=none`.
    pub winding: Option<(Phase, f32)>,
    /// `moved=`.
    pub moved: Option<bool>,
    /// `rise=` [K].
    pub winding_rise_k: Option<f32>,
    /// `vdda=` [V].
    pub vdda_v: Option<f32>,
    /// `bor=`.
    pub bor: Option<u8>,
    /// `clip=`: clipped samples since boot (firmware of issue 74 on).
    pub clipped: Option<u32>,
    /// `enc_rej=`: rejected encoder counts since boot (firmware of issue 74 on).
    pub encoder_rejects: Option<u32>,
    /// `stack=` [bytes]: the stack's high-water mark (firmware of issue 74 on).
    pub stack_used_bytes: Option<u32>,
    /// `clip_range=`: clipping persists in steady running, the front end's range is too
    /// small for the motor (firmware of issue 74 on).
    pub clip_range: Option<bool>,
}

/// The value of field `key` in `line` (`key=` at the start or after a space), up to the
/// next field (a `[..]` list whole); `None` when absent.
fn field<'a>(line: &'a str, key: &str) -> Option<&'a str> {
    let mut from = 0;
    while let Some(k) = line.get(from..).and_then(|rest| rest.find(key)) {
        let at = from + k;
        let before = line.get(..at).unwrap_or("");
        let after = line.get(at + key.len()..).unwrap_or("");
        if let Some(rest) = after.strip_prefix('=') {
            if at == 0 || before.ends_with(' ') {
                let end = if rest.starts_with('[') {
                    rest.find(']').map_or(rest.len(), |e| e + 1)
                } else {
                    rest.find(char::is_whitespace).unwrap_or(rest.len())
                };
                return rest.get(..end);
            }
        }
        from = at + key.len();
    }
    None
}

/// A number with a unit suffix (`151.2rad/s`, `4.1A`).
fn number(v: &str) -> Option<f32> {
    let end = v
        .find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e' | 'E')))
        .unwrap_or(v.len());
    v.get(..end)?.parse().ok()
}

/// Exactly `N` values parsed from the comma-separated `items` (items that do not parse are
/// left out).
fn parsed<T: core::str::FromStr + Copy + Default, const N: usize>(items: &str) -> Option<[T; N]> {
    let mut out = [T::default(); N];
    let mut n = 0;
    for x in items.split(',').filter_map(|s| s.trim().parse().ok()) {
        *out.get_mut(n)? = x;
        n += 1;
    }
    (n == N).then_some(out)
}

/// A `[a, b, c, d]` list of four values.
fn four<T: core::str::FromStr + Copy + Default>(v: &str) -> Option<[T; 4]> {
    parsed(v.strip_prefix('[')?.strip_suffix(']')?)
}

/// `name(p)`: a candidate; `None` for `none` or a probability of 0.
fn candidate(v: &str) -> Option<(Fault, f32)> {
    let (name, p) = v.split_once('(')?;
    let f = Fault::from_name(name)?;
    let p = number(p)?;
    (p > 0.0).then_some((f, p))
}

/// `ID:LEARNED/NEEDED`.
fn run(v: &str) -> Option<(u16, u32, u32)> {
    let (id, rest) = v.split_once(':')?;
    let (l, n) = rest.split_once('/')?;
    Some((id.parse().ok()?, l.parse().ok()?, n.parse().ok()?))
}

/// `None`, `Some(true)`, `Some(false)`.
fn optional_bool(v: &str) -> Option<Option<bool>> {
    match v {
        "None" => Some(None),
        _ => Some(Some(
            v.strip_prefix("Some(")?.strip_suffix(')')?.parse().ok()?,
        )),
    }
}

/// The verdict of a `call=` field: the decision table's names, and the names of older
/// firmware's one rule (`clear`, `not-commissioned`).
fn call_of(name: &str) -> Option<Verdict> {
    match name {
        "clear" => Some(Verdict::Healthy),
        "not-commissioned" => Some(Verdict::CouldNotJudge),
        other => Verdict::from_name(other),
    }
}

/// Parses one line of the decoder's output (without terminal colours); `None` when it is
/// not a status line (module docs).
pub fn parse(line: &str) -> Option<StatusReading<'_>> {
    let line = line.trim();
    let f = |k| field(line, k).and_then(number);
    let b = |k| field(line, k).and_then(|v| v.parse::<bool>().ok());
    let u = |k| field(line, k).and_then(|v| v.parse::<u32>().ok());
    Some(StatusReading {
        timestamp_s: line
            .split_whitespace()
            .next()
            .and_then(|t| t.parse::<f64>().ok()),
        residuals: four(field(line, "r")?)?,
        lamps: four(field(line, "lamps")?)?,
        fault: field(line, "fault")?.parse().ok()?,
        call: field(line, "call").and_then(call_of),
        candidates: ["top", "2nd"].map(|k| field(line, k).and_then(candidate)),
        speed_rad_s: f("wm"),
        zero_crossing_locked: field(line, "zc_locked").and_then(optional_bool),
        mode: field(line, "mode"),
        run: field(line, "run").and_then(run),
        overruns: u("overruns"),
        restarts: u("restarts"),
        samples: u("samples"),
        max_update_cycles: u("max_cyc"),
        iqs_a: f("iqs"),
        ids_a: f("ids"),
        vqs_v: f("vqs"),
        frame_hz: f("f"),
        quasi_steady: b("steady"),
        evaluating: b("eval"),
        sensors: field(line, "sens").and_then(parsed),
        band: field(line, "mid")
            .and_then(four)
            .zip(field(line, "half").and_then(four)),
        isolation: field(line, "iso").map(|named| {
            let change = f("iso_change").unwrap_or(0.0);
            (named, change, f("iso_p").unwrap_or(0.0))
        }),
        winding: field(line, "wind")
            .and_then(Phase::from_name)
            .map(|p| (p, f("wind_i2").unwrap_or(0.0))),
        moved: b("moved"),
        winding_rise_k: f("rise"),
        vdda_v: f("vdda"),
        bor: field(line, "bor").and_then(|v| v.parse().ok()),
        clipped: u("clip"),
        encoder_rejects: u("enc_rej"),
        stack_used_bytes: field(line, "stack")
            .and_then(|v| v.strip_suffix('B'))
            .and_then(|v| v.parse().ok()),
        clip_range: b("clip_range"),
    })
}

#[cfg(test)]
mod tests {
    use super::super::StatusLine;
    use super::*;

    /// A line with a value in every field, none of them a default.
    fn line() -> StatusLine<'static> {
        StatusLine {
            residuals: [0.0123, -0.1, 0.25, -0.004],
            lamps: [false, true, true, true],
            fault: true,
            call: "fault",
            top: ("b", 0.5),
            second: ("bl", 0.5),
            speed_rad_s: 150.5,
            zero_crossing_locked: Some(true),
            mode: "commissioned",
            run: (2, 4000, 4000),
            overruns: 3,
            restarts: 1,
            samples: 123_456,
            max_update_cycles: 2310,
            iqs_a: 4.25,
            ids_a: 2.5,
            vqs_v: 320.5,
            frame_hz: 50.02,
            quasi_steady: true,
            evaluating: true,
            sensors: (false, true, false),
            mid: [0.001, -0.01, 0.009, 0.0],
            half: [0.006, 0.011, 0.012, 0.007],
            isolation: ("rr", 0.48, 0.93),
            winding: ("b", 0.041),
            moved: true,
            winding_rise_k: 54.4,
            vdda_v: 3.301,
            bor: 4,
            clipped: 17,
            encoder_rejects: 3,
            stack_used_bytes: 2_344,
            clip_range: true,
        }
    }

    #[test]
    fn every_field_written_reads_back() {
        let w = line();
        // As probe-rs prints it: a timestamp and the level before the message.
        let text = format!("0.250000 INFO  {w}");
        let r = parse(&text).unwrap_or_else(|| panic!("not read: {text}"));
        assert_eq!(r.timestamp_s, Some(0.25));
        assert_eq!(
            (r.residuals, r.lamps, r.fault),
            (w.residuals, w.lamps, w.fault)
        );
        assert_eq!(r.call, Some(Verdict::Fault));
        assert_eq!(
            r.candidates,
            [Some((Fault::B, 0.5)), Some((Fault::Bl, 0.5))]
        );
        assert_eq!(r.speed_rad_s, Some(150.5));
        assert_eq!(r.zero_crossing_locked, Some(Some(true)));
        assert_eq!(
            (r.mode, r.run),
            (Some("commissioned"), Some((2, 4000, 4000)))
        );
        assert_eq!(
            (r.overruns, r.restarts, r.samples, r.max_update_cycles),
            (Some(3), Some(1), Some(123_456), Some(2310))
        );
        assert_eq!(
            (r.iqs_a, r.ids_a, r.vqs_v, r.frame_hz),
            (Some(4.25), Some(2.5), Some(320.5), Some(50.02))
        );
        assert_eq!((r.quasi_steady, r.evaluating), (Some(true), Some(true)));
        assert_eq!(r.sensors, Some([false, true, false]));
        assert_eq!(r.band, Some((w.mid, w.half)));
        assert_eq!(r.isolation, Some(("rr", 0.48, 0.93)));
        assert_eq!(r.winding, Some((Phase::B, 0.041)));
        assert_eq!((r.moved, r.winding_rise_k), (Some(true), Some(54.4)));
        assert_eq!((r.vdda_v, r.bor), (Some(3.301), Some(4)));
        assert_eq!(
            (r.clipped, r.encoder_rejects, r.stack_used_bytes),
            (Some(17), Some(3), Some(2_344))
        );
        assert_eq!(r.clip_range, Some(true));
    }

    #[test]
    fn the_text_writer_follows_the_format() {
        let text = format!("{}", line());
        let mut words = text.split(' ');
        for token in super::super::FORMAT.split(' ') {
            // A list's own spaces: skip the value's words up to the one with the key.
            let key = token.split_once('=').map_or(token, |(k, _)| k);
            assert!(
                words.any(|w| w.split_once('=').is_some_and(|(k, _)| k == key)),
                "{key}= not written in {text}"
            );
        }
        assert!(text.starts_with("r=[0.0123, -0.1, 0.25, -0.004] lamps=[false, true, true, true] fault=true call=fault top=b(0.5) 2nd=bl(0.5) wm=150.5rad/s zc_locked=Some(true) "));
        assert!(
            text.ends_with(
                " moved=true rise=54.4K vdda=3.301V bor=4 clip=17 enc_rej=3 stack=2344B clip_range=true"
            ),
            "{text}"
        );
    }

    #[test]
    fn an_older_line_reads_with_its_fields_absent() {
        let l = "INFO  r=[0.1, 0.2, 0.3, 0.4] lamps=[false, false, false, false] fault=false top=none(0.0) 2nd=none(0.0) wm=150.0rad/s mode=commissioning run=3:1000/4000 call=clear";
        let r = parse(l).expect("a status line");
        assert_eq!(r.run, Some((3, 1000, 4000)));
        assert_eq!(r.candidates, [None, None]);
        assert_eq!((r.iqs_a, r.band, r.isolation), (None, None, None));
        assert_eq!(r.call, Some(Verdict::Healthy));
        // A line of the firmware before issue 74: its new fields absent, the rest read.
        let before = "INFO  r=[0.1, 0.2, 0.3, 0.4] lamps=[false, false, false, false] fault=false call=healthy moved=false rise=0.0K vdda=3.3V bor=4";
        let r = parse(before).expect("a status line");
        assert_eq!((r.vdda_v, r.bor), (Some(3.3), Some(4)));
        assert_eq!(
            (
                r.clipped,
                r.encoder_rejects,
                r.stack_used_bytes,
                r.clip_range
            ),
            (None, None, None, None)
        );
        for other in [
            "INFO  sampling at 10000 Hz",
            "└─ drive_monitor::firmware::log_status @ src/firmware.rs:545",
            "r=[0.1, 0.2] lamps=[false] fault=false",
            "",
        ] {
            assert!(parse(other).is_none(), "{other}");
        }
    }
}
