"""Shared fixtures: the repository's scenes and the ``ssn`` program the package must agree
with (``SSN_BIN``, else ``target/release/ssn`` of this repository, built by
``cargo build --release -p ssn``)."""

import json
import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
SCENES = REPO / "scenes"

#: Keys of the documents that are wall times: they differ between any two runs.
WALL_TIMES = {"solve_seconds", "stability_seconds", "seconds"}


@pytest.fixture(scope="session")
def ssn_bin():
    path = pathlib.Path(os.environ.get("SSN_BIN", REPO / "target" / "release" / "ssn"))
    assert path.is_file(), (
        f"the ssn program is not at {path}: build it with `cargo build --release -p ssn` "
        "or set SSN_BIN"
    )
    return str(path)


@pytest.fixture(scope="session")
def cli(ssn_bin):
    """Runs ``ssn ARGS --json`` and returns its document (exit code 0 or 1 expected)."""

    def run(*args):
        done = subprocess.run(
            [ssn_bin, *map(str, args), "--json"], capture_output=True, text=True, check=False
        )
        assert done.returncode in (0, 1), done.stderr
        return json.loads(done.stdout)

    return run


def assert_same_document(python, command_line, path="", rel=1e-12):
    """The two documents have the same keys and values; numbers agree to ``rel`` (round-off:
    both come from the same library, the Python run in another process), wall times are
    not compared."""
    if isinstance(command_line, dict):
        assert isinstance(python, dict), path
        assert python.keys() == command_line.keys(), (path, python.keys() ^ command_line.keys())
        for key in command_line:
            if key in WALL_TIMES:
                continue
            assert_same_document(python[key], command_line[key], f"{path}.{key}", rel)
    elif isinstance(command_line, list):
        assert isinstance(python, list) and len(python) == len(command_line), path
        for k, (a, b) in enumerate(zip(python, command_line)):
            assert_same_document(a, b, f"{path}[{k}]", rel)
    elif isinstance(command_line, float) and not isinstance(command_line, bool):
        assert python == pytest.approx(command_line, rel=rel, abs=1e-300), path
    else:
        assert python == command_line, path
