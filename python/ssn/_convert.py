"""Matrices and contacts given in Python, as the native module reads them.

Every refusal is a ``SceneError`` (``SceneTypeError``, also a ``TypeError``, for a value
of the wrong type) naming the argument, the entry (0-based, as numpy indexes it) and what is
allowed.
"""

import numbers
import reprlib

import numpy as np

from ._errors import SceneError, SceneTypeError


def _real(a, name):
    """``a`` as a float array; a complex array is refused (its imaginary part would be lost)."""
    try:
        complex_values = np.iscomplexobj(a)
        if np.asarray(a).dtype == bool:
            raise TypeError("booleans")
        if not complex_values:
            return np.asarray(a, dtype=float)
    except (TypeError, ValueError, RecursionError) as e:
        raise SceneTypeError(
            f"{name}: not an array of real numbers ({e}): allowed a numpy array, a "
            "scipy.sparse matrix or nested lists of real numbers"
        ) from None
    raise SceneError(
        f"{name}: complex values (dtype {np.asarray(a).dtype}): allowed real numbers "
        "(the model's matrices and load are real)"
    )


def _shown(value):
    """``value`` as a message shows it: its repr, shortened (and bounded in depth, so that
    a list nested without end or containing itself shows as ``[[...]]``)."""
    return reprlib.repr(value)


def _finite(i, j, v, name):
    """Refuses the first non-finite entry ``v[k]`` at row ``i[k]``, column ``j[k]``."""
    bad = np.flatnonzero(~np.isfinite(v))
    if len(bad):
        k = bad[0]
        raise SceneError(
            f"{name}: entry ({int(i[k])}, {int(j[k])}) (0-based) is {v[k]}: allowed finite "
            f"numbers ({len(bad)} non-finite entries)"
        )


def coo(matrix, vector=False, name="matrix"):
    """``(rows, cols, i, j, values)`` of a numpy array, a scipy.sparse matrix or a list.

    A vector (``vector=True``) of length N (a 1-D array, or N x 1, or 1 x N) is read as an
    N x 1 matrix; any other shape is refused with the shape.
    """
    if hasattr(matrix, "tocoo"):
        c = matrix.tocoo()
        shape = c.shape
        i, j, v = c.row, c.col, _real(c.data, name)
        if vector and shape[0] == 1:
            shape, i, j = (shape[1], 1), j, i
    else:
        a = _real(matrix, name)
        if vector:
            if a.ndim > 2 or (a.ndim == 2 and min(a.shape) > 1):
                raise SceneError(
                    f"{name}: shape {a.shape}: allowed a vector of length N (shape (N,), "
                    "(N, 1) or (1, N))"
                )
            a = a.reshape(-1, 1)
        if a.ndim != 2:
            raise SceneError(f"{name}: {a.ndim} dimensions (shape {a.shape}): allowed 2")
        shape = a.shape
        nonzero = a != 0
        i, j = np.nonzero(nonzero)
        v = a[i, j]
    if vector and len(shape) == 2 and shape[1] != 1:
        raise SceneError(f"{name}: shape {shape}: allowed a vector of length N")
    _finite(i, j, np.asarray(v, dtype=float), name)
    return (
        int(shape[0]),
        int(shape[1]),
        np.asarray(i, dtype=np.int64).tolist(),
        np.asarray(j, dtype=np.int64).tolist(),
        np.asarray(v, dtype=float).tolist(),
    )


def _integer(value, what):
    """``value`` as an int when it is an integer (an int or an integer-valued float)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise SceneTypeError(f"{what}: {_shown(value)} ({type(value).__name__}): allowed an integer")
    if isinstance(value, numbers.Integral):
        return int(value)
    if not (np.isfinite(value) and float(value).is_integer()):
        raise SceneError(f"{what}: {_shown(value)}: allowed an integer")
    return int(value)


def _number(value, what):
    """``value`` as a float when it is a real number."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise SceneTypeError(f"{what}: {_shown(value)} ({type(value).__name__}): allowed a number")
    return float(value)


