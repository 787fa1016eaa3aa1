//! `monitor_io::nameplate::estimate` against six machines, 0.37 kW to 50 hp (five
//! published): each nameplate is computed here, at rated power, from the machine's published
//! T-equivalent circuit by the textbook steady-state model below (independent of the
//! simulator and of `monitor_io::nameplate`), rounded as a nameplate prints it, and the
//! estimate must give Rs, Rr, the total leakage Lls + Llr and Lm within 35 % of the
//! circuit's. Also: the refusals name the field. (The command, `params from-nameplate`: its
//! written TOML loads, its refusals name the option, its help: `sim-host/tests/cli/nameplate.rs`.)

use monitor_io::nameplate::{estimate, Connection, Nameplate, NemaDesign};
use nalgebra::Complex;
use std::f64::consts::{PI, TAU};

/// A published machine: per-phase star-equivalent T-circuit, reactances at the rated
/// frequency [ohm].
struct Machine {
    name: &'static str,
    p_kw: f64,
    v_ll: f64,
    f_hz: f64,
    poles: u32,
    rs: f64,
    rr: f64,
    xls: f64,
    xlr: f64,
    xm: f64,
}

const W50: f64 = 2.0 * PI * 50.0;

/// A 4-pole machine from its T-circuit `[rs, rr, xls, xlr, xm]` (ohm at `f_hz`).
fn machine(name: &'static str, p_kw: f64, v_ll: f64, f_hz: f64, t: [f64; 5]) -> Machine {
    let [rs, rr, xls, xlr, xm] = t;
    Machine {
        name,
        p_kw,
        v_ll,
        f_hz,
        poles: 4,
        rs,
        rr,
        xls,
        xlr,
        xm,
    }
}

/// A machine of Krause et al.'s table: 60 Hz, Xls = Xlr (ohm at 60 Hz).
fn krause(name: &'static str, hp: f64, v_ll: f64, rs: f64, xl: f64, xm: f64, rr: f64) -> Machine {
    machine(name, hp * 0.7457, v_ll, 60.0, [rs, rr, xl, xl, xm])
}

/// A Simscape preset as the Modelica Buildings library transcribes it: 400 V, 50 Hz,
/// Ls = Lr, Lm [H].
fn simscape(name: &'static str, p_kw: f64, rs: f64, rr: f64, ls: f64, lm: f64) -> Machine {
    let (xl, xm) = (W50 * (ls - lm), W50 * lm);
    machine(name, p_kw, 400.0, 50.0, [rs, rr, xl, xl, xm])
}

/// The six machines, 0.37 kW to 50 hp, all 4-pole.
fn machines() -> [Machine; 6] {
    [
        // A 0.37 kW, 400 V, 50 Hz machine (71 frame) made for this test, not a published
        // circuit: per-unit values typical of the size (base 400 V, 0.7 kVA: Rs 0.13 pu,
        // Rr 0.11 pu, Xls = Xlr 0.07 pu, Xm 1.1 pu). At 370 W its circuit gives 1375 rpm,
        // 1.05 A, power factor 0.69, efficiency 0.736 (no iron or friction loss), close to
        // catalogue 0.37 kW motors (1370-1400 rpm, 1.0-1.1 A, 0.70-0.75).
        machine(
            "small 0.37 kW",
            0.37,
            400.0,
            50.0,
            [30.0, 24.0, 16.0, 16.0, 260.0],
        ),
        // motulator (Aalto University's open-source drive simulator), its 2.2 kW, 400 V,
        // 50 Hz induction machine (nominal 5 A, 14.6 N m), inverse-Gamma parameters
        // R_s = 3.7, R_R = 2.1 ohm, L_sgm = 0.021, L_M = 0.224 H: the leakage all on the
        // stator side, Llr = 0.
        machine(
            "motulator 2.2 kW",
            2.2,
            400.0,
            50.0,
            [3.7, 2.1, W50 * 0.021, 0.0, W50 * 0.224],
        ),
        // Krause, Wasynczuk and Sudhoff, Analysis of Electric Machinery and Drive Systems:
        // the 3 hp, 220 V machine.
        krause("Krause 3 hp", 3.0, 220.0, 0.435, 0.754, 26.13, 0.816),
        // MATLAB/Simscape Electrical's asynchronous machine preset "4 kW, 400 V, 50 Hz,
        // 1430 rpm", as transcribed in the Modelica Buildings library (LBNL),
        // InductionMotors.Data.IM_5HP_400V_50Hz.
        simscape("Simscape 4 kW", 4.0, 1.405, 1.395, 0.178039, 0.1722),
        // The same library's IM_20HP_400V_50Hz (Simscape's 15 kW, 400 V, 50 Hz preset).
        simscape("Simscape 15 kW", 15.0, 0.2147, 0.2205, 0.065181, 0.06419),
        // Krause et al.'s 50 hp, 460 V machine.
        krause("Krause 50 hp", 50.0, 460.0, 0.087, 0.302, 13.08, 0.228),
    ]
}

