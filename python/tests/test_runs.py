"""The package's runs agree with the command line's JSON, for scenes read from files, the
built-in rod and a structure given as numpy or scipy.sparse matrices."""

import pathlib
import pickle
import subprocess
import threading
import time

import numpy as np
import pytest
import scipy.io
import scipy.linalg
import scipy.sparse

import ssn
from conftest import SCENES, assert_same_document

FIG1 = SCENES / "paper_fig1_modified_mass.toml"
FIG2 = SCENES / "paper_fig2.toml"
#: Three coexisting solutions at this frequency (the overhang of a gap of 0.25).
OVERHANG = {
    "rod.mass": "modified",
    "solver.harmonics": 10,
    "contact.gap": 0.25,
    "forcing.omega_ratio": 1.06,
}


def set_args(values):
    return [a for k, v in values.items() for a in ("--set", f"{k}={v}")]


def test_solve_of_a_scene_file_equals_the_command_line():
    scene = ssn.Scene.from_file(FIG1)
    solution = ssn.solve(scene)
    assert solution.converged and solution.termination == "converged"
    # The arrays are the document's curves: the extremes of the observed dof.
    doc = solution.to_dict()
    assert solution.displacement.max() == doc["tip_max"]
    assert solution.displacement.min() == doc["tip_min"]
    assert solution.contact_forces.shape == (1, len(solution.times))
    assert solution.observed_dof == 19  # the rod's tip: 20 elements, dofs 0..=19


def test_solve_sweep_and_solutions_equal_the_command_line(cli):
    scene = ssn.Scene.from_file(FIG1)
    assert_same_document(ssn.solve(scene).to_dict(), cli("solve", FIG1))
    fig2 = ssn.Scene.from_file(FIG2)
    response = ssn.sweep(fig2)
    assert_same_document(response.to_dict(), cli("sweep", FIG2))
    assert len(response) == len(response.omega) == response.to_dict()["points"]
    overhang = fig2.with_values(OVERHANG)
    found = ssn.solutions(overhang)
    assert_same_document(found.to_dict(), cli("solutions", FIG2, *set_args(OVERHANG)))
    # The overhang holds three solutions, the middle one unstable.
    assert [s["stable"] for s in found.solutions] == [True, False, True]
    assert found.displacements.shape[0] == 3


def test_modes_equals_the_command_line(cli):
    path = SCENES / "paper_rod_modes.toml"
    doc = ssn.modes(ssn.Scene.from_file(path))
    assert_same_document(doc, cli("modes", path))
    # The first point is the linear mode: the scene's damping ratio.
    assert doc["points"][0]["damping_ratio"] == pytest.approx(0.01, abs=1e-12)


def test_modes_starts_at_the_stuck_natural_frequency_of_the_friction_beam():
    # The cantilever whose tip pad (dof 21, 1-based) a Coulomb slider holds: stuck at small
    # amplitude, the mode is the linear one of K, M without the pad's dof.
    path = SCENES / "beam_friction_modes.toml"
    doc = ssn.modes(ssn.Scene.from_file(path).with_values({"modes.amplitude_to": 0.02}))
    k = scipy.io.mmread(SCENES / "beam_friction" / "K.mtx").toarray()
    m = scipy.io.mmread(SCENES / "beam_friction" / "M.mtx").toarray()
    kept = [i for i in range(k.shape[0]) if i != 20]
    omega2 = scipy.linalg.eigh(k[np.ix_(kept, kept)], m[np.ix_(kept, kept)], eigvals_only=True)
    omega_n = np.sqrt(omega2[0])
    first = doc["points"][0]
    # Round-off of two dense eigensolvers on a 20-dof beam (entries up to 2.4e4).
    assert first["omega"] == pytest.approx(omega_n, rel=1e-10)
    # The scene's D = 0.05 M: damping ratio 0.05 / (2 omega_n).
    assert first["damping_ratio"] == pytest.approx(0.05 / (2 * omega_n), rel=1e-10)
    # Past the slip onset (tip amplitude 0.01) the slider softens the mode.
    assert doc["points"][-1]["omega"] < omega_n * (1 - 1e-3)


def test_with_values_equals_set_on_the_command_line(cli):
    values = {"forcing.omega_ratio": 1.1, "solver.harmonics": 12, "contact.gap": 0.3}
    scene = ssn.Scene.from_file(FIG1).with_values(values)
    assert scene.values == values
    assert_same_document(ssn.solve(scene).to_dict(), cli("solve", FIG1, *set_args(values)))


