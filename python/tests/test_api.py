"""The package against the command line: the same documents, from files and from data in
memory; every error class with the command's message."""

import json
import re
import subprocess

import numpy as np
import pandas as pd
import pyarrow as pa
import pytest

import drive_monitor as dm
from conftest import cli_json, in_python_words

MOTULATOR = "examples/logs/motulator_2p2kw_dol.csv"
MOTULATOR_P = "examples/logs/motulator_2p2kw_dol.toml"
ITSC = "examples/recordings/itsc"


def test_diagnose_is_the_commands_document(repo, sim_host):
    r = dm.diagnose(repo / MOTULATOR, repo / MOTULATOR_P, commission=(1.5, 2.4))
    cli = cli_json(sim_host, "diagnose", "--params", MOTULATOR_P, MOTULATOR, "--commission", "1.5:2.4")
    assert r.to_dict() == cli
    assert r.verdict == cli["verdict"]
    assert r.isolation.events[0].event == cli["isolation"]["events"][0]["event"]
    # The time series as DataFrames.
    tl = r.timeline
    assert isinstance(tl, pd.DataFrame) and len(tl) == len(cli["timeline"])
    assert {"t_s", "r1", "r4", "lamp_r2"} <= set(tl.columns)


def test_a_dataframe_a_table_and_arrays_give_the_files_document(repo):
    path = repo / MOTULATOR
    from_file = dm.diagnose(path, repo / MOTULATOR_P, commission=(1.5, 2.4)).to_dict()
    frame = pd.read_csv(path)
    for data in (frame, pa.Table.from_pandas(frame), {c: frame[c].to_numpy() for c in frame.columns}):
        got = dm.diagnose(data, repo / MOTULATOR_P, commission=(1.5, 2.4)).to_dict()
        assert got == from_file


def test_params_as_a_dict_and_a_daq_log_through_its_columns(repo, sim_host):
    import tomllib

    p = tomllib.loads((repo / "examples/params/daq_2p2kw.toml").read_text())
    r = dm.diagnose(repo / "examples/logs/daq_2p2kw.csv", p, commission=(1.0, 6.5))
    cli = cli_json(sim_host, "diagnose", "--params", "examples/params/daq_2p2kw.toml",
                   "examples/logs/daq_2p2kw.csv", "--commission", "1:6.5")
    assert r.to_dict() == cli
    assert r.verdict == "healthy"


def test_real_recordings_with_a_baseline(repo):
    r = dm.diagnose(repo / ITSC / "SC_A0_B0_C1_001.csv", repo / ITSC / "baldor_0p75hp.toml",
                    baseline=[repo / ITSC / "SC_HLT_001.csv", repo / ITSC / "SC_HLT_002.csv"])
    assert r.unbalance.suspect_phase == "c"
    assert r.verdict == "fault"
    assert len(r.segments) == 2
    # One verdict: the finding it rests on names the phase, with a confidence of 0.5 or
    # more, and the line says what it was judged against.
    f = r.verdict_finding
    assert (f.source, f.fault, f.phase) == ("winding", "shorted_turns", "c")
    assert f.confidence >= 0.5
    assert r.verdict_line.startswith("FAULT shorted turns in phase c") and "healthy runs" in r.verdict_line


def test_the_verdict_line_is_the_commands_and_the_findings_a_frame(repo, sim_host):
    r = dm.diagnose(repo / MOTULATOR, repo / MOTULATOR_P, commission=(1.5, 2.4))
    text = subprocess.run(
        [sim_host, "diagnose", "--params", MOTULATOR_P, MOTULATOR, "--commission", "1.5:2.4"],
        cwd=repo, capture_output=True, text=True, check=True,
    ).stdout
    # The command wraps a long line at 160 characters, continuation lines indented by four
    # spaces: joined again, the verdict's line is the library's.
    assert f"verdict: {r.verdict_line}" in re.sub(r"\n    (?=\S)", " ", text).splitlines()
    frame = r.findings_frame
    assert set(frame["source"]) == {"residuals", "winding", "rotor", "operating_point",
                                    "parameter_fit", "data_quality"}
    # A healthy verdict says what was judged, and nothing it rests on is a named fault.
    assert r.verdict == "healthy" and r.verdict_line.startswith("healthy: ")
    assert not (frame["state"] == "named").any()


