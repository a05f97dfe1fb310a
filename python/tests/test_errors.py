"""Failures come back as exceptions of their kind, with the numbers that explain them, and
terminations as ``ssn.Termination`` members that agree with the command line's text."""

import subprocess

import pytest

import ssn
from conftest import SCENES

FIG1 = SCENES / "paper_fig1_modified_mass.toml"


def test_every_exception_of_the_package_is_an_ssn_error_and_bad_input_stays_a_value_error():
    for kind in (
        ssn.SceneError,
        ssn.TooLargeError,
        ssn.SolveError,
        ssn.NotConvergedError,
    ):
        assert issubclass(kind, ssn.SsnError)
    assert issubclass(ssn.SceneError, ValueError)
    assert issubclass(ssn.TooLargeError, ssn.SceneError)
    assert issubclass(ssn.SolveError, RuntimeError)
    assert not issubclass(ssn.SolveError, ssn.SceneError)
    assert issubclass(ssn.NotConvergedError, ssn.SolveError)


def test_stability_of_a_solve_that_did_not_converge_raises_not_converged_with_its_numbers():
    scene = ssn.Scene.from_file(FIG1).with_values({"solver.max_iterations": 1})
    solution = ssn.solve(scene)
    assert not solution.converged
    with pytest.raises(ssn.NotConvergedError) as raised:
        ssn.stability(scene)
    error = raised.value
    assert not isinstance(error, ssn.SceneError)
    # The numbers are those of the same solve run directly (it is deterministic).
    assert error.termination == solution.termination
    assert error.iterations == solution.iterations == 1
    assert error.residual_norm == solution.residual_norm


def test_a_run_over_the_memory_limit_raises_too_large_as_the_command_line_refuses_it(ssn_bin):
    values = {"rod.elements": 100000, "solver.harmonics": 2000}
    scene = ssn.Scene.rod(values=values)
    with pytest.raises(ssn.TooLargeError, match="GB of memory.*more than the") as raised:
        ssn.solve(scene)
    assert isinstance(raised.value, ssn.SceneError)
    # The program refuses the same scene with the bad-input exit code and the same words.
    args = [a for k, v in values.items() for a in ("--set", f"{k}={v}")]
    done = subprocess.run(
        [ssn_bin, "solve", str(SCENES / "paper_fig1.toml"), *args],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 2 and "GB of memory" in done.stderr


def test_the_termination_kind_is_the_first_word_of_the_command_lines_termination(cli):
    converged = ssn.solve(ssn.Scene.from_file(FIG1))
    assert converged.termination_kind is ssn.Termination.CONVERGED
    stopped = ssn.solve(ssn.Scene.from_file(FIG1).with_values({"solver.max_iterations": 1}))
    assert stopped.termination_kind is ssn.Termination.MAX_ITERATIONS
    document = cli("solve", FIG1, "--set", "solver.max_iterations=1")
    assert stopped.termination_kind == document["termination"].split()[0]
    with pytest.raises(ValueError):
        ssn.Termination.of("no such termination")
