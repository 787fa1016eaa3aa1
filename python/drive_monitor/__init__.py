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
    In-memory data goes to the library through Arrow's C stream interface (no temporary
    file) and is read through the same path as a file: the same results, and messages that
    name it ("DataFrame: missing column 'ia_A'"). Any object with ``__arrow_c_stream__``
    (a polars DataFrame, ...) is read too.

Parameter files
    A path, or a dict with the file's sections (``{"motor": {...}, "supply": {...},
    "columns": {...}}``).

Errors
    :class:`DriveMonitorError` and its subclasses :class:`ParamsError` (a parameter file or
    dict, a fleet's motor table), :class:`LogError`, :class:`OptionError`,
    :class:`AnalysisError` (and :class:`InternalError` for a bug), each carrying the
    command line's one-line message; the class is the library error's kind, never read
    from the message. No Rust panic crosses into Python.
    The GIL is released while the library runs, so threads (and Dask) run in parallel.

The fleet run over many motors' logs on Dask is :func:`drive_monitor.fleet.diagnose_many`;
with ``store=`` it keeps each motor's history, whose trend :func:`trend` reads
(:mod:`drive_monitor.history`).
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, Any, Dict, Iterable, List, Optional, Sequence, Tuple, Union

from . import _native
from ._native import (
    AnalysisError,
    DriveMonitorError,
    InternalError,
    LogError,
    OptionError,
    ParamsError,
)
from .history import Trend, trend
from ._results import (
    CompareResult,
    DiagnoseResult,
    ExplainResult,
    IdentifyResult,
    LadderResult,
    NameplateResult,
    Result,
)

__all__ = [
    "trend",
    "Trend",
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
    "LadderResult",
    "IdentifyResult",
    "NameplateResult",
    "DriveMonitorError",
    "ParamsError",
    "LogError",
    "OptionError",
    "AnalysisError",
    "InternalError",
]

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd

PathLike = Union[str, "os.PathLike[str]"]
#: A log: a path, a pandas DataFrame, a pyarrow Table, a dict of arrays, or any object
#: with ``__arrow_c_stream__``.
LogLike = Any
ParamsLike = Union[PathLike, Dict[str, Any]]
#: A commissioning window: ``(start_s, end_s)`` or the command line's ``"START:END"``.
CommissionLike = Union[Tuple[float, float], Sequence[float], str]


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
    raise ParamsError(f"the parameter dict: value {v!r} is not a number, text, table or list")


def _params_toml(params: Dict[str, Any]) -> str:
    """The TOML text of a parameter dict (sections of scalars; ``columns`` of tables)."""
    lines: List[str] = []
    for section, table in params.items():
        if not isinstance(table, dict):
            raise ParamsError(
                f"the parameter dict: section {section!r} is {table!r}, not a table of keys "
                f"(e.g. {{{section!r}: {{...}}}})"
            )
        lines.append(f"[{section}]")
        for k, v in table.items():
            lines.append(f"{k} = {_toml_value(v)}")
    return "\n".join(lines) + "\n"


def _params(params: ParamsLike) -> Tuple[str, bool]:
    """(path or TOML text, is_text) for the native functions."""
    if isinstance(params, dict):
        return _params_toml(params), True
    return os.fspath(params), False


def _log(log: LogLike) -> Tuple[Any, Optional[str]]:
    """(log, origin) for the native functions: a path as it is (origin ``None``), or data
    in memory as an object with ``__arrow_c_stream__`` and the name messages give it."""
    if isinstance(log, (str, os.PathLike)):
        return os.fspath(log), None
    import pyarrow as pa

    if isinstance(log, pa.Table):
        return log, "pyarrow Table"
    try:
        import pandas as pd

        if isinstance(log, pd.DataFrame):
            return pa.Table.from_pandas(log, preserve_index=False), "DataFrame"
    except ImportError:  # pragma: no cover - pandas is a dependency
        pass
    if isinstance(log, dict):
        import numpy as np

        try:
            return pa.table({str(k): np.asarray(v) for k, v in log.items()}), "dict"
        except (pa.ArrowException, ValueError, TypeError) as e:
            raise LogError(f"dict: not a table of columns of one length ({e})") from None
    if hasattr(log, "__arrow_c_stream__"):
        return log, type(log).__name__
    raise LogError(
        "log: a path, a pandas DataFrame, a pyarrow Table, a dict of arrays or an object with "
        f"__arrow_c_stream__, not {type(log).__name__}"
    )


def _commission(commission: Optional[CommissionLike]) -> Optional[Union[Tuple[float, float], str]]:
    """The window as the library takes it: ``"START:END"`` as given (the library's one
    parser reads it), a pair as ``(start_s, end_s)``; the library checks both."""
    if commission is None or isinstance(commission, str):
        return commission
    how = "give (start_s, end_s) or 'START:END' in seconds, e.g. (1.5, 2.4) or '1.5:2.4'"
    if not isinstance(commission, (tuple, list)):
        raise OptionError(f"commission = {commission!r}: {how}")
    if len(commission) != 2:
        raise OptionError(f"commission = {commission!r}: two values, the start and the end; {how}")
    try:
        a, b = (float(x) for x in commission)
    except (TypeError, ValueError):
        raise OptionError(f"commission = {commission!r}: not numbers; {how}") from None
    return a, b


def diagnose(
    log: LogLike,
    params: ParamsLike,
    commission: Optional[CommissionLike] = None,
    baseline: Optional[Union[LogLike, Sequence[LogLike]]] = None,
    load: Optional[str] = None,
    angle: Optional[str] = None,
    residuals: Optional[str] = None,
    allow_incomplete: bool = False,
    timeline_step: Optional[float] = None,
    group: Optional[str] = None,
    parallel_paths: Optional[int] = None,
    turn_calibration: Optional[Union[str, Dict[str, Any]]] = None,
) -> DiagnoseResult:
    """Replay a log through the monitor's core: lamps, the named fault with its size and
    phase, the shorted winding's phase, events, verdict (``sim-host diagnose``).

    Parameters
    ----------
    log : path, DataFrame, pyarrow Table or dict of arrays
        The measurement (see the module's doc for the columns).
    params : path or dict
        The motor's parameter file.
    commission : (start_s, end_s) or "START:END", optional
        Learn the healthy thresholds over this window of the log [s] (``(1.5, 2.4)`` or
        the command line's ``"1.5:2.4"``).
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
        Timeline resolution [s] (default: the command line's, 0.5 s); finite and > 0, a
        step of 0 is refused (``OptionError``) as on the command line.
    group : str, optional
        The TDMS group holding the channels.
    parallel_paths : int, optional
        Parallel paths of each phase of the winding, 1..8 (1, the default; 2 for a double star):
        the shorted-turn level is sized with one path's resistance.
    turn_calibration : path or dict, optional
        A calibration of the shorted-turn level learned from labelled runs of the same
        motor (the JSON of ``sim-host diagnose --turn-calibration``): the level is read from
        it instead of the model (``.shorted_turns["basis"]`` says which).

    Returns
    -------
    DiagnoseResult
        ``.verdict``, ``.candidates``, ``.isolation``, ``.unbalance``, ... (the JSON keys);
        ``.shorted_turns`` the level of a named short (fraction, low, high, basis);
        ``.timeline`` as a DataFrame; ``.to_dict()`` the command's ``--json`` document.

    Raises
    ------
    ParamsError, LogError, OptionError, AnalysisError
    """
    p, is_text = _params(params)
    window = _commission(commission)
    base = [] if baseline is None else (
        list(baseline) if isinstance(baseline, (list, tuple)) else [baseline]
    )
    data, origin = _log(log)
    doc = _native.diagnose(
        data,
        p,
        log_origin=origin,
        params_is_text=is_text,
        commission=window,
        baseline=[_log(b) for b in base],
        load=load,
        angle=angle,
        residuals=residuals,
        allow_incomplete=allow_incomplete,
        timeline_step=None if timeline_step is None else float(timeline_step),
        group=group,
        parallel_paths=None if parallel_paths is None else int(parallel_paths),
        turn_calibration=_calibration_text(turn_calibration),
    )
    return DiagnoseResult(json.loads(doc))


def _calibration_text(cal: Optional[Union[str, Dict[str, Any]]]) -> Optional[str]:
    """A shorted-turn calibration as its JSON text: a dict as it is, a path read."""
    if cal is None:
        return None
    if isinstance(cal, dict):
        return json.dumps(cal)
    return Path(cal).read_text()


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
    data, origin = _log(log)
    doc = _native.compare(
        data,
        p,
        log_origin=origin,
        params_is_text=is_text,
        **_analysis_kwargs(effects, from_s, to_s, no_fit, group),
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
    ladder: bool = False,
) -> Union[ExplainResult, LadderResult]:
    """Rank the physical effects missing from the model by how much of its error each
    explains: ``ranking``, ``verdict``, ``unexplained`` (``sim-host explain``).

    With ``ladder=True``, walk the ladder instead (``sim-host explain --ladder``): add the
    effect that lowers the held-back error most, keep it when the step passes its test, and
    go on until the error is within the noise-floor band or nothing plausible helps. The
    result (:class:`LadderResult`) has ``start``, ``ladder`` (one step each: ``effect``,
    ``added``, ``fitted``, ``error``, ``heldback_error``, ``noise_floor``,
    ``ratio_to_floor``, ``significance``, ...), ``stop`` and ``stopped_because``;
    ``.ladder_frame`` is the steps as a DataFrame."""
    p, is_text = _params(params)
    data, origin = _log(log)
    doc = _native.explain(
        data,
        p,
        log_origin=origin,
        params_is_text=is_text,
        rotor_bars=rotor_bars,
        ladder=ladder,
        **_analysis_kwargs(effects, from_s, to_s, no_fit, group),
    )
    if ladder:
        return LadderResult(json.loads(doc))
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
    data, origin = _log(log)
    doc = _native.identify(
        data,
        p,
        log_origin=origin,
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
) -> "pd.DataFrame":
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