def test_the_built_in_rod_is_the_scene_of_the_same_keys(cli, tmp_path):
    rod = ssn.Scene.rod(elements=20, mass="modified", gap=0.5, values={"solver.harmonics": 20})
    text = FIG1.read_text().replace('title = "Paper Fig. 1 (modified mass, massless contact node)"', "")
    path = tmp_path / "rod.toml"
    path.write_text(text)
    python = ssn.solve(rod).to_dict()
    command_line = cli("solve", path)
    python.pop("scene"), command_line.pop("scene")
    assert_same_document(python, command_line)


def read_matrix_market(path):
    a = scipy.io.mmread(path)
    return a.toarray() if scipy.sparse.issparse(a) else np.asarray(a)


@pytest.mark.parametrize("kind", ["numpy", "scipy"])
def test_a_model_from_matrices_equals_the_exported_scene(cli, ssn_bin, tmp_path, kind):
    """The rod exported as Matrix Market files, read back with scipy and given as matrices,
    solves to the command line's answer on the exported scene (another path to the same
    structure: files read by scipy, COO triplets, no scene file)."""
    out = tmp_path / "rod"
    subprocess.run([ssn_bin, "export-model", str(FIG1), str(out)], check=True, capture_output=True)
    f = read_matrix_market(out / "f.mtx").ravel()
    if kind == "scipy":
        # The stored entries of the files, in three sparse formats.
        m, k, d = (scipy.io.mmread(out / f"{name}.mtx") for name in "MKD")
        m, k = scipy.sparse.csr_matrix(m), scipy.sparse.csc_matrix(k)
    else:
        m, k, d = (read_matrix_market(out / f"{name}.mtx") for name in "MKD")
    n = k.shape[0]
    # The exported scene: the tip (1-based dof n) against a stop at 0.5, H = 20.
    exported = (out / "scene.toml").read_text()
    assert f"dof = {n}\ndirection = 1\ngap = 0.5" in exported and "harmonics = 20" in exported
    values = {"solver.harmonics": 20, "output.dof": n}
    scene = ssn.Scene.from_matrices(m, k, f, contacts=[(n - 1, 0.5)], damping=d, values=values)
    python = ssn.solve(scene).to_dict()
    command_line = cli("solve", out / "scene.toml")
    python.pop("scene"), command_line.pop("scene")
    assert_same_document(python, command_line)
    # A contact given as a row of G is the same contact.
    row = np.zeros(n)
    row[n - 1] = 1.0
    by_row = ssn.Scene.from_matrices(
        m, k, f, contacts=[{"row": row, "gap": 0.5}], damping=d, values=values
    )
    assert_same_document(ssn.solve(by_row).to_dict(), python | {"scene": "<matrices>"})
    # A sweep and the solutions at one frequency of the structure given as matrices equal
    # those of the program on the exported scene with the same keys set (the exported scene
    # states every solver key, the time samples too: set them for the new H on both sides).
    more = {
        "solver.harmonics": 10,
        "solver.time_samples": 128,
        "sweep.omega_ratio_from": 0.9,
        "sweep.omega_ratio_to": 1.1,
    }
    sweep_scene = scene.with_values(more)
    response = ssn.sweep(sweep_scene).to_dict()
    assert_same_document(response, cli("sweep", out / "scene.toml", *set_args(more)))
    assert response["points"] > 5 and response["converged"]
    at = {"forcing.omega_ratio": 1.05}
    found = ssn.solutions(sweep_scene.with_values(at)).to_dict()
    assert_same_document(found, cli("solutions", out / "scene.toml", *set_args(more | at)))
    assert len(found["solutions"]) >= 1