def _row(row, what, n):
    """A row of G over ``n`` dofs as ``(dofs, coefficients)`` (0-based dofs of its non-zero
    entries)."""
    r = _real(row, what).ravel()
    if len(r) != n:
        raise SceneError(f"{what}: {len(r)} entries: allowed {n}, one per dof of the matrices")
    nonzero = np.flatnonzero(r)
    if len(nonzero) == 0:
        raise SceneError(f"{what}: no non-zero entry: allowed a row of G with one")
    _finite(np.zeros(len(r), dtype=int), np.arange(len(r)), r, what)
    return nonzero.tolist(), r[nonzero].tolist()


CONTACT_KEYS = ("dof", "row", "gap", "direction", "friction", "tangent")

#: Largest magnitude of a gap, a row coefficient or a friction coefficient (as in scene files).
MAX_SCALE = 1e100

#: Largest departure of ``|cos|`` from 1 at which a tangential row counts as parallel to the
#: normal row (as in scene files: round-off of rows given to 16 digits).
PARALLEL_TOLERANCE = 1e-9


def _dense_row(dofs, coefficients, n):
    """The row of G with ``coefficients`` at the 1-based ``dofs`` as a dense vector."""
    row = np.zeros(n)
    np.add.at(row, np.asarray(dofs) - 1, coefficients)
    return row


def _check_values(k, point, dofs):
    """Refuses, naming contact ``k`` (0-based), what a scene file refuses in one contact: a gap
    or a coefficient that is not finite or above ``MAX_SCALE`` in magnitude, a row of norm
    below ``1 / MAX_SCALE``, a direction other than +1 or -1, a friction coefficient outside
    ``[0, MAX_SCALE]``, a tangential row parallel to the normal row."""
    if not (np.isfinite(point["gap"]) and abs(point["gap"]) <= MAX_SCALE):
        raise SceneError(
            f"contact {k}: gap {point['gap']}: allowed a finite number with |gap| <= 1e100"
        )
    if point.get("direction", 1) not in (1, -1):
        raise SceneError(
            f"contact {k}: direction {point['direction']}: allowed 1 (obstacle on the positive "
            "side: u[dof] <= gap) or -1 (negative side: -u[dof] <= gap)"
        )
    for key, name in [("coefficients", "row"), ("tangent_coefficients", "tangent")]:
        values = np.abs(point.get(key, [1.0]))
        largest = values.max()
        if largest > MAX_SCALE:
            raise SceneError(f"contact {k}: {name} entry {largest:g}: allowed |entries| <= 1e100")
        norm = largest * np.linalg.norm(values / largest)
        if norm < 1.0 / MAX_SCALE:
            raise SceneError(
                f"contact {k}: {name} of Euclidean norm {norm:g}: allowed >= 1e-100 (the "
                "contact's stiffness 1 / (G K^-1 G^T) would overflow)"
            )
    if "friction" not in point:
        return
    mu = point["friction"]
    if not 0.0 <= mu <= MAX_SCALE:
        raise SceneError(
            f"contact {k}: friction {mu}: allowed a finite Coulomb coefficient mu >= 0 (the "
            "slip limit is mu times the normal force)"
        )
    if "dof" in point:
        normal = _dense_row([point["dof"]], [float(point["direction"])], dofs)
    else:
        normal = _dense_row(point["dofs"], point["coefficients"], dofs)
    tangent = _dense_row(point["tangent_dofs"], point["tangent_coefficients"], dofs)
    normal, tangent = normal / np.abs(normal).max(), tangent / np.abs(tangent).max()
    cosine = normal @ tangent / (np.linalg.norm(normal) * np.linalg.norm(tangent))
    if abs(cosine) >= 1.0 - PARALLEL_TOLERANCE:
        raise SceneError(
            f"contact {k}: tangent parallel to the contact's normal row (cosine {cosine:.6f}): "
            "allowed a tangential row independent of the normal row (the slip direction)"
        )


