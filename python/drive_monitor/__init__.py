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
    from the message. As Python's convention asks (numpy and pandas follow it), a bad value
    is also a ``ValueError`` and a value of the wrong type a ``TypeError``
    (:class:`OptionTypeError`, :class:`ParamsTypeError`, :class:`LogTypeError`:
    ``parallel_paths=2.5``, ``from_s="1.5"``), so ``except ValueError`` and ``except
    TypeError`` catch them; a file that does not exist is also a ``FileNotFoundError``
    (:class:`LogNotFoundError`, :class:`ParamsNotFoundError`); a bug is also a
    ``RuntimeError``. No Rust panic crosses into Python.
    The GIL is released while the library runs, so threads (and Dask) run in parallel.

The fleet run over many motors' logs on Dask is :func:`drive_monitor.fleet.diagnose_many`;
with ``store=`` it keeps each motor's history, whose trend :func:`trend` reads
(:mod:`drive_monitor.history`).
"""

from __future__ import annotations

# The helpers under underscore names: the package's namespace is its public API
# (`__all__`), so `dir(drive_monitor)` and completion show no `os`, `json` or `Dict`.
import ast as _ast
import inspect as _inspect
import json as _json
import numbers as _numbers
import os as _os
import tempfile as _tempfile
import textwrap as _textwrap
from pathlib import Path as _Path
from typing import TYPE_CHECKING as _TYPE_CHECKING
from typing import Any as _Any
from typing import Dict as _Dict
from typing import Iterable as _Iterable
from typing import List as _List
from typing import Optional as _Optional
from typing import Sequence as _Sequence
from typing import Tuple as _Tuple
from typing import Union as _Union

from . import _native
from ._errors import (
    AnalysisError,
    DriveMonitorError,
    InternalError,
    LogError,
    LogNotFoundError,
    LogTypeError,
    OptionError,
    OptionTypeError,
    ParamsError,
    ParamsNotFoundError,
    ParamsTypeError,
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

#: The package's version: the library's (its Cargo version, the wheel's too).
__version__: str = _native.__version__

#: The public API: everything else in the namespace is a submodule or has an underscore.
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
    "ParamsTypeError",
    "LogError",
    "LogTypeError",
    "LogNotFoundError",
    "ParamsNotFoundError",
    "OptionError",
    "OptionTypeError",
    "AnalysisError",
    "InternalError",
    "PathLike",
    "LogLike",
    "ParamsLike",
    "CommissionLike",
]

if _TYPE_CHECKING:  # pragma: no cover
    import pandas as pd

PathLike = _Union[str, "_os.PathLike[str]"]
#: A log: a path, a pandas DataFrame, a pyarrow Table, a dict of arrays, or any object
#: with ``__arrow_c_stream__``.
LogLike = _Any
ParamsLike = _Union[PathLike, _Dict[str, _Any]]
#: A commissioning window: ``(start_s, end_s)`` or the command line's ``"START:END"``.
CommissionLike = _Union[_Tuple[float, float], _Sequence[float], str]


def _toml_value(v: _Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(float(v)) if isinstance(v, float) else str(v)
    if isinstance(v, str):
        return _json.dumps(v)
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_toml_value(x)}" for k, x in v.items()) + " }"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise ParamsTypeError(f"the parameter dict: value {v!r} is not a number, text, table or list")


def _params_toml(params: _Dict[str, _Any]) -> str:
    """The TOML text of a parameter dict (sections of scalars; ``columns`` of tables)."""
    lines: _List[str] = []
    for section, table in params.items():
        if not isinstance(table, dict):
            raise ParamsTypeError(
                f"the parameter dict: section {section!r} is {table!r}, not a table of keys "
                f"(e.g. {{{section!r}: {{...}}}})"
            )
        lines.append(f"[{section}]")
        for k, v in table.items():
            lines.append(f"{k} = {_toml_value(v)}")
    return "\n".join(lines) + "\n"


def _params(params: ParamsLike) -> _Tuple[str, bool]:
    """(path or TOML text, is_text) for the native functions."""
    if isinstance(params, dict):
        return _params_toml(params), True
    if not isinstance(params, (str, _os.PathLike)):
        raise ParamsTypeError(
            f"params: a path (str or os.PathLike) or a dict of sections, not {_a_type(params)}"
        )
    return _os.fspath(params), False


def _a_type(v: _Any) -> str:
    """The type of ``v`` as a message names it, with its article (``a float``, ``an int``),
    as the extension's messages do."""
    name = type(v).__name__
    return f"{'an' if name[:1] in 'aeiou' else 'a'} {name}"


