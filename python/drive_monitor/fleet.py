"""Many motors' logs judged on Dask (``diagnose_many``): one row per log.

The motor table says which parameter file, commissioning window, healthy baseline and load
belong to which motor, and which logs are its (a pattern on the file name); it is the
``sim-host fleet`` command's table (docs/python.md), given as a TOML file or as rows (a
pandas DataFrame or a list of dicts with the keys ``name``, ``params``, ``logs`` and,
optionally, ``commission``, ``baseline``, ``load``, ``time_from_name``).

Each log is one Dask task: the worker fetches it (any fsspec URL: ``s3://``, ``gs://``,
``abfs://``, ``http(s)://``; local paths as they are), runs the library's diagnosis (the GIL
released) and returns the row. A bad file is a row with its ``error``; the run never fails for
one log. The scheduling, retries and placement are Dask's.

With ``store=PATH`` each judged log is also kept in the motors' history (the store
``sim-host fleet --store`` writes; :func:`drive_monitor.trend` reads it): the workers return
the rows, and the client appends them as they come, in one place (one writer, one
transaction per log), skipping logs already stored.
"""

from __future__ import annotations

import json as _json
import os as _os
import tempfile as _tempfile
import typing as _typing
import warnings as _warnings
from pathlib import Path as _Path

from . import _native
from ._errors import OptionError, ParamsError, ParamsTypeError

# The module's namespace holds its own names only (``__all__``, the helpers, the errors):
# the standard library's modules under private names, the typing names for type checkers
# alone (the annotations are not evaluated: ``from __future__ import annotations``).
if _typing.TYPE_CHECKING:  # pragma: no cover
    from typing import Any, Dict, List, Optional, Sequence, Union

    import distributed
    import pandas as pd

__all__ = ["diagnose_many", "local_cluster", "worker_environ", "motor_table_toml", "COLUMNS"]

#: The fleet table's columns, in order (the same as ``sim-host fleet``'s CSV header).
COLUMNS: List[str] = list(_native.fleet_columns())


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(float(v))
    if isinstance(v, (str, _os.PathLike)):
        return _json.dumps(_os.fspath(v))
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise ParamsTypeError(f"the motor table (rows): value {v!r} is not a number, text or list")


def worker_environ() -> Dict[str, str]:
    """The environment a fleet worker process runs best in, set before it starts (Dask's
    ``distributed.nanny.pre-spawn-environ``; on a real cluster, the workers' environment):

    - ``MALLOC_ARENA_MAX=1``, ``MALLOC_MMAP_MAX_=0``, ``MALLOC_TRIM_THRESHOLD_=2147483647``:
      glibc keeps freed memory for reuse instead of handing the log-sized series back to the
      kernel after every log (the ``sim-host`` binary does the same with ``mallopt``); without
      it a worker spends a fifth of its time on page faults;
    - ``RAYON_NUM_THREADS=1``: one thread per single-threaded worker (Dask runs one worker
      per core), no oversubscription.
    """
    return {
        "MALLOC_ARENA_MAX": "1",
        "MALLOC_MMAP_MAX_": "0",
        "MALLOC_TRIM_THRESHOLD_": "2147483647",
        "RAYON_NUM_THREADS": "1",
    }


def local_cluster(n_workers: Optional[int] = None) -> "distributed.LocalCluster":
    """A ``LocalCluster`` for the fleet run: one single-threaded worker process per core
    (``n_workers`` to choose), each started with :func:`worker_environ`."""
    import dask
    from dask.distributed import LocalCluster

    with dask.config.set({"distributed.nanny.pre-spawn-environ": worker_environ()}):
        return LocalCluster(
            n_workers=n_workers or _os.cpu_count() or 1, threads_per_worker=1, processes=True
        )


def _is_path(motors: Any) -> bool:
    return isinstance(motors, (str, _os.PathLike))


def motor_table_toml(motors: Any, base: Optional[Union[str, "_os.PathLike[str]"]] = None) -> str:
    """The TOML text of a motor table read from a TOML file (a path), or given as rows (a
    DataFrame or a list of dicts), checked by the library (relative paths from ``base``:
    by default the file's folder, or the working directory for rows).

    Raises
    ------
    ParamsError
        Naming the file (or "the motor table (rows)"): it cannot be read, it is not a motor
        table (an unknown key, a motor without ``params``, no motor at all, ...).
    """
    if _is_path(motors):
        path = _Path(_os.fspath(motors))
        folder = base if base is not None else path.resolve().parent
        return _native.fleet_read_table(_os.fspath(path), _os.fspath(folder))
    try:
        import pandas as pd

        if isinstance(motors, pd.DataFrame):
            motors = motors.to_dict(orient="records")
    except ImportError:  # pragma: no cover
        pass
    if not isinstance(motors, (list, tuple)) or not all(isinstance(m, dict) for m in motors):
        raise ParamsTypeError(
            "the motor table: give a TOML file's path, a DataFrame or a list of dicts "
            f"(name, params, logs, ...), not {type(motors).__name__}"
        )
    out = []
    for m in motors:
        out.append("[[motor]]")
        for k, v in m.items():
            if v is None or (isinstance(v, float) and v != v):
                continue
            if k == "baseline" and isinstance(v, (str, _os.PathLike)):
                v = [v]  # one healthy log (or folder) is a list of one, not its letters
            out.append(f"{k} = {_toml_value(v)}")
    text = "\n".join(out) + "\n"
    _native.fleet_check_table(text, "the motor table (rows)", _os.fspath(base or _os.getcwd()))
    return text


