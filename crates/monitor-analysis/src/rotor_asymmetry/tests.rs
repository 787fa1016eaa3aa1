//! Tests of the MCSA report (sidebands, steady stretches, what cannot be judged).

use super::*;

/// A log that ends in a step (the last 0.2 s block's slip is off the final quarter's
/// median): no steady stretch, "cannot judge", not an index past the end (found on a
/// 1 kHz, 11 kW log with a start, V/f steps and a dip, where `explain` panicked).
#[test]
fn a_log_that_ends_in_a_step_cannot_be_judged() {
    let n = 1000;
    let slip = |k: usize| if k < n - 100 { 0.03 } else { 0.06 };
    let d = Prepared {
        t_s: (0..n).map(|k| k as f64 * 1e-3).collect(),
        dt_s: 1e-3,
        omega_s: vec![314.0; n],
        omega_r: (0..n).map(|k| 314.0 * (1.0 - slip(k))).collect(),
        ..Default::default()
    };
    let r = mcsa(&d, 2.0, None, None);
    assert!(!r.judged);
    let why = r.cannot_judge_because.unwrap_or_default();
    assert!(why.contains("not steady at the end"), "{why}");
}

#[test]
fn a_long_steady_log_is_read_over_its_last_stretch_only() {
    // 700 s at 200 Hz, 2 % slip at 50 Hz: sidebands 2 s f = 2 Hz off, the (1 - 2s) f one
    // at -40 dB. The whole log is steady; only its last MAX_STRETCH_S are read, and the
    // level is still right.
    let (dt, n) = (1.0 / 200.0, 140_000);
    let (f1, s) = (50.0, 0.02);
    let w = 2.0 * PI * f1;
    let d = Prepared {
        t_s: (0..n).map(|k| k as f64 * dt).collect(),
        dt_s: dt,
        omega_s: vec![w; n],
        omega_r: vec![w * (1.0 - s); n],
        i_ab: (0..n)
            .map(|k| {
                let t = k as f64 * dt;
                let a =
                    10.0 * (w * t).cos() + 0.1 * (2.0 * PI * (1.0 - 2.0 * s) * f1 * t + 0.5).cos();
                super::super::prep::C64::new(a, 0.0)
            })
            .collect(),
        ..Default::default()
    };
    let r = mcsa(&d, 2.0, None, None);
    assert!(r.judged, "{:?}", r.cannot_judge_because);
    let (t_a, t_end) = (r.window_s[0], r.window_s[1]);
    assert!(
        ((t_end - t_a) - MAX_STRETCH_S).abs() < 2.0 * dt,
        "{t_a}..{t_end}"
    );
    let lo = r.lower_sideband_db.unwrap_or(0.0);
    assert!((lo + 40.0).abs() < 0.5, "{lo}");
    assert!((r.resolution_hz.unwrap_or(1.0) - 1.0 / MAX_STRETCH_S).abs() < 1e-4);
}

#[test]
fn half_length_spectrum_is_the_full_complex_one() {
    // Odd length, an offset and two tones: against a full-length complex FFT.
    let dt = 1e-3;
    let x: Vec<f64> = (0..1001)
        .map(|k| {
            let t = k as f64 * dt;
            3.0 + (2.0 * PI * 50.0 * t).sin() + 0.01 * (2.0 * PI * 47.3 * t).cos()
        })
        .collect();
    let (df, amp) = spectrum(&mut rustfft::FftPlanner::new(), &x, dt, f64::INFINITY);
    let n = x.len();
    let nfft = (4 * n).next_power_of_two();
    let mean = x.iter().sum::<f64>() / n as f64;
    // 4-term Blackman-Harris (Harris 1978, table I).
    let w = |k: usize| {
        let x = 2.0 * PI * k as f64 / n as f64;
        0.35875 - 0.48829 * x.cos() + 0.14128 * (2.0 * x).cos() - 0.01168 * (3.0 * x).cos()
    };
    let wsum: f64 = (0..n).map(w).sum();
    let mut buf = vec![Complex::new(0.0, 0.0); nfft];
    for k in 0..n {
        buf[k] = Complex::new((x[k] - mean) * w(k), 0.0);
    }
    rustfft::FftPlanner::new()
        .plan_fft_forward(nfft)
        .process(&mut buf);
    assert_eq!(amp.len(), nfft / 2);
    assert!((df - 1.0 / (nfft as f64 * dt)).abs() < 1e-15);
    for k in 0..nfft / 2 {
        let want = 2.0 * buf[k].norm() / wsum;
        assert!(
            (amp[k] - want).abs() < 1e-12,
            "bin {k}: {} vs {want}",
            amp[k]
        );
    }
    // Asked for 60 Hz, it stops just above.
    let (_, short) = spectrum(&mut rustfft::FftPlanner::new(), &x, dt, 60.0);
    assert!(short.len() as f64 * df >= 60.0 && short.len() < nfft / 2);
    assert_eq!(short[..], amp[..short.len()]);
}

