//! Issue 86, item 7: the diagnose report's charts a crew can read at a glance. No legend
//! covers data (on the residuals, lamps and rotor charts a legend stood over curves where
//! every corner held some); the residuals chart draws each residual's threshold band, so a
//! crew sees why r1 lit and r2 did not. Over the shipped logs: motulator's example with a
//! commissioning window, the DAQ example, a real recording of shorted turns, and the
//! simulator's Rs fault scenario. About 3 s in the test profile.

use assert_cmd::Command;
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace") // ok: test
        .to_path_buf()
}

/// The SVG charts of `diagnose --report` with `args`.
fn charts(dir: &Path, name: &str, args: &[&str]) -> Vec<String> {
    let out = dir.join(format!("{name}.html"));
    let run = Command::cargo_bin("sim-host")
        .expect("binary") // ok: test
        .current_dir(repo())
        .arg("diagnose")
        .args(args)
        .args(["--report", out.to_str().expect("utf8")]) // ok: test
        .output()
        .expect("runs"); // ok: test
    assert!(
        run.status.success(),
        "{name}: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    let html = std::fs::read_to_string(out).expect("report"); // ok: test
    html.split("<svg")
        .skip(1)
        .map(|s| s.split("</svg>").next().unwrap_or_default().to_string())
        .collect()
}

/// The number after `key="` in `tag`.
fn attr(tag: &str, key: &str) -> Option<f64> {
    let at = tag.find(&format!(" {key}=\""))? + key.len() + 3;
    tag[at..].split('"').next()?.parse().ok()
}

/// The legend's box of a chart (`x, y, width, height` px): plotters draws its background
/// as the one translucent rectangle.
fn legend_box(svg: &str) -> Option<(f64, f64, f64, f64)> {
    svg.split("<rect").skip(1).find_map(|r| {
        let tag = r.split('>').next()?;
        tag.contains("opacity=\"0.85\"").then_some(())?;
        Some((
            attr(tag, "x")?,
            attr(tag, "y")?,
            attr(tag, "width")?,
            attr(tag, "height")?,
        ))
    })
}

/// Points along the chart's data lines (coloured polylines, 11 per segment) inside the
/// legend's box; a polyline wholly inside it is the legend's own key.
fn covered(svg: &str) -> usize {
    let Some((x, y, w, h)) = legend_box(svg) else {
        return 0;
    };
    let inside = |p: (f64, f64)| p.0 > x && p.0 < x + w && p.1 > y && p.1 < y + h;
    let mut n = 0;
    for pl in svg.split("<polyline").skip(1) {
        let tag = pl.split('>').next().unwrap_or_default();
        if tag.contains("stroke=\"#000000\"") {
            continue;
        }
        let pts: Vec<(f64, f64)> = tag
            .split("points=\"")
            .nth(1)
            .unwrap_or_default()
            .split('"')
            .next()
            .unwrap_or_default()
            .split_whitespace()
            .filter_map(|p| {
                let (a, b) = p.split_once(',')?;
                Some((a.parse().ok()?, b.parse().ok()?))
            })
            .collect();
        if pts.iter().all(|p| inside(*p)) {
            continue;
        }
        for seg in pts.windows(2) {
            for k in 0..=10 {
                let f = f64::from(k) / 10.0;
                let p = (
                    seg[0].0 + f * (seg[1].0 - seg[0].0),
                    seg[0].1 + f * (seg[1].1 - seg[0].1),
                );
                n += usize::from(inside(p));
            }
        }
    }
    n
}

#[test]
fn no_legend_covers_data_and_the_residuals_chart_draws_the_thresholds() {
    let dir = tempfile::tempdir().expect("temp dir"); // ok: test
    let d = dir.path();
    let fault = d.join("fault_rs.csv");
    let sim = Command::cargo_bin("sim-host")
        .expect("binary") // ok: test
        .current_dir(repo())
        .args([
            "simulate",
            "--params",
            "examples/params/2p2kw.toml",
            "--scenario",
            "examples/scenarios/fault_rs_2p2kw.toml",
            "--out",
            fault.to_str().expect("utf8"), // ok: test
        ])
        .output()
        .expect("simulates"); // ok: test
    assert!(sim.status.success());
    let runs: [(&str, Vec<&str>, bool); 4] = [
        (
            "motulator",
            vec![
                "--params",
                "examples/logs/motulator_2p2kw_dol.toml",
                "examples/logs/motulator_2p2kw_dol.csv",
                "--commission",
                "1.5:2.4",
            ],
            true,
        ),
        (
            "daq",
            vec![
                "--params",
                "examples/params/daq_2p2kw.toml",
                "examples/logs/daq_2p2kw.csv",
                "--commission",
                "1:6.5",
            ],
            true,
        ),
        (
            "itsc",
            vec![
                "--params",
                "examples/recordings/itsc/baldor_0p75hp.toml",
                "examples/recordings/itsc/SC_A0_B0_C1_001.csv",
            ],
            false,
        ),
        (
            "fault_rs",
            vec![
                "--params",
                "examples/params/2p2kw.toml",
                fault.to_str().expect("utf8"), // ok: test
                "--commission",
                "1.5:4.5",
            ],
            true,
        ),
    ];
    for (name, args, residuals) in runs {
        let svgs = charts(d, name, &args);
        assert!(!svgs.is_empty(), "{name}");
        for (k, svg) in svgs.iter().enumerate() {
            assert_eq!(covered(svg), 0, "{name}, chart {k}: the legend covers data");
        }
        if residuals {
            assert!(
                svgs[0].contains("threshold bands r1..r4 ["),
                "{name}: the residuals chart draws no threshold band"
            );
        }
    }
}
