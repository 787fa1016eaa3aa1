"""Data in memory goes to the library through Arrow's C stream interface, without a
temporary file, and is read through the same path as a file: the same document as the same
data read from a Parquet file, messages that name the data; the commissioning window in
both spellings; the exception class from the library's error kind."""

import tempfile

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

import drive_monitor as dm

MOTULATOR = "examples/logs/motulator_2p2kw_dol.csv"
MOTULATOR_P = "examples/logs/motulator_2p2kw_dol.toml"
ITSC = "examples/recordings/itsc"


@pytest.fixture(scope="module")
def frame(repo):
    return pd.read_csv(repo / MOTULATOR)


@pytest.fixture()
def no_temp_files(monkeypatch):
    """Any temporary file made during the call fails it."""

    def refuse(*_a, **_k):
        raise AssertionError("a temporary file was made")

    for name in ("mkstemp", "NamedTemporaryFile", "TemporaryFile", "mkdtemp"):
        monkeypatch.setattr(tempfile, name, refuse)


def test_a_dataframe_is_the_same_parquet_file_key_for_key(repo, frame, tmp_path, no_temp_files):
    path = tmp_path / "log.parquet"
    pq.write_table(pa.Table.from_pandas(frame, preserve_index=False), path)
    from_file = dm.diagnose(path, repo / MOTULATOR_P, commission=(1.5, 2.4)).to_dict()
    from_frame = dm.diagnose(frame, repo / MOTULATOR_P, commission=(1.5, 2.4)).to_dict()
    assert from_frame.keys() == from_file.keys()
    for k in from_file:
        assert from_frame[k] == from_file[k], k
    # compare reads the same rows too (its document holds no path).
    c_file = dm.compare(path, repo / MOTULATOR_P, no_fit=True).to_dict()
    c_frame = dm.compare(frame, repo / MOTULATOR_P, no_fit=True).to_dict()
    assert c_frame == c_file


def test_the_columns_mapping_and_units_apply_to_data(repo):
    """A DAQ's log (its own names, mA, rpm) as a DataFrame with the parameter file's
    [columns]: the same document as the file."""
    p = repo / "examples/params/daq_2p2kw.toml"
    log = repo / "examples/logs/daq_2p2kw.csv"
    from_file = dm.diagnose(log, p, commission=(1.0, 6.5)).to_dict()
    from_frame = dm.diagnose(pd.read_csv(log), p, commission=(1.0, 6.5)).to_dict()
    assert from_frame == from_file
    assert from_file["verdict"] == "healthy"


def test_baselines_as_data(repo):
    p = repo / ITSC / "baldor_0p75hp.toml"
    files = [repo / ITSC / "SC_HLT_001.csv", repo / ITSC / "SC_HLT_002.csv"]
    judged = repo / ITSC / "SC_A0_B0_C1_001.csv"
    from_files = dm.diagnose(judged, p, baseline=files).to_dict()
    # The recordings have no header row: their [columns] maps the channels by place.
    frames = [pd.read_csv(f, header=None) for f in files]
    from_data = dm.diagnose(judged, p, baseline=frames).to_dict()
    assert from_data["unbalance"] == from_files["unbalance"]
    assert from_data["verdict"] == from_files["verdict"] == "fault"


@pytest.mark.parametrize(
    "make, origin",
    [
        (lambda f: f, "DataFrame"),
        (lambda f: pa.Table.from_pandas(f, preserve_index=False), "pyarrow Table"),
        (lambda f: {c: f[c].to_numpy() for c in f.columns}, "dict"),
    ],
)
def test_messages_name_the_data_not_a_file(repo, frame, make, origin):
    with pytest.raises(dm.LogError) as e:
        dm.diagnose(make(frame.drop(columns=["ia_A"])), repo / MOTULATOR_P)
    msg = str(e.value)
    assert msg.startswith(f"{origin}: missing column 'ia_A'"), msg
    assert ".parquet" not in msg and "/tmp" not in msg and "\n" not in msg, msg


def test_a_column_of_text_is_refused_naming_it(repo, frame):
    bad = frame.assign(ia_A=frame["ia_A"].astype(str))
    with pytest.raises(dm.LogError) as e:
        dm.diagnose(bad, repo / MOTULATOR_P)
    assert str(e.value).startswith("DataFrame: column 'ia_A' is of type"), str(e.value)


def test_missing_values_are_the_quality_stages_as_in_a_file(repo, frame, tmp_path):
    holes = frame.copy()
    holes.loc[1000:1010, "ib_A"] = np.nan
    path = tmp_path / "holes.parquet"
    pq.write_table(pa.Table.from_pandas(holes, preserve_index=False), path)
    from_file = dm.diagnose(path, repo / MOTULATOR_P).data_quality.to_dict()
    from_frame = dm.diagnose(holes, repo / MOTULATOR_P).data_quality.to_dict()
    assert from_frame == from_file
    assert from_file["bad_rows"] == 11


def test_commission_in_both_spellings(repo):
    pair = dm.diagnose(repo / MOTULATOR, repo / MOTULATOR_P, commission=(1.5, 2.4)).to_dict()
    text = dm.diagnose(repo / MOTULATOR, repo / MOTULATOR_P, commission="1.5:2.4").to_dict()
    listed = dm.diagnose(repo / MOTULATOR, repo / MOTULATOR_P, commission=[1.5, 2.4]).to_dict()
    assert text == pair == listed
    assert pair["commissioning"] != dm.diagnose(repo / MOTULATOR, repo / MOTULATOR_P).to_dict()["commissioning"]


@pytest.mark.parametrize("bad", ["1.5", "1.5:2.4:3", "a:b", 1.5, (1.5,), ("x", 2)])
def test_a_bad_commission_is_one_line_naming_it(repo, bad):
    with pytest.raises(dm.OptionError) as e:
        dm.diagnose(repo / MOTULATOR, repo / MOTULATOR_P, commission=bad)
    msg = str(e.value)
    assert msg.startswith("commission = "), msg
    assert "could not convert" not in msg and "\n" not in msg, msg


@pytest.mark.parametrize(
    "params, says",
    [
        ({"motor": "abc"}, "'motor'"),
        ({"motor": {"rs_ohm": object()}}, "not a number"),
        ({"motor": {"rs_ohm": "abc"}}, "expected f64"),
    ],
)
def test_a_bad_parameter_dict_is_a_params_error(repo, params, says):
    with pytest.raises(dm.ParamsError) as e:
        dm.diagnose(repo / MOTULATOR, params)
    assert not isinstance(e.value, dm.OptionError)
    assert says in str(e.value) and "\n" not in str(e.value), str(e.value)