#[test]
fn the_resolution_rule_keeps_the_search_clear_of_the_main_lobe() {
    // Leakage of a tone 4.2 bins off (between bins, 4x padded) below -90 dB; a tone
    // 80 dB down 5 bins off read within 0.5 dB.
    let (dt, n) = (1e-3, 2000);
    let x: Vec<f64> = (0..n)
        .map(|k| {
            let t = k as f64 * dt;
            (2.0 * PI * 50.3 * t).cos() + 1e-4 * (2.0 * PI * 52.8 * t).cos()
        })
        .collect();
    let (df, amp) = spectrum(&mut rustfft::FftPlanner::new(), &x, dt, 100.0);
    let (_, a1) = peak(df, &amp, 50.3, 0.3);
    let (_, a2) = peak(df, &amp, 52.8, 0.5);
    let far = peak(df, &amp, 48.0, 0.2).1;
    assert!(20.0 * (far / a1).log10() < -90.0, "{far}");
    assert!((20.0 * (a2 / a1).log10() + 80.0).abs() < 0.5, "{a2}");
}

#[test]
fn spectral_delta_inverts_the_backward_current_relation() {
    // n broken bars of N: r = n / (N - 2n) of the torque current, split between the
    // two sidebands; the delta it gives is Kliman's 3n / (N - 3n).
    for (n, nb, q, split) in [(1.0, 28.0, 0.8, 0.7), (2.0, 40.0, 0.6, 0.9)] {
        let r = n / (nb - 2.0 * n);
        let db = |x: f64| 20.0 * (x * q).log10();
        let d = spectral_delta(db(split * r), db((1.0 - split) * r), q).unwrap();
        assert!((d - 3.0 * n / (nb - 3.0 * n)).abs() < 1e-9, "{d}");
    }
    assert!(spectral_delta(-3.0, -3.0, 0.5).is_none());
    assert!(fit_and_spectrum_agree(0.2, 0.15) && !fit_and_spectrum_agree(0.2, 0.05));
    assert!(!fit_and_spectrum_agree(0.01, 1e-5));
}

#[test]
fn spectrum_reads_a_sideband_level() {
    // 60 Hz of amplitude 10 and 56 Hz of amplitude 0.1: -40 dB.
    let dt = 1.0 / 2000.0;
    let x: Vec<f64> = (0..20000)
        .map(|k| {
            let t = k as f64 * dt;
            10.0 * (2.0 * PI * 60.0 * t).cos() + 0.1 * (2.0 * PI * 56.0 * t + 1.0).cos()
        })
        .collect();
    let (df, amp) = spectrum(&mut rustfft::FftPlanner::new(), &x, dt, f64::INFINITY);
    let (f, a) = peak(df, &amp, 60.0, 1.0);
    let (fl, al) = peak(df, &amp, 56.0, 0.8);
    assert!((f - 60.0).abs() < df && (fl - 56.0).abs() < df, "{f} {fl}");
    assert!((a - 10.0).abs() < 0.1, "{a}");
    assert!((20.0 * (al / a).log10() + 40.0).abs() < 0.3, "{al}");
}
