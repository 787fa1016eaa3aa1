"""What a wrong call is told (issue 76): a keyword of the wrong type names itself, the type
given and the one expected; an unknown name lists its near matches and the library's; the
docs' function table lists every public function; the package has its version."""

import importlib.metadata
import inspect
import re

import pytest

import drive_monitor as dm
from drive_monitor import fleet

MOTULATOR = "examples/logs/motulator_2p2kw_dol.csv"
MOTULATOR_P = "examples/logs/motulator_2p2kw_dol.toml"


@pytest.mark.parametrize(
    "option, value, says",
    [
        ("parallel_paths", 2.5, "parallel_paths = 2.5: a float, not an int"),
        ("parallel_paths", "2", "parallel_paths = '2': a str, not an int"),
        ("parallel_paths", True, "parallel_paths = True: a bool, not an int"),
        ("timeline_step", "0.5", "timeline_step = '0.5': a str, not a number of seconds"),
        ("timeline_step", True, "timeline_step = True: a bool, not a number of seconds"),
        ("load", 3, "load = 3: an int, not a str: give one of unknown, viscous"),
        ("allow_incomplete", 1, "allow_incomplete = 1: an int, not a bool"),
        ("commission", 5, "commission = 5: an int, not a pair of numbers or a str"),
        ("commission", (True, 2.0), "commission = (True, 2.0): not numbers"),
        ("turn_calibration", 3, "turn_calibration = 3: an int, not a path"),
    ],
)
def test_a_wrong_type_names_the_argument_and_the_type_expected(repo, option, value, says):
    # Checked where the one description of the options is read (python/src/options.rs), so
    # every option of DIAGNOSE_OPTIONS is: never rounded, parsed from text or taken as a bool.
    with pytest.raises(dm.OptionError) as e:
        dm.diagnose(repo / MOTULATOR, repo / MOTULATOR_P, **{option: value})
    msg = str(e.value)
    assert says in msg and "\n" not in msg, msg
    # Python's convention (issue 79): a wrong type is a TypeError.
    assert isinstance(e.value, TypeError) and isinstance(e.value, dm.OptionTypeError), type(e.value)


def test_the_right_types_are_taken(repo):
    # An int where seconds are asked for is a number; numpy's ints and floats too. The
    # options pass, and the missing log is what is refused.
    import numpy as np

    for step, paths in ((1, 2), (0.25, np.int64(2)), (np.float32(0.5), 8)):
        with pytest.raises(dm.LogError):
            dm.diagnose(repo / "nosuch.csv", repo / MOTULATOR_P, timeline_step=step, parallel_paths=paths)


def test_an_unknown_keyword_names_the_near_one(repo):
    with pytest.raises(TypeError, match="unexpected keyword argument 'parallel_path'; did you mean 'parallel_paths'"):
        dm.diagnose(repo / MOTULATOR, repo / MOTULATOR_P, parallel_path=2)


@pytest.mark.parametrize("call", [dm.compare, dm.explain])
def test_an_unknown_effect_lists_the_near_matches_and_the_library(repo, call):
    with pytest.raises(dm.OptionError) as e:
        call(repo / MOTULATOR, repo / MOTULATOR_P, effects="load_torq")
    msg = str(e.value)
    assert msg.startswith("effect 'load_torq' is not in the library; did you mean 'load_torque'?"), msg
    assert "the library's effects: " in msg and "saturation" in msg and "windage" in msg, msg
    # Far from every name: no guess, the list alone.
    with pytest.raises(dm.OptionError) as e:
        call(repo / MOTULATOR, repo / MOTULATOR_P, effects="zzzz")
    assert "did you mean" not in str(e.value) and "the library's effects: " in str(e.value)


def public_functions():
    """`name` for the package's functions, `fleet.name` for the fleet module's."""
    for prefix, mod in (("", dm), ("fleet.", fleet)):
        for name in mod.__all__:
            if inspect.isfunction(getattr(mod, name)):
                yield prefix + name


def test_the_docs_function_table_lists_every_public_function(repo):
    text = (repo / "docs/python.md").read_text()
    table = text[text.index("| function | the command | result |"):]
    table = table[: table.index("\n\n")]
    listed = set(re.findall(r"^\| `([a-z_.]+)\(", table, re.M))
    functions = set(public_functions())
    assert {"diagnose", "trend", "fleet.diagnose_many"} <= functions
    assert functions <= listed, f"missing from docs/python.md's table: {sorted(functions - listed)}"
    assert "`explain(log, params, ..., ladder=True)`" in table


def test_the_package_has_its_version(repo):
    assert re.fullmatch(r"\d+\.\d+\.\d+\S*", dm.__version__), dm.__version__
    # The wheel's metadata and the library's Cargo version say the same.
    assert dm.__version__ == importlib.metadata.version("drive-monitor")
    cargo = (repo / "python/Cargo.toml").read_text()
    assert f'version = "{dm.__version__}"' in cargo