def _expand(logs: Union[str, Sequence[str]], storage_options: Optional[Dict[str, Any]]) -> List[str]:
    """The logs: a list as given, or a glob (local or fsspec URL) expanded."""
    if isinstance(logs, (str, _os.PathLike)):
        pattern = _os.fspath(logs)
        if any(c in pattern for c in "*?["):
            import fsspec

            fs, _, paths = fsspec.get_fs_token_paths(pattern, storage_options=storage_options or {})
            if not paths:
                # The command line's words (monitor_api's FleetError::NoMatch), once.
                raise OptionError(f"logs: the pattern '{pattern}' matches no file")
            protocol = fs.protocol if isinstance(fs.protocol, str) else fs.protocol[0]
            if protocol in ("file", "local"):
                return sorted(paths)
            return sorted(f"{protocol}://{p}" for p in paths)
        return [pattern]
    return [_os.fspath(x) for x in logs]


def _is_remote(log: str) -> bool:
    return "://" in log and not log.startswith("file://")


def _fetch(log: str, storage_options: Optional[Dict[str, Any]]) -> str:
    """A remote log copied (in 4 MiB chunks) to a local temporary file of the same
    extension; its path (the caller removes it)."""
    import fsspec

    suffix = _Path(log.split("?", 1)[0]).suffix
    fd, tmp = _tempfile.mkstemp(suffix=suffix, prefix="drive_monitor_fleet_")
    _os.close(fd)
    try:
        with fsspec.open(log, "rb", **(storage_options or {})) as src, open(tmp, "wb") as dst:
            while True:
                chunk = src.read(1 << 22)
                if not chunk:
                    break
                dst.write(chunk)
    except BaseException:
        _os.remove(tmp)
        raise
    return tmp


def _row(log: str, table_toml: str, base: str, storage_options: Optional[Dict[str, Any]]) -> Dict[str, Any]:
    """One log's row, on a worker: fetched if remote, diagnosed, its row (never raises)."""
    shown = log
    local = log[len("file://"):] if log.startswith("file://") else log
    tmp = None
    try:
        if _is_remote(log):
            tmp = _fetch(log, storage_options)
            local = tmp
        return _json.loads(_native.fleet_row(table_toml, base, local, shown))
    except Exception as e:  # a worker's own failure (a fetch) is the row's error too
        row = {c: None for c in COLUMNS}
        row.update(motor="", file=shown, error=f"{type(e).__name__}: {e}")
        return row
    finally:
        if tmp is not None and _os.path.exists(tmp):
            _os.remove(tmp)


def _remote_time(log: str, storage_options: Optional[Dict[str, Any]]) -> Optional[int]:
    """A remote log's modification time [s since 1970 UTC], where its store says one."""
    try:
        import fsspec

        fs, path = fsspec.core.url_to_fs(log, **(storage_options or {}))
        info = fs.info(path)
    except Exception:  # no time: the fetched copy's own
        return None
    for key in ("mtime", "LastModified", "last_modified", "updated", "created"):
        v = info.get(key)
        if v is None:
            continue
        if hasattr(v, "timestamp"):
            return int(v.timestamp())
        try:
            return int(float(v))
        except (TypeError, ValueError):
            continue
    return None


def _store_row(
    log: str, table_toml: str, base: str, storage_options: Optional[Dict[str, Any]]
) -> Dict[str, Any]:
    """One log's fleet row, store row and time, on a worker (never raises): the time from
    the log itself, else its name (``time_from_name``), else the file's modification time
    (a remote file's, where its store says one), as ``sim-host fleet --store``."""
    local = log[len("file://"):] if log.startswith("file://") else log
    tmp = None
    try:
        modified_s = None
        if _is_remote(log):
            modified_s = _remote_time(log, storage_options)
            tmp = _fetch(log, storage_options)
            local = tmp
        return _json.loads(
            _native.fleet_store_row_timed(table_toml, base, local, log, modified_s)
        )
    except Exception as e:
        row = {c: None for c in COLUMNS}
        row.update(motor="", file=log, error=f"{type(e).__name__}: {e}")
        return {"row": row, "stored": None, "time": None}
    finally:
        if tmp is not None and _os.path.exists(tmp):
            _os.remove(tmp)


