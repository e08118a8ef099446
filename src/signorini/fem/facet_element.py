"""The facet elements: the trace of a Lagrange element on a facet of its cell (an edge in 2D),
where boundary data, tractions and contact live (docs/method.md, *Discrete problem*, *P1
elements and their estimator*).

A :class:`FacetElement` holds what the contact boundary reads of an element: the basis on a
facet, the number of nodes per facet, the contact weights (the shares ``m_z / |F|`` of the
hats of the contact force density (4.1) and ``w_z / |F|`` of the basis functions on a straight
facet), the pieces ``γ̃_p`` of a contact facet that belong to each of its nodes with their hats
(η6) and without (η8), how per-facet nodal data are read as P2 data, and how a nodal force
becomes the consistent nodal pressure (:meth:`FacetElement.pressure`). The cell's element
(:class:`~signorini.fem.element.Element`) carries its facet element as ``Element.facet``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..mesh.reference import INTERVAL, TRIANGLE, ReferenceCell
from . import p1, p2

__all__ = ["FaceElement", "FacetElement", "P1_INTERVAL", "P2_INTERVAL", "P2_TRIANGLE"]


@dataclass(frozen=True, eq=False)
class FacetElement:
    """The facts of one Lagrange element on a facet of its cell.

    Attributes
    ----------
    name : str
        The cell element's name and the facet's reference cell, e.g. ``"P2 interval"``.
    reference : ReferenceCell
        The facet's reference cell (:data:`~signorini.mesh.reference.INTERVAL` in 2D, with
        the parameter ``t`` in [0, 1] from the facet's start to its end).
    n_nodes : int
        Nodes per facet, ``[start, end]`` (P1) or ``[start, end, midpoint]`` (P2).
    basis : callable
        Values ``(q, n_nodes)`` of the facet's basis functions at ``t (q,)``.
    hat_share, basis_share : tuples of n_nodes floats
        ``∫_F φ_z ds / |F|`` (the hat of the contact force density s_z = Λ_z / m_z, (4.1):
        the half-edge hats of Q^h (3.6) for P2, the P1 hat for P1) and ``∫_F ψ_z ds / |F|``
        (the basis function, the consistent pressure's ``w_z``) of each facet node on a
        straight facet.
    hat_pieces : tuple of ``(lo, hi, column, (φ(0), φ'))``
        The pieces ``γ̃_p`` of [0, 1] that belong to each facet node (``column``), with the
        hat ``φ_p(t) = φ(0) + φ' t`` there (η6): the thirds for P2 (paper (4.12)), the halves
        for P1.
    node_parts : tuple of ``(lo, hi, column)``
        The same pieces without the hat (η8).
    """

    name: str
    reference: ReferenceCell
    n_nodes: int
    basis: Callable[[np.ndarray], np.ndarray]
    hat_share: tuple[float, ...]
    basis_share: tuple[float, ...]
    hat_pieces: tuple
    node_parts: tuple

    def __repr__(self) -> str:
        return self.name

    def facet_values(self, values: np.ndarray) -> np.ndarray:
        """Per-facet nodal data ``(k, n_nodes, ...)`` as ``(k, 3, ...)`` at ``[start, end,
        midpoint]``: unchanged for P2; for P1 the midpoint gets the mean of the ends (so the
        quadratic through the three is the linear interpolant)."""
        values = np.asarray(values, dtype=np.float64)
        if self.n_nodes == 3:
            return values
        mid = 0.5 * (values[:, 0] + values[:, 1])
        return np.concatenate([values, mid[:, None]], axis=1)

    def pressure(self, force: np.ndarray, weight: np.ndarray) -> np.ndarray:
        """The consistent nodal pressure ``p_z = Λ_z / w_z`` of nodal forces ``Λ_z`` (docs/
        method.md, *Discrete problem*).

        ``w_z = ∫_{Γ_C} ψ_z ds`` is the integral of node z's basis function over its contact
        facets (``ContactSet.basis_integral``): for a pressure p linear along the facets (P1:
        constant), ``Λ_z = ∫ p ψ_z ds = p(z) w_z``, so ``p_z`` recovers p at the nodes. On an
        interval every ``w_z`` is positive (P2: ``|F|/6`` at the ends, ``2|F|/3`` at the
        midpoint; P1: ``|F|/2``), and this is the division, elementwise. It turns any nodal
        force of the contact boundary into a stress: the friction force ``Λ_t,z``, the slip
        bound ``s_z``, a master part's transferred force (``w_k`` over the master's facets).

        The trap in three dimensions: on a P2 triangular face the vertex basis functions
        integrate to zero, ``∫_F ψ_z = 0``, so ``w_z`` vanishes at a face's vertices and the
        division is undefined there. A facet element of a 3D cell overrides this method
        (e.g. with the weights of a dual or lumped basis) instead of dividing.

        Parameters
        ----------
        force : (k,) or (k, c) float array
            Nodal forces ``Λ_z`` (or ``c`` components of them).
        weight : (k,) float array
            The nodes' basis integrals ``w_z`` (``(k, 1)`` with a force ``(k, c)``).

        Returns
        -------
        float array, the shape of ``force``
            ``force / weight``.
        """
        return force / weight


#: P2 on an edge: the half-edge hats of Q^h are linear on [0, 1/3] (start), [2/3, 1] (end)
#: and on the two halves of the middle third (midpoint), paper (3.6), (4.12)
P2_INTERVAL = FacetElement(
    name="P2 interval",
    reference=INTERVAL,
    n_nodes=3,
    basis=p2.edge_basis,
    hat_share=(1 / 4, 1 / 4, 1 / 2),
    basis_share=(1 / 6, 1 / 6, 2 / 3),
    hat_pieces=(
        (0.0, 1 / 3, 0, (1.0, -2.0)),
        (2 / 3, 1.0, 1, (-1.0, 2.0)),
        (1 / 3, 0.5, 2, (0.0, 2.0)),
        (0.5, 2 / 3, 2, (2.0, -2.0)),
    ),
    node_parts=((0.0, 1 / 3, 0), (2 / 3, 1.0, 1), (1 / 3, 2 / 3, 2)),
)

#: P1 on an edge: the hat φ_z is the basis function (m_z = w_z = |e|/2 per edge at a vertex),
#: γ̃_p the half of each contact edge next to p (Krause–Veeser–Walloth's choice for linear
#: elements)
P1_INTERVAL = FacetElement(
    name="P1 interval",
    reference=INTERVAL,
    n_nodes=2,
    basis=p1.edge_basis,
    hat_share=(1 / 2, 1 / 2),
    basis_share=(1 / 2, 1 / 2),
    hat_pieces=((0.0, 0.5, 0, (1.0, -1.0)), (0.5, 1.0, 1, (0.0, 1.0))),
    node_parts=((0.0, 0.5, 0), (0.5, 1.0, 1)),
)


def _contact_on_faces(what: str) -> property:
    """A property that refuses: the estimator's pieces of a face are not built yet."""

    def refuse(self: FaceElement) -> None:
        raise NotImplementedError(
            f"{self.name}: {what} of a triangular face is not defined yet -- the estimator on "
            "contact faces is the third part of the 3D work (issue 38); on a flat P2 triangle "
            "the vertex basis functions integrate to zero, so the 2D pieces do not carry over"
        )

    return property(refuse)


class FaceElement(FacetElement):
    """The trace of a 3D cell's element on a triangular face: its basis, nodes per face, basis
    integrals and contact weights (docs/method.md, *Three dimensions: contact on faces*).

    The contact weights of a face: ``hat_share`` the shares ``∫_F φ_p / |F|`` of the P1 hats
    of the once-refined face (the 4 triangles of its side midpoints; the 3D ``Q^h`` of the
    force density ``s_z = Λ_z / m_z``, (4.1)), ``(1/12, 1/12, 1/12, 1/4, 1/4, 1/4)`` for P2;
    ``basis_share`` those of the P2 functions, ``(0, 0, 0, 1/3, 1/3, 1/3)``, and
    :meth:`transformed_share` those of the transformed basis φ̃ of contact condition (b),
    positive for ``0 < α < 1/2``. The pieces ``γ̃_p`` of a face (``hat_pieces``,
    ``node_parts``, the estimator's η6 and η8 on faces) refuse with ``NotImplementedError``.

    Parameters
    ----------
    name : str
    reference : ReferenceCell
        :data:`~signorini.mesh.reference.TRIANGLE`.
    n_nodes : int
        Nodes per face (6 for P2: the vertices, then the midpoints of its sides).
    basis : callable
        Values ``(q, n_nodes)`` at triangle reference points ``s (q, 2)``.
    basis_share, hat_share : tuples of n_nodes floats
        ``∫_F ψ_z / |F|`` and ``∫_F φ_z / |F|`` on a flat face.
    """

    def __init__(
        self,
        name: str,
        reference: ReferenceCell,
        n_nodes: int,
        basis: Callable[[np.ndarray], np.ndarray],
        basis_share: tuple[float, ...],
        hat_share: tuple[float, ...],
    ) -> None:
        for key, value in (
            ("name", name),
            ("reference", reference),
            ("n_nodes", n_nodes),
            ("basis", basis),
            ("basis_share", basis_share),
            ("hat_share", hat_share),
        ):
            object.__setattr__(self, key, value)

    hat_pieces = _contact_on_faces("the pieces γ̃_p of a contact face (hat_pieces)")
    node_parts = _contact_on_faces("the pieces γ̃_p of a contact face (node_parts)")

    def facet_values(self, values: np.ndarray) -> np.ndarray:
        """Per-face nodal data ``(k, 6, ...)``, unchanged (P2)."""
        return np.asarray(values, dtype=np.float64)

    def transformed_share(self, alpha: float) -> tuple[float, ...]:
        """``∫_F φ̃_z / |F|`` on a flat face for the transformed basis ``φ̃_v = φ_v + α Σ φ_e``,
        ``φ̃_e = (1 − 2α) φ_e`` (docs/method.md, *Three dimensions: the contact condition on P2
        faces*): ``w_v + 2α w_e`` at a vertex (its two sides), ``(1 − 2α) w_e`` at a midpoint;
        ``(2α/3, …, (1 − 2α)/3, …)`` for P2, the basis shares at ``α = 0``."""
        w = self.basis_share
        return tuple(w[v] + alpha * (w[3 + v] + w[3 + (v + 2) % 3]) for v in range(3)) + tuple(
            (1.0 - 2.0 * alpha) * w[e] for e in range(3, 6)
        )

    def pressure(self, force: np.ndarray, weight: np.ndarray) -> np.ndarray:
        """The nodal pressure ``p_z = Λ_z / w_z`` of forces on a basis with positive integrals
        ``w_z`` (the transformed basis of condition (b): ``Λ̃_z / ∫ φ̃_z``, exact for a constant
        pressure).

        Raises
        ------
        ValueError
            Where a weight is not positive: the vertices of the P2 basis itself (condition
            (a), ``∫_F ψ_v = 0``), whose pressure is the recovered one
            (``FaceContactSet.recovered_pressure``).
        """
        weight = np.asarray(weight, dtype=np.float64)
        bad = ~(weight > 0)
        if bad.any():
            k = int(np.flatnonzero(bad.reshape(weight.shape[0], -1).any(axis=1))[0])
            raise ValueError(
                f"{self.name}: the nodal pressure Λ_z / w_z needs positive weights; w[{k}] = "
                f"{weight.ravel()[k]:.3g} (on a P2 face the vertex functions integrate to zero: "
                "use the transformed basis, alpha > 0, or the recovered pressure)"
            )
        return np.asarray(force, dtype=np.float64) / weight


#: P2 on a triangular face of a tetrahedron: the P2 triangle's basis; the vertex functions
#: integrate to zero, the midpoint functions to |F|/3; the hats of the once-refined face to
#: |F|/12 at a vertex (one of its 4 triangles) and |F|/4 at a midpoint (three)
P2_TRIANGLE = FaceElement(
    name="P2 triangle",
    reference=TRIANGLE,
    n_nodes=6,
    basis=p2.basis,
    basis_share=(0.0, 0.0, 0.0, 1 / 3, 1 / 3, 1 / 3),
    hat_share=(1 / 12, 1 / 12, 1 / 12, 1 / 4, 1 / 4, 1 / 4),
)
