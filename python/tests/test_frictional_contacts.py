"""3-D frictional contacts through the package: a node sliding on a circle against its closed
form, and the shipped blade-casing scene (a moving obstacle, no other load) solved and swept
to the command line's documents with each point's 3-D contact numbers."""

import math

import numpy as np
import pytest
import scipy.io
import scipy.sparse

import ssn
from conftest import SCENES, assert_same_document

BLADE_CASING = SCENES / "blade_casing.toml"
OMEGA, MU, NORMAL = 1.3, 0.3, 1.5
#: The blade-casing scene's friction coefficient.
BLADE_FRICTION = 0.3


def write_node(directory):
    """One node (three unit masses on unit springs, damping 0.05) pressed along z by a
    static load 2 on an obstacle at 0.5 (normal force 1.5), driven in the plane by
    ``(cos w t, sin w t)``; the scene's path."""
    eye = scipy.sparse.identity(3, format="coo")
    for name, matrix in [("M", eye), ("K", eye), ("D", 0.05 * eye)]:
        scipy.io.mmwrite(directory / f"{name}.mtx", matrix)
    for name, index, value in [("fc", 0, 1.0), ("fs", 1, 1.0), ("press", 2, 2.0)]:
        vector = scipy.sparse.coo_matrix(([value], ([index], [0])), shape=(3, 1))
        scipy.io.mmwrite(directory / f"{name}.mtx", vector)
    (directory / "nodes.dof").write_text("7.1\n7.2\n7.3\n")
    scene = directory / "scene.toml"
    scene.write_text(
        '[model]\nmass = "M.mtx"\nstiffness = "K.mtx"\ndamping = "D.mtx"\n'
        'dof_map = "nodes.dof"\n\n[forcing]\nvector = "fc.mtx"\nvector_sin = "fs.mtx"\n'
        f'static = "press.mtx"\namplitude = 1.0\nomega = {OMEGA}\n\n[[contact.point]]\n'
        f"node = 7\nnormal = [0.0, 0.0, 1.0]\ngap = 0.5\nfriction = {MU}\n\n"
        '[solver]\nmethod = "ssn-hb"\nharmonics = 3\n'
    )
    return scene


def circle_radius():
    """The sliding circle's radius: ``((k - m w^2)^2 + c^2 w^2) r^2 + 2 c w b r + b^2 - F^2
    = 0`` with ``b = mu N`` (no code of ours)."""
    w, b = OMEGA, MU * NORMAL
    a = (1.0 - w * w) ** 2 + (0.05 * w) ** 2
    half = 0.05 * w * b
    return (-half + math.sqrt(half * half - a * (b * b - 1.0))) / a


def test_a_node_sliding_on_a_circle_dissipates_two_pi_mu_n_r(cli, tmp_path):
    scene_path = write_node(tmp_path)
    solution = ssn.solve(ssn.Scene.from_file(scene_path))
    doc = solution.to_dict()
    assert_same_document(doc, cli("solve", scene_path))
    (contact,) = doc["frictional_contacts"]
    expected = 2.0 * math.pi * MU * NORMAL * circle_radius()
    # Exact on the circle at any H: Newton's tolerance alone (1e-10 of the forces).
    assert contact["dissipated_energy"] == pytest.approx(expected, rel=1e-8)
    assert contact["max_normal_force"] == pytest.approx(NORMAL, rel=1e-8)
    assert contact["max_tangential_force"] == pytest.approx(MU * NORMAL, rel=1e-8)
    assert contact["slip_fraction"] == 1.0
    t1, t2 = (np.asarray(c) for c in contact["tangential_force"])
    assert np.allclose(np.hypot(t1, t2), MU * NORMAL, rtol=1e-8)


def test_the_blade_casing_scene_solves_and_sweeps_as_the_command_line(cli):
    scene = ssn.Scene.from_file(BLADE_CASING)
    solved = ssn.solve(scene).to_dict()
    assert_same_document(solved, cli("solve", BLADE_CASING))
    (contact,) = solved["frictional_contacts"]
    # The tip touches the casing over part of the period and slides all the while.
    assert 0.0 < contact["slip_fraction"] < 1.0 and contact["stick_fraction"] == 0.0
    response = ssn.sweep(scene).to_dict()
    assert_same_document(response, cli("sweep", BLADE_CASING))
    points = response["frictional_contacts"]
    assert len(points) == response["points"] and all(len(p) == 1 for p in points)
    # Sliding whenever it touches: the largest tangential force is mu times the largest
    # normal force, to HB's truncation at the contact's onset (measured 8.6e-3 at H = 20).
    for (point,) in points:
        assert point["dissipated_energy"] > 0.0
        assert point["max_tangential_force"] == pytest.approx(
            BLADE_FRICTION * point["max_normal_force"], rel=2e-2
        )
