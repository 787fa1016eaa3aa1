//! Shared helpers of the analysis tests: the scenarios and logs of
//! `monitor_testkit::analysis_common` (re-exported; the full sweeps are described there),
//! and the analysis run on a log through the library.
#![allow(dead_code, missing_docs, unused_imports)]

pub use monitor_testkit::analysis_common::*;

use monitor_analysis::{prep::ReadOptions, Analysis, Options};
use monitor_core::EffectKind;
use monitor_io::params::ParamFile;
use std::path::Path;

pub fn analyse(log: &Path, p: &ParamFile, from: f64) -> Analysis {
    let opts = ReadOptions {
        from_s: from,
        to_s: f64::INFINITY,
    };
    Analysis::load(log, *p, opts, &mut |_| {}).expect("load")
}

pub fn opts(effects: &[&str]) -> Options {
    Options {
        effects: effects
            .iter()
            .map(|s| EffectKind::from_name(s).expect("library name").into())
            .collect(),
        fit_base: true,
        laws: Default::default(),
    }
}
