"""The fleet run on a Dask LocalCluster with two worker processes, against the command line:
24 simulated logs of three motors (healthy, faults), a corrupt file and a file no motor
claims; per log the same verdict, fault and size as ``sim-host fleet``."""

import json
import subprocess

import pandas as pd
import pytest

import drive_monitor as dm
from drive_monitor import fleet

MOTORS = {
    "m3hp": ("examples/params/3hp.toml", 60.0),
    "m2p2": ("examples/params/2p2kw.toml", 50.0),
    "m11k": ("examples/params/11kw_2pole.toml", 50.0),
}
FAULTS = [None, None, None, ("rs", 0.4), ("rr", 0.5), ("lr", -0.4), ("current_sensor", 0.3), None]


@pytest.fixture(scope="module")
def plant(tmp_path_factory, repo):
    """24 logs (8 per motor) as Parquet, a corrupt CSV, a stray file; the motor table."""
    d = tmp_path_factory.mktemp("plant")
    logs = []
    for name, (params, _f) in MOTORS.items():
        for k, fault in enumerate(FAULTS):
            sc = f"duration_s = 8.0\nsample_rate_hz = 4000.0\nseed = {k + 1}\n"
            if fault:
                sc += f'[[faults]]\nkind = "{fault[0]}"\nat_s = 4.0\nchange = {fault[1]}\n'
                if fault[0].endswith("_sensor"):
                    sc += 'mode = "gain"\n'
            out = d / f"{name}_{k:02d}.parquet"
            dm.simulate(repo / params, sc, out=out)
            logs.append(str(out))
    bad = d / "m2p2_corrupt.csv"
    bad.write_text("t_s,ia_A,ib_A\n0,1,2\nx,y\n")
    logs.append(str(bad))
    stray = d / "other_00.csv"
    stray.write_text("t_s,ia_A,ib_A,ic_A\n0,1,2,3\n")
    logs.append(str(stray))
    table = d / "motors.toml"
    table.write_text(
        "".join(
            f'[[motor]]\nname = "{n}"\nparams = "{repo / p}"\nlogs = "{n}_*"\ncommission = [1.5, 3.5]\n'
            for n, (p, _f) in MOTORS.items()
        )
    )
    return d, logs, table


def test_the_fleet_on_dask_gives_the_commands_rows(plant, sim_host):
    from dask.distributed import Client, LocalCluster

    d, logs, table = plant
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True) as cluster, Client(cluster) as client:
        rows = fleet.diagnose_many(logs, table, client=client)
    assert list(rows.columns) == fleet.COLUMNS
    assert len(rows) == len(logs) == 26
    cli = json.loads(
        subprocess.run([sim_host, "fleet", str(table), *logs, "--json"], capture_output=True, text=True, check=True).stdout
    )
    want = pd.DataFrame(cli, columns=fleet.COLUMNS)
    for col in ("motor", "file", "verdict", "fault", "phase", "error"):
        assert rows[col].fillna("").tolist() == want[col].fillna("").tolist(), col
    assert rows["size"].fillna(0).round(6).tolist() == want["size"].fillna(0).round(6).tolist()
    # The corrupt file and the stray one are rows with their errors, not a failed run.
    errs = rows.set_index("file")["error"]
    assert "m2p2_corrupt" in " ".join(rows.loc[rows.error.notna(), "file"])
    assert errs[str(d / "other_00.csv")].startswith("no motor")
    # The faults are found: every faulty log is not healthy, and the parametric ones named.
    for name in MOTORS:
        for k, fault in enumerate(FAULTS):
            r = rows.set_index("file").loc[str(d / f"{name}_{k:02d}.parquet")]
            if fault and fault[0] in ("rs", "rr", "lr"):
                assert r.verdict == "fault", (name, k, r.to_dict())


