"""The store of the motors' history (issue 53): written by the Dask fleet run and by
``sim-host fleet --store``, read back by Python's own ``sqlite3`` (``pandas.read_sql``) and,
from its Parquet mirror, by ``pandas.read_parquet``: the same rows, value for value; and
``drive_monitor.trend`` on it."""

import sqlite3
import subprocess

import pandas as pd
import pytest

import drive_monitor as dm
from drive_monitor import fleet
from drive_monitor.history import STORE_COLUMNS, TREND_COLUMNS

DAYS = 8


@pytest.fixture(scope="module")
def month(tmp_path_factory, repo):
    """Eight daily logs of two motors (the second with a short growing from day 3), each
    dated a day apart by its modification time; the motor table."""
    import os

    d = tmp_path_factory.mktemp("history")
    logs = []
    for name, params in (("pump", "examples/params/3hp.toml"), ("fan", "examples/params/2p2kw.toml")):
        for day in range(DAYS):
            sc = f"duration_s = 6.0\nsample_rate_hz = 4000.0\nseed = {day + 1}\n"
            if name == "fan" and day >= 3:
                sc += f'[[effects]]\nname = "phase_asymmetry"\nfraction = {0.004 * (day - 2)}\n'
            out = d / f"{name}_{day:02d}.parquet"
            dm.simulate(repo / params, sc, out=out)
            t = 1_793_491_200 + day * 86_400
            os.utime(out, (t, t))
            logs.append(str(out))
    table = d / "motors.toml"
    table.write_text(
        "".join(
            f'[[motor]]\nname = "{n}"\nparams = "{repo / p}"\nlogs = "{n}_*"\n'
            for n, p in (("pump", "examples/params/3hp.toml"), ("fan", "examples/params/2p2kw.toml"))
        )
    )
    return d, logs, table


def read_sqlite(path):
    with sqlite3.connect(path) as con:
        return pd.read_sql("SELECT * FROM logs ORDER BY log_id", con)


def read_mirror(path):
    df = pd.read_parquet(str(path) + ".parquet")
    for c in ("motor", "day"):
        df[c] = df[c].astype(str)
    return df[STORE_COLUMNS].sort_values("log_id").reset_index(drop=True)


def same_rows(a, b):
    assert list(a.columns) == list(b.columns) == STORE_COLUMNS
    assert len(a) == len(b)
    for c in STORE_COLUMNS:
        x, y = a[c], b[c]
        if pd.api.types.is_numeric_dtype(x) and pd.api.types.is_numeric_dtype(y):
            assert ((x.astype(float) - y.astype(float)).abs().fillna(0) == 0).all() and (
                x.isna() == y.isna()
            ).all(), c
        else:
            assert x.astype(object).where(x.notna(), None).tolist() == y.astype(object).where(
                y.notna(), None
            ).tolist(), c


def test_the_dask_run_stores_each_log_once_and_sqlite_and_parquet_agree(month, tmp_path):
    from dask.distributed import Client, LocalCluster

    d, logs, table = month
    store = tmp_path / "history.db"
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True) as cluster, Client(cluster) as client:
        rows = fleet.diagnose_many(logs, table, client=client, store=store)
        again = fleet.diagnose_many(logs, table, client=client, store=store)
    assert len(rows) == len(again) == len(logs)
    sql = read_sqlite(store)
    assert len(sql) == len(logs), "a log stored twice or missing"
    assert sorted(sql.log_path) == sorted(logs)
    assert set(sql.day) == {f"2026-11-{1 + k:02d}" for k in range(DAYS)}
    # The store's verdicts are the fleet rows'.
    by_file = rows.set_index("file")
    for _, r in sql.iterrows():
        assert r.verdict == by_file.loc[r.log_path, "verdict"]
    same_rows(sql, read_mirror(store))


def test_the_command_lines_store_reads_back_the_same_in_pandas(month, tmp_path, sim_host):
    d, logs, table = month
    store = tmp_path / "cli.db"
    out = subprocess.run(
        [sim_host, "fleet", str(table), *logs, "--store", str(store)], capture_output=True, text=True
    )
    assert out.returncode == 0, out.stderr
    sql = read_sqlite(store)
    assert len(sql) == len(logs)
    same_rows(sql, read_mirror(store))