/// The textbook steady state of the T-circuit at slip `s` (Fitzgerald, Kingsley and
/// Umans, Electric Machinery, ch. 6): `Z = Rs + j Xls + j Xm || (Rr/s + j Xlr)`, the
/// stator current `I = V_ph / Z`, the rotor current by the current divider, the shaft
/// power `3 I2^2 Rr (1 - s)/s` (no friction). Returns (I [A], power factor, P_in [W],
/// P_shaft [W]).
fn steady(m: &Machine, s: f64) -> (f64, f64, f64, f64) {
    let v = Complex::new(m.v_ll / 3f64.sqrt(), 0.0);
    let zm = Complex::new(0.0, m.xm);
    let zr = Complex::new(m.rr / s, m.xlr);
    let z = Complex::new(m.rs, m.xls) + zm * zr / (zm + zr);
    let i = v / z;
    let i2 = i * zm / (zm + zr);
    let p_in = 3.0 * (v * i.conj()).re;
    let p_shaft = 3.0 * i2.norm_sqr() * m.rr * (1.0 - s) / s;
    (
        i.norm(),
        (v * i.conj()).re / (v.norm() * i.norm()),
        p_in,
        p_shaft,
    )
}

/// Locked-rotor current over rated current of the circuit, to one decimal.
fn locked_rotor_ratio(m: &Machine, i_rated: f64) -> f64 {
    let (i_lr, ..) = steady(m, 1.0);
    (10.0 * i_lr / i_rated).round() / 10.0
}

/// Rounds to `d` significant digits.
fn sig(x: f64, d: i32) -> f64 {
    let k = 10f64.powi(d - 1 - x.abs().log10().floor() as i32);
    (x * k).round() / k
}

