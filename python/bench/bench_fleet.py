"""Throughput of the fleet run: rows per second per core, on Dask and on the command line.

Simulates N logs (three motors, 60 s at 10 kHz each: 600 000 rows), then judges them all
(1) with ``sim-host fleet`` (one process, its threads on every core) and (2) with
``drive_monitor.fleet.diagnose_many`` on ``fleet.local_cluster()`` (one single-threaded
worker process per core, started with ``fleet.worker_environ()``); prints rows per second per core for each and their ratio.

    python python/bench/bench_fleet.py [N_LOGS] [SIM_HOST]

Figures are in docs/performance.md ("The fleet run").
"""

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import drive_monitor as dm
from drive_monitor import fleet

REPO = Path(__file__).resolve().parents[2]
# Each log's length [s] at 10 kHz (a minute: 600 000 rows; env BENCH_FLEET_S).
DURATION_S = float(os.environ.get("BENCH_FLEET_S", "60"))
SIZES = {
    "a3hp": "examples/params/3hp.toml",
    "b2p2": "examples/params/2p2kw.toml",
    "c11k": "examples/params/11kw_2pole.toml",
}


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 24
    sim_host = sys.argv[2] if len(sys.argv) > 2 else str(REPO / "target/release/sim-host")
    cores = os.cpu_count() or 1
    d = Path(tempfile.mkdtemp(prefix="bench_fleet_"))
    logs, names = [], list(SIZES)
    for k in range(n):
        name = names[k % len(names)]
        sc = f"duration_s = {DURATION_S}\nsample_rate_hz = 10000.0\nseed = {k + 1}\n"
        if k % 4 == 3:
            sc += '[[faults]]\nkind = "rr"\nat_s = 12.0\nchange = 0.4\n'
        log = d / f"{name}_{k:03d}.parquet"
        dm.simulate(REPO / SIZES[name], sc, out=log)
        logs.append(str(log))
    table = d / "motors.toml"
    table.write_text(
        "".join(
            f'[[motor]]\nname = "{m}"\nparams = "{REPO / p}"\nlogs = "{m}_*"\ncommission = [2.0, 8.0]\n'
            for m, p in SIZES.items()
        )
    )
    rows_total = int(n * DURATION_S * 10_000)

    t0 = time.perf_counter()
    subprocess.run([sim_host, "fleet", str(table), *logs], check=True, capture_output=True)
    cli_s = time.perf_counter() - t0

    from dask.distributed import Client

    with fleet.local_cluster(cores) as cluster, Client(cluster) as client:
        client.run(lambda: __import__("drive_monitor"))  # the workers' imports out of the timing
        t0 = time.perf_counter()
        out = fleet.diagnose_many(logs, table, client=client)
        dask_s = time.perf_counter() - t0
    assert out.error.isna().all(), out[out.error.notna()]

    per_core = lambda s: rows_total / s / cores  # noqa: E731
    print(f"{n} logs, {rows_total} rows, {cores} cores")
    print(f"sim-host fleet:          {cli_s:7.2f} s wall, {per_core(cli_s) / 1e6:6.2f} M rows/s per core")
    print(f"diagnose_many on Dask:   {dask_s:7.2f} s wall, {per_core(dask_s) / 1e6:6.2f} M rows/s per core")
    print(f"Dask per core / CLI per core: {cli_s / dask_s:.2f}")


if __name__ == "__main__":
    main()