def _number(name: str, v: _Any) -> _Optional[float]:
    """A keyword that takes a number (an int or a float, numpy's too) as a float; ``None``
    as ``None``. A bool, a str or anything else is refused as the extension refuses
    ``diagnose``'s options: an :class:`OptionTypeError` naming the keyword, the type given
    and the one expected, never parsed from text."""
    if v is None:
        return None
    if isinstance(v, bool) or not isinstance(v, _numbers.Real):
        raise OptionTypeError(f"{name} = {v!r}: {_a_type(v)}, not a number (an int or a float)")
    return float(v)


def _count(name: str, v: _Any) -> _Optional[int]:
    """A keyword that takes a whole number (an int, numpy's too; never a bool or a float) of
    0 to 4294967295 (the library's ``u32``); ``None`` as ``None``. The wrong type is an
    :class:`OptionTypeError`, a number out of the range an :class:`OptionError` (a
    ``ValueError``), each naming the keyword."""
    if v is None:
        return None
    if isinstance(v, bool) or not isinstance(v, _numbers.Integral):
        raise OptionTypeError(f"{name} = {v!r}: {_a_type(v)}, not an int (a whole number)")
    if not 0 <= int(v) <= 0xFFFF_FFFF:
        raise OptionError(f"{name} = {v!r}: not a count (0 to 4294967295)")
    return int(v)


def _log(log: LogLike) -> _Tuple[_Any, _Optional[str]]:
    """(log, origin) for the native functions: a path as it is (origin ``None``), or data
    in memory as an object with ``__arrow_c_stream__`` and the name messages give it."""
    if isinstance(log, (str, _os.PathLike)):
        return _os.fspath(log), None
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
    raise LogTypeError(
        "log: a path, a pandas DataFrame, a pyarrow Table, a dict of arrays or an object with "
        f"__arrow_c_stream__, not {type(log).__name__}"
    )


def diagnose(
    log: LogLike,
    params: ParamsLike,
    baseline: _Optional[_Union[LogLike, _Sequence[LogLike]]] = None,
    group: _Optional[str] = None,
    **options: _Any,
) -> DiagnoseResult:
    """Replay a log through the monitor's core: lamps, the named fault with its size and
    phase, the shorted winding's phase, events, verdict (``sim-host diagnose``).

    Parameters
    ----------
    log : path, DataFrame, pyarrow Table or dict of arrays
        The measurement (see the module's doc for the columns).
    params : path or dict
        The motor's parameter file.
    baseline : log or list of logs, optional
        (One log, a path or data, is a list of one.)
        Healthy logs of the same motor (files, folders, or data): the winding's negative
        sequence is judged against their mean, their spread sets the least change.
    group : str, optional
        The TDMS group holding the channels.
    {options}
    Returns
    -------
    DiagnoseResult
        ``.verdict``, ``.candidates``, ``.isolation``, ``.unbalance``, ... (the JSON keys);
        ``.shorted_turns`` the level of a named short (fraction, low, high, basis);
        ``.timeline`` as a DataFrame; ``.to_dict()`` the command's ``--json`` document.

    Raises
    ------
    ParamsError, LogError, OptionError, AnalysisError
        A bad value (each also a ``ValueError``); a file that does not exist is a
        :class:`LogNotFoundError` or :class:`ParamsNotFoundError` (also a
        ``FileNotFoundError``).
    OptionTypeError, ParamsTypeError, LogTypeError
        A value of the wrong type (each also a ``TypeError``): ``parallel_paths=2.5``.
    """
    p, is_text = _params(params)
    base = _items(baseline)
    data, origin = _log(log)
    doc = _native.diagnose(
        data,
        p,
        log_origin=origin,
        params_is_text=is_text,
        baseline=[_log(b) for b in base],
        group=group,
        **options,
    )
    return DiagnoseResult(_json.loads(doc))


def _with_options(f: _Any, described: _List[_Tuple[str, str, str, str]]) -> _Any:
    """``f`` with the options of the library's one description (``_native.diagnose_options``:
    name, annotation, default, doc) in its signature, as keyword-only parameters in place of
    ``**options``, and in its docstring's parameters (where ``{options}`` stands)."""
    sig = _inspect.signature(f)
    kept = [p for p in sig.parameters.values() if p.kind is not p.VAR_KEYWORD]
    named = [
        _inspect.Parameter(name, _inspect.Parameter.KEYWORD_ONLY, default=_ast.literal_eval(default), annotation=ann)
        for name, ann, default, _doc in described
    ]
    f.__signature__ = sig.replace(parameters=kept + named)
    lines = []
    for name, ann, default, doc in described:
        lines.append(f"{name} : {ann}, default {default}")
        lines.extend("    " + w for w in _textwrap.wrap(doc, 80))
    f.__doc__ = (f.__doc__ or "").replace("{options}", "\n    ".join(lines) + "\n")
    return f


_with_options(diagnose, _native.diagnose_options())


