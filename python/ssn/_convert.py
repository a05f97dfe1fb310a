"""Matrices and contacts given in Python, as the native module reads them.

Every refusal is a ``ValueError`` (``TypeError`` for a value of the wrong type) naming the
argument, the entry (0-based, as numpy indexes it) and what is allowed.
"""

import numbers

import numpy as np


def _real(a, name):
    """``a`` as a float array; a complex array is refused (its imaginary part would be lost)."""
    if np.iscomplexobj(a):
        raise ValueError(
            f"{name}: complex values (dtype {np.asarray(a).dtype}): allowed real numbers "
            "(the model's matrices and load are real)"
        )
    try:
        return np.asarray(a, dtype=float)
    except (TypeError, ValueError) as e:
        raise TypeError(f"{name}: not an array of real numbers ({e})") from None


def _finite(i, j, v, name):
    """Refuses the first non-finite entry ``v[k]`` at row ``i[k]``, column ``j[k]``."""
    bad = np.flatnonzero(~np.isfinite(v))
    if len(bad):
        k = bad[0]
        raise ValueError(
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
                raise ValueError(
                    f"{name}: shape {a.shape}: allowed a vector of length N (shape (N,), "
                    "(N, 1) or (1, N))"
                )
            a = a.reshape(-1, 1)
        if a.ndim != 2:
            raise ValueError(f"{name}: {a.ndim} dimensions (shape {a.shape}): allowed 2")
        shape = a.shape
        nonzero = a != 0
        i, j = np.nonzero(nonzero)
        v = a[i, j]
    if vector and len(shape) == 2 and shape[1] != 1:
        raise ValueError(f"{name}: shape {shape}: allowed a vector of length N")
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
        raise TypeError(f"{what}: {value!r} ({type(value).__name__}): allowed an integer")
    if isinstance(value, numbers.Integral):
        return int(value)
    if not (np.isfinite(value) and float(value).is_integer()):
        raise ValueError(f"{what}: {value!r}: allowed an integer")
    return int(value)


def _number(value, what):
    """``value`` as a float when it is a real number."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise TypeError(f"{what}: {value!r} ({type(value).__name__}): allowed a number")
    return float(value)


def _row(row, what):
    """A row of G as ``(dofs, coefficients)`` (0-based dofs of its non-zero entries)."""
    r = _real(row, what).ravel()
    nonzero = np.flatnonzero(r)
    if len(nonzero) == 0:
        raise ValueError(f"{what}: no non-zero entry: allowed a row of G with one")
    _finite(np.zeros(len(r), dtype=int), np.arange(len(r)), r, what)
    return nonzero.tolist(), r[nonzero].tolist()


CONTACT_KEYS = ("dof", "row", "gap", "direction", "friction", "tangent")


def _contact_dict(k, item):
    """The scene keys of the contact mapping ``item`` (dofs 1-based, as in scene files)."""
    unknown = sorted(set(item) - set(CONTACT_KEYS), key=str)
    if unknown:
        raise ValueError(
            f"contact {k}: unknown key {unknown[0]!r}: allowed {', '.join(CONTACT_KEYS)} "
            "(friction with a tangential row `tangent`)"
        )
    if "gap" not in item:
        raise ValueError(f"contact {k}: `gap` missing")
    if ("dof" in item) == ("row" in item):
        raise ValueError(f"contact {k}: allowed one of `dof` (0-based) and `row` (a row of G)")
    point = {"gap": _number(item["gap"], f"contact {k}: gap")}
    direction = _integer(item.get("direction", 1), f"contact {k}: direction")
    if "row" in item:
        dofs, coefficients = _row(item["row"], f"contact {k}: row")
        if len(dofs) == 1 and abs(coefficients[0]) == 1.0:
            point["dof"], point["direction"] = dofs[0] + 1, direction * int(coefficients[0])
        else:
            if "direction" in item:
                raise ValueError(
                    f"contact {k}: `direction` with a row over several dofs: the signs of "
                    "the row give the direction"
                )
            point["dofs"] = [d + 1 for d in dofs]
            point["coefficients"] = coefficients
    else:
        point["dof"] = _integer(item["dof"], f"contact {k}: dof") + 1
        point["direction"] = direction
    if ("friction" in item) != ("tangent" in item):
        raise ValueError(
            f"contact {k}: `friction` and `tangent` (the tangential row of G) go together"
        )
    if "friction" in item:
        point["friction"] = _number(item["friction"], f"contact {k}: friction")
        dofs, coefficients = _row(item["tangent"], f"contact {k}: tangent")
        point["tangent_dofs"] = [d + 1 for d in dofs]
        point["tangent_coefficients"] = coefficients
    return point


def contacts(items):
    """Contacts as dictionaries of ``[[contact.point]]`` keys (dofs 1-based).

    Each item is ``(dof, gap)``, ``(dof, gap, direction)`` with a 0-based dof, or a mapping
    with ``dof`` or ``row`` (a row of G over the dofs), ``gap``, optionally ``direction``
    (with ``dof`` or a signed unit row), and ``friction`` with ``tangent`` (the tangential
    row of G: Coulomb friction of that contact). Two contacts on one dof and direction are
    refused with their 0-based indices and dof.
    """
    out = []
    for k, item in enumerate(items):
        if isinstance(item, dict):
            point = _contact_dict(k, item)
        else:
            try:
                dof, gap, *rest = item
            except (TypeError, ValueError):
                raise ValueError(
                    f"contact {k}: {item!r}: allowed (dof, gap), (dof, gap, direction) or a "
                    "mapping"
                ) from None
            if len(rest) > 1:
                raise ValueError(f"contact {k}: {len(rest) + 2} values: allowed 2 or 3")
            point = {
                "dof": _integer(dof, f"contact {k}: dof") + 1,
                "gap": _number(gap, f"contact {k}: gap"),
                "direction": _integer(rest[0], f"contact {k}: direction") if rest else 1,
            }
        if "dof" in point:
            if point["dof"] < 1:
                raise ValueError(
                    f"contact {k}: dof {point['dof'] - 1}: allowed a 0-based dof >= 0"
                )
            same = (point["dof"], point["direction"])
            for other, p in enumerate(out):
                if (p.get("dof"), p.get("direction")) == same:
                    raise ValueError(
                        f"contacts {other} and {k}: both on dof {point['dof'] - 1} (0-based) "
                        f"with direction {point['direction']}: allowed one contact per dof "
                        "and direction (two contacts on one dof need opposite directions)"
                    )
        out.append(point)
    return out
