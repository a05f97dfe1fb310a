"""What Python hands to the native module is checked where it is given: matrices that are
complex, of the wrong shape or not finite, dofs that are not integers, duplicate or
unknown contact keys and values of the wrong type are refused naming the argument, the key
and the entry (0-based, as numpy indexes it), never converted silently; values nested
without end or keys deeper than any scene key are refused without exhausting the stack; a
contact with friction given as matrices is the same contact as in a scene file."""

import pytest
import numpy as np

import ssn

K = np.array([[2.0, -1.0], [-1.0, 1.0]])
M = np.eye(2)
F = np.array([0.0, 1.0])


def refused(error, *words, **kwargs):
    """``Scene.from_matrices(**kwargs)`` (M, K, F by default) raises ``error`` naming ``words``."""
    args = {"mass": M, "stiffness": K, "load": F} | kwargs
    with pytest.raises(error) as raised:
        ssn.Scene.from_matrices(**args)
    for word in words:
        assert word in str(raised.value), str(raised.value)


def test_complex_matrices_are_refused_not_cut_to_their_real_part():
    refused(ValueError, "stiffness", "complex", stiffness=K + 1e-3j * np.eye(2))
    refused(ValueError, "load", "complex", load=F.astype(complex))


def test_a_load_that_is_not_a_vector_is_refused_with_its_shape():
    refused(ValueError, "load", "(2, 2)", load=np.ones((2, 2)))
    refused(ValueError, "load", "(10, 2)", load=np.ones((10, 2)))
    # A column or a row of the right length is a vector.
    damped = {"damping.zeta": 0.02}
    ssn.Scene.from_matrices(M, K, F.reshape(-1, 1), values=damped)
    ssn.Scene.from_matrices(M, K, F.reshape(1, -1), values=damped)


def test_non_finite_entries_are_refused_naming_the_matrix_and_the_entry():
    for bad in [np.nan, np.inf]:
        mass = M.copy()
        mass[1, 1] = bad
        refused(ValueError, "mass", "entry (1, 1)", mass=mass)
    refused(ValueError, "stiffness", "entry (0, 1)", stiffness=np.array([[2.0, np.inf], [-1.0, 1.0]]))


def test_a_dof_that_is_not_an_integer_is_refused():
    refused(ValueError, "contact 0", "dof", "1.7", contacts=[(1.7, 0.1)])
    refused(TypeError, "contact 0", "dof", contacts=[{"dof": "1", "gap": 0.1}])
    # An integer-valued float or a numpy integer is that dof.
    ssn.Scene.from_matrices(M, K, F, contacts=[(1.0, 0.1)])
    ssn.Scene.from_matrices(M, K, F, contacts=[(np.int64(1), 0.1)])


def test_a_duplicate_contact_is_named_with_python_indices():
    refused(ValueError, "contacts 0 and 1", "dof 1 (0-based)", contacts=[(1, 0.1), (1, 0.2)])
    refused(
        ValueError, "contacts 0 and 2", "dof 1 (0-based)",
        contacts=[(1, 0.1), (1, 0.2, -1), {"row": [0.0, 1.0], "gap": 0.3}],
    )


def test_unknown_keys_of_a_contact_mapping_are_refused():
    refused(ValueError, "contact 0", "'fricton'", contacts=[{"dof": 1, "gap": 0.1, "fricton": 0.3}])
    # Friction without its tangential row, and the reverse.
    refused(ValueError, "tangent", contacts=[{"dof": 1, "gap": 0.1, "friction": 0.3}])
    refused(ValueError, "friction", contacts=[{"dof": 1, "gap": 0.1, "tangent": [1.0, 0.0]}])


FRICTION_SCENE = """[model]
mass = "M.mtx"
stiffness = "K.mtx"
[damping]
zeta = 0.02
[forcing]
vector = "f.mtx"
amplitude = 0.1
[[contact.point]]
dofs = [1, 2]
coefficients = [1.0, -1.0]
gap = 0.05
friction = 0.3
tangent_dofs = [1, 2]
tangent_coefficients = [1.0, 1.0]
"""


def write_matrix_market(path, a):
    rows, cols = a.shape
    entries = [(i, j, a[i, j]) for i in range(rows) for j in range(cols) if a[i, j] != 0]
    lines = [f"{i + 1} {j + 1} {float(v)!r}" for i, j, v in entries]
    path.write_text(
        f"%%MatrixMarket matrix coordinate real general\n{rows} {cols} {len(entries)}\n"
        + "\n".join(lines) + "\n"
    )


