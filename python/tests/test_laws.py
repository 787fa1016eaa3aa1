"""A user's own law (``laws=``): the same answer as ``sim-host ... --laws``, a law file with a
mistake a ValueError naming the law and the problem, a missing one a FileNotFoundError."""

import pytest

import drive_monitor as dm
from conftest import cli_json, in_python_words

DATA = "sim-host/tests/data/motulator"
PULSE = f"{DATA}/kw2p2_pulse1.csv"
PARAMS = f"{DATA}/kw2p2.toml"
LAWS = f"{DATA}/laws/compressor1.toml"


def test_compare_with_the_users_law_is_the_commands_document(repo, sim_host):
    c = dm.compare(repo / PULSE, repo / PARAMS, laws=repo / LAWS,
                   effects=["flux_dynamics", "current_dynamics", "d_axis_dynamics",
                            "cross_coupling_dynamics", "compressor"])
    cli = cli_json(sim_host, "compare", "--params", PARAMS, PULSE, "--laws", LAWS, "--effects",
                   "flux_dynamics,current_dynamics,d_axis_dynamics,cross_coupling_dynamics,compressor")
    # The same document; its advice names Python's keyword where the command names its flag.
    assert c.to_dict() == in_python_words(cli, {"--from 0.7": "from_s=0.7"})
    fitted = {e["effect"]: e for e in cli["fitted_effects"]}
    # The compressor's pulsation, t0 + a sin(theta + phi): its values the log's (9.49 N m,
    # 3.65 N m, 0.9 rad), the error at the noise floor.
    law = fitted["compressor"]["parameters"]
    assert abs(law["t0"]["value"] / 9.49 - 1) < 0.1 and abs(law["a"]["value"] / 3.65 - 1) < 0.1
    assert c.normalized_rms_error < 1.5 * c.noise_floor


def test_a_law_with_a_mistake_is_a_value_error_naming_it(repo, tmp_path):
    bad = tmp_path / "laws.toml"
    bad.write_text((repo / LAWS).read_text().replace("sin(theta", "sin(thetta"))
    with pytest.raises(ValueError) as e:
        dm.compare(repo / PULSE, repo / PARAMS, laws=bad)
    msg = str(e.value)
    assert isinstance(e.value, dm.OptionError)
    assert "law 'compressor'" in msg and "position 14" in msg and "'theta'" in msg, msg
    assert "\n" not in msg
    with pytest.raises(FileNotFoundError):
        dm.explain(repo / PULSE, repo / PARAMS, laws=tmp_path / "none.toml")
    with pytest.raises(TypeError):
        dm.compare(repo / PULSE, repo / PARAMS, laws=3)
    # A name neither the library nor the file has: its near match.
    with pytest.raises(ValueError, match="did you mean 'compressor'"):
        dm.compare(repo / PULSE, repo / PARAMS, laws=repo / LAWS, effects=["compresor"])


def test_simulate_runs_the_users_law(repo):
    scenario = "duration_s = 1.0\nsample_rate_hz = 2000.0\n[load]\nkind = \"viscous\"\nbl_nms = 0.0\n"
    df = dm.simulate(repo / PARAMS, scenario, laws=repo / LAWS)
    # The compressor's load (its start values, t0 5 N m, a 2 N m) slows the machine below the
    # no-load speed of the same run without it.
    free = dm.simulate(repo / PARAMS, scenario)
    assert df["wm_rad_s"].iloc[-200:].mean() < free["wm_rad_s"].iloc[-200:].mean() - 0.5
