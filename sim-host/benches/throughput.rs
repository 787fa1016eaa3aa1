//! Simulator throughput on the reference scenario (2.2 kW machine started
//! direct-on-line, 14.6 N m load torque from 2.5 s, 10 s at 10 kHz, ideal sensors):
//! one iteration = 10 simulated seconds, so simulated s per wall s = 10 / time.
//! Also the same run with the default (noisy, quantised) sensor chain.
//!
//! `CARGO_TARGET_DIR=... cargo bench -p sim-host --bench throughput`.
//! (`sim-host bench` reports the same figure plus CSV writing and accuracy.)

// criterion_group! generates an undocumented public function.
#![allow(missing_docs)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use monitor_io::params::ParamFile;
use monitor_sim::{simulate, Scenario, SensorSpec};

fn reference(c: &mut Criterion) {
    let p = ParamFile::reference_2p2kw();
    let sc = Scenario::reference_2p2kw();
    let mut g = c.benchmark_group("simulator");
    g.sample_size(10);
    g.bench_function("reference_10s_ideal_sensors", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            simulate(&p, &sc, |r| acc += r.i_abc[0]).unwrap();
            black_box(acc)
        })
    });
    let noisy = Scenario {
        sensors: SensorSpec::default(),
        ..sc.clone()
    };
    g.bench_function("reference_10s_adc_noise", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            simulate(&p, &noisy, |r| acc += r.i_abc[0]).unwrap();
            black_box(acc)
        })
    });
    g.finish();
}

criterion_group!(benches, reference);
criterion_main!(benches);
