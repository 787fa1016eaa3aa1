"""A motor's history: the store ``sim-host fleet --store`` and ``diagnose_many(store=...)``
write, and the trend of each motor's indicators (``drive_monitor.trend``).

The store is an SQLite file (one row per judged log, read with Python's own ``sqlite3``:
``pandas.read_sql("SELECT * FROM logs", sqlite3.connect(path))``) and its mirror, a Parquet
dataset partitioned by motor and day in ``PATH.parquet/`` (``pandas.read_parquet``, Dask's
``dd.read_parquet``). The trend (Theil-Sen's slope with Sen's interval, against the
indicator's own scatter, at like operating points) is the library's, the same as
``sim-host trend`` prints: docs/trend.md.
"""

from __future__ import annotations

# The helpers under underscore names, the typing names only for the type checker: the
# module's namespace is its public API (`__all__`), no `os`, `json` or `Dict`.
import json as _json
import os as _os
import typing as _typing

from . import _native

if _typing.TYPE_CHECKING:  # pragma: no cover
    from typing import Any, Dict, List, Optional, Union

    import pandas as pd

__all__ = ["trend", "Trend", "STORE_COLUMNS", "TREND_COLUMNS"]

#: The store's columns, in order (SQLite's ``logs`` table; the Parquet files hold all but
#: ``motor`` and ``day``, which are the dataset's partitions).
STORE_COLUMNS: "List[str]" = list(_native.store_columns())

#: The columns of :attr:`Trend.indicators`, one row per motor and the indicators its logs
#: measured (an indicator no log of the motor measured, such as the parity residuals of
#: logs without voltages, has no row: absent, not zero). ``sentence`` is the indicator's
#: line as ``sim-host trend`` prints it; ``reason`` the typed reason beside it, a dict with
#: its ``kind`` (``fault_level_in_a_row``, ``slope``, ``held``, ``not_yet``, ``no_alarm``,
#: ...) and the numbers that decided.
TREND_COLUMNS: "List[str]" = [
    "motor",
    "indicator",
    "unit",
    "logs",
    "slope_per_day",
    "slope_low",
    "slope_high",
    "scatter",
    "moves_scatters",
    "last",
    "fault_level",
    "days_to_fault",
    "days_to_fault_recent",
    "alarm",
    "alarm_since",
    "reference_centre",
    "reference_scatter",
    "from_reference_scatters",
    "normalisation",
    "sentence",
    "reason",
]


class Trend(_typing.NamedTuple):
    """What :func:`trend` returns."""

    #: The stored rows (columns :data:`STORE_COLUMNS`), by motor and time.
    rows: "pd.DataFrame"
    #: One row per motor and indicator (columns :data:`TREND_COLUMNS`), the motors ranked
    #: (alarmed first, then the fastest-moving), as ``sim-host trend --json``'s ``motors``.
    indicators: "pd.DataFrame"
    #: ``sim-host trend --json``'s ``motors`` as they are (with each indicator's series).
    motors: List[Dict[str, Any]]


def trend(
    store: Union[str, "_os.PathLike[str]"],
    motor: Optional[str] = None,
    since: Optional[str] = None,
    window_days: float = 14.0,
    k: float = 3.0,
    reference_until: Optional[str] = None,
) -> Trend:
    """The store's rows and the trend of each motor's indicators.

    Parameters
    ----------
    store : path
        The SQLite store ``sim-host fleet --store`` or ``diagnose_many(store=...)`` wrote.
    motor : str, optional
        Only this motor.
    since : str, optional
        Only logs from this UTC day on (``YYYY-MM-DD``).
    window_days : float
        The window the slope is taken over, ending at each motor's last log [days].
    k : float
        How many scatters the line must move the indicator over the window to alarm.
    reference_until : str, optional
        The baseline: each motor's logs up to the end of this UTC day (``YYYY-MM-DD``) are
        its reference (the bands, the scatters from the reference, the alarm's clearing),
        as ``sim-host trend --reference-until``. Default: each motor's first
        ``window_days`` of logs whose verdict is healthy or watching.

    Raises
    ------
    LogError
        No store at the path, or not a store.
    OptionError
        A bad date (``since``, ``reference_until``), window or k.
    """
    import pandas as pd

    doc = _json.loads(
        _native.store_trend(_os.fspath(store), motor, since, window_days, k, reference_until)
    )
    rows = pd.DataFrame(doc["rows"], columns=STORE_COLUMNS)
    flat = [
        {"motor": m["motor"], **{c: t.get(c) for c in TREND_COLUMNS if c != "motor"}}
        for m in doc["motors"]
        for t in m["indicators"]
    ]
    return Trend(rows, pd.DataFrame(flat, columns=TREND_COLUMNS), doc["motors"])