def _contact_dict(k, item, n):
    """The scene keys of the contact mapping ``item`` (dofs 1-based, as in scene files)."""
    unknown = sorted(set(item) - set(CONTACT_KEYS), key=str)
    if unknown:
        raise SceneError(
            f"contact {k}: unknown key {unknown[0]!r}: allowed {', '.join(CONTACT_KEYS)} "
            "(friction with a tangential row `tangent`)"
        )
    if "gap" not in item:
        raise SceneError(f"contact {k}: `gap` missing")
    if ("dof" in item) == ("row" in item):
        raise SceneError(f"contact {k}: allowed one of `dof` (0-based) and `row` (a row of G)")
    point = {"gap": _number(item["gap"], f"contact {k}: gap")}
    direction = _integer(item.get("direction", 1), f"contact {k}: direction")
    if "row" in item:
        dofs, coefficients = _row(item["row"], f"contact {k}: row", n)
        if len(dofs) == 1 and abs(coefficients[0]) == 1.0:
            point["dof"], point["direction"] = dofs[0] + 1, direction * int(coefficients[0])
        else:
            if "direction" in item:
                raise SceneError(
                    f"contact {k}: `direction` with a row over several dofs: the signs of "
                    "the row give the direction"
                )
            point["dofs"] = [d + 1 for d in dofs]
            point["coefficients"] = coefficients
    else:
        point["dof"] = _integer(item["dof"], f"contact {k}: dof") + 1
        point["direction"] = direction
    if ("friction" in item) != ("tangent" in item):
        raise SceneError(
            f"contact {k}: `friction` and `tangent` (the tangential row of G) go together"
        )
    if "friction" in item:
        point["friction"] = _number(item["friction"], f"contact {k}: friction")
        dofs, coefficients = _row(item["tangent"], f"contact {k}: tangent", n)
        point["tangent_dofs"] = [d + 1 for d in dofs]
        point["tangent_coefficients"] = coefficients
    return point


def _check_pair(k, point, previous):
    """Refuses contact ``k`` on one dof beside an earlier contact in ``previous`` on that dof:
    in the same direction, or in the opposite direction with no room between the obstacles
    (a sum of the gaps <= 0); both named with their 0-based indices and dof."""
    dof, direction = point["dof"], point["direction"]
    for other, p in enumerate(previous):
        if p.get("dof") != dof:
            continue
        if p["direction"] == direction:
            raise SceneError(
                f"contacts {other} and {k}: both on dof {dof - 1} (0-based) with direction "
                f"{direction}: allowed one contact per dof and direction (two contacts on one "
                "dof need opposite directions)"
            )
        clearance = p["gap"] + point["gap"]
        if not clearance > 0.0:
            raise SceneError(
                f"contacts {other} and {k}: gaps {p['gap']} and {point['gap']} on dof "
                f"{dof - 1} (0-based) in opposite directions (clearance {clearance}): allowed "
                "two gaps on one dof whose sum is > 0 (room between the two obstacles)"
            )


def contacts(items, dofs):
    """Contacts on matrices of ``dofs`` dofs as dictionaries of ``[[contact.point]]`` keys
    (dofs 1-based).

    Each item is ``(dof, gap)``, ``(dof, gap, direction)`` with a 0-based dof, or a mapping
    with ``dof`` or ``row`` (a row of G over the dofs), ``gap``, optionally ``direction``
    (with ``dof`` or a signed unit row), and ``friction`` with ``tangent`` (the tangential
    row of G: Coulomb friction of that contact). What a scene file refuses in a contact is
    refused here, naming the contact by its 0-based index and its dofs 0-based.
    """
    try:
        if isinstance(items, dict):
            raise TypeError
        items = list(items)
    except TypeError:
        raise SceneTypeError(
            f"contacts: {_shown(items)} ({type(items).__name__}): allowed a list of contacts "
            "(a list of one mapping for one contact)"
        ) from None
    out = []
    for k, item in enumerate(items):
        if isinstance(item, dict):
            point = _contact_dict(k, item, dofs)
        else:
            try:
                dof, gap, *rest = item
            except (TypeError, ValueError):
                raise SceneError(
                    f"contact {k}: {_shown(item)}: allowed (dof, gap), (dof, gap, direction) or a "
                    "mapping"
                ) from None
            if len(rest) > 1:
                raise SceneError(f"contact {k}: {len(rest) + 2} values: allowed 2 or 3")
            point = {
                "dof": _integer(dof, f"contact {k}: dof") + 1,
                "gap": _number(gap, f"contact {k}: gap"),
                "direction": _integer(rest[0], f"contact {k}: direction") if rest else 1,
            }
        if "dof" in point and not 1 <= point["dof"] <= dofs:
            raise SceneError(
                f"contact {k}: dof {point['dof'] - 1}: allowed a 0-based dof from 0 to "
                f"{dofs - 1} (the matrices have {dofs} dofs)"
            )
        _check_values(k, point, dofs)
        if "dof" in point:
            _check_pair(k, point, out)
        out.append(point)
    return out


