"""A small plant judged on Dask: a dozen motors of three sizes, a few with faults.

Simulates each motor's log (Parquet) with the project's simulator, judges every log with
``drive_monitor.fleet.diagnose_many`` on a LocalCluster, prints the fleet table and draws
a fleet overview (motors by state; the named faults with their sizes) with matplotlib.

    python python/examples/fleet_overview.py [OUT_DIR]

Run it from the repository's root (it reads examples/params/).
"""

import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import drive_monitor as dm  # noqa: E402
from drive_monitor import fleet  # noqa: E402

SIZES = {
    "3hp": "examples/params/3hp.toml",
    "2p2kw": "examples/params/2p2kw.toml",
    "11kw": "examples/params/11kw_2pole.toml",
}
# (size, fault, change): twelve motors, four of them with a fault.
PLANT = [
    ("3hp", None, 0.0), ("3hp", "rr", 0.5), ("3hp", None, 0.0), ("3hp", None, 0.0),
    ("2p2kw", None, 0.0), ("2p2kw", "rs", 0.4), ("2p2kw", None, 0.0), ("2p2kw", None, 0.0),
    ("11kw", None, 0.0), ("11kw", "lr", -0.4), ("11kw", "rr", 0.3), ("11kw", None, 0.0),
]


def main(out_dir: Path) -> None:
    out_dir.mkdir(parents=True, exist_ok=True)
    motors, logs = [], []
    for k, (size, fault, change) in enumerate(PLANT):
        name = f"{size}_m{k:02d}"
        scenario = f"duration_s = 8.0\nsample_rate_hz = 4000.0\nseed = {k + 1}\n"
        if fault:
            scenario += f'[[faults]]\nkind = "{fault}"\nat_s = 4.0\nchange = {change}\n'
        log = out_dir / f"{name}_day1.parquet"
        dm.simulate(SIZES[size], scenario, out=log)
        logs.append(str(log))
        motors.append(
            {"name": name, "params": str(Path(SIZES[size]).resolve()), "logs": f"{name}_*", "commission": [1.5, 3.5]}
        )
    rows = fleet.diagnose_many(logs, motors)  # a LocalCluster, one worker per core
    print(rows[["motor", "verdict", "fault", "size", "phase", "confidence", "error"]].to_string(index=False))

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4))
    counts = rows["verdict"].fillna("error").value_counts()
    colours = {"healthy": "tab:green", "fault": "tab:red", "watching": "tab:orange", "could_not_judge": "tab:gray", "error": "black"}
    ax1.bar(counts.index, counts.values, color=[colours.get(v, "tab:blue") for v in counts.index])
    ax1.set_title("Motors by state")
    ax1.set_ylabel("motors")
    named = rows[rows.fault.notna()]
    ax2.barh(named.motor + " " + named.fault, 100 * named["size"], color="tab:red")
    ax2.set_xlabel("size of the named fault [%]")
    ax2.set_title("Named faults")
    fig.tight_layout()
    png = out_dir / "fleet_overview.png"
    fig.savefig(png, dpi=120)
    print(f"wrote {png}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp(prefix="fleet_")))
