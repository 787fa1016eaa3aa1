"""Type stubs of the Rust extension (drive_monitor._native). Every function returns the
command's ``--json`` document as a string; the package's Python layer wraps it."""

from typing import List, Optional, Tuple

class DriveMonitorError(Exception): ...
class ParamsError(DriveMonitorError): ...
class LogError(DriveMonitorError): ...
class OptionError(DriveMonitorError): ...
class AnalysisError(DriveMonitorError): ...
class InternalError(DriveMonitorError): ...

def diagnose(
    log: str,
    params: str,
    params_is_text: bool = ...,
    commission: Optional[Tuple[float, float]] = ...,
    baseline: List[str] = ...,
    load: Optional[str] = ...,
    angle: Optional[str] = ...,
    residuals: Optional[str] = ...,
    allow_incomplete: bool = ...,
    timeline_step: Optional[float] = ...,
    group: Optional[str] = ...,
) -> str: ...
def compare(
    log: str,
    params: str,
    params_is_text: bool = ...,
    effects: List[str] = ...,
    from_s: Optional[float] = ...,
    to_s: Optional[float] = ...,
    no_fit: bool = ...,
    group: Optional[str] = ...,
) -> str: ...
def explain(
    log: str,
    params: str,
    params_is_text: bool = ...,
    effects: List[str] = ...,
    from_s: Optional[float] = ...,
    to_s: Optional[float] = ...,
    no_fit: bool = ...,
    group: Optional[str] = ...,
    rotor_bars: Optional[int] = ...,
) -> str: ...
def identify(
    log: str,
    params: str,
    params_is_text: bool = ...,
    from_s: Optional[float] = ...,
    to_s: Optional[float] = ...,
    group: Optional[str] = ...,
) -> str: ...
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
    columns_from: Optional[str] = ...,
) -> str: ...
def simulate(params: str, scenario_toml: str, out: str, params_is_text: bool = ...) -> str: ...
def fleet_row(table_toml: str, base: str, log: str, shown: str) -> str: ...
def fleet_columns() -> List[str]: ...
