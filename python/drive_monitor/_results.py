"""Typed results: the command's JSON document with its keys as attributes.

``Result.to_dict()`` returns the document exactly as the command line's ``--json`` prints
it; attribute access returns nested :class:`Result` objects for tables, lists of them for
lists of tables, and plain values otherwise. The time series come as pandas DataFrames.
"""

from __future__ import annotations

import copy
from typing import Any, Dict, List, Optional


class Result:
    """A JSON document whose keys are attributes (``r.isolation.events``)."""

    def __init__(self, doc: Dict[str, Any]):
        object.__setattr__(self, "_doc", doc)

    def to_dict(self) -> Dict[str, Any]:
        """The document, as the command line's ``--json`` prints it (a deep copy)."""
        return copy.deepcopy(self._doc)

    def keys(self) -> List[str]:
        """The document's keys."""
        return list(self._doc.keys())

    def __getattr__(self, name: str) -> Any:
        try:
            return _wrap(self._doc[name])
        except KeyError:
            raise AttributeError(
                f"{type(self).__name__} has no key {name!r} (keys: {', '.join(self._doc)})"
            ) from None

    def __getitem__(self, name: str) -> Any:
        return _wrap(self._doc[name])

    def __contains__(self, name: object) -> bool:
        return name in self._doc

    def __dir__(self) -> List[str]:
        return sorted(set(super().__dir__()) | set(self._doc))

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError("results are read-only: use to_dict() for a copy to change")

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Result) and self._doc == other._doc

    def __repr__(self) -> str:
        keys = ", ".join(list(self._doc)[:6])
        more = ", ..." if len(self._doc) > 6 else ""
        return f"{type(self).__name__}({keys}{more})"


def _wrap(v: Any) -> Any:
    if isinstance(v, dict):
        return Result(v)
    if isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
        return [Result(x) for x in v]
    return v


def _frame(rows: List[Dict[str, Any]]):
    import pandas as pd

    return pd.DataFrame(rows)


class DiagnoseResult(Result):
    """``diagnose``'s report. Keys: ``verdict`` (``fault``, ``watching``, ``healthy``,
    ``could_not_judge``), ``verdict_line`` (the one line every output shows),
    ``verdict_finding`` (the finding the verdict rests on: ``source``, ``state``, ``fault``,
    ``size``, ``size_unit``, ``phase``, ``confidence``, ``against``, ``summary``),
    ``findings`` (one per analysis), ``judged``, ``not_judged``,
    ``verdict_withheld_because``, ``lamps``, ``candidates``, ``isolation``, ``unbalance``,
    ``rotor``, ``commissioning``, ``data_quality``, ``first_detection_s``, ``timeline``, ...
    (docs/isolation.md, "One verdict from all the evidence")."""

    @property
    def findings_frame(self):
        """The analyses' findings as a DataFrame, one row per analysis (``source``:
        residuals, winding, rotor, operating_point, parameter_fit, data_quality; ``state``,
        ``fault``, ``size``, ``size_unit``, ``phase``, ``confidence``, ``against``,
        ``summary``): what the verdict was decided from."""
        return _frame(self._doc.get("findings", []))

    @property
    def timeline(self):
        """The timeline as a DataFrame: one row per point (``t_s``; ``r1``..``r4`` the
        normalised residuals; ``lamp_r1``..``lamp_r4``; ``speed_rad_s``; the states).
        ``to_dict()["timeline"]`` keeps the JSON's list."""
        rows = []
        for p in self._doc.get("timeline", []):
            row = {k: v for k, v in p.items() if k not in ("residuals", "lamps")}
            for k, (r, lit) in enumerate(zip(p.get("residuals", []), p.get("lamps", []))):
                row[f"r{k + 1}"] = r
                row[f"lamp_r{k + 1}"] = lit
            rows.append(row)
        return _frame(rows)

    @property
    def events(self):
        """The isolation's events (names and load moves, with times) as a DataFrame."""
        return _frame(self._doc.get("isolation", {}).get("events", []))

    @property
    def shorted_turns(self) -> Optional[Dict[str, Any]]:
        """How many turns are shorted in the named phase (``unbalance.shorted_turns``):
        ``phase``, ``fraction`` of its turns, the interval ``low``..``high``, ``basis``
        (``physics``: the model, no labels; ``calibration``: learned from labelled runs),
        ``loop_ratio``; None without a named phase."""
        return self._doc.get("unbalance", {}).get("shorted_turns")

    @property
    def segments(self):
        """The negative sequence's steady stretches (``unbalance.segments``) as a
        DataFrame."""
        return _frame(self._doc.get("unbalance", {}).get("segments", []))