/// The machine's nameplate at rated power (the slip where the shaft gives P, by
/// bisection), rounded as nameplates print it: current to 3 digits, power factor to 0.01,
/// efficiency to 0.001 (a percentage with one decimal), speed to 1 rpm.
fn nameplate(m: &Machine, with_locked_rotor_ratio: bool) -> Nameplate {
    let (mut lo, mut hi) = (1e-5, 0.3);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if steady(m, mid).3 < 1000.0 * m.p_kw {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let s = 0.5 * (lo + hi);
    let (i, pf, p_in, _) = steady(m, s);
    let n_sync = 120.0 * m.f_hz / f64::from(m.poles);
    Nameplate {
        power_kw: m.p_kw,
        voltage_v: m.v_ll,
        current_a: sig(i, 3),
        frequency_hz: m.f_hz,
        speed_rpm: (n_sync * (1.0 - s)).round(),
        power_factor: (100.0 * pf).round() / 100.0,
        efficiency: (1000.0 * 1000.0 * m.p_kw / p_in).round() / 1000.0,
        poles: None,
        connection: Connection::Star,
        locked_rotor_ratio: with_locked_rotor_ratio.then(|| locked_rotor_ratio(m, i)),
        design: NemaDesign::B,
    }
}

/// Relative errors of the estimate (Rs, Rr, Lls + Llr, Lm), and whether each true value
/// lies in the estimate's stated range.
fn errors(m: &Machine, with_ratio: bool) -> ([f64; 4], [bool; 4]) {
    let n = nameplate(m, with_ratio);
    let e = estimate(&n).unwrap_or_else(|err| panic!("{}: {err}", m.name));
    assert_eq!(e.poles, m.poles, "{}: poles inferred", m.name);
    let w = TAU * m.f_hz;
    let truth = [m.rs, m.rr, (m.xls + m.xlr) / w, m.xm / w];
    let keys = [
        "motor.rs_ohm",
        "motor.rr_ohm",
        "lls_h + llr_h",
        "motor.lm_h",
    ];
    let mut err = [0.0; 4];
    let mut inside = [false; 4];
    for (k, key) in keys.iter().enumerate() {
        let v = e.value(key).expect(key);
        err[k] = v.value / truth[k] - 1.0;
        inside[k] = v.lo <= truth[k] && truth[k] <= v.hi;
    }
    (err, inside)
}

fn table(with_ratio: bool) -> Vec<(&'static str, [f64; 4], [bool; 4])> {
    let rows: Vec<_> = machines()
        .iter()
        .map(|m| {
            let (e, inside) = errors(m, with_ratio);
            (m.name, e, inside)
        })
        .collect();
    eprintln!(
        "{} IA/IN: machine | Rs | Rr | Lls+Llr | Lm (error; * = true value outside the stated range)",
        if with_ratio { "with" } else { "without" }
    );
    for (name, e, inside) in &rows {
        let cell = |k: usize| format!("{:+.1} %{}", 100.0 * e[k], if inside[k] { "" } else { "*" });
        eprintln!(
            "{name} | {} | {} | {} | {}",
            cell(0),
            cell(1),
            cell(2),
            cell(3)
        );
    }
    rows
}

#[test]
fn six_machines_within_35_percent_with_the_locked_rotor_ratio() {
    for (name, e, inside) in table(true) {
        for (k, what) in ["Rs", "Rr", "Lls + Llr", "Lm"].iter().enumerate() {
            assert!(
                e[k].abs() <= 0.35,
                "{name}: {what} off by {:+.1} %",
                100.0 * e[k]
            );
            assert!(inside[k], "{name}: true {what} outside the stated range");
        }
    }
}

/// A nameplate is a guaranteed value, and the motor on the bench differs from it within IEC
/// 60034-1's tolerances (efficiency: 15 % of the losses; power factor: a sixth of
/// `1 - cos phi`). With the plate's efficiency and power factor moved to the ends of those
/// tolerances (each way, with IA/IN), every true value stays inside the stated range, and
/// the table says how far Rs moves (it takes the losses' remainder).
#[test]
fn plates_off_by_the_iec_tolerances_keep_every_true_value_in_its_range() {
    let mut worst_rs: f64 = 0.0;
    let mut outside = Vec::new();
    for m in machines() {
        let base = nameplate(&m, true);
        let d_eta = 0.15 * (1.0 - base.efficiency);
        let d_pf = ((1.0 - base.power_factor) / 6.0).clamp(0.02, 0.07);
        for (de, dp) in [(-d_eta, 0.0), (d_eta, 0.0), (0.0, -d_pf), (0.0, d_pf)] {
            let mut n = base;
            n.efficiency = base.efficiency + de;
            n.power_factor = (base.power_factor + dp).min(0.99);
            let Ok(e) = estimate(&n) else {
                // (A plate the tolerances make impossible, such as an efficiency above
                // 1 - slip, is refused, which is right.)
                continue;
            };
            let w = TAU * m.f_hz;
            let truth = [m.rs, m.rr, (m.xls + m.xlr) / w, m.xm / w];
            for (key, t) in [
                "motor.rs_ohm",
                "motor.rr_ohm",
                "lls_h + llr_h",
                "motor.lm_h",
            ]
            .iter()
            .zip(truth)
            {
                let v = e.value(key).expect(key);
                if key == &"motor.rs_ohm" {
                    worst_rs = worst_rs.max((v.value / t - 1.0).abs());
                }
                if !(v.lo <= t && t <= v.hi) {
                    outside.push(format!(
                        "{} eta {:+.3} pf {:+.3}: {key} true {t:.4} outside {:.4}..{:.4} (estimate {:.4})",
                        m.name, de, dp, v.lo, v.hi, v.value
                    ));
                }
            }
        }
    }
    eprintln!(
        "plates off by the IEC tolerances: Rs off by up to {:.0} %",
        100.0 * worst_rs
    );
    assert!(outside.is_empty(), "{outside:#?}");
}

#[test]
fn without_the_locked_rotor_ratio_only_the_leakage_of_an_atypical_machine_misses() {
    // The total leakage is then the typical 0.12 Z_b. The 15 kW preset's is 0.069 Z_b
    // (its locked-rotor current is 11.9 x rated, where catalogues give 6..8): the one
    // value beyond 35 %, still inside the stated range.
    for (name, e, inside) in table(false) {
        for (k, what) in ["Rs", "Rr", "Lls + Llr", "Lm"].iter().enumerate() {
            let atypical = name == "Simscape 15 kW" && k == 2;
            assert!(
                atypical || e[k].abs() <= 0.35,
                "{name}: {what} off by {:+.1} %",
                100.0 * e[k]
            );
            assert!(inside[k], "{name}: true {what} outside the stated range");
        }
    }
}

/// A nameplate that is fine: the small 0.37 kW machine's (the first of [`machines`]).
fn good() -> Nameplate {
    nameplate(&machines()[0], false)
}

/// The message of refusing `n`: one line, starting with the field's name (the library's
/// words; the command line says `--efficiency`, as `sim-host/tests/cli/nameplate.rs` checks).
fn refused(n: Nameplate, field: &str) -> String {
    let e = estimate(&n).expect_err("refused").to_string();
    assert!(e.starts_with(field), "{field}: {e}");
    assert!(!e.contains('\n'), "{e}");
    e
}

#[test]
fn nameplates_no_induction_motor_can_have_are_refused_naming_the_option() {
    assert!(estimate(&good()).is_ok());
    for eta in [1.2, 1.0, 0.0, -0.5, f64::NAN] {
        refused(
            Nameplate {
                efficiency: eta,
                ..good()
            },
            "efficiency",
        );
    }
    for pf in [1.3, 1.0, 0.0, f64::INFINITY] {
        refused(
            Nameplate {
                power_factor: pf,
                ..good()
            },
            "power_factor",
        );
    }
    // At and above synchronous speed (1500 rpm for 4 poles at 50 Hz), and above a 2-pole
    // motor's when the poles are inferred.
    for rpm in [1500.0, 1600.0] {
        let e = refused(
            Nameplate {
                speed_rpm: rpm,
                poles: Some(4),
                ..good()
            },
            "speed_rpm",
        );
        assert!(e.contains("synchronous"), "{e}");
    }
    refused(
        Nameplate {
            speed_rpm: 3100.0,
            ..good()
        },
        "speed_rpm",
    );
    // 1000 rpm at 50 Hz: 6 poles would be synchronous, 4 poles a slip of 33 %.
    let e = refused(
        Nameplate {
            speed_rpm: 1000.0,
            ..good()
        },
        "speed_rpm",
    );
    assert!(e.ends_with("give poles"), "{e}");
    refused(
        Nameplate {
            poles: Some(5),
            ..good()
        },
        "poles",
    );
    // 10 rpm at 50 Hz would be a 598-pole machine.
    refused(
        Nameplate {
            speed_rpm: 10.0,
            ..good()
        },
        "speed_rpm",
    );
    for (field, n) in [
        (
            "power_kw",
            Nameplate {
                power_kw: -2.2,
                ..good()
            },
        ),
        (
            "current_a",
            Nameplate {
                current_a: f64::NAN,
                ..good()
            },
        ),
        (
            "voltage_v",
            Nameplate {
                voltage_v: 0.0,
                ..good()
            },
        ),
        (
            "frequency_hz",
            Nameplate {
                frequency_hz: 5000.0,
                ..good()
            },
        ),
    ] {
        refused(n, field);
    }
    // Output power 10x the electrical input sqrt3 V I pf eta (kW typed for W, or the wrong
    // voltage's current).
    let e = refused(
        Nameplate {
            power_kw: 22.0,
            ..good()
        },
        "power_kw",
    );
    assert!(e.contains("current_a") && e.contains("ratio"), "{e}");
    // An efficiency the slip forbids: the rotor copper loss alone is slip x air-gap power.
    let n = good();
    let slip = 1.0 - n.speed_rpm / 1500.0;
    let e = refused(
        Nameplate {
            efficiency: 1.005 - slip,
            power_factor: n.power_factor * n.efficiency / (1.005 - slip),
            ..n
        },
        "efficiency",
    );
    assert!(e.contains("slip"), "{e}");
}
