//! An inverter-fed motor through the firmware's sampling path (issue 51).
//!
//! The 2.2 kW reference machine is simulated at the board's trigger rate (80 kHz: the
//! 10 kHz sample rate times `drive_monitor::acquisition::OVERSAMPLING`), healthy and with
//! the rotor resistance +50 %, then fed by a two-level PWM inverter switching at 4 and
//! 8 kHz (`monitor_sim::pwm`: the ripple on the voltages and currents, through the front
//! end's 16 kHz single-pole RC). Each trigger's six readings are quantized by the board's
//! front end (`AdcSampler::quantize`, the codes the ADCs deliver), the eight sequences of a
//! sample period averaged by the firmware's own `acquisition::average_half`, scaled by the
//! sampler (`AdcSampler::build`) into the 10 kHz log the board's monitor sees, and that log
//! goes through `diagnose` (`monitor_replay::diagnose_rows`, commissioned on the healthy
//! 2-4 s). The verdict on the inverter-fed log must be the sinusoidal supply's, through the
//! same path. For comparison the acquisition before (one trigger per sample, no average) is
//! run on the same rows, and its residual error is reported.

use drive_monitor::acquisition::{
    sum_half, trigger_rate_hz, PwmFilter, CHANNELS, HALF_LEN, OVERSAMPLING,
};
use drive_monitor::board::{CurrentCode, VoltageCode};
use drive_monitor::motor_source;
use drive_monitor::sampling::RawFrame;
use monitor_core::{Abc, Fault};
use monitor_io::log::{Channels, Row};
use monitor_io::params::ParamFile;
use monitor_replay::{diagnose_rows, DiagnoseReport, ReplayOptions};
use monitor_sim::pwm::{apply_pwm, PwmSpec};
use monitor_sim::{simulate_to_vec, SensorSpec};
use monitor_studies::fault_signatures::{scenario, Protocol};

const FS: u32 = drive_monitor::board::DEFAULT_SAMPLE_RATE_HZ;
/// The voltage front end's full scale for an inverter-fed motor [V]: above the PWM's
/// highest phase-to-neutral level, 2/3 of the DC link (433 V for the 650 V link of a 400 V
/// drive), with room for a braking link's rise (docs/firmware.md, "Inverter-fed motors").
/// The sinusoidal supply goes through the same front end.
const INVERTER_FULL_SCALE_V: f32 = 600.0;
/// The front end's anti-alias corner for an inverter-fed motor [Hz]: 1 kohm and 100 nF
/// (the board's 10 nF gives 16 kHz, enough for a sinusoidal supply). Measured below: with
/// 16 kHz the inverter's components near 80 kHz (the trigger rate, 20 x a 4 kHz carrier)
/// fold onto the fundamental and read the voltage 0.27 % low, which the isolation names as
/// a voltage-sensor gain error.
const INVERTER_FRONT_END_HZ: f64 = 1_591.5;

fn protocol() -> Protocol {
    Protocol {
        sample_rate_hz: f64::from(trigger_rate_hz(FS)),
        ..Protocol::default()
    }
}

/// The machine at the trigger rate, ideal sensors (the board's front end quantizes).
fn rows_at_trigger_rate(p: &ParamFile, fault: Option<(Fault, f64)>) -> Vec<Row> {
    let mut sc = scenario(fault, &protocol());
    sc.sensors = SensorSpec::ideal();
    simulate_to_vec(p, &sc).expect("simulation")
}

fn abc(x: [f64; 3]) -> Abc {
    Abc {
        a: x[0] as f32,
        b: x[1] as f32,
        c: x[2] as f32,
    }
}

/// How the board turns a sample period's triggers into one sample.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Path {
    /// The firmware's: the `OVERSAMPLING` sequences summed, then `PwmFilter`.
    Firmware,
    /// The acquisition before: the period's first trigger alone, unfiltered.
    OneTrigger,
}

/// The log the board's monitor sees through `path`. The speed is the row's at the
/// period's first trigger; the encoder count is not used.
fn board_log(rows: &[Row], path: Path) -> Vec<Row> {
    let mut record = motor_source::default_record();
    record.voltage_full_scale_v = INVERTER_FULL_SCALE_V;
    let mut sampler = *motor_source::sample_path(&record, FS)
        .expect("board path")
        .sampler();
    let mut filter = PwmFilter::new(FS, record.supply.f_hz as f32);
    rows.chunks_exact(OVERSAMPLING)
        .map(|period| {
            let mut v = [0u16; HALF_LEN];
            let mut i = [0u16; HALF_LEN];
            let take = if path == Path::Firmware {
                OVERSAMPLING
            } else {
                1
            };
            for (k, row) in period.iter().take(take).enumerate() {
                let raw = sampler.quantize(abc(row.v_abc.unwrap_or([0.0; 3])), abc(row.i_abc), 0);
                for x in 0..CHANNELS {
                    v[k * CHANNELS + x] = raw.v[x].0;
                    i[k * CHANNELS + x] = raw.i[x].0;
                }
            }
            let n = take * CHANNELS;
            // The firmware's path sums all eight sequences (the filter's input).
            let (vs, _) = sum_half(&v[..n]);
            let (is, _) = sum_half(&i[..n]);
            let ([va, vb, vc], [ia, ib, ic]) = match path {
                Path::Firmware => {
                    let (v, i, _) = filter.step(vs, is, 0);
                    (v, i)
                }
                Path::OneTrigger => (vs.map(|x| x as u16), is.map(|x| x as u16)),
            };
            let raw = RawFrame {
                v: [VoltageCode(va), VoltageCode(vb), VoltageCode(vc)],
                i: [CurrentCode(ia), CurrentCode(ib), CurrentCode(ic)],
                encoder_count: 0,
                clipped: drive_monitor::sampling::Clipped::NONE,
                encoder_rejects: 0,
            };
            let s = sampler.build(&raw);
            let first = &period[0];
            Row {
                t_s: first.t_s,
                v_abc: Some([s.v_abc.a, s.v_abc.b, s.v_abc.c].map(f64::from)),
                i_abc: [s.i_abc.a, s.i_abc.b, s.i_abc.c].map(f64::from),
                wm_rad_s: first.wm_rad_s,
                enc_count: None,
                t_winding_c: None,
            }
        })
        .collect()
}