def test_compare_explain_identify_nameplate(repo, sim_host):
    c = dm.compare(repo / MOTULATOR, repo / MOTULATOR_P, from_s=0.8, effects=["load_torque"])
    cli = cli_json(sim_host, "compare", "--params", MOTULATOR_P, MOTULATOR, "--from", "0.8",
                   "--effects", "load_torque")
    # The same document; the load step moves the light shaft fast, so its advice adds the
    # machine's dynamics and names Python's keyword where the command names its flag.
    dyn = "load_torque,flux_dynamics,current_dynamics,d_axis_dynamics,cross_coupling_dynamics"
    assert c.to_dict() == in_python_words(cli, {f"--effects {dyn}": f"effects={dyn.split(',')}"})
    assert c.normalized_rms_error < 0.05
    # Where the error lives, as the command line says it: the lines each with their
    # frequency and reading, the same words.
    assert c.leftover.summary[0].startswith("leftover: ")
    lines = c.leftover_lines
    assert list(lines.columns[:2]) == ["frequency_hz", "reading"]
    assert len(lines) == len(cli["leftover"]["lines"])
    e = dm.explain(repo / MOTULATOR, repo / MOTULATOR_P, from_s=0.8)
    assert e.ranking[0].effect == "load_torque"
    # The same document; its advice names Python's keyword where the command names its flag.
    cli = cli_json(sim_host, "explain", "--params", MOTULATOR_P, MOTULATOR, "--from", "0.8")
    assert "Add it with effects=['load_torque']" in e.verdict
    assert e.to_dict() == in_python_words(cli, {"--effects load_torque": "effects=['load_torque']",
                                                "effects or --from)": "effects or from_s=...)"})
    n = dm.params_from_nameplate(2.2, 400, 4.8, 50, 1438, 0.77, 0.863,
                                 columns_from=repo / "examples/params/daq_2p2kw.toml")
    assert n.poles == 4 and "[columns]" in n.toml
    i = dm.identify(repo / "examples/logs/daq_2p2kw.csv", n.params)
    assert i.identification.relative_rms_error < 0.01
    rs = [x for x in i.identification.estimates if x.key == "rs_ohm"][0]
    assert abs(rs.value / 3.7 - 1) < 0.03
    # As `sim-host identify`: the DAQ's [columns] only when asked to keep them.
    assert "[columns]" not in i.toml
    kept = dm.identify(repo / "examples/logs/daq_2p2kw.csv", n.params, keep_columns=True)
    assert "[columns]" in kept.toml


def test_explain_ladder_matches_the_cli(repo, sim_host):
    # The motulator log past its start (load step at 2.5 s): the ladder adds the load torque
    # the paper's viscous load cannot follow, the whole-log error falls at every step.
    lad = dm.explain(repo / MOTULATOR, repo / MOTULATOR_P, from_s=0.8, ladder=True)
    assert lad.to_dict() == cli_json(sim_host, "explain", "--ladder", "--params", MOTULATOR_P,
                                     MOTULATOR, "--from", "0.8")
    assert "load_torque" in lad.final_effects
    errors = [lad.start.error] + [s.error for s in lad.ladder]
    assert all(b < a for a, b in zip(errors, errors[1:])), errors
    assert errors[-1] < errors[0] / 5
    frame = lad.ladder_frame
    assert list(frame["step"]) == list(range(len(errors)))
    assert lad.stop in {"noise_floor", "nothing_helps", "library_exhausted"}


def test_the_reports_advice_is_in_pythons_words(repo, sim_host):
    # Without commissioning the report advises it: as the keyword argument to pass, where
    # the command line names its flag; nothing in the document names a flag.
    r = dm.diagnose(repo / MOTULATOR, repo / MOTULATOR_P)
    advice = r.to_dict()["commissioning"]["advice"]
    assert "commission (commission='START:END')" in advice, advice
    assert not re.search(r"--[a-z]", json.dumps(r.to_dict())), advice
    cli = cli_json(sim_host, "diagnose", "--params", MOTULATOR_P, MOTULATOR)
    assert "commission (--commission START:END)" in cli["commissioning"]["advice"]
    assert r.to_dict() == in_python_words(cli, {"--commission START:END": "commission='START:END'"})


def test_simulate_returns_the_schema(repo):
    frame = dm.simulate(repo / "examples/params/3hp.toml",
                        "duration_s = 0.5\nsample_rate_hz = 2000.0\nseed = 1\n")
    assert list(frame.columns[:7]) == ["t_s", "va_V", "vb_V", "vc_V", "ia_A", "ib_A", "ic_A"]
    assert len(frame) == 1000