def test_trend_returns_the_rows_and_each_motors_indicators(month, tmp_path, sim_host):
    d, logs, table = month
    store = tmp_path / "t.db"
    subprocess.run([sim_host, "fleet", str(table), *logs, "--store", str(store)], check=True, capture_output=True)
    t = dm.trend(store)
    assert list(t.rows.columns) == STORE_COLUMNS and len(t.rows) == len(logs)
    assert list(t.indicators.columns) == TREND_COLUMNS
    assert set(t.indicators.motor) == {"pump", "fan"}
    # The fan's negative sequence grows day by day: its slope's interval is above zero.
    i2 = t.indicators.set_index(["motor", "indicator"]).loc[("fan", "i2_over_i1")]
    assert i2.slope_low > 0, i2.to_dict()
    only = dm.trend(store, motor="pump")
    assert set(only.rows.motor) == {"pump"}
    with pytest.raises(dm.LogError, match="no store"):
        dm.trend(tmp_path / "none.db")
    with pytest.raises(dm.OptionError, match="since"):
        dm.trend(store, since="yesterday")


def test_the_history_module_exposes_its_api_only():
    import drive_monitor.history as h

    public = {n for n in dir(h) if not n.startswith("_")}
    assert not public & {"os", "json", "typing", "Dict", "List", "Any", "Optional", "Union", "NamedTuple"}, public
    assert set(h.__all__) <= public


def test_trend_takes_a_marked_reference(month, tmp_path, sim_host):
    d, logs, table = month
    store = tmp_path / "r.db"
    subprocess.run([sim_host, "fleet", str(table), *logs, "--store", str(store)], check=True, capture_output=True)
    first = dm.trend(store).rows.day.min()
    t = dm.trend(store, reference_until=first)
    for m in t.motors:
        assert m["reference"]["marked"] and m["reference"]["last_day"] == first, m["reference"]
    with pytest.raises(dm.OptionError, match="reference_until"):
        dm.trend(store, reference_until="soon")


ITSC = (
    ["SC_HLT_001", "SC_HLT_002", "SC_HLT_001", "SC_HLT_002"]
    + ["SC_A0_B0_C1_001", "SC_A0_B0_C1_002", "SC_A0_B0_C2_001", "SC_A0_B0_C2_002"]
    + ["SC_A0_B0_C3_001", "SC_A0_B0_C4_001"]
)
UNMEASURED = ["residual_d", "residual_q", "residual_t", "stator_excess_pct"]


def test_a_current_only_bench_alarms_on_its_fault_logs_and_drops_what_it_cannot_measure(repo, tmp_path, sim_host):
    """Issue 79: ten dated copies of the real ITSC bench's logs (currents only; four healthy,
    then shorts from 10 % to 40 %): the trend alarms on the FAULT level of two logs in a row,
    and the residuals and Rs beyond Rr, which these logs cannot measure, are absent from the
    trend's frame and null in the rows (SQLite and Parquet), not zeros."""
    import shutil

    itsc = repo / "examples" / "recordings" / "itsc"
    logs = []
    for k, name in enumerate(ITSC):
        to = tmp_path / f"bench_202611{k + 1:02d}.csv"
        shutil.copy(itsc / f"{name}.csv", to)
        logs.append(str(to))
    table = tmp_path / "motors.toml"
    table.write_text(
        f'[[motor]]\nname = "bench"\nparams = "{itsc / "baldor_0p75hp.toml"}"\nlogs = "bench_*"\n'
        'time_from_name = "bench_%Y%m%d"\n'
    )
    store = tmp_path / "bench.db"
    subprocess.run([sim_host, "fleet", str(table), *logs, "--store", str(store)], check=True, capture_output=True)
    t = dm.trend(store)
    assert set(t.indicators.indicator).isdisjoint(UNMEASURED), t.indicators.indicator.tolist()
    i2 = t.indicators.set_index("indicator").loc["i2_over_i1"]
    assert i2.alarm, i2.sentence
    assert i2.reason["kind"] == "fault_level_in_a_row" and i2.reason["logs"] == 6, i2.reason
    assert "TREND ALARM" in i2.sentence
    for frame in (t.rows, read_sqlite(store), read_mirror(store)):
        assert len(frame) == len(ITSC)
        for c in UNMEASURED + ["deviation_sigma"]:
            assert frame[c].isna().all(), (c, frame[c].tolist())
        assert frame["i2_over_i1"].notna().all()
