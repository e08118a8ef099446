"""Conforming simplicial meshes (triangles, tetrahedra) with labelled boundary facets (edges
in 2D, faces in 3D).

Conventions (fixed for the whole package)
-----------------------------------------
- ``points (n_points, 2)`` float64, ``cells (n_cells, 3)`` int64, counter-clockwise; or, in
  3D, ``points (n_points, 3)``, ``cells (n_cells, 4)`` with ``det[x1 − x0, x2 − x0, x3 − x0]
  > 0``, so that local face ``k`` (opposite vertex ``k``) of ``TETRAHEDRON`` is outward
  (:mod:`signorini.mesh.tetrahedra`). The cells' width sets :attr:`Mesh.reference` and
  :attr:`Mesh.dim`. In 3D the facets are the faces (``boundary (n_b, 3)``) and the edges
  (six per cell) carry the P2 nodes; the cells keep their vertex order
  (:func:`~signorini.mesh.tetrahedra.initial_vertex_order`).
- Local edge ``k`` of a cell joins its local vertices ``TRIANGLE.edges[k]``, ``k`` and ``k + 1``
  mod 3 (:mod:`signorini.mesh.reference`, the one owner of local topology).
- Local edge 0 (``cells[:, 0]``–``cells[:, 1]``) is the *refinement edge* of newest vertex
  bisection and ``cells[:, 2]`` the newest vertex. :meth:`Mesh.from_arrays` puts the longest
  edge first; refinement keeps the convention.
- ``edges (n_edges, 2)`` store each undirected edge once, as ``(min, max)`` vertex pair.
  ``cell2edge (n_cells, 3)`` gives the edge of local edge ``k``. The *facets* (where parts,
  tractions, jumps and contact live; a triangle's facets are its edges, the same arrays in
  2D): ``facet2cell (n_facets, 2)`` the two cells of a facet, ``-1`` outside the domain
  (boundary facets have their cell in column 0).
- The boundary is split into named *parts* (``part_names``); every boundary facet carries the
  index of its part in ``boundary_part``. What a part means (Dirichlet, Neumann, contact) is the
  business of :mod:`signorini.problem`, not of the mesh. Parts survive refinement.
- Cells carry a *region* (``region_names``, ``cell_region``: e.g. one per material,
  :mod:`signorini.mesh.regions`); a child cell takes its parent's region.

A :class:`Mesh` is immutable; derived topology is computed once and cached. Building one from
user arrays runs the checks of :mod:`signorini.mesh.validation`.

Part selectors follow the package's one convention for user functions: they are called with
points ``x`` of shape ``(..., 2)`` (here the boundary edge midpoints, ``(n, 2)``) and return
one value per point.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping
from functools import cached_property

import numpy as np

from .curves import Curve
from .mesh_geometry import MeshGeometry
from .parts import check_parts, part_indices
from .reference import ReferenceCell
from .regions import RegionSpec, checked_regions, region_labels
from .surfaces import Surface
from .tetrahedra import REFERENCES, initial_vertex_order, reference_of, reoriented
from .topology import (
    boundary_facets,
    entity_topology,
    facet_local,
    longest_edge_first,
    rows_of,
)
from .validation import (
    MeshError,
    as_cells,
    as_points,
    check_on_curve,
    nondegenerate_area,
    validate_mesh,
)
from .validation3d import check_on_surface, nondegenerate_volume

__all__ = ["Mesh", "MeshError", "boundary_facets"]

logger = logging.getLogger(__name__)

_NO_CELLS = np.zeros(0, dtype=np.int64)
_NO_CELLS.flags.writeable = False


class Mesh(MeshGeometry):
    """An immutable conforming triangulation with named boundary parts.

    Parameters
    ----------
    points : (n_points, 2) float array
        Vertex coordinates.
    cells : (n_cells, 3) int array
        Counter-clockwise triangles; local edge 0 is the refinement edge.
    boundary : (n_boundary, 2) int array
        Vertex pairs of all boundary edges (any orientation).
    boundary_part : (n_boundary,) int array
        Index into ``part_names`` of each boundary edge.
    part_names : sequence of str
        Names of the boundary parts; every part must own at least one edge.
    validate : bool
        Check the mesh (:func:`~signorini.mesh.validation.validate_mesh`: orientation,
        degeneracy, duplicate points, conformity, overlap, labels). Unlike
        :meth:`from_arrays`, the constructor refuses clockwise cells. Refinement, which
        preserves validity by construction, skips it.
    curves : sequence of Curve or None, optional
        The curve each part carries (``None`` for a part without one), one per part name;
        attach curves with :meth:`with_curve`, which checks them.
    cell_region : (n_cells,) int array, optional
        Index into ``region_names`` of each cell; by default every cell is in one region,
        ``"body"``.
    region_names : sequence of str, optional
        The names of the cell regions (e.g. Gmsh physical surfaces), one per region index.

    Attributes
    ----------
    reoriented : (k,) int array
        Indices of the cells that :meth:`from_arrays` received clockwise and listed
        counter-clockwise (empty for every other mesh, e.g. a refined one).
    curves : tuple of Curve or None
        The curve of each part, ``None`` for straight parts (see :meth:`with_curve`).

    Raises
    ------
    MeshError
        With a message naming the offending cells, edges or points.
    """

    reoriented: np.ndarray = _NO_CELLS

    def __init__(
        self,
        points: np.ndarray,
        cells: np.ndarray,
        boundary: np.ndarray,
        boundary_part: np.ndarray,
        part_names: tuple[str, ...] | list[str],
        *,
        validate: bool = True,
        curves: tuple[Curve | None, ...] | list[Curve | None] | None = None,
        cell_region: np.ndarray | None = None,
        region_names: tuple[str, ...] | list[str] | None = None,
    ) -> None:
        if validate:  # argument kinds first: a clear error instead of NumPy's
            points = as_points(points)
            cells = as_cells(cells, len(points), width=points.shape[1] + 1)
        self.points = np.ascontiguousarray(points, dtype=np.float64)
        self.cells = np.ascontiguousarray(cells, dtype=np.int64)
        boundary = np.asarray(boundary, dtype=np.int64)
        width = self.cells.shape[1] - 1  # a facet's vertices
        if boundary.ndim == 1 and boundary.size % width == 0:  # flat list of facets, or empty
            boundary = boundary.reshape(-1, width)
        self.boundary = np.ascontiguousarray(boundary)
        self.boundary_part = np.ascontiguousarray(boundary_part, dtype=np.int64).reshape(-1)
        self.part_names = tuple(str(p) for p in part_names)
        if curves is None:
            curves = (None,) * len(self.part_names)
        self.curves = tuple(curves)
        if len(self.curves) != len(self.part_names) or not all(
            c is None or isinstance(c, (Curve, Surface)) for c in self.curves
        ):
            raise MeshError(
                f"curves needs one Curve or None per part ({len(self.part_names)}) (in 3D a "
                f"Surface), got {self.curves!r}"
            )
        self.cell_region, self.region_names = checked_regions(
            cell_region, region_names, self.cells.shape[0]
        )
        for a in (self.points, self.cells, self.boundary, self.boundary_part, self.cell_region):
            a.flags.writeable = False
        if validate:
            validate_mesh(self)

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_arrays(
        cls,
        points: np.ndarray,
        cells: np.ndarray,
        parts: Mapping[str, np.ndarray | Callable[[np.ndarray], np.ndarray]],
        *,
        regions: RegionSpec | None = None,
    ) -> Mesh:
        """Build a mesh from user arrays, putting each triangle's longest edge first.

        Cells may come in either orientation (other tools mix them): clockwise cells are
        listed counter-clockwise (negative tetrahedra positively); their indices are kept in
        :attr:`reoriented` and their number is logged (``logging.INFO``). Only degenerate
        cells are refused. Tetrahedra keep their vertex order
        (:func:`~signorini.mesh.tetrahedra.initial_vertex_order`).

        Parameters
        ----------
        points : (n_points, d) float array
            d = 2, or d = 3 for tetrahedra.
        cells : (n_cells, d + 1) int array
            Triangles or tetrahedra, in either orientation.
        parts : mapping from part name (str) to either
            - a ``(k, d)`` int array of boundary facets' vertices (pairs, or face triples),
            - or a selector ``f(x) -> (n,) bool array``, called with the boundary facet
              centroids ``x`` of shape ``(n, d)`` (edge midpoints in 2D; ``x[:, 0]`` …
              are the coordinates). A 2D selector written ``f(x, y)`` still works, with a
              ``DeprecationWarning``.

            Selectors claim only the edges no list names; a boundary edge claimed by two
            parts is an error.
        regions : array or mapping, optional
            The cells' regions (e.g. one per material): an ``(n_cells,)`` array of int or str
            labels, or a mapping region name -> selector ``f(x) -> (n,) bool`` of the cell
            centroids ``x (n, d)`` claiming every cell once
            (:func:`~signorini.mesh.regions.region_labels`). By default one region, ``"body"``.

        Raises
        ------
        MeshError
            Before any work for arguments of the wrong kind (``points`` or ``cells`` that
            are not arrays of numbers, ``parts`` that is not a mapping); then at the first
            fault of the mesh, naming it.
        """
        names = check_parts(parts)
        points = as_points(points)
        cells = as_cells(cells, len(points), width=points.shape[1] + 1)
        reference = reference_of(points, cells)
        if reference.dim == 2:
            measure = nondegenerate_area(points, cells)
        else:
            measure = nondegenerate_volume(points, cells)
        cells, flipped = reoriented(cells, measure)
        if flipped.size:
            logger.info(
                "Mesh.from_arrays: %d of %d cells were clockwise and were reoriented",
                flipped.size,
                cells.shape[0],
            )
        if reference.dim == 2:
            cells = longest_edge_first(points, cells)
        else:
            cells = initial_vertex_order(points, cells)
        bnd = boundary_facets(cells, reference.facets)
        part_of = part_indices(points, bnd, parts, names)
        region, region_names = region_labels(regions, points[cells].mean(axis=1))
        mesh = cls(
            points, cells, bnd, part_of, names, cell_region=region, region_names=region_names
        )
        if flipped.size:
            mesh.reoriented = _frozen(flipped)
        return mesh

    def with_curve(self, part: str, curve: Curve | Surface, *, rtol: float = 1e-8) -> Mesh:
        """A new mesh whose boundary part ``part`` carries ``curve`` (in 3D a surface).

        Refinement then puts the new vertex of a bisected edge of the part at the curve's
        halfway point (:meth:`Curve.halfway`) instead of the chord midpoint, and the P2
        space puts the edge's midpoint node there (:attr:`curved_midpoints`). Cells with an
        edge on a part carrying a curve other than a :class:`~signorini.mesh.curves.Line` are
        isoparametric in assembly (:mod:`signorini.fem.iso`). The points are not moved.

        Parameters
        ----------
        part : str
            A boundary part of the mesh.
        curve : Curve
            E.g. :class:`~signorini.mesh.curves.Circle` or
            :class:`~signorini.mesh.curves.Line`; replaces any curve the part had. In 3D a
            :class:`~signorini.mesh.surfaces.Surface` (``Sphere``, ``Cylinder``), moving the
            midpoints of the edges of the part's faces.
        rtol : float
            Every vertex of the part must lie within ``rtol`` times the mesh's diameter
            (the diagonal of its bounding box) of the curve.

        Raises
        ------
        MeshError
            If ``part`` is not a part, ``curve`` is not a :class:`Curve`, or a vertex of the
            part is off the curve (naming the vertex and its distance).
        """
        index = self.part_index(part)
        kind = "Curve (Line, Circle, ProjectedCurve)" if self.dim == 2 else "Surface (Sphere, …)"
        if not isinstance(curve, Curve if self.dim == 2 else Surface):
            raise MeshError(
                f"with_curve: the curve of part {part!r} must be a {kind}, got "
                f"{type(curve).__name__}"
            )
        vertices = np.unique(self.boundary[self.boundary_part == index])
        check = check_on_curve if self.dim == 2 else check_on_surface
        check(self.points, vertices, curve, part, rtol)
        curves = list(self.curves)
        curves[index] = curve
        mesh = Mesh(
            self.points,
            self.cells,
            self.boundary,
            self.boundary_part,
            self.part_names,
            validate=False,
            curves=curves,
            cell_region=self.cell_region,
            region_names=self.region_names,
        )
        mesh.reoriented = self.reoriented
        return mesh

    # ------------------------------------------------------------------ sizes
    @property
    def reference(self) -> ReferenceCell:
        """The reference cell of the cells, ``TRIANGLE`` for ``cells (n, 3)``, ``TETRAHEDRON``
        for ``(n, 4)``: the one owner of their local topology (edges, facets, VTK names)."""
        return REFERENCES[self.cells.shape[1]]

    @property
    def dim(self) -> int:
        """The dimension of the cells and the points, ``(n_points, dim)``: 2 or 3."""
        return self.reference.dim

    @property
    def n_points(self) -> int:
        return self.points.shape[0]

    @property
    def n_cells(self) -> int:
        return self.cells.shape[0]

    @property
    def n_edges(self) -> int:
        return self.edges.shape[0]

    @property
    def n_facets(self) -> int:
        return self.facets.shape[0]

    # ------------------------------------------------------------------ topology
    @cached_property
    def _topology(self) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """The facets: in 2D the edges (one ``np.unique``), in 3D the faces."""
        return entity_topology(self.cells, self.n_points, self.reference.facets)

    @cached_property
    def _edge_topology(self) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        if self.dim == 2:
            return self._topology
        return entity_topology(self.cells, self.n_points, self.reference.edges, facets=False)

    @property
    def edges(self) -> np.ndarray:
        """``(n_edges, 2)`` vertex pairs, ``min`` first: the carriers of the P2 edge nodes."""
        return self._edge_topology[0]

    @property
    def cell2edge(self) -> np.ndarray:
        """``(n_cells, n_edges of the cell)`` edge index of local edge ``k``
        (``reference.edges[k]``)."""
        return self._edge_topology[1]

    @property
    def facets(self) -> np.ndarray:
        """``(n_facets, dim)`` the vertices of each facet, sorted: where boundary parts,
        tractions, jumps and contact live. A triangle's facets are its edges, so in 2D this
        is :attr:`edges` (the same array)."""
        return self._topology[0]

    @property
    def cell2facet(self) -> np.ndarray:
        """``(n_cells, n_facets of the cell)`` facet index of local facet ``k``
        (``reference.facets[k]``); :attr:`cell2edge` in 2D."""
        return self._topology[1]

    @property
    def facet2cell(self) -> np.ndarray:
        """``(n_facets, 2)`` the cells of each facet, ``-1`` outside the domain (boundary
        facets have their cell in column 0)."""
        return self._topology[2]

    @cached_property
    def facet_local(self) -> np.ndarray:
        """``(n_facets, 2)`` local index ``k`` of each facet in its cells ``facet2cell[:, 0]``
        and ``facet2cell[:, 1]`` (``-1`` outside): ``cell2facet[facet2cell[f, s],
        facet_local[f, s]] == f``."""
        return facet_local(self.cell2facet, self.facet2cell)

    @cached_property
    def boundary_facet(self) -> np.ndarray:
        """``(n_boundary,)`` mesh facet index of each row of :attr:`boundary`."""
        return rows_of(self.facets, self.boundary, self.n_points)

    @cached_property
    def facet_part(self) -> np.ndarray:
        """``(n_facets,)`` boundary part index of each facet, ``-1`` for interior facets."""
        part = np.full(self.n_facets, -1, dtype=np.int64)
        part[self.boundary_facet] = self.boundary_part
        return _frozen(part)

    def part_index(self, name: str) -> int:
        """Index of boundary part ``name``; a clear error if there is none."""
        try:
            return self.part_names.index(name)
        except ValueError:
            raise MeshError(
                f"the mesh has no boundary part {name!r}; its parts are {list(self.part_names)}"
            ) from None

    def part_facets(self, name: str) -> np.ndarray:
        """Mesh facet indices of boundary part ``name``."""
        return self.boundary_facet[self.boundary_part == self.part_index(name)]

    def oriented_boundary(self, facet_index: np.ndarray) -> np.ndarray:
        """The vertices ``(k, dim)`` of boundary facets in their cell's local order
        (``reference.facets``): counter-clockwise around their cell in 2D."""
        cell = self.facet2cell[facet_index, 0]
        local = self.reference.facets[self.facet_local[facet_index, 0]]
        return self.cells[cell[:, None], local]

    # ------------------------------------------------------------------ geometry (MeshGeometry)
    def region_cells(self, name: str) -> np.ndarray:
        """Indices of the cells of region ``name``."""
        if name not in self.region_names:
            raise MeshError(
                f"the mesh has no cell region {name!r}; its regions are {list(self.region_names)}"
            )
        return np.flatnonzero(self.cell_region == self.region_names.index(name))

    def part_measure(self, name: str) -> float:
        """Total measure of boundary part ``name`` (its length in 2D)."""
        return float(self.facet_measure[self.part_facets(name)].sum())

    def __repr__(self) -> str:
        parts = list(self.part_names)
        return f"Mesh(n_points={self.n_points}, n_cells={self.n_cells}, parts={parts})"


def _frozen(a: np.ndarray) -> np.ndarray:
    """Mark a cached array read-only (a Mesh is immutable)."""
    a.flags.writeable = False
    return a
