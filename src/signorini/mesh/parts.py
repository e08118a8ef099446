"""Boundary parts named by the user (:meth:`Mesh.from_arrays <signorini.mesh.Mesh.from_arrays>`):
each part given as a list of boundary vertex pairs (face triples in 3D) or as a selector
``f(x)`` of the edge midpoints ``x (n, 2)`` (face centroids ``(n, 3)``), checked before any
work and resolved to one part index per boundary facet.
"""

from __future__ import annotations

import inspect
import warnings
from collections.abc import Callable, Mapping

import numpy as np

from .topology import find_rows
from .validation import MeshError, as_cells

__all__ = ["check_parts", "part_indices"]


def check_parts(parts: object) -> list[str]:
    """The part names of ``parts``, after checking that it is a mapping from str to an edge
    list or a selector (before any work on the mesh)."""
    if not isinstance(parts, Mapping):
        raise MeshError(
            "parts must be a mapping {name: (k, 2) boundary vertex pairs or selector f(x)}, "
            f"got {type(parts).__name__}"
        )
    for name, spec in parts.items():
        if not isinstance(name, str):
            raise MeshError(f"part names must be strings, got {name!r}")
        if callable(spec):
            continue
        if isinstance(spec, (str, bytes)):
            raise MeshError(
                f"boundary part {name!r} must be a (k, 2) array of boundary vertex pairs or a "
                f"selector f(x), got the string {spec[:40]!r}"
            )
        try:
            a = np.asarray(spec)
        except (TypeError, ValueError):  # ragged nested sequences
            a = np.array([None])
        if a.size and a.dtype.kind not in "iuf":
            raise MeshError(
                f"boundary part {name!r} must be a (k, 2) array of boundary vertex pairs or a "
                f"selector f(x), got {type(spec).__name__}"
            )
    return list(parts)


def _takes_x_and_y(f: Callable) -> bool:
    """Whether ``f`` is an old-style selector ``f(x, y)``: exactly two required positional
    parameters and no ``*args``."""
    try:
        params = inspect.signature(f).parameters.values()
    except (TypeError, ValueError):  # no signature (some builtins): the documented form
        return False
    positional = (inspect.Parameter.POSITIONAL_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD)
    required = [p for p in params if p.kind in positional and p.default is inspect.Parameter.empty]
    star = any(p.kind is inspect.Parameter.VAR_POSITIONAL for p in params)
    return len(required) == 2 and not star


def _select(name: str, f: Callable, mid: np.ndarray) -> np.ndarray:
    """The selector of part ``name`` at the edge midpoints ``mid (n, 2)`` (face centroids
    ``(n, 3)``): a ``(n,)`` bool array, or a :class:`MeshError` naming the part."""
    try:
        if mid.shape[1] == 2 and _takes_x_and_y(f):
            warnings.warn(
                f"the selector of boundary part {name!r} takes (x, y); selectors take the "
                "points x of shape (n, 2): write `lambda x: ...` with x[:, 0] and x[:, 1] "
                "for the coordinates (the form f(x, y) will stop working)",
                DeprecationWarning,
                stacklevel=4,  # the caller of Mesh.from_arrays
            )
            hit = f(mid[:, 0], mid[:, 1])
        else:
            hit = f(mid)
    except Exception as exc:
        raise MeshError(
            f"the selector of boundary part {name!r} raised {type(exc).__name__}: {exc}"
        ) from exc
    hit = np.asarray(hit)
    if hit.dtype.kind not in "biuf" or hit.size != len(mid):
        raise MeshError(
            f"the selector of boundary part {name!r} must return one bool per edge "
            f"midpoint, shape ({len(mid)},), got shape {hit.shape} of {hit.dtype}"
        )
    return hit.astype(bool).reshape(-1)


def part_indices(
    points: np.ndarray,
    bnd: np.ndarray,
    parts: Mapping[str, np.ndarray | Callable[[np.ndarray], np.ndarray]],
    names: list[str],
) -> np.ndarray:
    """``(n_boundary,)`` the index into ``names`` of the part that claims each boundary facet
    ``bnd (n_boundary, d)`` (edges, or faces in 3D; ``-1`` for none): the facets a part
    lists, then the facets its selector picks among those no list names (see :meth:`Mesh.from_arrays
    <signorini.mesh.Mesh.from_arrays>`).

    Raises
    ------
    MeshError
        If a listed pair is not a boundary edge, or two parts claim one edge.
    """
    part_of = np.full(len(bnd), -1, dtype=np.int64)
    width = bnd.shape[1]
    what = "edge" if width == 2 else "face"
    listed = None  # edges named by an explicit list; predicates only claim the others
    for index in sorted(range(len(names)), key=lambda i: callable(parts[names[i]])):
        name = names[index]
        spec = parts[name]
        if callable(spec):
            if listed is None:
                listed = part_of >= 0
            if width == 2:
                mid = 0.5 * (points[bnd[:, 0]] + points[bnd[:, 1]])
            else:
                mid = points[bnd].mean(axis=1)  # the face centroids
            hit = _select(name, spec, mid)
            where = np.flatnonzero(hit & ~listed)
        else:
            pairs = np.asarray(spec)
            if pairs.size == 0:
                where = np.zeros(0, dtype=np.int64)
            else:
                if pairs.ndim == 1 and pairs.size % width == 0:
                    pairs = pairs.reshape(-1, width)
                pairs = as_cells(pairs, len(points), what=f"boundary {what}s", width=width)
                where, found = find_rows(bnd, pairs, len(points))
                if not found.all():
                    bad = pairs[~found][0]
                    raise MeshError(
                        f"boundary part {name!r}: {tuple(int(v) for v in bad)} is not a "
                        f"boundary {what} of the mesh"
                    )
        taken = where[part_of[where] >= 0]
        if taken.size:
            other = names[part_of[taken[0]]]
            bad = bnd[taken[0]]
            raise MeshError(
                f"boundary {what} {tuple(int(v) for v in bad)} is claimed by both parts "
                f"{other!r} and {name!r}"
            )
        part_of[where] = index
    return part_of
