"""Shared fixtures: the repository, the `sim-host` binary to compare with."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def repo() -> Path:
    return REPO


@pytest.fixture(scope="session")
def sim_host() -> str:
    """The command line the package must agree with: $SIM_HOST, else the workspace's
    release or debug build, else a fresh debug build."""
    env = os.environ.get("SIM_HOST")
    if env:
        return env
    for kind in ("release", "debug"):
        p = REPO / "target" / kind / "sim-host"
        if p.exists():
            return str(p)
    subprocess.run(["cargo", "build", "-p", "sim-host"], cwd=REPO, check=True)
    return str(REPO / "target" / "debug" / "sim-host")


def cli_json(sim_host: str, *args: str):
    import json

    out = subprocess.run([sim_host, *args, "--json"], capture_output=True, text=True, cwd=REPO)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def in_python_words(doc, words: dict):
    """The command's document `doc` with its advice in Python's words: in every string, each
    of the command line's spellings in `words` (`"--effects load_torque"`) replaced by
    Python's (`"effects=['load_torque']"`); the rest of the document as the command's."""
    if isinstance(doc, str):
        for cli, py in words.items():
            doc = doc.replace(cli, py)
        return doc
    if isinstance(doc, list):
        return [in_python_words(x, words) for x in doc]
    if isinstance(doc, dict):
        return {k: in_python_words(v, words) for k, v in doc.items()}
    return doc