def test_a_bad_value_raises_a_scene_error_naming_the_key():
    scene = ssn.Scene.from_file(FIG1)
    with pytest.raises(ssn.SceneError, match=r"solver\.harmonics.*1\.\.=2000"):
        scene.with_values({"solver.harmonics": 0})
    with pytest.raises(ssn.SceneError, match="gapp"):
        scene.with_values({"contact.gapp": 0.3})
    with pytest.raises(ssn.SceneError, match=r"contact\.gap"):
        scene.with_values({"contact.gap": "wide"})
    with pytest.raises(ssn.SceneError, match="no such file|cannot read scene"):
        ssn.Scene.from_file(SCENES / "missing.toml")
    with pytest.raises(ssn.SceneError, match=r"forcing\.amplitude"):
        ssn.Scene.rod(amplitude=float("nan"))
    # A non-symmetric stiffness is named like the file of an imported model.
    k = np.array([[2.0, -1.0], [-0.5, 2.0]])
    with pytest.raises(ssn.SceneError, match="not symmetric"):
        ssn.Scene.from_matrices(np.eye(2), k, [1.0, 0.0])
    assert issubclass(ssn.SceneError, ValueError)


def test_scenes_and_results_survive_pickling():
    scene = ssn.Scene.from_file(FIG2).with_values({"contact.gap": 0.3})
    again = pickle.loads(pickle.dumps(scene))
    assert again.values == scene.values and again.text == scene.text
    solution = ssn.solve(scene)
    copy = pickle.loads(pickle.dumps(solution))
    assert copy.to_dict() == solution.to_dict()
    np.testing.assert_array_equal(copy.displacement, solution.displacement)
    response = ssn.sweep(scene)
    assert pickle.loads(pickle.dumps(response)).to_dict() == response.to_dict()
    m = scipy.sparse.diags([1.0, 1.0, 0.0]).tocsr()
    k = scipy.sparse.csr_matrix(np.array([[2.0, -1, 0], [-1, 12, -10], [0, -10, 10]]))
    model = ssn.Scene.from_matrices(m, k, [0.0, 1.0, 0.0], contacts=[(2, 0.1)],
                                    values={"damping.zeta": 0.02, "forcing.amplitude": 0.5})
    model_again = pickle.loads(pickle.dumps(model))
    assert ssn.solve(model_again).to_dict()["tip_max"] == ssn.solve(model).to_dict()["tip_max"]


def test_stability_of_the_overhang_solutions():
    """The stability of the solve at the frequency equals that of the same solution found by
    `solutions` (the first crossing is the one a solve from zero reaches here)."""
    scene = ssn.Scene.from_file(FIG2).with_values(OVERHANG | {"forcing.omega_ratio": 0.9})
    st = ssn.stability(scene)
    found = ssn.solutions(scene).solutions
    assert len(found) == 1 and st.stable is True and found[0]["stable"] is True
    assert st.floquet_max_abs == pytest.approx(found[0]["floquet_max_abs"], rel=1e-8)
    assert abs(st.multipliers[0]) == pytest.approx(st.floquet_max_abs, rel=1e-12)


def test_solves_release_the_gil():
    """A Python thread keeps running while a sweep runs in another thread."""
    scene = ssn.Scene.from_file(FIG2).with_values({"solver.harmonics": 20, "rod.elements": 200})
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    counter = threading.Thread(target=count)
    counter.start()
    started = time.perf_counter()
    ssn.sweep(scene)
    elapsed = time.perf_counter() - started
    done.set()
    counter.join()
    during = [t for t in ticks if started < t < started + elapsed]
    # With the GIL held the counter would not tick at all during the sweep; sleeping 1 ms a
    # tick, it ticks at least once per 20 ms even on a loaded machine.
    assert elapsed > 0.05, "the sweep is too short to tell"
    assert len(during) >= elapsed / 0.02, (len(during), elapsed)


def test_a_mistuning_pattern_from_numpy_equals_the_command_line(cli):
    """A [bladed_disk] scene whose per-blade mistuning is a numpy array: the solve equals the
    program's with the same list given by --set."""
    disk = SCENES / "bladed_disk_mistuned.toml"
    pattern = np.random.default_rng(7).normal(0.0, 0.02, 8)
    values = {"bladed_disk.blades": 8, "bladed_disk.mistuning": pattern, "contact.gap": 0.5}
    python = ssn.solve(ssn.Scene.from_file(disk).with_values(values)).to_dict()
    listed = "[" + ", ".join(repr(float(d)) for d in pattern) + "]"
    as_text = {**values, "bladed_disk.mistuning": listed}
    assert_same_document(python, cli("solve", disk, *set_args(as_text)))
    with pytest.raises(ssn.SceneError, match="bladed_disk.mistuning"):
        ssn.Scene.from_file(disk).with_values({"bladed_disk.mistuning": pattern})