class _LeftoverMixin:
    """Where the model's remaining error lives (the document's ``leftover``)."""

    @property
    def leftover_lines(self):
        """The strongest spectral lines of the model's remaining error (``leftover.lines``)
        as a DataFrame: ``frequency_hz``, its ``reading`` (``shaft_frequency``,
        ``twice_slip_frequency``, ``supply_frequency``, ``not_named``) with its
        ``multiple`` and the ``expected_hz`` on this log, ``says`` (the reading in words),
        ``share`` of the error, ``amplitude`` and ``unit`` in the ``equation`` it is
        strongest in; empty where nothing is left to place (or no leftover was computed)."""
        doc = self._doc.get("leftover") or {}
        keep = (
            "frequency_hz",
            "reading",
            "multiple",
            "expected_hz",
            "says",
            "share",
            "amplitude",
            "unit",
            "equation",
            "prominence",
        )
        import pandas as pd

        rows = [{k: x.get(k) for k in keep} for x in doc.get("lines", [])]
        return pd.DataFrame(rows, columns=list(keep))


class CompareResult(_LeftoverMixin, Result):
    """``compare``'s report. Keys: ``effects``, ``normalized_rms_error``, ``noise_floor``,
    ``channels``, ``worst_windows``, ``base_parameters``, ``unbalance``, ``data_quality``,
    ``leftover`` (where the error lives: ``equations``, ``in_time``, ``windows``,
    ``spectrum``, ``lines`` each with ``frequency_hz`` and ``reading``, ``follows``,
    ``shaft_angle``, ``hint``, ``summary``; ``.leftover_lines`` is its lines as a
    DataFrame)."""

    @property
    def channels_frame(self):
        """Per-channel RMS errors as a DataFrame."""
        return _frame(self._doc.get("channels", []))

    @property
    def worst_windows_frame(self):
        """The windows where the model fails most, as a DataFrame (the condition flattened)."""
        rows = []
        for w in self._doc.get("worst_windows", []):
            row = {k: v for k, v in w.items() if k != "condition"}
            row.update({f"condition_{k}": v for k, v in (w.get("condition") or {}).items()})
            rows.append(row)
        return _frame(rows)


class ExplainResult(Result):
    """``explain``'s report. Keys: ``baseline_normalized_rms_error``, ``ranking``,
    ``unexplained``, ``verdict``, ``rotor_asymmetry``, ``data_quality``, ..."""

    @property
    def ranking_frame(self):
        """The ranking as a DataFrame (rank, standing, effect, errors, explained fractions on
        the held-back windows and the whole log, plausibility): ranked candidates first, then
        ``no_effect``, then ``not_plausible``."""
        keep = (
            "rank",
            "standing",
            "effect",
            "normalized_rms_error",
            "validation_normalized_rms_error",
            "explained_fraction",
            "whole_log_explained_fraction",
            "plausible",
            "summary",
        )
        return _frame([{k: r.get(k) for k in keep} for r in self._doc.get("ranking", [])])


