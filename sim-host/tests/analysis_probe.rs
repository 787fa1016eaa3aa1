//! Exploratory probe (ignored): prints the explain ranking for every effect scenario.
mod analysis_common;
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
    let nominal = perturbed(&truth, 0.05);
    let mut list: Vec<Option<&str>> = vec![None];
    for n in sim_host::sim::Effect::NAMES {
        list.push(Some(n));
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

/// Read-speed probe (ignored): `ANALYSIS_BENCH_LOG=... cargo test --test analysis_probe read_speed -- --ignored --nocapture`.
#[test]
#[ignore]
fn read_speed() {
    let path =
        std::env::var("ANALYSIS_BENCH_LOG").unwrap_or("/tmp/sim-host-bench-3600s.csv".into());
    let t = std::time::Instant::now();
    let mut n = 0u64;
    let ok = sim_host::analysis::fastcsv::for_each_row(
        std::path::Path::new(&path),
        &mut |_| {},
        &mut |_| {
            n += 1;
            true
        },
    )
    .unwrap();
    println!(
        "parse only: {n} rows in {:.2} s (fast path {ok})",
        t.elapsed().as_secs_f64()
    );
    let t = std::time::Instant::now();
    let d = sim_host::analysis::prep::decimate_log(
        std::path::Path::new(&path),
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
    let p = sim_host::analysis::prep::frame(&d, &sim_host::params::ParamFile::reference_2p2kw());
    println!(
        "frame: {} samples in {:.2} s",
        p.len(),
        t.elapsed().as_secs_f64()
    );
}