#: Largest relative asymmetry ``|a_ij - a_ji| / max |a|`` of a mass or stiffness matrix (as
#: for an imported model: round-off).
SYMMETRY_TOLERANCE = 1e-9


def _summed(n, i, j, v):
    """The entries ``(i, j, v)`` of an ``n``-column matrix with duplicates summed, as sorted
    keys ``i n + j`` and their values."""
    keys, inverse = np.unique(np.asarray(i) * n + np.asarray(j), return_inverse=True)
    values = np.zeros(len(keys))
    np.add.at(values, inverse, v)
    return keys, values


def _check_symmetric(name, n, i, j, v):
    """Refuses a matrix with ``|a_ij - a_ji| > SYMMETRY_TOLERANCE max |a|``, naming the
    first such entry 0-based."""
    keys, values = _summed(n, i, j, v)
    if len(keys) == 0:
        return
    rows, cols = keys // n, keys % n
    transposed_keys = cols * n + rows
    at = np.minimum(np.searchsorted(keys, transposed_keys), len(keys) - 1)
    transposed = np.where(keys[at] == transposed_keys, values[at], 0.0)
    tolerance = SYMMETRY_TOLERANCE * np.abs(values).max()
    bad = np.flatnonzero(np.abs(values - transposed) > tolerance)
    if len(bad):
        k = bad[0]
        r, c = int(rows[k]), int(cols[k])
        raise SceneError(
            f"{name}: not symmetric: entry ({r}, {c}) (0-based) = {values[k]:e} but ({c}, {r}) "
            f"= {transposed[k]:e}: allowed |a_ij - a_ji| <= {tolerance:e} (relative "
            f"{SYMMETRY_TOLERANCE:e} of the largest entry)"
        )
    diagonal = np.flatnonzero((rows == cols) & (values < 0.0))
    if name == "mass" and len(diagonal):
        d = int(rows[diagonal[0]])
        raise SceneError(
            f"mass: entry ({d}, {d}) (0-based) = {values[diagonal[0]]:e}: allowed >= 0 (0: a "
            "massless dof)"
        )


def parts(mass, stiffness, load, damping=None):
    """The model's parts as ``[(file name, coo)]`` (``coo`` as :func:`coo` gives it), after
    the checks of an imported model that name an entry, here 0-based with the argument's
    name: sizes (``stiffness`` N x N, ``mass`` and ``damping`` as ``stiffness``, ``load`` of
    length N), symmetry of ``mass`` and ``stiffness``, a mass diagonal >= 0."""
    k = coo(stiffness, name="stiffness")
    n = k[0]
    if k[1] != n or n == 0:
        raise SceneError(f"stiffness: shape ({k[0]}, {k[1]}): allowed N x N with N >= 1")
    f = coo(load, True, "load")
    if f[0] != n:
        raise SceneError(f"load: length {f[0]}: allowed {n} (one entry per dof of the stiffness)")
    square = [("M.mtx", "mass", coo(mass, name="mass")), ("K.mtx", "stiffness", k)]
    if damping is not None:
        square.append(("D.mtx", "damping", coo(damping, name="damping")))
    for _, name, (rows, cols, i, j, v) in square:
        if (rows, cols) != (n, n):
            raise SceneError(
                f"{name}: shape ({rows}, {cols}): allowed ({n}, {n}), the stiffness' shape"
            )
        if name != "damping":
            _check_symmetric(name, n, i, j, v)
    return [(file, matrix) for file, _, matrix in square] + [("f.mtx", f)]
