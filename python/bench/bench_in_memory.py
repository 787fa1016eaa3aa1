"""A 1 M-row log judged from a pandas DataFrame against the same data read from a file.

Simulates the 3 hp motor for 100 s at 10 kHz (1 000 000 rows) with a stator-resistance
fault at 60 s, keeps it as a DataFrame, writes it as Parquet (pyarrow's defaults) and as
CSV, then times ``drive_monitor.diagnose`` on each (the best of REPEATS runs; the
DataFrame's time includes its conversion to Arrow), and checks the documents agree. For
comparison, the way the package took a DataFrame before: written to a temporary Parquet
file, then read.

    python python/bench/bench_in_memory.py [REPEATS]

Figures are in docs/performance.md ("Python: data in memory") and docs/python.md.
"""

import sys
import tempfile
import time
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq

import drive_monitor as dm

REPO = Path(__file__).resolve().parents[2]
PARAMS = REPO / "examples/params/3hp.toml"
SCENARIO = """duration_s = 100.0
sample_rate_hz = 10000.0
seed = 7
[[faults]]
kind = "rs"
at_s = 60.0
change = 0.4
"""


def best(f, repeats):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return min(times), out


def main():
    repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    frame = dm.simulate(PARAMS, SCENARIO)
    print(f"rows: {len(frame)}")
    with tempfile.TemporaryDirectory() as d:
        pq_path = Path(d) / "log.parquet"
        csv_path = Path(d) / "log.csv"
        pq.write_table(pa.Table.from_pandas(frame, preserve_index=False), pq_path)
        frame.to_csv(csv_path, index=False)
        args = dict(commission=(1.0, 3.0))
        t_frame, r_frame = best(lambda: dm.diagnose(frame, PARAMS, **args), repeats)
        t_pq, r_pq = best(lambda: dm.diagnose(pq_path, PARAMS, **args), repeats)
        t_csv, r_csv = best(lambda: dm.diagnose(csv_path, PARAMS, **args), repeats)

        def through_a_file():  # what the package did before: a temporary Parquet file
            tmp = Path(d) / "tmp.parquet"
            pq.write_table(pa.Table.from_pandas(frame, preserve_index=False), tmp)
            return dm.diagnose(tmp, PARAMS, **args)

        t_tmp, _ = best(through_a_file, repeats)
    assert r_frame.to_dict() == r_pq.to_dict(), "the DataFrame's document differs from the file's"
    print(f"verdict: {r_frame.verdict}")
    print(f"DataFrame: {t_frame:.2f} s")
    print(f"Parquet file: {t_pq:.2f} s ({t_frame / t_pq:.2f}x the DataFrame's time)")
    print(f"CSV file: {t_csv:.2f} s ({t_frame / t_csv:.2f}x)")
    print(f"DataFrame through a temporary Parquet file (before): {t_tmp:.2f} s")


if __name__ == "__main__":
    main()
