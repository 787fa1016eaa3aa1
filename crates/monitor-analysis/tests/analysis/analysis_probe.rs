//! Exploratory probe (ignored): prints the explain ranking for every effect scenario.
use crate::analysis_common;
use analysis_common::*;

#[test]
#[ignore]
fn probe() {
    let which = std::env::var("MOTOR").unwrap_or("2p2".into());
    let only = std::env::var("EFFECT").ok();
    let noise: u32 = std::env::var("NOISE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let dir = tempfile::tempdir().unwrap();
    let truth = motor(&which);
    let off: f64 = std::env::var("OFF")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0.05);
    let nominal = perturbed(&truth, off);
    // EFFECT=sweep: the V/f sweep scenario with no effect (what the model alone leaves).
    if std::env::var("EFFECT").as_deref() == Ok("sweep") {
        let keep = std::env::var("KEEP").ok();
        let mut s = scenario(&which, Some(keep.as_deref().unwrap_or("windage")), noise);
        if keep.is_none() {
            s.effects.clear();
        }
        let log = write_log(dir.path(), "sweep", &truth, &s, false);
        let a = analyse(&log, &nominal, settle_s(&which));
        let base_env = std::env::var("BASE").unwrap_or_default();
        let base: Vec<&str> = base_env.split(',').filter(|s| !s.is_empty()).collect();
        if let Ok(g) = std::env::var("TRUTH_G") {
            use monitor_analysis::simplified_model::{
                simulate, BaseParams, Dynamics, Magnetising, ModelTerms,
            };
            let n = &a.constants;
            let g: f64 = g.parse().unwrap();
            let xm = 2.0 * std::f64::consts::PI * nominal.supply.f_hz * nominal.motor.lm_h;
            let t = ModelTerms {
                magnetising: Magnetising {
                    core_loss_s: if g > 0.0 { 1.0 / (g * xm) } else { 0.0 },
                    ..Default::default()
                },
                dynamics: Dynamics {
                    rotor_flux_tau_s: Some(n.lr_h / n.rr_ohm),
                    stator_current_la_h: Some(n.la_h),
                    ..Default::default()
                },
                ..Default::default()
            };
            let p = simulate(&a.data, n, &BaseParams::nominal(n), &t);
            let e = monitor_analysis::metrics::errors(&a.data, &p, None);
            println!(
                "truth model (Rfe = {g} Xm): error {:.4}",
                e.normalized_rms_error
            );
            if let Ok(dump) = std::env::var("DUMP") {
                dump_csv(&dump, &a, &p);
            }
            for ch in &e.channels {
                println!("   {ch:?}");
            }
        }
        let out = a.compare(&opts(&base)).unwrap();
        if std::env::var("TRUTH_G").is_err() {
            if let Ok(dump) = std::env::var("DUMP") {
                dump_csv(&dump, &a, &out.prediction);
            }
        }
        let c = out.report;
        println!(
            "sweep, no effect: error {:.4} noise {:.4}",
            c.normalized_rms_error, c.noise_floor
        );
        for ch in &c.channels {
            println!("   {ch:?}");
        }
        for w in &c.worst_windows {
            println!("   {w:?}");
        }
        println!("   base {:?}", c.base_parameters);
        return;
    }
    let mut list: Vec<Option<&str>> = vec![None];
    for n in monitor_core::EffectKind::ALL {
        list.push(Some(n.name()));
    }
    for e in list {
        if let Some(o) = &only {
            if e.unwrap_or("none") != o {
                continue;
            }
        }
        let s = scenario(&which, e, noise);
        let log = write_log(dir.path(), e.unwrap_or("none"), &truth, &s, false);
        let from = settle_s(&which);
        let a = analyse(&log, &nominal, from);
        let t = std::time::Instant::now();
        let base_env = std::env::var("BASE").unwrap_or_default();
        let base: Vec<&str> = base_env
            .split(',')
            .filter(|s| !s.is_empty() && Some(*s) != e)
            .collect();
        let out = a.explain(&opts(&base), &|_| {}).unwrap();
        let r = &out.report;
        println!(
            "== {:?} base {:.4} noise {:.4} unexpl {} ({:.1}s)",
            e,
            r.baseline_normalized_rms_error,
            r.noise_floor,
            r.unexplained,
            t.elapsed().as_secs_f64()
        );
        for c in r.ranking.iter().take(4) {
            println!(
                "   {:<18} {:.4} val {:.4} expl {:.2}  {}",
                c.effect,
                c.normalized_rms_error,
                c.validation_normalized_rms_error,
                c.explained_fraction,
                c.summary
            );
        }
        if let Some(top) = e {
            let mut with = base.clone();
            with.push(top);
            let c = a.compare(&opts(&with)).unwrap();
            let b = a.compare(&opts(&base)).unwrap();
            println!("   compare base: {:.4}", b.report.normalized_rms_error);
            println!(
                "   compare --effects {top}: {:.4}",
                c.report.normalized_rms_error
            );
        }
    }
}

/// Read-speed probe (ignored): `ANALYSIS_BENCH_LOG=... cargo test -p monitor-analysis --test analysis analysis_probe::read_speed -- --ignored --nocapture`.
#[test]
#[ignore]
fn read_speed() {
    let path =
        std::env::var("ANALYSIS_BENCH_LOG").unwrap_or("/tmp/sim-host-bench-3600s.csv".into());
    let t = std::time::Instant::now();
    /// Counts rows.
    struct Count(u64);
    impl monitor_io::log::RowSink for Count {
        fn row(&mut self, _: &monitor_io::log::Row) -> bool {
            self.0 += 1;
            true
        }
        fn restart(&mut self) {
            self.0 = 0;
        }
    }
    let file = monitor_io::log::LogFile::open(std::path::Path::new(&path)).unwrap();
    let mut n = Count(0);
    file.for_each_row(&mut |_| {}, &mut n).unwrap();
    println!(
        "parse only: {} rows in {:.2} s",
        n.0,
        t.elapsed().as_secs_f64()
    );
    let t = std::time::Instant::now();
    let params = monitor_io::params::ParamFile::reference_2p2kw();
    let (d, _) = monitor_analysis::prep::decimate_log(
        std::path::Path::new(&path),
        &params,
        Default::default(),
        &mut |_| {},
    )
    .unwrap();
    println!(
        "decimate: {} samples in {:.2} s",
        d.t_s.len(),
        t.elapsed().as_secs_f64()
    );
    let t = std::time::Instant::now();
    let p = monitor_analysis::prep::voltage_model_flux_frame(&d, &params);
    println!(
        "frame: {} samples in {:.2} s",
        p.len(),
        t.elapsed().as_secs_f64()
    );
}

fn dump_csv(
    path: &str,
    a: &monitor_analysis::Analysis,
    pr: &monitor_analysis::simplified_model::Prediction,
) {
    use std::io::Write;
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let d = &a.data;
    writeln!(f, "t,w,wp,iq,iqp,vq,vd,id,i_f,ws,iq_all,ineg,ire,iim,th").unwrap();
    for k in 0..d.len() {
        writeln!(
            f,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            d.t_s[k],
            d.omega_r[k],
            pr.omega_r[k],
            d.iq_pos[k],
            pr.iq[k],
            d.vq[k],
            d.vd[k],
            d.id[k],
            d.i_f[k],
            d.omega_s[k],
            d.iq[k],
            d.i_neg[k].norm(),
            d.i_ab[k].re,
            d.i_ab[k].im,
            d.theta[k]
        )
        .unwrap();
    }
}
