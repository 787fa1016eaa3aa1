"""The package's exception classes, defined here so that each can derive from the built-in
class Python's convention asks for (numpy and pandas follow it): a bad value is a
``ValueError``, a value of the wrong type a ``TypeError``. The extension raises these very
classes (``pyo3::import_exception!`` in ``python/src/lib.rs``); ``drive_monitor`` and
``drive_monitor._native`` export them.

- :class:`DriveMonitorError`: the base of every error the package raises.
- :class:`ParamsError`, :class:`LogError`, :class:`OptionError`, :class:`AnalysisError`:
  a bad value (a parameter file's, a log's, an option's content, a log the analysis cannot
  run on), so also ``ValueError``.
- :class:`ParamsNotFoundError`, :class:`LogNotFoundError`: the parameter file or the log
  does not exist, so also ``FileNotFoundError`` (``except FileNotFoundError`` catches a
  missing file, as Python's own ``open`` raises it; ``except LogError`` still does).
- :class:`ParamsTypeError`, :class:`LogTypeError`, :class:`OptionTypeError`: the same
  errors for a value of the wrong type (``parallel_paths=2.5``, ``from_s="1.5"``, a log that
  is a number), so also ``TypeError``; ``except OptionError`` still catches them.
- :class:`InternalError`: a bug (the library panicked), so also ``RuntimeError``.
"""

from __future__ import annotations

__all__ = [
    "DriveMonitorError",
    "ParamsError",
    "ParamsTypeError",
    "LogError",
    "LogTypeError",
    "ParamsNotFoundError",
    "LogNotFoundError",
    "OptionError",
    "OptionTypeError",
    "AnalysisError",
    "InternalError",
]


class DriveMonitorError(Exception):
    """Base of every drive_monitor error."""

    __module__ = "drive_monitor"


class ParamsError(DriveMonitorError, ValueError):
    """The parameter file cannot be read, or is not one (a bad value: also a ValueError)."""

    __module__ = "drive_monitor"


class ParamsTypeError(ParamsError, TypeError):
    """A parameter dict holds a value of a type no parameter file has (also a TypeError)."""

    __module__ = "drive_monitor"


class LogError(DriveMonitorError, ValueError):
    """The log cannot be read, or is not one (a bad value: also a ValueError)."""

    __module__ = "drive_monitor"


class ParamsNotFoundError(ParamsError, FileNotFoundError):
    """The parameter file does not exist (also a FileNotFoundError)."""

    __module__ = "drive_monitor"


class LogNotFoundError(LogError, FileNotFoundError):
    """The log file does not exist (also a FileNotFoundError)."""

    __module__ = "drive_monitor"


class LogTypeError(LogError, TypeError):
    """The log is of a type no log is (not a path nor data): also a TypeError."""

    __module__ = "drive_monitor"


class OptionError(DriveMonitorError, ValueError):
    """An option is wrong (a window, a baseline, a name), or the analysis refused the data
    (a bad value: also a ValueError)."""

    __module__ = "drive_monitor"


class OptionTypeError(OptionError, TypeError):
    """An option of the wrong type (``parallel_paths=2.5``, a str where a number goes):
    also a TypeError."""

    __module__ = "drive_monitor"


class AnalysisError(DriveMonitorError, ValueError):
    """The analysis could not run on this log (a bad value: also a ValueError)."""

    __module__ = "drive_monitor"


class InternalError(DriveMonitorError, RuntimeError):
    """A bug: the library panicked (please report it with the call)."""

    __module__ = "drive_monitor"