fn diagnose(p: &ParamFile, log: &[Row]) -> DiagnoseReport {
    let channels = Channels {
        voltages: true,
        speed: true,
        encoder: false,
        temperature: false,
    };
    let opts = ReplayOptions {
        commission: Some(protocol().commission),
        ..ReplayOptions::default()
    };
    diagnose_rows(p, channels, log, opts).expect("diagnose")
}

/// The fundamental phasor (`f_hz`) of phase a's voltage and current over the last second,
/// by a DFT over whole periods [V, A], as (cos, sin) coefficients.
fn fundamental(log: &[Row], f_hz: f64) -> ([f64; 2], [f64; 2]) {
    let n = FS as usize;
    let tail = &log[log.len() - n..];
    let (mut v, mut i) = ([0.0; 2], [0.0; 2]);
    for r in tail {
        let w = std::f64::consts::TAU * f_hz * r.t_s;
        let (c, s) = (w.cos(), w.sin());
        let (va, ia) = (r.v_abc.unwrap()[0], r.i_abc[0]);
        v[0] += 2.0 * va * c / n as f64;
        v[1] += 2.0 * va * s / n as f64;
        i[0] += 2.0 * ia * c / n as f64;
        i[1] += 2.0 * ia * s / n as f64;
    }
    (v, i)
}

/// The relative size of the difference of two phasors.
fn phasor_error(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1]) / b[0].hypot(b[1])
}

/// The done-when of issue 51: healthy and with the rotor resistance +50 %, a 4 kHz and an
/// 8 kHz inverter give the sinusoidal supply's verdict, the same fault named and its size
/// within 2 points, through the firmware's sampling path (oversampling and `PwmFilter`)
/// and `diagnose`. The fundamental the board sees is the sinusoidal supply's within
/// 0.1 %; the acquisition before (one trigger per sample, no filter) is farther off.
/// 4 and 8 kHz (the done-when); `MONITOR_FULL_SWEEPS=1` adds carriers that are no
/// divisor of the trigger rate and 16 kHz.
fn carriers() -> Vec<f64> {
    let mut c = vec![4_000.0, 8_000.0];
    if std::env::var_os("MONITOR_FULL_SWEEPS").is_some() {
        c.extend([4_300.0, 7_700.0, 16_000.0]);
    }
    c
}

#[test]
fn an_inverter_fed_motor_gets_the_sinusoidal_supplys_verdict_through_the_oversampling() {
    let p = ParamFile::reference_2p2kw();
    for fault in [None, Some((Fault::Rr, 0.5))] {
        let rows = rows_at_trigger_rate(&p, fault);
        let sine = board_log(&rows, Path::Firmware);
        let sine_one = board_log(&rows, Path::OneTrigger);
        let reference = diagnose(&p, &sine);
        let (sv, si) = fundamental(&sine, p.supply.f_hz);
        for carrier_hz in carriers() {
            let spec = PwmSpec {
                front_end_cutoff_hz: Some(INVERTER_FRONT_END_HZ),
                ..PwmSpec::for_machine(&p, carrier_hz)
            };
            let pwm = apply_pwm(&rows, &spec).expect("pwm");
            let board = board_log(&pwm, Path::Firmware);
            let report = diagnose(&p, &board);
            let (fv, fi) = fundamental(&board, p.supply.f_hz);
            let (ov, oi) = fundamental(&board_log(&pwm, Path::OneTrigger), p.supply.f_hz);
            let (sov, soi) = fundamental(&sine_one, p.supply.f_hz);
            let (ev, ei) = (phasor_error(fv, sv), phasor_error(fi, si));
            let (eov, eoi) = (phasor_error(ov, sov), phasor_error(oi, soi));
            let change = |r: &DiagnoseReport| r.candidates.first().and_then(|c| c.change);
            eprintln!(
                "{fault:?}, {carrier_hz} Hz: verdict {:?} ({:?} on the sine), named {:?} {:?} ({:?} {:?}); fundamental error v {:.3} %, i {:.3} % (one trigger: {:.3} %, {:.3} %)",
                report.verdict,
                reference.verdict,
                report.isolation.named,
                change(&report),
                reference.isolation.named,
                change(&reference),
                100.0 * ev,
                100.0 * ei,
                100.0 * eov,
                100.0 * eoi
            );
            assert_eq!(
                report.verdict, reference.verdict,
                "{fault:?} {carrier_hz} Hz"
            );
            assert_eq!(
                report.isolation.named, reference.isolation.named,
                "{fault:?} {carrier_hz} Hz"
            );
            assert_eq!(
                report.isolation.state, reference.isolation.state,
                "{fault:?} {carrier_hz} Hz"
            );
            if let (Some(a), Some(b)) = (change(&report), change(&reference)) {
                assert!((a - b).abs() < 0.02, "{a} against {b}");
            }
            assert!(ev < 1e-3 && ei < 1e-3, "{ev} {ei}");
            if carrier_hz <= 8_000.0 {
                assert!(eov > ev, "{eov} {ev}");
            }
        }
    }
}
