"""Python's convention for errors (issue 79): a value of the wrong type is caught by
``except TypeError``, a bad value by ``except ValueError``, as numpy's and pandas' are; the
package's own classes derive from them (and ``except OptionError`` still catches an option
of the wrong type)."""

import pickle

import numpy as np
import pytest

import drive_monitor as dm
from drive_monitor import fleet

MOTULATOR = "examples/logs/motulator_2p2kw_dol.csv"
MOTULATOR_P = "examples/logs/motulator_2p2kw_dol.toml"
NAMEPLATE = dict(power_kw=2.2, voltage_v=400.0, current_a=4.8, frequency_hz=50.0, speed_rpm=1430.0,
                 power_factor=0.81, efficiency=0.84)


def test_the_classes_derive_from_pythons():
    for cls in (dm.ParamsError, dm.LogError, dm.OptionError, dm.AnalysisError):
        assert issubclass(cls, ValueError) and issubclass(cls, dm.DriveMonitorError), cls
        assert not issubclass(cls, TypeError), cls
    for cls, kind in ((dm.OptionTypeError, dm.OptionError), (dm.ParamsTypeError, dm.ParamsError),
                      (dm.LogTypeError, dm.LogError)):
        assert issubclass(cls, TypeError) and issubclass(cls, kind), cls
    assert issubclass(dm.InternalError, RuntimeError) and issubclass(dm.InternalError, dm.DriveMonitorError)
    assert not issubclass(dm.InternalError, ValueError)
    # The extension raises the package's classes, not copies of them.
    from drive_monitor import _native

    assert _native.OptionError is dm.OptionError and _native.OptionTypeError is dm.OptionTypeError


# A value of the wrong type: what is called, the class, and what the message says.
WRONG_TYPES = [
    (lambda r: dm.diagnose(r / MOTULATOR, r / MOTULATOR_P, parallel_paths=2.5), dm.OptionError,
     "parallel_paths = 2.5: a float, not an int"),
    (lambda r: dm.diagnose(r / MOTULATOR, r / MOTULATOR_P, timeline_step="0.5"), dm.OptionError,
     "timeline_step = '0.5': a str, not a number"),
    (lambda r: dm.diagnose(r / MOTULATOR, r / MOTULATOR_P, commission=5), dm.OptionError,
     "commission = 5: an int, not a pair"),
    (lambda r: dm.diagnose(r / MOTULATOR, r / MOTULATOR_P, commission=("x", 2)), dm.OptionError,
     "not numbers"),
    (lambda r: dm.diagnose(r / MOTULATOR, r / MOTULATOR_P, load=3), dm.OptionError, "load = 3: an int, not a str"),
    (lambda r: dm.diagnose(r / MOTULATOR, r / MOTULATOR_P, turn_calibration=3), dm.OptionError,
     "turn_calibration = 3: an int, not a path"),
    (lambda r: dm.compare(r / MOTULATOR, r / MOTULATOR_P, from_s="1.5"), dm.OptionError,
     "from_s = '1.5': a str, not a number"),
    (lambda r: dm.explain(r / MOTULATOR, r / MOTULATOR_P, effects=[3]), dm.OptionError,
     "an int, not a str"),
    (lambda r: dm.explain(r / MOTULATOR, r / MOTULATOR_P, rotor_bars=2.5), dm.OptionError,
     "rotor_bars = 2.5: a float, not an int"),
    (lambda r: dm.identify(r / MOTULATOR, r / MOTULATOR_P, to_s="2"), dm.OptionError,
     "to_s = '2': a str, not a number"),
    (lambda r: dm.params_from_nameplate(**{**NAMEPLATE, "power_kw": "2.2"}), dm.OptionError,
     "power_kw = '2.2': a str, not a number"),
    (lambda r: dm.params_from_nameplate(**NAMEPLATE, poles=4.0), dm.OptionError, "poles = 4.0: a float"),
    (lambda r: dm.diagnose(42, r / MOTULATOR_P), dm.LogError, "not int"),
    (lambda r: dm.diagnose(r / MOTULATOR, 3), dm.ParamsError, "params: a path"),
    (lambda r: dm.diagnose(r / MOTULATOR, {"motor": "abc"}), dm.ParamsError, "'motor'"),
    (lambda r: dm.diagnose(r / MOTULATOR, {"motor": {"rs_ohm": object()}}), dm.ParamsError, "not a number"),
    (lambda r: fleet.motor_table_toml(3), dm.ParamsError, "not int"),
]


@pytest.mark.parametrize("call, kind, says", WRONG_TYPES)
def test_a_wrong_type_is_a_type_error(repo, call, kind, says):
    try:
        call(repo)
    except TypeError as e:
        assert isinstance(e, kind) and isinstance(e, dm.DriveMonitorError), type(e)
        assert says in str(e) and "\n" not in str(e), str(e)
    else:
        pytest.fail("no error")