@pytest.mark.parametrize(
    "call, error, says",
    [
        (lambda r: dm.diagnose(r / MOTULATOR, r / "nosuch.toml"), dm.ParamsError, "nosuch.toml"),
        (lambda r: dm.diagnose(r / MOTULATOR, {"motor": {"rs_ohm": 1.0}}), dm.ParamsError, "missing"),
        (lambda r: dm.diagnose(r / "nosuch.csv", r / MOTULATOR_P), dm.LogError, "nosuch.csv"),
        (lambda r: dm.diagnose({"t_s": np.zeros(3)}, r / MOTULATOR_P), dm.LogError, "ia_A"),
        (lambda r: dm.diagnose(r / MOTULATOR, r / MOTULATOR_P, commission=(3.0, 2.0)), dm.OptionError, "commission = 3:2"),
        (lambda r: dm.diagnose(r / MOTULATOR, r / MOTULATOR_P, commission="4:x"), dm.OptionError, "commission = 4:x"),
        # The one check of every front end: a step of 0 is refused (not clamped), as on
        # the command line, and parallel paths are 1..=8.
        (lambda r: dm.diagnose(r / MOTULATOR, r / MOTULATOR_P, timeline_step=0), dm.OptionError, "timeline_step = 0"),
        (lambda r: dm.diagnose(r / MOTULATOR, r / MOTULATOR_P, parallel_paths=0), dm.OptionError, "parallel_paths = 0"),
        (lambda r: dm.diagnose(r / MOTULATOR, r / MOTULATOR_P, load="heavy"), dm.OptionError, "load"),
        (lambda r: dm.compare(r / MOTULATOR, r / MOTULATOR_P, from_s=4.99), dm.OptionError, "at least"),
        (lambda r: dm.identify(r / ITSC / "SC_HLT_001.csv", r / ITSC / "baldor_0p75hp.toml"), dm.OptionError, "identify"),
    ],
)
def test_every_error_class_carries_the_commands_message(repo, call, error, says):
    with pytest.raises(error) as e:
        call(repo)
    assert isinstance(e.value, dm.DriveMonitorError)
    msg = str(e.value)
    assert says in msg and "\n" not in msg, msg


def test_the_gil_is_released(repo):
    """Two threads run two diagnoses in about the time of one (the GIL released)."""
    import threading
    import time

    def one():
        dm.diagnose(repo / MOTULATOR, repo / MOTULATOR_P)

    t0 = time.perf_counter()
    one()
    single = time.perf_counter() - t0
    t0 = time.perf_counter()
    ts = [threading.Thread(target=one) for _ in range(2)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    both = time.perf_counter() - t0
    # With the GIL held, two would take twice as long; allow the machine's noise.
    assert both < 1.8 * single + 0.05, (single, both)


def test_the_shorted_turn_level_from_the_model_and_from_a_calibration(repo, sim_host):
    # 30 % of phase c's turns shorted, a double-star winding: the model's level is the
    # command's, in the result, the verdict's size and its unit.
    log, p = repo / ITSC / "SC_A0_B0_C3_001.csv", repo / ITSC / "baldor_0p75hp.toml"
    r = dm.diagnose(log, p, parallel_paths=2)
    cli = cli_json(sim_host, "diagnose", "--params", str(p), str(log), "--parallel-paths", "2")
    assert r.to_dict() == in_python_words(cli, {"--commission START:END": "commission='START:END'"})
    t = r.shorted_turns
    assert t["phase"] == "c" and t["basis"] == "physics"
    assert t["low"] <= t["fraction"] <= t["high"]
    assert 0.15 <= t["fraction"] <= 0.35  # within one step of the truth, 30 %
    assert r.verdict_finding.size_unit == "turns_fraction"
    assert r.verdict_finding.size == pytest.approx(t["fraction"])
    # A calibration that puts this run's loop ratio at exactly 30 % of phase c's turns:
    # the level is read from it, and the model's stays beside it.
    x = t["loop_ratio"]
    points = [[[0.0, 0.0]] * 8 for _ in range(3)]
    points[2][0] = [x, 0.3]
    cal = {"points": points, "counts": [0, 0, 1], "scatter": 0.01, "runs": 1}
    c = dm.diagnose(log, p, parallel_paths=2, turn_calibration=cal)
    assert c.shorted_turns["basis"] == "calibration"
    assert c.shorted_turns["fraction"] == pytest.approx(0.3, abs=1e-3)
    assert c.unbalance.shorted_turns_physics["fraction"] == pytest.approx(t["fraction"])
