"""What the frictional extension of the estimator reads on the contact facets (edges in 2D;
docs/method.md, *Estimator*, "With friction").

With Tresca or Coulomb friction, η4 balances the tangential stress by the discrete friction
stress, ``‖σ_t(u_h) + p_t,h‖``, and η8 measures the defect of the friction work,
``∫ (max(b_h, |p_t,h|) |u_t| − p_t,h u_t)``. Both are quadratics on each contact facet through
nodal values at ``[start, end, midpoint]``:

- ``p_t,z = Λ_t,z / w_z``, the consistent friction stress (``ContactResult.tangential_pressure``;
  the obstacle acts on the body with ``−Λ_t t``, so ``p_t ≈ −σ_t``);
- ``b_z = s_z / w_z``, the slip bound as a stress, with ``s_z`` the node's friction law's bound
  at the contact force ``Λ_z`` (:mod:`signorini.algebra.friction.laws`; Tresca ``s_z = ∫ s ψ_z``,
  so ``b_z = s_z / w_z``; Coulomb ``F Λ_z``, so ``b_z = F p_z``): ``|p_t,z| ≤ b_z`` is the
  solver's nodal law ``|Λ_t,z| ≤ s_z`` divided by ``w_z``; 0 on frictionless parts;
- ``u_t(z) = ũ_h(z)·t_z − u_t,ref(z)``, ``t_z`` the constraint's tangent
  (``ContactSet.facet_tangent``), ``ũ_h`` relative to the master with two bodies
  (``ContactSet.facet_relative``), ``u_t,ref`` the reference the law's slip starts from
  (``ContactResult.tangential_reference``: a load step's previous displacement, a moving
  obstacle's motion; 0 for one step at rest).

At a Dirichlet end point of Γ_C the stresses are 0 and ``u_t = u_D·t``; its third of the facet
is given to the facet's midpoint (Dirichlet nodes carry no term).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..contact.solution import ContactResult

__all__ = ["FrictionFacets", "friction_facets", "move_dirichlet_thirds"]


class FrictionFacets(NamedTuple):
    """The frictional quantities at ``[start, end, midpoint]`` of each contact facet, each
    ``(n_ce, 3)``: ``friction`` p_t,z and ``bound`` b_z (stresses, divided by the estimator's
    stress unit), ``slip`` u_t (displacement)."""

    friction: np.ndarray
    bound: np.ndarray
    slip: np.ndarray


def friction_facets(result: ContactResult, unit: float = 1.0) -> FrictionFacets | None:
    """The nodal inputs of η4 and η8 with friction on the contact facets, stresses divided by
    the stress unit ``unit``; ``None`` for a result without friction (then η4 is the paper's
    ``‖σ_t(u_h)‖`` and η8 = 0)."""
    cs = result.contact
    if not cs.has_friction:
        return None
    force = cs.friction.slip_bound(result.contact_force, result.active)  # s_z
    bound = result.space.element.facet.pressure(force, cs.basis_integral)
    loc = cs.facet_local
    inside = loc >= 0
    row = np.maximum(loc, 0)
    tangent = cs.facet_tangent[..., 0, :]
    slip = np.einsum("ejc,ejc->ej", cs.facet_relative(result.u), tangent)
    # the law acts on the slip from the reference (a load step's previous one, the
    # obstacle's motion): so does the friction work
    slip = slip - np.where(inside, result.tangential_reference[row], 0.0)
    return FrictionFacets(
        friction=np.where(inside, result.tangential_pressure[row], 0.0) / unit,
        bound=np.where(inside, bound[row], 0.0) / unit,
        slip=slip,
    )


def move_dirichlet_thirds(parts: np.ndarray, facet_local: np.ndarray) -> np.ndarray:
    """Per-node parts ``(n_ce, 3)`` with the part of a Dirichlet end point (``facet_local``
    ``-1``) added to the facet's midpoint, so that Dirichlet nodes carry none and the parts
    still sum to the facet's integral. With P1's ``facet_local (n_ce, 2)`` (no midpoint node)
    it goes to the facet's other end."""
    out = parts.copy()
    for col in (0, 1):
        at = facet_local[:, col] < 0
        # P1 (two nodes a facet): to the facet's other end, unless that is a Dirichlet node too
        other = 1 - col
        to = 2 if facet_local.shape[1] == 3 else other
        if to == other:
            at &= facet_local[:, other] >= 0
        out[at, to] += out[at, col]
        out[at, col] = 0.0
    return out