# A value of the right type that is not one the call takes.
BAD_VALUES = [
    (lambda r: dm.diagnose(r / MOTULATOR, r / MOTULATOR_P, commission=(3.0, 2.0)), dm.OptionError,
     "commission = 3:2"),
    (lambda r: dm.diagnose(r / MOTULATOR, r / MOTULATOR_P, commission="1.5:2.4:3"), dm.OptionError,
     "commission = "),
    (lambda r: dm.diagnose(r / MOTULATOR, r / MOTULATOR_P, commission=(1.5,)), dm.OptionError, "two values"),
    (lambda r: dm.diagnose(r / MOTULATOR, r / MOTULATOR_P, parallel_paths=0), dm.OptionError,
     "parallel_paths = 0"),
    (lambda r: dm.diagnose(r / MOTULATOR, r / MOTULATOR_P, timeline_step=0), dm.OptionError,
     "timeline_step = 0"),
    (lambda r: dm.diagnose(r / MOTULATOR, r / MOTULATOR_P, load="heavy"), dm.OptionError, "load"),
    (lambda r: dm.diagnose(r / MOTULATOR, r / MOTULATOR_P, turn_calibration={"x": np.float64(1)}),
     dm.OptionError, "turn_calibration"),
    (lambda r: dm.compare(r / MOTULATOR, r / MOTULATOR_P, effects="load_torq"), dm.OptionError,
     "effect 'load_torq' is not in the library"),
    (lambda r: dm.compare(r / MOTULATOR, r / MOTULATOR_P, from_s=4.99), dm.OptionError, "at least"),
    (lambda r: dm.explain(r / MOTULATOR, r / MOTULATOR_P, rotor_bars=-1), dm.OptionError, "rotor_bars = -1"),
    (lambda r: dm.params_from_nameplate(**NAMEPLATE, connection="tri"), dm.OptionError, "connection = 'tri'"),
    (lambda r: dm.diagnose(r / "nosuch.csv", r / MOTULATOR_P), dm.LogError, "nosuch.csv"),
    (lambda r: dm.diagnose({"t_s": np.zeros(3)}, r / MOTULATOR_P), dm.LogError, "ia_A"),
    (lambda r: dm.diagnose(r / MOTULATOR, r / "nosuch.toml"), dm.ParamsError, "nosuch.toml"),
    (lambda r: dm.diagnose(r / MOTULATOR, {"motor": {"rs_ohm": 1.0}}), dm.ParamsError, "missing"),
    (lambda r: dm.trend(r / "nosuch.db"), dm.LogError, "no store"),
]


@pytest.mark.parametrize("call, kind, says", BAD_VALUES)
def test_a_bad_value_is_a_value_error(repo, call, kind, says):
    try:
        call(repo)
    except ValueError as e:
        assert isinstance(e, kind) and isinstance(e, dm.DriveMonitorError), type(e)
        assert not isinstance(e, TypeError), type(e)
        assert says in str(e) and "\n" not in str(e), str(e)
    else:
        pytest.fail("no error")


@pytest.mark.parametrize("call, kind", [
    (lambda r: dm.diagnose(r / "nosuch.csv", r / MOTULATOR_P), dm.LogNotFoundError),
    (lambda r: dm.identify(r / "nosuch.csv", r / MOTULATOR_P), dm.LogNotFoundError),
    (lambda r: dm.diagnose(r / MOTULATOR, r / "nosuch.toml"), dm.ParamsNotFoundError),
])
def test_a_missing_file_is_a_file_not_found_error(repo, call, kind):
    # Python's convention for a file that is not there (issue 86): FileNotFoundError, as
    # open() raises; still the package's LogError / ParamsError, so also a ValueError.
    with pytest.raises(FileNotFoundError) as e:
        call(repo)
    assert isinstance(e.value, kind) and isinstance(e.value, ValueError), type(e.value)
    assert "nosuch" in str(e.value)


def test_a_glob_that_matches_nothing_is_a_value_error(tmp_path, repo):
    with pytest.raises(ValueError, match="matches no file") as e:
        fleet.diagnose_many(str(tmp_path / "none_*.csv"), [{"name": "m", "params": str(repo / MOTULATOR_P),
                                                             "logs": "*"}])
    assert isinstance(e.value, dm.OptionError)


def test_an_error_survives_pickling(repo):
    # Dask carries a worker's error to the client pickled: the class and message arrive.
    for call, kind, _ in (WRONG_TYPES[0], BAD_VALUES[0]):
        with pytest.raises(kind) as e:
            call(repo)
        back = pickle.loads(pickle.dumps(e.value))
        assert type(back) is type(e.value) and str(back) == str(e.value)
