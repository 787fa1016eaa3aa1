use super::*;
use crate::log::Column;
use std::f64::consts::TAU;

const RATE: f64 = 5000.0;
const F: f64 = 50.0;

/// A motor's row at `t`: 300 V phase voltages, 10 A currents lagging by `lag` rad,
/// positive sequence, a 1 % negative sequence in the currents, a little noise-like
/// harmonic, the shaft at 150 rad/s.
fn row(t: f64, lag: f64) -> Row {
    let w = TAU * F * t;
    let ph = |a: f64, shift: f64, k: usize| a * (w - shift - k as f64 * TAU / 3.0).cos();
    let neg = |k: usize| 0.1 * (-w + k as f64 * TAU / 3.0 + 0.3).cos();
    let harm = |k: usize| 0.2 * (7.0 * w - k as f64 * 7.0 * TAU / 3.0).cos();
    Row {
        t_s: t,
        v_abc: Some([0, 1, 2].map(|k| ph(300.0, 0.0, k) + 3.0 * harm(k))),
        i_abc: [0, 1, 2].map(|k| ph(10.0, lag, k) + neg(k) + harm(k)),
        wm_rad_s: Some(150.0),
        enc_count: None,
        t_winding_c: None,
    }
}

/// A mutation of a row's channels (the schema's column indices of the row: voltages 0..3,
/// currents 3..6, speed 6).
type Mutation = fn(&mut [f64; 7]);
/// A case: its name, the change to a row, and the finding that must name it.
type MutationCase = (&'static str, Mutation, fn(&WiringFault) -> bool);

fn cells(r: &Row) -> [f64; 7] {
    let v = r.v_abc.unwrap_or([0.0; 3]);
    [
        v[0],
        v[1],
        v[2],
        r.i_abc[0],
        r.i_abc[1],
        r.i_abc[2],
        r.wm_rad_s.unwrap_or(0.0),
    ]
}

fn back(r: &Row, x: [f64; 7]) -> Row {
    Row {
        v_abc: r.v_abc.map(|_| [x[0], x[1], x[2]]),
        i_abc: [x[3], x[4], x[5]],
        wm_rad_s: r.wm_rad_s.map(|_| x[6]),
        ..*r
    }
}

/// The cell index of a schema column.
fn index(c: Column) -> usize {
    match c {
        Column::Va => 0,
        Column::Vb => 1,
        Column::Vc => 2,
        Column::Ia => 3,
        Column::Ib => 4,
        Column::Ic => 5,
        _ => 6,
    }
}

/// The check's findings on 2 s of rows, with `lag` and the mutation applied, voltages or
/// not, then the rows with each finding's fix applied as `[columns]` would (every
/// column reads the channel now read as `reads`, its sign turned where `invert`).
fn run(lag: f64, m: Mutation, voltages: bool) -> (Vec<WiringFault>, Vec<WiringFault>) {
    let rows: Vec<Row> = (0..(2.0 * RATE) as usize)
        .map(|k| {
            let r = row(k as f64 / RATE, lag);
            let mut x = cells(&r);
            m(&mut x);
            let r = back(&r, x);
            Row {
                v_abc: r.v_abc.filter(|_| voltages),
                ..r
            }
        })
        .collect();
    let ctx = WiringContext {
        omega_dt: Some(TAU * F / RATE),
        sync_rad_s: 157.0,
    };
    let check = |rows: &[Row]| {
        let mut c = WiringCheck::default();
        for r in rows {
            c.push(r);
        }
        c.findings(&ctx)
    };
    let found = check(&rows);
    let fixed: Vec<Row> = rows
        .iter()
        .map(|r| {
            let mut x = cells(r);
            for f in &found {
                let before = x;
                for fix in f.fix() {
                    let s = if fix.invert { -1.0 } else { 1.0 };
                    x[index(fix.column)] = s * before[index(fix.reads)];
                }
            }
            back(r, x)
        })
        .collect();
    (found, check(&fixed))
}

#[test]
fn a_motor_wired_right_passes_at_every_load() {
    for lag_deg in [5.0f64, 35.0, 60.0, 85.0] {
        let (found, _) = run(lag_deg.to_radians(), |_| {}, true);
        assert!(found.is_empty(), "lag {lag_deg}: {found:?}");
        let (found, _) = run(lag_deg.to_radians(), |_| {}, false);
        assert!(found.is_empty(), "lag {lag_deg}, currents only: {found:?}");
    }
}

#[test]
fn each_mix_up_is_named_with_the_mapping_that_fixes_it() {
    let cases: [MutationCase; 8] = [
        (
            "b and c exchanged in both sets",
            |x| {
                x.swap(1, 2);
                x.swap(4, 5);
            },
            |f| {
                matches!(
                    f,
                    WiringFault::PhaseOrderReversed {
                        shaft_backwards: false,
                        ..
                    }
                )
            },
        ),
        (
            "ib and ic exchanged",
            |x| x.swap(4, 5),
            |f| {
                matches!(
                    f,
                    WiringFault::Exchanged {
                        set: PhaseSet::Currents,
                        first: Column::Ib,
                        second: Column::Ic,
                        ..
                    }
                )
            },
        ),
        (
            "ia and ib exchanged",
            |x| x.swap(3, 4),
            |f| {
                matches!(
                    f,
                    WiringFault::Exchanged {
                        set: PhaseSet::Currents,
                        first: Column::Ia,
                        second: Column::Ib,
                        ..
                    }
                )
            },
        ),
        (
            "va and vc exchanged",
            |x| x.swap(0, 2),
            |f| {
                matches!(
                    f,
                    WiringFault::Exchanged {
                        set: PhaseSet::Voltages,
                        first: Column::Vc,
                        second: Column::Va,
                        ..
                    }
                )
            },
        ),
        (
            "ib reversed",
            |x| x[4] = -x[4],
            |f| {
                matches!(
                    f,
                    WiringFault::Reversed {
                        channel: Column::Ib,
                        ..
                    }
                )
            },
        ),
        (
            "currents rotated",
            |x| x[3..6].rotate_left(1),
            |f| matches!(f, WiringFault::Rotated { .. }),
        ),
        (
            "speed reversed",
            |x| x[6] = -x[6],
            |f| matches!(f, WiringFault::SpeedReversed { .. }),
        ),
        (
            "the motor backwards",
            |x| {
                x.swap(1, 2);
                x.swap(4, 5);
                x[6] = -x[6];
            },
            |f| {
                matches!(
                    f,
                    WiringFault::PhaseOrderReversed {
                        shaft_backwards: true,
                        ..
                    }
                )
            },
        ),
    ];
    for lag_deg in [10.0f64, 40.0, 80.0] {
        for (what, m, expected) in &cases {
            let (found, after) = run(lag_deg.to_radians(), *m, true);
            assert!(
                found.iter().any(expected),
                "{what} at {lag_deg} deg: {found:?}"
            );
            assert!(
                after.is_empty(),
                "{what} at {lag_deg} deg, fixed: {after:?} (was {found:?})"
            );
            assert!(
                found.iter().all(|f| f.sentence().len() <= 160),
                "{:?}",
                found.iter().map(WiringFault::sentence).collect::<Vec<_>>()
            );
        }
    }
}

#[test]
fn without_voltages_the_currents_are_judged_against_the_shaft() {
    let (found, after) = run(0.6, |x| x.swap(4, 5), false);
    assert!(
        matches!(found[..], [WiringFault::CurrentsAgainstShaft { .. }]),
        "{found:?}"
    );
    assert!(after.is_empty(), "{after:?}");
    let (found, after) = run(0.6, |x| x[3] = -x[3], false);
    assert!(
        matches!(
            found[..],
            [WiringFault::Reversed {
                channel: Column::Ia,
                ..
            }]
        ),
        "{found:?}"
    );
    assert!(after.is_empty(), "{after:?}");
}

#[test]
fn a_duplicated_channel_is_named() {
    let (found, _) = run(0.6, |x| x[4] = x[3], true);
    assert!(
        matches!(
            found[..],
            [WiringFault::Duplicated {
                first: Column::Ia,
                second: Column::Ib,
                ..
            }]
        ),
        "{found:?}"
    );
}