def test_a_glob_and_rows_as_the_motor_table(plant, repo):
    d, _logs, _table = plant
    motors = pd.DataFrame(
        [{"name": "m3hp", "params": str(repo / MOTORS["m3hp"][0]), "logs": "m3hp_*", "commission": [1.5, 3.5]}]
    )
    from dask.distributed import Client, LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False) as cluster, Client(cluster) as client:
        rows = fleet.diagnose_many(str(d / "m3hp_0*.parquet"), motors, client=client)
    assert len(rows) == 8 and (rows.motor == "m3hp").all()


def test_a_missing_or_bad_motor_table_is_a_params_error_naming_it(plant, tmp_path):
    _d, logs, _table = plant
    with pytest.raises(dm.ParamsError) as e:
        fleet.diagnose_many(logs, str(tmp_path / "nope.toml"))
    assert "nope.toml" in str(e.value) and "\n" not in str(e.value), str(e.value)
    bad = tmp_path / "bad.toml"
    bad.write_text('[[motor]]\nname = "m"\nlogs = "*"\n')  # no params
    with pytest.raises(dm.ParamsError) as e:
        fleet.diagnose_many(logs, bad)
    assert "bad.toml" in str(e.value) and "params" in str(e.value), str(e.value)
    with pytest.raises(dm.ParamsError) as e:
        fleet.diagnose_many(logs, [{"name": "m", "logs": "*", "colour": "red"}])
    assert "the motor table (rows)" in str(e.value), str(e.value)


def test_a_glob_that_matches_nothing_is_an_error_naming_it(plant, tmp_path):
    _d, _logs, table = plant
    pattern = str(tmp_path / "none_*.parquet")
    with pytest.raises(dm.OptionError) as e:
        fleet.diagnose_many(pattern, table)
    assert pattern in str(e.value) and "matches no file" in str(e.value), str(e.value)
    # Worded once, in the command line's words.
    assert str(e.value).count("matches no file") == 1, str(e.value)
    assert str(e.value) == f"logs: the pattern '{pattern}' matches no file", str(e.value)


def test_the_module_exposes_its_own_names_only():
    for name in ("os", "json", "tempfile", "typing", "Path", "Any", "Dict", "List",
                 "Optional", "Sequence", "Union", "TYPE_CHECKING"):
        assert not hasattr(fleet, name), name
    assert set(fleet.__all__) <= set(vars(fleet))


def test_a_stored_logs_time_comes_from_its_name_else_its_modification_time(plant, tmp_path):
    """Issue 65: the Dask run dates a log as ``sim-host fleet --store`` does: by the motor's
    ``time_from_name`` where the name has the date (2026-11-03, though the file was written
    today), else by the file's modification time, and says so."""
    import shutil
    import sqlite3

    from dask.distributed import Client, LocalCluster

    d, logs, _table = plant
    named = tmp_path / "m3hp_20261103_0600.parquet"
    other = tmp_path / "m3hp_latest.parquet"
    shutil.copyfile(logs[0], named)
    shutil.copyfile(logs[0], other)
    table = tmp_path / "motors.toml"
    params = open(d / "motors.toml").read().split("[[motor]]")[1]
    table.write_text("[[motor]]" + params + 'time_from_name = "m3hp_%Y%m%d_%H%M"\n')
    store = tmp_path / "h.db"
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True) as cluster, Client(cluster) as client:
        with pytest.warns(UserWarning, match="do not match time_from_name") as said:
            fleet.diagnose_many([str(named), str(other)], table, client=client, store=store)
    lines = [str(w.message) for w in said]
    assert any("modification times" in w for w in lines), lines
    with sqlite3.connect(store) as c:
        got = dict(c.execute("SELECT log_path, day || ' ' || time_source FROM logs").fetchall())
    # 2026-11-03T06:00:00Z (`date -u -d 2026-11-03T06:00:00Z +%s`).
    assert got[str(named)] == "2026-11-03 file_name", got
    assert got[str(other)].endswith(" modified") and not got[str(other)].startswith("2026-11-03"), got
    with sqlite3.connect(store) as c:
        (t,) = c.execute("SELECT log_time_s FROM logs WHERE log_path = ?", (str(named),)).fetchone()
    assert t == 1_793_685_600
