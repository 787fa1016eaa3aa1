"""Type stubs of the Rust extension (drive_monitor._native), its one description for type
checkers (the package's own modules are annotated in place; tests/test_stubs.py holds this
file to the extension). Every function returns the command's ``--json`` document as a
string; the package's Python layer wraps it. A ``log`` is a path when ``log_origin`` is
``None``, else an object with ``__arrow_c_stream__`` that messages call ``log_origin``."""

from typing import Any, List, Optional, Tuple, Union

#: The library's Cargo version (``drive_monitor.__version__``).
__version__: str

# The package's exception classes (defined in _errors.py, raised and exported by the
# extension).
from ._errors import AnalysisError as AnalysisError
from ._errors import DriveMonitorError as DriveMonitorError
from ._errors import InternalError as InternalError
from ._errors import LogError as LogError
from ._errors import LogNotFoundError as LogNotFoundError
from ._errors import LogTypeError as LogTypeError
from ._errors import OptionError as OptionError
from ._errors import OptionTypeError as OptionTypeError
from ._errors import ParamsError as ParamsError
from ._errors import ParamsNotFoundError as ParamsNotFoundError
from ._errors import ParamsTypeError as ParamsTypeError

def diagnose(
    log: Any,
    params: str,
    log_origin: Optional[str] = ...,
    params_is_text: bool = ...,
    baseline: List[Tuple[Any, Optional[str]]] = ...,
    group: Optional[str] = ...,
    **options: Any,
) -> str: ...
def diagnose_options() -> List[Tuple[str, str, str, str]]: ...
def compare(
    log: Any,
    params: str,
    log_origin: Optional[str] = ...,
    params_is_text: bool = ...,
    effects: List[str] = ...,
    from_s: Optional[float] = ...,
    to_s: Optional[float] = ...,
    no_fit: bool = ...,
    group: Optional[str] = ...,
    laws: Optional[str] = ...,
) -> str: ...
def explain(
    log: Any,
    params: str,
    log_origin: Optional[str] = ...,
    params_is_text: bool = ...,
    effects: List[str] = ...,
    from_s: Optional[float] = ...,
    to_s: Optional[float] = ...,
    no_fit: bool = ...,
    group: Optional[str] = ...,
    rotor_bars: Optional[int] = ...,
    ladder: bool = ...,
    laws: Optional[str] = ...,
) -> str: ...
def identify(
    log: Any,
    params: str,
    log_origin: Optional[str] = ...,
    params_is_text: bool = ...,
    from_s: Optional[float] = ...,
    to_s: Optional[float] = ...,
    group: Optional[str] = ...,
    keep_columns: bool = ...,
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
def simulate(
    params: str,
    scenario: str,
    out: str,
    params_is_text: bool = ...,
    scenario_is_text: bool = ...,
    laws: Optional[str] = ...,
) -> str: ...
def fleet_row(table_toml: str, base: str, log: str, shown: str) -> str: ...
def fleet_columns() -> List[str]: ...
def fleet_read_table(path: str, base: str) -> str: ...
def fleet_check_table(text: str, shown: str, base: str) -> None: ...
def fleet_check_outputs(
    table_toml: str, base: str, table_path: Optional[str], logs: List[str], store: str
) -> None: ...
def fleet_store_row(
    table_toml: str, base: str, log: str, shown: str, time_s: Optional[int] = ...
) -> str: ...
def fleet_store_row_timed(
    table_toml: str, base: str, log: str, shown: str, modified_s: Optional[int] = ...
) -> str: ...
def fleet_time_warnings(table_toml: str, base: str, times_json: str) -> List[str]: ...
def store_append(store: str, rows_json: str) -> Tuple[int, int]: ...
def store_trend(
    store: str,
    motor: Optional[str] = ...,
    since: Optional[str] = ...,
    window_days: float = ...,
    k: float = ...,
    reference_until: Optional[str] = ...,
) -> str: ...
def store_columns() -> List[str]: ...