def _items(value: _Any) -> _List[_Any]:
    """A list-valued parameter as a list: ``None`` as none, one text, path or data (a
    ``str``, an ``os.PathLike``, a DataFrame, ...) as one item, any other iterable as its
    items. ``effects="load_torque"`` is ``["load_torque"]``, never its letters."""
    if value is None:
        return []
    if isinstance(value, (str, bytes, _os.PathLike, dict)) or not isinstance(value, _Iterable):
        return [value]
    if hasattr(value, "__arrow_c_stream__") or type(value).__name__ == "DataFrame":
        return [value]
    return list(value)


def _analysis_kwargs(
    effects: _Optional[_Union[str, _Iterable[str]]],
    from_s: _Optional[float],
    to_s: _Optional[float],
    no_fit: bool,
    group: _Optional[str],
    laws: _Optional[PathLike] = None,
) -> _Dict[str, _Any]:
    names = _items(effects)
    for e in names:
        if not isinstance(e, str):
            raise OptionTypeError(f"effects = {effects!r}: {_a_type(e)}, not a str: give the effects' names")
    return dict(
        effects=names,
        from_s=_number("from_s", from_s),
        to_s=_number("to_s", to_s),
        no_fit=no_fit,
        group=group,
        laws=_laws_path(laws),
    )


def _laws_path(laws: _Optional[PathLike]) -> _Optional[str]:
    """A law file's path (``laws=``), or None; a value that is not a path is a TypeError."""
    if laws is None:
        return None
    if not isinstance(laws, (str, _os.PathLike)):
        raise OptionTypeError(f"laws = {laws!r}: {_a_type(laws)}, not a path: give the law file's path")
    return _os.fspath(laws)


def compare(
    log: LogLike,
    params: ParamsLike,
    effects: _Optional[_Union[str, _Iterable[str]]] = None,
    from_s: _Optional[float] = None,
    to_s: _Optional[float] = None,
    no_fit: bool = False,
    group: _Optional[str] = None,
    laws: _Optional[PathLike] = None,
) -> CompareResult:
    """Compare the paper's simplified model (with ``effects`` added) with the measurement:
    ``normalized_rms_error``, ``channels``, ``worst_windows`` (``sim-host compare``).

    ``effects`` names the effects already in the model: a list, or one name
    (``effects="load_torque"`` is ``["load_torque"]``); with ``laws`` (a law file,
    ``sim-host compare --laws``) the name of one of its laws too. ``from_s``/``to_s`` limit
    the analysed window [s] (at least 25 supply periods).

    Raises
    ------
    FileNotFoundError
        ``laws`` names no file.
    OptionError
        A law file with a mistake (one line naming the law, the position and the problem),
        or an effect name neither the library nor the laws have (with near matches).
    """
    p, is_text = _params(params)
    data, origin = _log(log)
    doc = _native.compare(
        data,
        p,
        log_origin=origin,
        params_is_text=is_text,
        **_analysis_kwargs(effects, from_s, to_s, no_fit, group, laws),
    )
    return CompareResult(_json.loads(doc))


def explain(
    log: LogLike,
    params: ParamsLike,
    effects: _Optional[_Union[str, _Iterable[str]]] = None,
    from_s: _Optional[float] = None,
    to_s: _Optional[float] = None,
    no_fit: bool = False,
    group: _Optional[str] = None,
    rotor_bars: _Optional[int] = None,
    ladder: bool = False,
    laws: _Optional[PathLike] = None,
) -> _Union[ExplainResult, LadderResult]:
    """Rank the physical effects missing from the model by how much of its error each
    explains: ``ranking``, ``verdict``, ``unexplained`` (``sim-host explain``).

    With ``ladder=True``, walk the ladder instead (``sim-host explain --ladder``): add the
    effect that lowers the held-back error most, keep it when the step passes its test, and
    go on until the error is within the noise-floor band or nothing plausible helps. The
    result (:class:`LadderResult`) has ``summary`` (what was found, where it ended, why it
    stopped), ``start``, ``ladder`` (one step each: ``effect`` (absent on the base rung),
    ``added``, ``base`` (the base parameters' changes), ``dropped``, ``fitted``, ``error``,
    ``heldback_error``, ``noise_floor``, ``ratio_to_floor``, ``significance``, ...),
    ``base_changes``, ``final_fit`` (the chosen model refitted on the whole log), ``stop``
    and ``stopped_because``; ``.ladder_frame`` is the steps as a DataFrame, ``.base_frame``
    the six base parameters against the file.

    ``laws`` is a file of your own laws (``sim-host explain --laws``): each is a candidate
    beside the library's effects, fitted and judged the same way and reported by its name.
    A missing file raises ``FileNotFoundError``, a law with a mistake ``OptionError`` (a
    ``ValueError``)."""
    p, is_text = _params(params)
    data, origin = _log(log)
    doc = _native.explain(
        data,
        p,
        log_origin=origin,
        params_is_text=is_text,
        rotor_bars=_count("rotor_bars", rotor_bars),
        ladder=ladder,
        **_analysis_kwargs(effects, from_s, to_s, no_fit, group, laws),
    )
    if ladder:
        return LadderResult(_json.loads(doc))
    return ExplainResult(_json.loads(doc))


