"""A user's first day (issue 65): an output that is an input is refused before anything is
written, a text where a list is expected is one item, and the package's namespace is its
public API."""

import os
import shutil
from pathlib import Path

import pytest

import drive_monitor as dm
from drive_monitor import fleet

SCENARIO = "duration_s = 0.05\nsample_rate_hz = 2000.0\nseed = 1\n"


@pytest.fixture
def inputs(tmp_path, repo):
    """A parameter file (p.toml) and a scenario file (sc.toml) in a fresh folder."""
    params = tmp_path / "p.toml"
    shutil.copy(repo / "examples/params/2p2kw.toml", params)
    scenario = tmp_path / "sc.toml"
    scenario.write_text(SCENARIO)
    return params, scenario


def _refused(params, scenario, out, field):
    p, s = Path(params), Path(scenario)
    before = (p.read_bytes(), s.read_bytes())
    with pytest.raises(dm.OptionError, match="refusing to overwrite the input") as e:
        dm.simulate(params, scenario, out=out)
    msg = str(e.value)
    assert f"(the {field})" in msg and "out = " in msg and "\n" not in msg, msg
    assert (p.read_bytes(), s.read_bytes()) == before


def test_simulate_refuses_out_the_scenario_or_the_params(inputs):
    params, scenario = inputs
    _refused(params, scenario, scenario, "scenario")
    _refused(params, scenario, params, "params")
    # As strings, by another spelling, and through a link.
    _refused(str(params), str(scenario), os.path.join(str(scenario.parent), ".", "sc.toml"), "scenario")
    link = scenario.parent / "log.parquet"
    link.symlink_to(scenario)
    _refused(params, scenario, link, "scenario")
    assert sorted(p.name for p in scenario.parent.iterdir()) == ["log.parquet", "p.toml", "sc.toml"]


def test_simulate_writes_a_new_out_and_returns_it(inputs):
    params, scenario = inputs
    out = scenario.parent / "run.parquet"
    frame = dm.simulate(params, scenario, out=out)
    assert out.exists() and len(frame) > 0 and "ia_A" in frame.columns
    csv = scenario.parent / "run.csv"
    same = dm.simulate(params, SCENARIO, out=csv)
    assert len(same) == len(frame)
    assert csv.read_text().startswith("t_s,")


def test_the_fleet_store_may_not_be_a_file_it_reads(inputs):
    params, _ = inputs
    log = params.parent / "m_1.csv"
    log.write_text("t_s,ia_A,ib_A,ic_A\n0,1,2,-3\n")
    table = [{"name": "m", "params": str(params), "logs": "m_*"}]
    before = log.read_bytes()
    with pytest.raises(dm.OptionError, match=r"refusing to overwrite the input .*\(the logs\)"):
        fleet.diagnose_many([str(log)], table, store=log)
    assert log.read_bytes() == before


def test_a_text_where_a_list_is_expected_is_one_item(repo):
    assert dm._analysis_kwargs("load_torque", None, None, False, None)["effects"] == ["load_torque"]
    assert dm._analysis_kwargs(("windage", "iron_loss"), None, None, False, None)["effects"] == [
        "windage",
        "iron_loss",
    ]
    assert dm._items(repo / "x.csv") == [repo / "x.csv"]
    assert dm._items(None) == []
    # Through the library: the message names the effect, not its first letter.
    log, params = repo / "examples/logs/motulator_2p2kw_dol.csv", repo / "examples/logs/motulator_2p2kw_dol.toml"
    for call in (dm.compare, dm.explain):
        with pytest.raises(dm.OptionError, match="effect 'no_such_effect' is not in the library"):
            call(log, params, effects="no_such_effect")


def test_a_motor_tables_baseline_may_be_one_path(tmp_path, repo):
    rows = [{"name": "m", "params": str(repo / "examples/params/2p2kw.toml"), "logs": "m_*",
             "baseline": str(tmp_path / "healthy.csv")}]
    text = fleet.motor_table_toml(rows, tmp_path)
    assert "baseline = [" in text


def test_the_namespace_is_the_public_api():
    names = set(dir(dm))
    for helper in ("os", "json", "tempfile", "Path", "Dict", "Any", "List", "Optional", "Union",
                   "annotations", "TYPE_CHECKING"):
        assert helper not in names, helper
    for name in dm.__all__:
        assert hasattr(dm, name), name
    assert len(set(dm.__all__)) == len(dm.__all__)
    public = {n for n in names if not n.startswith("_")}
    # Beside `__all__`, only the package's submodules.
    assert public - set(dm.__all__) <= {"fleet", "history"}, public - set(dm.__all__)
