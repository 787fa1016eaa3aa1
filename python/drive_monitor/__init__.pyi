"""Type stubs of drive_monitor (see the module's docstring)."""

import os
from typing import Any, Dict, Iterable, Optional, Sequence, Tuple, Union

import pandas as pd

from ._native import (
    AnalysisError as AnalysisError,
    DriveMonitorError as DriveMonitorError,
    InternalError as InternalError,
    LogError as LogError,
    OptionError as OptionError,
    ParamsError as ParamsError,
)
from ._results import (
    CompareResult as CompareResult,
    DiagnoseResult as DiagnoseResult,
    ExplainResult as ExplainResult,
    IdentifyResult as IdentifyResult,
    NameplateResult as NameplateResult,
    Result as Result,
)

PathLike = Union[str, os.PathLike[str]]
LogLike = Any
ParamsLike = Union[PathLike, Dict[str, Any]]

def diagnose(
    log: LogLike,
    params: ParamsLike,
    commission: Optional[Tuple[float, float]] = ...,
    baseline: Optional[Union[LogLike, Sequence[LogLike]]] = ...,
    load: Optional[str] = ...,
    angle: Optional[str] = ...,
    residuals: Optional[str] = ...,
    allow_incomplete: bool = ...,
    timeline_step: Optional[float] = ...,
    group: Optional[str] = ...,
) -> DiagnoseResult: ...
def compare(
    log: LogLike,
    params: ParamsLike,
    effects: Optional[Iterable[str]] = ...,
    from_s: Optional[float] = ...,
    to_s: Optional[float] = ...,
    no_fit: bool = ...,
    group: Optional[str] = ...,
) -> CompareResult: ...
def explain(
    log: LogLike,
    params: ParamsLike,
    effects: Optional[Iterable[str]] = ...,
    from_s: Optional[float] = ...,
    to_s: Optional[float] = ...,
    no_fit: bool = ...,
    group: Optional[str] = ...,
    rotor_bars: Optional[int] = ...,
) -> ExplainResult: ...
def identify(
    log: LogLike,
    params: ParamsLike,
    from_s: Optional[float] = ...,
    to_s: Optional[float] = ...,
    group: Optional[str] = ...,
) -> IdentifyResult: ...
def params_from_nameplate(
    power_kw: float,
    voltage_v: float,
    current_a: float,
    frequency_hz: float,
    speed_rpm: float,
    power_factor: float,
    efficiency: float,
    poles: Optional[int] = ...,
    connection: str = ...,
    locked_rotor_ratio: Optional[float] = ...,
    nema_design: str = ...,
    columns_from: Optional[PathLike] = ...,
) -> NameplateResult: ...
def simulate(
    params: ParamsLike, scenario: Union[PathLike, str], out: Optional[PathLike] = ...
) -> pd.DataFrame: ...
