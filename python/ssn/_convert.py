"""Matrices and contacts given in Python, as the native module reads them."""

import numpy as np


def coo(matrix, vector=False):
    """``(rows, cols, i, j, values)`` of a numpy array, a scipy.sparse matrix or a list.

    A vector (``vector=True``) of length N is read as an N x 1 matrix.
    """
    if hasattr(matrix, "tocoo"):
        c = matrix.tocoo()
        shape = c.shape
        i, j, v = c.row, c.col, c.data
        if vector and shape[0] == 1:
            shape, i, j = (shape[1], 1), j, i
    else:
        a = np.asarray(matrix, dtype=float)
        if vector:
            a = a.reshape(-1, 1)
        if a.ndim != 2:
            raise ValueError(f"a matrix must have 2 dimensions, not {a.ndim}")
        shape = a.shape
        i, j = np.nonzero(a)
        v = a[i, j]
    return (
        int(shape[0]),
        int(shape[1]),
        np.asarray(i, dtype=np.int64).tolist(),
        np.asarray(j, dtype=np.int64).tolist(),
        np.asarray(v, dtype=float).tolist(),
    )


def contacts(items):
    """Contacts as ``(dof, gap, direction)`` with a 0-based dof.

    Each item is ``(dof, gap)``, ``(dof, gap, direction)`` or a mapping with ``dof`` or
    ``row`` (a row of G: a signed unit vector), ``gap`` and optionally ``direction``.
    """
    out = []
    for k, item in enumerate(items):
        if isinstance(item, dict):
            gap = float(item["gap"])
            direction = int(item.get("direction", 1))
            if "row" in item:
                row = np.asarray(item["row"], dtype=float).ravel()
                nonzero = np.flatnonzero(row)
                if len(nonzero) != 1 or abs(abs(row[nonzero[0]]) - 1.0) > 0:
                    raise ValueError(
                        f"contact {k}: row of G with {len(nonzero)} non-zero entries: "
                        "allowed a signed unit row (+1 or -1 on one dof); contacts that "
                        "combine dofs are not supported"
                    )
                dof = int(nonzero[0])
                direction *= int(np.sign(row[dof]))
            else:
                dof = int(item["dof"])
        else:
            dof, gap, *rest = item
            dof, gap = int(dof), float(gap)
            direction = int(rest[0]) if rest else 1
        if dof < 0:
            raise ValueError(f"contact {k}: dof {dof}: allowed a 0-based dof >= 0")
        out.append((dof, gap, direction))
    return out