def test_a_contact_with_friction_over_two_dofs_is_the_scene_files_contact(tmp_path):
    """The same contact (normal row u1 - u2, Coulomb friction 0.3 along u1 + u2) from a
    scene file and from matrices: the same solve, to the last digit (one structure, two
    ways in)."""
    for name, a in [("M.mtx", M), ("K.mtx", K), ("f.mtx", F.reshape(-1, 1))]:
        write_matrix_market(tmp_path / name, a)
    (tmp_path / "scene.toml").write_text(FRICTION_SCENE)
    from_file = ssn.solve(ssn.Scene.from_file(tmp_path / "scene.toml")).to_dict()
    contact = {"row": [1.0, -1.0], "gap": 0.05, "friction": 0.3, "tangent": [1.0, 1.0]}
    scene = ssn.Scene.from_matrices(
        M, K, F, contacts=[contact], values={"damping.zeta": 0.02, "forcing.amplitude": 0.1}
    )
    from_matrices = ssn.solve(scene).to_dict()
    assert from_file["converged"], from_file["termination"]
    for key in ["iterations", "tip_min", "tip_max", "contact_force_mean", "residual_norm"]:
        assert from_matrices[key] == from_file[key], key


def test_values_of_the_wrong_type_name_their_key():
    rod = ssn.Scene.rod()
    with pytest.raises(TypeError, match="`forcing.amplitude`"):
        rod.with_values({"forcing.amplitude": object()})
    with pytest.raises(TypeError, match="scene key 3"):
        rod.with_values({3: 1.0})


def test_deep_keys_and_values_are_refused_without_exhausting_the_stack():
    rod = ssn.Scene.rod()
    with pytest.raises(ssn.SceneError, match="at most 8 parts"):
        rod.with_values({".".join(["a"] * 60_000): 1.0})
    deep = 1.0
    for _ in range(100_000):
        deep = [deep]
    with pytest.raises(ValueError, match="`forcing.amplitude`: lists nested more than 8"):
        rod.with_values({"forcing.amplitude": deep})
    itself = []
    itself.append(itself)
    with pytest.raises(ValueError, match="contains itself"):
        rod.with_values({"forcing.amplitude": itself})


def test_every_refusal_of_a_python_input_is_a_scene_error_of_the_package():
    """Bad values are ``ssn.SceneError``; values of the wrong type ``ssn.SceneTypeError``,
    which is both a ``SceneError`` and a ``TypeError``."""
    assert issubclass(ssn.SceneTypeError, ssn.SceneError)
    assert issubclass(ssn.SceneTypeError, TypeError)
    for kwargs in [
        {"stiffness": K + 1e-3j * np.eye(2)},
        {"load": np.ones((10, 2))},
        {"mass": np.array([[np.nan, 0.0], [0.0, 1.0]])},
        {"contacts": [(1.7, 0.1)]},
        {"contacts": [(1, 0.1), (1, 0.2)]},
        {"contacts": [{"dof": 1, "gap": 0.1, "friction": 0.3}]},
    ]:
        refused(ssn.SceneError, **kwargs)
    for kwargs in [
        {"contacts": [{"dof": "1", "gap": 0.1}]},
        {"contacts": [(1, "0.1")]},
        {"contacts": 5},
        {"contacts": {"dof": 1, "gap": 0.1}},
        {"mass": [[object(), 0.0], [0.0, 1.0]]},
    ]:
        refused(ssn.SceneTypeError, "allowed", **kwargs)
    rod = ssn.Scene.rod()
    with pytest.raises(ssn.SceneTypeError, match="`forcing.amplitude`.*allowed"):
        rod.with_values({"forcing.amplitude": object()})
    with pytest.raises(ssn.SceneTypeError, match="scene key 3: allowed"):
        rod.with_values({3: 1.0})
    itself = []
    itself.append(itself)
    with pytest.raises(ssn.SceneError, match="`forcing.amplitude`.*contains itself"):
        rod.with_values({"forcing.amplitude": itself})