def _gather_into_store(
    client: Any, futures: List[Any], store: str, table_toml: str, base: str
) -> List[Dict[str, Any]]:
    """The workers' rows in the logs' order, each store row appended as its log finishes
    (here, in the client: the store's one writer); then a warning (``UserWarning``) for
    each thing the stored logs' times have to say (times that are files' modification
    times, names ``time_from_name`` does not read), the command line's lines."""
    from dask.distributed import as_completed

    index = {f.key: i for i, f in enumerate(futures)}
    rows: List[Optional[Dict[str, Any]]] = [None] * len(futures)
    times: List[Any] = []
    for fut in as_completed(futures):
        out = fut.result()
        rows[index[fut.key]] = out["row"]
        if out["stored"] is not None:
            stored, _ = _native.store_append(store, _json.dumps([out["stored"]]))
            if stored and out.get("time") is not None:
                times.append([out["stored"]["motor"], out["time"]])
    for line in _native.fleet_time_warnings(table_toml, base, _json.dumps(times)):
        if line.startswith("warning: "):
            line = line[len("warning: "):]
        _warnings.warn(line, UserWarning, stacklevel=3)
    return [r for r in rows if r is not None]


def diagnose_many(
    logs: Union[str, Sequence[str]],
    motors: Any,
    client: Any = None,
    storage_options: Optional[Dict[str, Any]] = None,
    base: Optional[Union[str, "_os.PathLike[str]"]] = None,
    store: Optional[Union[str, "_os.PathLike[str]"]] = None,
) -> "pd.DataFrame":
    """Diagnose many motors' logs on a Dask cluster; one row per log.

    Parameters
    ----------
    logs : list of paths/URLs, or a glob (local or any fsspec URL: ``s3://bucket/logs/*.csv``)
        The logs (CSV, TDMS or Parquet); one path is a list of one.
    motors : path to a motor table (TOML), a DataFrame, or a list of dicts
        Which parameter file, commissioning window, baseline and load belong to which motor,
        and which logs are its (``logs``: a pattern on the file name).
    client : dask.distributed.Client, optional
        Where to run. Default: :func:`local_cluster` (one single-threaded worker process per
        core, started with :func:`worker_environ`), closed at the end.
    storage_options : dict, optional
        fsspec's options for remote logs (credentials, endpoints).
    base : path, optional
        The folder the motor table's relative paths start from (default: the table file's
        folder, or the working directory for rows).
    store : path, optional
        Also append each judged log to this store of the motors' history (SQLite, and its
        Parquet mirror in ``store + ".parquet"``), in the client as the logs finish; a log
        already stored is not stored twice. Its motor is the table's name; its time the
        log's own (a time column of timestamps in the parameter file's ``[columns]``, a
        TDMS ``wf_start_time``), else the date in its file name by the motor's
        ``time_from_name`` pattern, else the file's modification time, and a
        ``UserWarning`` says when times are modification times (docs/trend.md).

    Returns
    -------
    pandas.DataFrame
        One row per log, columns :data:`COLUMNS`: motor, file, rows, rate_hz, verdict, fault,
        size, phase, confidence, first_detection_s, load_moves, data_quality, error.

    Raises
    ------
    ParamsError
        The motor table cannot be read or is not one (naming the file).
    OptionError
        A glob that matches no file (naming the pattern); a ``store`` that is one of the
        files the run reads (the motor table, a parameter file, a baseline, a log), refused
        before anything is written.
    """
    import pandas as pd

    if base is None:
        base = (
            str(_Path(_os.fspath(motors)).resolve().parent) if _is_path(motors) else _os.getcwd()
        )
    table = motor_table_toml(motors, base)
    paths = _expand(logs, storage_options)
    if store is not None:
        # Before anything is written: the store may not be a file the run reads.
        local = [p[len("file://"):] if p.startswith("file://") else p for p in paths]
        _native.fleet_check_outputs(
            table,
            _os.fspath(base),
            _os.fspath(motors) if _is_path(motors) else None,
            [p for p in local if not _is_remote(p)],
            _os.fspath(store),
        )
    own = client is None
    cluster = None
    if own:
        from dask.distributed import Client

        cluster = local_cluster()
        client = Client(cluster)
    try:
        futures = client.map(
            _row if store is None else _store_row,
            paths,
            table_toml=table,
            base=_os.fspath(base),
            storage_options=storage_options,
            pure=False,
        )
        if store is None:
            rows = client.gather(futures)
        else:
            rows = _gather_into_store(client, futures, _os.fspath(store), table, _os.fspath(base))
    finally:
        if own:
            client.close()
            if cluster is not None:
                cluster.close()
    return pd.DataFrame(rows, columns=COLUMNS)