def identify(
    log: LogLike,
    params: ParamsLike,
    from_s: _Optional[float] = None,
    to_s: _Optional[float] = None,
    group: _Optional[str] = None,
    keep_columns: bool = False,
) -> IdentifyResult:
    """Identify the motor's circuit (Rs, Rr, the leakage, Lm) and J, B + Bl from a log of
    its healthy running, starting from ``params`` (``sim-host identify``).

    ``.identification.estimates`` holds each value with its 95 % interval;
    ``.toml`` is the identified parameter file's text, without the start file's
    ``[columns]`` table unless ``keep_columns=True`` (as ``sim-host identify --keep-columns``:
    the identified file then reads only the DAQ's logs). A log the start file's motor cannot
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
        from_s=_number("from_s", from_s),
        to_s=_number("to_s", to_s),
        group=group,
        keep_columns=bool(keep_columns),
    )
    return IdentifyResult(_json.loads(doc))


def params_from_nameplate(
    power_kw: float,
    voltage_v: float,
    current_a: float,
    frequency_hz: float,
    speed_rpm: float,
    power_factor: float,
    efficiency: float,
    poles: _Optional[int] = None,
    connection: str = "star",
    locked_rotor_ratio: _Optional[float] = None,
    nema_design: str = "B",
    columns_from: _Optional[PathLike] = None,
) -> NameplateResult:
    """A parameter file estimated from a motor's nameplate, each value with its range and
    source (``sim-host params from-nameplate``). ``.toml`` is the file's text, ``.params``
    the file as a dict (usable as ``params`` by the other functions)."""
    doc = _native.params_from_nameplate(
        _number("power_kw", power_kw),
        _number("voltage_v", voltage_v),
        _number("current_a", current_a),
        _number("frequency_hz", frequency_hz),
        _number("speed_rpm", speed_rpm),
        _number("power_factor", power_factor),
        _number("efficiency", efficiency),
        poles=_count("poles", poles),
        connection=connection,
        locked_rotor_ratio=_number("locked_rotor_ratio", locked_rotor_ratio),
        nema_design=nema_design,
        columns_from=None if columns_from is None else _os.fspath(columns_from),
    )
    return NameplateResult(_json.loads(doc))


def simulate(
    params: ParamsLike,
    scenario: _Union[PathLike, str],
    out: _Optional[PathLike] = None,
    laws: _Optional[PathLike] = None,
) -> "pd.DataFrame":
    """Simulate the motor of ``params`` through ``scenario`` (a scenario file, or its TOML
    text) with the project's simulator (``sim-host simulate``).

    Returns the log as a pandas DataFrame with the schema's columns (``t_s``, ``va_V``, ...,
    SI units), and writes it to ``out`` too when given (CSV, TDMS or Parquet by extension),
    whole or not at all. ``laws`` (a law file, ``sim-host simulate --laws``) injects each of
    its laws at its parameters' start values.

    Raises
    ------
    OptionError
        ``out`` is the parameter file or the scenario file (by any path, ``./`` spelling or
        link): "refusing to overwrite the input ...", and nothing is written.
    ParamsError, OptionError
        A bad parameter file or scenario.
    """
    import pyarrow.parquet as pq

    is_file = isinstance(scenario, _os.PathLike) or (
        isinstance(scenario, str) and "\n" not in scenario and _Path(scenario).exists()
    )
    p, is_text = _params(params)
    kwargs = dict(params_is_text=is_text, scenario_is_text=not is_file, laws=_laws_path(laws))
    if out is not None:
        # The library checks `out` against the parameter file and the scenario file before
        # anything is written (an OptionError naming both), then writes it atomically.
        _native.simulate(p, _os.fspath(scenario), _os.fspath(out), **kwargs)
        if _os.fspath(out).lower().endswith(".parquet"):
            return pq.read_table(_os.fspath(out)).to_pandas()
    fd, tmp = _tempfile.mkstemp(suffix=".parquet", prefix="drive_monitor_sim_")
    _os.close(fd)
    try:
        _native.simulate(p, _os.fspath(scenario), tmp, **kwargs)
        return pq.read_table(tmp).to_pandas()
    finally:
        if _os.path.exists(tmp):
            _os.remove(tmp)


# `from __future__ import annotations` binds `annotations` in the namespace; the flag it
# sets stays with the code compiled above.
del annotations
