"""The contact terms' integrals on the contact facets of Γ_C (edges in 2D; η4, η5, η6, η8;
docs/method.md, *Estimator*) and the nodal data they read there: the pressure p_z and the
semi-contact density s_z. All of it is Γ_C's data, O(√n) numbers, replicated on every rank
of a run (:mod:`.owned`); each rank integrates its own contact facets.
"""

from __future__ import annotations

import numpy as np

from ..contact.contact_set import SEMI_CONTACT
from ..contact.solution import ContactResult
from ..fem.mapping import facet_groups
from .friction_facets import FrictionFacets, move_dirichlet_thirds
from .terms import FacetSet, complementarity, friction_work, normal_stress, tangential_stress
from .traction import CellStress, direction_field

__all__ = ["contact_node_parts", "contact_stress", "facet_pressure", "semi_contact_density"]


def contact_stress(
    stresses: CellStress,
    mesh,
    facets: FacetSet,
    normal: np.ndarray,
    direction: np.ndarray,
    t: np.ndarray,
    w: np.ndarray,
    pressure: np.ndarray | None = None,
    friction: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """η4's and η5's integrals ``(k,)`` on the contact ``facets`` from ``σ(u_h) n`` at the
    points ``t`` (weights ``w``): split along the contact part's normal ``normal (k, 2)``
    on straight facets where every nodal constraint direction ``direction (k, 3, 2)`` is that
    normal (the paper's case), else along the direction field
    (:func:`~signorini.estimator.terms.direction_field`; docs/method.md, *Estimator*, "On
    curved boundaries"); with the nodal friction stresses ``friction (k, 3)`` η4 is
    ``‖σ_t + p_t,h‖²``, with the nodal pressures ``pressure (k, 3)`` η5 is
    ``‖σ_nn + p_h‖²``."""
    J4, J5 = np.zeros(facets.index.size), np.zeros(facets.index.size)
    e = facets.index
    for rows, sn, geometry in stresses.on_facets(mesh.facet2cell[e, 0], mesh.facet_local[e, 0], t):
        ds = geometry.speeds(t)
        d, n = direction[rows], normal[rows]
        index = np.arange(e.size)[rows]
        same = np.zeros(len(d), dtype=bool)
        if geometry.normals(t).shape[1] == 1:  # a straight facet: is every n_z its normal?
            same = ~(d != n[:, None, :]).any(axis=(1, 2))
        for sel in (np.flatnonzero(same), np.flatnonzero(~same)):
            if sel.size == 0:
                continue
            split = n[sel] if same[sel[0]] else direction_field(d[sel], t)
            p = None if pressure is None else pressure[index[sel]]
            f = None if friction is None else friction[index[sel]]
            J4[index[sel]] = tangential_stress(sn[sel], split, w, ds[sel], t, f)
            J5[index[sel]] = normal_stress(sn[sel], split, t, w, ds[sel], p)
    return J4, J5


def contact_node_parts(
    result: ContactResult,
    gap: np.ndarray,
    density: np.ndarray,
    friction: FrictionFacets | None,
    curved: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """η6's and η8's parts ``(n_ce, n_nodes)`` of each contact facet's nodes (its facet
    element's nodes: P2 start, end, midpoint; P1 the two ends), η8's with the part of a
    Dirichlet end point moved to a free node (:func:`~.friction.move_dirichlet_thirds`; zero
    without friction), integrated along each facet's geometry (``curved (n_ce,)`` bool: quadratic);
    ``gap``, ``density`` ``(n_ce, 3)`` as :func:`~.terms.complementarity` reads them."""
    space, cs = result.space, result.contact
    facet = space.element.facet
    parts6 = np.zeros(gap.shape)
    parts8 = np.zeros(gap.shape)
    for rows, facets in facet_groups(space.node_points[cs.facet_nodes], curved):
        parts6[rows] = complementarity(gap[rows], density[rows], facets, None, facet.hat_pieces)
        if friction is not None:
            slip, bound, p_t = friction.slip[rows], friction.bound[rows], friction.friction[rows]
            parts8[rows] = friction_work(slip, p_t, bound, facets, None, facet.node_parts)
    n = facet.n_nodes
    return parts6[:, :n], move_dirichlet_thirds(parts8, cs.facet_local)[:, :n]


def facet_pressure(result: ContactResult) -> np.ndarray:
    """The nodal pressures ``p_z`` at ``[start, end, midpoint]`` of each contact facet
    ``(n_ce, 3)``, 0 at Dirichlet end points."""
    loc = result.contact.facet_local
    return np.where(loc >= 0, result.pressure[np.maximum(loc, 0)], 0.0)


def semi_contact_density(result: ContactResult) -> np.ndarray:
    """The density ``s_p`` (4.1) at ``[start, end, midpoint]`` of each contact facet where p is
    a semi-contact node, else 0: ``(n_ce, 3)``. A negative Λ_p is round-off (the solver's
    KKT check bounds it) and counts as 0: η6² = s_p d_p must not turn negative."""
    loc = result.contact.facet_local
    semi = result.classes == SEMI_CONTACT
    use = (loc >= 0) & semi[np.maximum(loc, 0)]
    return np.where(use, np.maximum(result.density[np.maximum(loc, 0)], 0.0), 0.0)