def test_a_contact_the_matrices_refuse_is_named_by_its_python_index():
    """Whatever a scene file would refuse in a contact is refused with the contact's 0-based
    index and 0-based dofs (the second contact here: `contact 1`, never `contact 2` or
    `entry 2` as the scene file's 1-based numbering would say)."""
    good = (0, 0.1)
    for bad, words in [
        ((2, 0.1), ["dof 2", "from 0 to 1"]),
        ({"row": [0.0, 0.0, 1.0], "gap": 0.1}, ["row", "3 entries", "allowed 2"]),
        ((1, np.nan), ["gap nan", "finite"]),
        ((1, 0.1, 2), ["direction 2", "allowed 1", "or -1"]),
        ({"row": [1.0, -1.0], "gap": 0.1, "friction": -0.3, "tangent": [1.0, 1.0]},
         ["friction -0.3", "mu >= 0"]),
        ({"row": [1.0, -1.0], "gap": 0.1, "friction": 0.3, "tangent": [-2.0, 2.0]},
         ["tangent parallel", "independent"]),
        ({"row": [1.0, -1e200], "gap": 0.1}, ["row entry 1e+200", "<= 1e100"]),
        ({"row": [1e-300, 0.0], "gap": 0.1}, ["row of Euclidean norm 1e-300", ">= 1e-100"]),
    ]:
        with pytest.raises(ssn.SceneError) as raised:
            ssn.Scene.from_matrices(M, K, F, contacts=[good, bad])
        message = str(raised.value)
        assert message.startswith("contact 1: "), message
        for word in words:
            assert word in message, message
        assert "contact 2" not in message and "entry 2" not in message, message
    # Two stops on one dof with no room between them: both indices and the dof 0-based.
    refused(
        ssn.SceneError, "contacts 0 and 2", "dof 1 (0-based)", "clearance -0.1",
        contacts=[(1, 0.1), good, (1, -0.2, -1)],
    )


def test_rows_nested_without_end_or_containing_themselves_are_refused_with_their_contact():
    itself = [1.0]
    itself.append(itself)
    deep = 1.0
    for _ in range(100_000):
        deep = [deep]
    for row in [itself, deep]:
        refused(ssn.SceneTypeError, "contact 0: row", contacts=[{"row": row, "gap": 0.1}])
        refused(ssn.SceneTypeError, "contact 0: dof", contacts=[(row, 0.1)])


def test_matrices_the_model_refuses_are_named_by_argument_with_0_based_entries():
    """The checks of an imported model that name an entry (symmetry, a negative mass, the
    sizes) name the argument and the entry 0-based, as numpy indexes it (a scene file's
    `K.mtx` would say entry (1, 2))."""
    refused(
        ssn.SceneError, "stiffness: not symmetric", "entry (0, 1) (0-based)",
        stiffness=np.array([[2.0, -1.0], [0.0, 1.0]]),
    )
    # Within the import's tolerance (1e-9 of the largest entry): accepted, as from a file.
    nearly = K + np.array([[0.0, 1e-10], [0.0, 0.0]])
    ssn.Scene.from_matrices(M, nearly, F, values={"damping.zeta": 0.02})
    refused(ssn.SceneError, "mass: entry (1, 1) (0-based)", ">= 0", mass=np.diag([1.0, -1.0]))
    refused(ssn.SceneError, "load: length 3", "allowed 2", load=np.ones(3))
    refused(ssn.SceneError, "mass: shape (3, 3)", "allowed (2, 2)", mass=np.eye(3))
    refused(ssn.SceneError, "damping: shape (2, 3)", damping=np.ones((2, 3)))
    refused(ssn.SceneError, "stiffness: shape (2, 3)", stiffness=np.ones((2, 3)))
    # The names of the in-memory files never reach the user.
    for bad in [{"mass": np.eye(3)}, {"load": np.ones(3)}, {"stiffness": np.triu(K)}]:
        with pytest.raises(ssn.SceneError) as raised:
            ssn.Scene.from_matrices(**({"mass": M, "stiffness": K, "load": F} | bad))
        assert ".mtx" not in str(raised.value), str(raised.value)


def test_values_that_are_not_a_dict_or_out_of_range_integers_are_scene_errors():
    rod = ssn.Scene.rod()
    with pytest.raises(ssn.SceneTypeError, match="values: a list: allowed a dict"):
        rod.with_values([("forcing.amplitude", 0.1)])
    with pytest.raises(ssn.SceneTypeError, match="values: a list: allowed a dict"):
        ssn.Scene.from_matrices(M, K, F, values=[1])
    with pytest.raises(ssn.SceneError, match="`rod.elements`: the integer 2361183241434822606848"):
        rod.with_values({"rod.elements": 2**71})
    # Booleans are not numbers of a matrix or a row (as they are no dof).
    refused(ssn.SceneTypeError, "contact 0: row", contacts=[{"row": [True, False], "gap": 0.1}])
    refused(ssn.SceneTypeError, "mass", mass=np.eye(2, dtype=bool))
