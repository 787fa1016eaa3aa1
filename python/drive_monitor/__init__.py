"""drive_monitor: fault detection for 3-phase induction motors, from Python.

The same library the ``sim-host`` command line runs (Rust, through PyO3): no diagnosis logic
lives in Python. Every function takes a log and a parameter file and returns a typed result
whose fields are the command's JSON keys; ``result.to_dict()`` is the command's ``--json``
document, key for key.

Logs
    A path (CSV, TDMS or Parquet, by extension), or data in memory: a pandas DataFrame, a
    pyarrow Table, or a dict of numpy arrays, with the schema's column names (``t_s``,
    ``va_V``, ``vb_V``, ``vc_V``, ``ia_A``, ``ib_A``, ``ic_A``, ``wm_rad_s``; SI units) or
    the DAQ's own, mapped by the parameter file's ``[columns]`` table as for files.
    In-memory data is written to a temporary Parquet file and read by the same reader.

Parameter files
    A path, or a dict with the file's sections (``{"motor": {...}, "supply": {...},
    "columns": {...}}``).

Errors
    :class:`DriveMonitorError` and its subclasses :class:`ParamsError`, :class:`LogError`,
    :class:`OptionError`, :class:`AnalysisError` (and :class:`InternalError` for a bug),
    each carrying the command line's one-line message. No Rust panic crosses into Python.
    The GIL is released while the library runs, so threads (and Dask) run in parallel.

The fleet run over many motors' logs on Dask is :func:`drive_monitor.fleet.diagnose_many`.
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import Any, Dict, Iterable, List, Optional, Sequence, Tuple, Union

from . import _native
from ._native import (
    AnalysisError,
    DriveMonitorError,
    InternalError,
    LogError,
    OptionError,
    ParamsError,
)
from ._results import (
    CompareResult,
    DiagnoseResult,
    ExplainResult,
    IdentifyResult,
    NameplateResult,
    Result,
)

__all__ = [
    "diagnose",
    "compare",
    "explain",
    "identify",
    "params_from_nameplate",
    "simulate",
    "Result",
    "DiagnoseResult",
    "CompareResult",
    "ExplainResult",
    "IdentifyResult",
    "NameplateResult",
    "DriveMonitorError",
    "ParamsError",
    "LogError",
    "OptionError",
    "AnalysisError",
    "InternalError",
]

PathLike = Union[str, "os.PathLike[str]"]
LogLike = Any  # a path, a pandas DataFrame, a pyarrow Table, or a dict of arrays
ParamsLike = Union[PathLike, Dict[str, Any]]


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(float(v)) if isinstance(v, float) else str(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_toml_value(x)}" for k, x in v.items()) + " }"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise OptionError(f"parameter value {v!r} is not a number, text, table or list")


def _params_toml(params: Dict[str, Any]) -> str:
    """The TOML text of a parameter dict (sections of scalars; ``columns`` of tables)."""
    lines: List[str] = []
    for section, table in params.items():
        if not isinstance(table, dict):
            raise OptionError(f"parameter section {section!r} is not a table")
        lines.append(f"[{section}]")
        for k, v in table.items():
            lines.append(f"{k} = {_toml_value(v)}")
    return "\n".join(lines) + "\n"


def _params(params: ParamsLike) -> Tuple[str, bool]:
    """(path or TOML text, is_text) for the native functions."""
    if isinstance(params, dict):
        return _params_toml(params), True
    return os.fspath(params), False


class _LogFile:
    """A log for the native functions: its path, written to a temporary Parquet file first
    when the data is in memory (removed on exit)."""

    def __init__(self, log: LogLike):
        self._tmp: Optional[str] = None
        if isinstance(log, (str, os.PathLike)):
            self.path = os.fspath(log)
            return
        table = _to_arrow(log)
        import pyarrow.parquet as pq

        fd, tmp = tempfile.mkstemp(suffix=".parquet", prefix="drive_monitor_")
        os.close(fd)
        pq.write_table(table, tmp)
        self._tmp = tmp
        self.path = tmp

    def __enter__(self) -> "_LogFile":
        return self

    def __exit__(self, *exc: Any) -> None:
        if self._tmp is not None:
            try:
                os.remove(self._tmp)
            except OSError:
                pass


def _to_arrow(log: Any):
    """A pyarrow Table of a DataFrame, a Table, or a dict of 1-D arrays (columns as float64
    where numeric)."""
    import pyarrow as pa

    if isinstance(log, pa.Table):
        return log
    try:
        import pandas as pd

        if isinstance(log, pd.DataFrame):
            return pa.Table.from_pandas(log, preserve_index=False)
    except ImportError:  # pragma: no cover - pandas is a dependency
        pass
    if isinstance(log, dict):
        import numpy as np

        return pa.table({str(k): np.asarray(v) for k, v in log.items()})
    raise LogError(
        f"log: a path, a pandas DataFrame, a pyarrow Table or a dict of arrays, not {type(log).__name__}"
    )


def diagnose(
    log: LogLike,
    params: ParamsLike,
    commission: Optional[Tuple[float, float]] = None,
    baseline: Optional[Union[LogLike, Sequence[LogLike]]] = None,
    load: Optional[str] = None,
    angle: Optional[str] = None,
    residuals: Optional[str] = None,
    allow_incomplete: bool = False,
    timeline_step: Optional[float] = None,
    group: Optional[str] = None,
) -> DiagnoseResult:
    """Replay a log through the monitor's core: lamps, the named fault with its size and
    phase, the shorted winding's phase, events, verdict (``sim-host diagnose``).

    Parameters
    ----------
    log : path, DataFrame, pyarrow Table or dict of arrays
        The measurement (see the module's doc for the columns).
    params : path or dict
        The motor's parameter file.
    commission : (start_s, end_s), optional
        Learn the healthy thresholds over this window of the log [s].
    baseline : log or list of logs, optional
        Healthy logs of the same motor (files, folders, or data): the winding's negative
        sequence is judged against their mean, their spread sets the least change.
    load : {"unknown", "viscous"}, optional
        What is known of the load ("unknown", the default: a load change is a load move,
        never a fault).
    angle : {"rotor-flux", "pll", "zero-crossing"}, optional
        The frame's angle source (default "rotor-flux").
    residuals : {"steady", "full"}, optional
        The residual form the lamps act on (eq. 37, the default, or eq. 36).
    allow_incomplete : bool
        Report even when the commissioning window was not learned.
    timeline_step : float, optional
        Timeline resolution [s] (default: the command line's, 0.5 s).
    group : str, optional
        The TDMS group holding the channels.

    Returns
    -------
    DiagnoseResult
        ``.verdict``, ``.candidates``, ``.isolation``, ``.unbalance``, ... (the JSON keys);
        ``.timeline`` as a DataFrame; ``.to_dict()`` the command's ``--json`` document.

    Raises
    ------
    ParamsError, LogError, OptionError, AnalysisError
    """
    p, is_text = _params(params)
    base = [] if baseline is None else (
        list(baseline) if isinstance(baseline, (list, tuple)) else [baseline]
    )
    files = [_LogFile(b) for b in base]
    try:
        with _LogFile(log) as f:
            doc = _native.diagnose(
                f.path,
                p,
                params_is_text=is_text,
                commission=None if commission is None else (float(commission[0]), float(commission[1])),
                baseline=[b.path for b in files],
                load=load,
                angle=angle,
                residuals=residuals,
                allow_incomplete=allow_incomplete,
                timeline_step=None if timeline_step is None else float(timeline_step),
                group=group,
            )
    finally:
        for b in files:
            b.__exit__()
    return DiagnoseResult(json.loads(doc))


def _analysis_kwargs(
    effects: Optional[Iterable[str]],
    from_s: Optional[float],
    to_s: Optional[float],
    no_fit: bool,
    group: Optional[str],
) -> Dict[str, Any]:
    return dict(
        effects=list(effects or []),
        from_s=None if from_s is None else float(from_s),
        to_s=None if to_s is None else float(to_s),
        no_fit=no_fit,
        group=group,
    )


def compare(
    log: LogLike,
    params: ParamsLike,
    effects: Optional[Iterable[str]] = None,
    from_s: Optional[float] = None,
    to_s: Optional[float] = None,
    no_fit: bool = False,
    group: Optional[str] = None,
) -> CompareResult:
    """Compare the paper's simplified model (with ``effects`` added) with the measurement:
    ``normalized_rms_error``, ``channels``, ``worst_windows`` (``sim-host compare``).

    ``from_s``/``to_s`` limit the analysed window [s] (at least 25 supply periods).
    """
    p, is_text = _params(params)
    with _LogFile(log) as f:
        doc = _native.compare(
            f.path, p, params_is_text=is_text, **_analysis_kwargs(effects, from_s, to_s, no_fit, group)
        )
    return CompareResult(json.loads(doc))


def explain(
    log: LogLike,
    params: ParamsLike,
    effects: Optional[Iterable[str]] = None,
    from_s: Optional[float] = None,
    to_s: Optional[float] = None,
    no_fit: bool = False,
    group: Optional[str] = None,
    rotor_bars: Optional[int] = None,
) -> ExplainResult:
    """Rank the physical effects missing from the model by how much of its error each
    explains: ``ranking``, ``verdict``, ``unexplained`` (``sim-host explain``)."""
    p, is_text = _params(params)
    with _LogFile(log) as f:
        doc = _native.explain(
            f.path,
            p,
            params_is_text=is_text,
            rotor_bars=rotor_bars,
            **_analysis_kwargs(effects, from_s, to_s, no_fit, group),
        )
    return ExplainResult(json.loads(doc))


def identify(
    log: LogLike,
    params: ParamsLike,
    from_s: Optional[float] = None,
    to_s: Optional[float] = None,
    group: Optional[str] = None,
) -> IdentifyResult:
    """Identify the motor's circuit (Rs, Rr, the leakage, Lm) and J, B + Bl from a log of
    its healthy running, starting from ``params`` (``sim-host identify``).

    ``.identification.estimates`` holds each value with its 95 % interval;
    ``.toml`` is the identified parameter file's text. A log the start file's motor cannot
    have drawn (a unit), a fit that leaves more than 10 % of the current, or implausible
    values raise :class:`OptionError` naming the likely cause.
    """
    p, is_text = _params(params)
    with _LogFile(log) as f:
        doc = _native.identify(
            f.path,
            p,
            params_is_text=is_text,
            from_s=None if from_s is None else float(from_s),
            to_s=None if to_s is None else float(to_s),
            group=group,
        )
    return IdentifyResult(json.loads(doc))


def params_from_nameplate(
    power_kw: float,
    voltage_v: float,
    current_a: float,
    frequency_hz: float,
    speed_rpm: float,
    power_factor: float,
    efficiency: float,
    poles: Optional[int] = None,
    connection: str = "star",
    locked_rotor_ratio: Optional[float] = None,
    nema_design: str = "B",
    columns_from: Optional[PathLike] = None,
) -> NameplateResult:
    """A parameter file estimated from a motor's nameplate, each value with its range and
    source (``sim-host params from-nameplate``). ``.toml`` is the file's text, ``.params``
    the file as a dict (usable as ``params`` by the other functions)."""
    doc = _native.params_from_nameplate(
        float(power_kw),
        float(voltage_v),
        float(current_a),
        float(frequency_hz),
        float(speed_rpm),
        float(power_factor),
        float(efficiency),
        poles=poles,
        connection=connection,
        locked_rotor_ratio=locked_rotor_ratio,
        nema_design=nema_design,
        columns_from=None if columns_from is None else os.fspath(columns_from),
    )
    return NameplateResult(json.loads(doc))


def simulate(
    params: ParamsLike,
    scenario: Union[PathLike, str],
    out: Optional[PathLike] = None,
):
    """Simulate the motor of ``params`` through ``scenario`` (a scenario file, or its TOML
    text) with the project's simulator (``sim-host simulate``).

    Returns the log as a pandas DataFrame with the schema's columns (``t_s``, ``va_V``, ...,
    SI units), and writes it to ``out`` too when given (CSV, TDMS or Parquet by extension).
    """
    import pandas as pd
    import pyarrow.parquet as pq

    text = scenario
    if isinstance(scenario, os.PathLike) or (
        isinstance(scenario, str) and "\n" not in scenario and Path(scenario).exists()
    ):
        text = Path(scenario).read_text()
    p, is_text = _params(params)
    if out is not None and not os.fspath(out).endswith(".parquet"):
        _native.simulate(p, text, os.fspath(out), params_is_text=is_text)
    fd, tmp = tempfile.mkstemp(suffix=".parquet", prefix="drive_monitor_sim_")
    os.close(fd)
    try:
        _native.simulate(p, text, tmp, params_is_text=is_text)
        frame = pq.read_table(tmp).to_pandas()
        if out is not None and os.fspath(out).endswith(".parquet"):
            os.replace(tmp, os.fspath(out))
            tmp = None
        return frame
    finally:
        if tmp is not None and os.path.exists(tmp):
            os.remove(tmp)
