"""Shape measures of tetrahedra: dihedral angles and similarity classes (docs/method.md,
*Three dimensions: bisection*), the numbers that show bisection keeps cells shape regular.
"""

from __future__ import annotations

from itertools import permutations

import numpy as np

from .reference import TETRAHEDRON

__all__ = ["dihedral_angles", "min_dihedral_angle", "similarity_classes", "similarity_forms"]

#: The 24 orderings of a tetrahedron's vertices.
_PERMUTATIONS = np.array(list(permutations(range(4))), dtype=np.int64)


def dihedral_angles(points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """``(n, 6)`` dihedral angles (radians) at the local edges ``TETRAHEDRON.edges`` of the
    cells ``(n, 4)``: at edge ``i–j`` the angle between the faces opposite the other two
    vertices ``k, l``, ``pi - angle(n_k, n_l)`` of their normals."""
    p = points[cells]
    face = p[:, TETRAHEDRON.facets]  # (n, 4, 3, 3), face k opposite vertex k
    normal = np.cross(face[:, :, 1] - face[:, :, 0], face[:, :, 2] - face[:, :, 0])
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    others = np.array([sorted(set(range(4)) - set(e)) for e in TETRAHEDRON.edges.tolist()])
    cos = np.einsum("nek,nek->ne", normal[:, others[:, 0]], normal[:, others[:, 1]])
    return np.pi - np.arccos(np.clip(cos, -1.0, 1.0))


def min_dihedral_angle(points: np.ndarray, cells: np.ndarray) -> float:
    """The smallest dihedral angle (degrees) of the cells ``(n, 4)``."""
    return float(np.degrees(dihedral_angles(points, cells).min()))


def similarity_forms(points: np.ndarray, cells: np.ndarray, *, decimals: int = 8) -> np.ndarray:
    """``(n, 6)`` the canonical form of each cell ``(n, 4)`` up to translation, scaling,
    rotation and reflection: the lexicographically smallest, over the 24 vertex orderings,
    of the six squared edge lengths divided by the largest (six lengths in a fixed vertex
    labelling fix a tetrahedron up to isometry), rounded to ``decimals`` digits; two cells
    are similar where their rows are equal."""
    e = TETRAHEDRON.edges
    q = points[cells][:, _PERMUTATIONS]  # (n, 24, 4, 3)
    d = q[:, :, e[:, 1]] - q[:, :, e[:, 0]]
    length2 = (d * d).sum(-1)  # (n, 24, 6)
    length2 /= length2.max(axis=-1, keepdims=True)
    form = np.round(length2, decimals)
    # the lexicographically smallest of the 24 rows
    rank = np.lexsort(form.transpose(2, 0, 1)[::-1].reshape(6, -1)).reshape(-1)
    flat = form.reshape(-1, 6)[rank]
    owner = rank // 24
    _, first = np.unique(owner, return_index=True)
    return flat[first]


def similarity_classes(
    points: np.ndarray, cells: np.ndarray, *, rotations: bool = True, decimals: int = 8
) -> int:
    """The number of similarity classes of the cells ``(n, 4)``.

    With ``rotations`` (the default), cells are equal up to translation, scaling, rotation
    and reflection (:func:`similarity_forms`). Without, cells are equal up to translation and
    scaling only (and the point reflection ``x -> -x``): the canonical form is the sorted set
    of the six edge vectors, each of sign with its first non-zero component positive,
    divided by the longest. Forms are rounded to ``decimals`` digits.
    """
    if rotations:
        canon = similarity_forms(points, cells, decimals=decimals)
    else:
        e = TETRAHEDRON.edges
        p = points[cells]
        d = p[:, e[:, 1]] - p[:, e[:, 0]]  # (n, 6, 3)
        d /= np.linalg.norm(d, axis=-1).max(axis=1)[:, None, None]
        d = np.round(d, decimals) + 0.0
        lead = np.take_along_axis(d, (d != 0).argmax(-1)[..., None], axis=-1)
        d *= np.where(lead < 0, -1.0, 1.0)
        d = np.round(d, decimals) + 0.0
        key = d.reshape(-1, 3)
        # the six vectors of each cell in lexicographic order
        cell = np.repeat(np.arange(cells.shape[0]), 6)
        idx = np.lexsort((key[:, 2], key[:, 1], key[:, 0], cell))
        canon = key[idx].reshape(-1, 18)
    return int(np.unique(canon, axis=0).shape[0])