class LadderResult(_LeftoverMixin, Result):
    """``explain --ladder``'s report. Keys: ``summary`` (what was found, then why it
    stopped), ``base_changes`` (the base parameters that differ from the file, with their
    intervals), ``final_fit`` (the chosen model refitted on the whole log), ``start``,
    ``ladder`` (the steps in order: an effect added, with what it dropped, or the base
    parameters refitted), ``stop``, ``stopped_because``, ``final_effects``, ``last_round``,
    ``skipped``, ``split``, ``test``, ``data``, ``data_quality``, ``leftover`` (where the
    chosen model's error lives when the ladder stops above the noise floor, else None; as
    ``compare``'s; ``.leftover_lines`` is its lines as a DataFrame)."""

    @property
    def base_frame(self):
        """The six base parameters against the file (from the chosen model refitted on the
        whole log) as a DataFrame: parameter, relative change, its 95 % interval, the file's
        and the refitted value, whether the log identifies it and whether the ladder names
        the change."""
        rows = []
        for c in (self._doc.get("final_fit") or {}).get("base", []):
            interval = c.get("interval") or [None, None]
            rows.append(
                {
                    "base": c.get("base"),
                    "change": c.get("change"),
                    "low": interval[0],
                    "high": interval[1],
                    "file_value": c.get("file_value"),
                    "value": c.get("value"),
                    "unit": c.get("unit"),
                    "identified": c.get("identified"),
                    "changed": c.get("changed"),
                }
            )
        return _frame(rows)

    @property
    def ladder_frame(self):
        """The steps as a DataFrame, step 0 the model as configured: step, effects added
        (``base`` for the base rung), effects dropped, the base changes it named, whole-log
        and held-back error, each as a multiple of its noise floor, the test statistic
        (``significance``) and the shares of the error beyond the floor explained."""
        start = self._doc.get("start", {})
        rows = [
            {
                "step": 0,
                "added": "",
                "dropped": "",
                "base": "",
                "error": start.get("error"),
                "heldback_error": start.get("heldback_error"),
                "noise_floor": start.get("noise_floor"),
                "ratio_to_floor": start.get("ratio_to_floor"),
                "significance": None,
                "explained": None,
                "heldback_explained": None,
            }
        ]
        for k, s in enumerate(self._doc.get("ladder", []), start=1):
            rows.append(
                {
                    "step": k,
                    "added": "+".join(s.get("added", [])) if s.get("effect") else "base",
                    "dropped": "+".join(s.get("dropped", [])),
                    "base": ", ".join(
                        "%s %+.1f %%" % (c["base"], 100.0 * c["change"])
                        for c in s.get("base", [])
                        if c.get("changed")
                    ),
                    "error": s.get("error"),
                    "heldback_error": s.get("heldback_error"),
                    "noise_floor": s.get("noise_floor"),
                    "ratio_to_floor": s.get("ratio_to_floor"),
                    "significance": s.get("significance"),
                    "explained": s.get("explained"),
                    "heldback_explained": s.get("heldback_explained"),
                }
            )
        return _frame(rows)


class IdentifyResult(Result):
    """``identify``'s result. Keys: ``identification`` (``estimates``, ``inverse_gamma``,
    ``relative_rms_error``, ``solver``, ...), ``out``, ``toml``."""

    @property
    def estimates_frame(self):
        """The estimates as a DataFrame: name, unit, start, value, 95 % interval, or why not
        identified."""
        return _frame(self._doc.get("identification", {}).get("estimates", []))


class NameplateResult(Result):
    """``params from-nameplate``'s result. Keys: ``nameplate``, ``poles``, ``slip``,
    ``values`` (each with its range and source), ``toml``."""

    @property
    def params(self) -> Dict[str, Any]:
        """The parameter file as a dict (``{"motor": {...}, "supply": {...}}``), usable as
        ``params`` by the other functions."""
        try:
            import tomllib  # Python 3.11+
        except ImportError:  # pragma: no cover
            import tomli as tomllib  # type: ignore
        return tomllib.loads(self._doc["toml"])
