"""Cell regions: a label per cell naming the part of the body it belongs to (a material).

A mesh's cells carry ``cell_region (n_cells,)``, an index into ``region_names``; a mesh built
without regions has one, :data:`DEFAULT_REGION`. Children of a refined cell take their
parent's region (:func:`~signorini.mesh.refine.refine_nvb`). Region selectors follow the
package's convention for user functions: they are called with points ``x (n, 2)``, here the
cell centroids, and return one value per point.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np

from .validation import MeshError

__all__ = ["DEFAULT_REGION", "RegionSpec", "checked_regions", "region_labels", "with_regions"]

#: The one region of a mesh built without regions.
DEFAULT_REGION = "body"

RegionSpec = np.ndarray | Mapping[str, Callable[[np.ndarray], np.ndarray]]


def region_labels(
    regions: RegionSpec | None, centroids: np.ndarray
) -> tuple[np.ndarray, tuple[str, ...]]:
    """The index ``(n_cells,)`` of each cell's region and the region names, from a user's
    ``regions``.

    Parameters
    ----------
    regions : array_like, mapping or None
        - ``None``: every cell in :data:`DEFAULT_REGION`;
        - an ``(n_cells,)`` array of int or str labels (an int label ``3`` names the region
          ``"3"``), regions sorted by label;
        - a mapping region name -> selector ``f(x) -> (n,) bool`` of the cell centroids
          ``x (n, 2)``; every cell must be claimed by exactly one selector; regions in the
          mapping's order.
    centroids : (n_cells, 2) float array

    Raises
    ------
    MeshError
        Naming the fault: a wrong length or kind, a selector that raises (chained) or returns
        the wrong thing, a cell claimed by none or by two selectors (with its centroid).
    """
    n = len(centroids)
    if regions is None:
        return np.zeros(n, dtype=np.int64), (DEFAULT_REGION,)
    if isinstance(regions, Mapping):
        return _from_selectors(regions, centroids)
    labels = np.asarray(regions)
    if labels.shape != (n,):
        raise MeshError(
            f"regions must give one label per cell ({n}), got an array of shape {labels.shape}"
        )
    if (
        labels.dtype.kind not in "iuUSO"
        or labels.dtype.kind == "O"
        and n
        and not all(isinstance(v, str | int | np.integer) for v in labels)
    ):
        raise MeshError(
            f"regions must be int or str labels, or a mapping name -> selector; got dtype "
            f"{labels.dtype}"
        )
    unique, index = np.unique(labels, return_inverse=True)
    return index.astype(np.int64).reshape(-1), tuple(str(v) for v in unique)


def _from_selectors(
    regions: Mapping[str, Callable[[np.ndarray], np.ndarray]], centroids: np.ndarray
) -> tuple[np.ndarray, tuple[str, ...]]:
    n = len(centroids)
    names = tuple(str(k) for k in regions)
    if not names:
        raise MeshError("regions is an empty mapping; give at least one region")
    index = np.full(n, -1, dtype=np.int64)
    for k, (name, select) in enumerate(regions.items()):  # a loop over regions, not cells
        if not callable(select):
            raise MeshError(
                f"the selector of region {name!r} must be a function f(x) of the cell "
                f"centroids x (n, 2), got {type(select).__name__}"
            )
        try:
            mask = np.asarray(select(centroids))
        except Exception as exc:
            raise MeshError(
                f"the selector of region {name!r} raised {type(exc).__name__}: {exc} (it is "
                f"called with the cell centroids x of shape ({n}, 2))"
            ) from exc
        if mask.shape != (n,) or mask.dtype != bool:
            raise MeshError(
                f"the selector of region {name!r} must return a bool array of shape ({n},) "
                f"for the cell centroids, got {mask.dtype} of shape {mask.shape}"
            )
        twice = mask & (index >= 0)
        if twice.any():
            c = int(np.flatnonzero(twice)[0])
            raise MeshError(
                f"cell {c} (centroid {centroids[c].tolist()}) is claimed by regions "
                f"{names[index[c]]!r} and {name!r}; each cell belongs to one region"
            )
        index[mask] = k
    free = np.flatnonzero(index < 0)
    if free.size:
        c = int(free[0])
        raise MeshError(
            f"{free.size} cell(s) belong to no region, e.g. cell {c} (centroid "
            f"{centroids[c].tolist()}); the selectors of {list(names)} must cover every cell"
        )
    return index, names


def with_regions(mesh, regions: RegionSpec):
    """A copy of ``mesh`` (the same points, cells, boundary parts and curves) whose cells carry
    ``regions``, as :func:`region_labels` reads them (labels per cell, or selectors of the
    cell centroids): regions for a mesh built without them, e.g. by
    :func:`~signorini.mesh.builders.half_disc` or a builder of an example.

    Parameters
    ----------
    mesh : Mesh
    regions : array_like or mapping

    Returns
    -------
    Mesh

    Raises
    ------
    MeshError
        As :func:`region_labels`: a cell claimed by no selector or by two, labels of the wrong
        size.
    """
    region, names = region_labels(regions, mesh.points[mesh.cells].mean(axis=1))
    return type(mesh)(
        mesh.points,
        mesh.cells,
        mesh.boundary,
        mesh.boundary_part,
        mesh.part_names,
        validate=False,
        curves=mesh.curves,
        cell_region=region,
        region_names=names,
    )


def checked_regions(
    cell_region: np.ndarray | None, region_names: tuple[str, ...] | list[str] | None, n: int
) -> tuple[np.ndarray, tuple[str, ...]]:
    """The cells' region indices ``(n,)`` (read-only) and the region names of a mesh of ``n``
    cells, checked; by default every cell in one region, :data:`DEFAULT_REGION`.

    Raises
    ------
    MeshError
        If ``cell_region`` does not give each cell an index into ``region_names``, or the
        names repeat.
    """
    if cell_region is None:
        cell_region = np.zeros(n, dtype=np.int64)
    names = (DEFAULT_REGION,) if region_names is None else tuple(str(r) for r in region_names)
    region = np.ascontiguousarray(cell_region, dtype=np.int64).reshape(-1)
    if region.shape != (n,) or (n and (region.min() < 0 or region.max() >= len(names))):
        raise MeshError(
            f"cell_region must give each of the {n} cells an index into region_names "
            f"{list(names)}, got shape {region.shape}"
            + (f" and values in [{region.min()}, {region.max()}]" if region.size else "")
        )
    if len(set(names)) != len(names):
        raise MeshError(f"region_names must be distinct, got {list(names)}")
    region.flags.writeable = False
    return region, names
