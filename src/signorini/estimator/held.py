"""The traction residual on parts that hold only part of the displacement, and the boundary
facets η3 gains beyond the Neumann parts (docs/method.md, *Rollers and components*,
*Estimator*).

A roller holds ``u·n`` and leaves the tangential traction free, so ``σ_t(u_h) = (σ(u_h)n)·t``
must vanish there; a one-component Dirichlet part (``Dirichlet((0.0, None))``) holds one
Cartesian component and leaves the other's traction free. Their facets enter η3 as Neumann
facets with zero data on the free component: ``h_p ‖(σ(u_h) n)_free‖²``. The masters of contact
pairs enter it too, with the slave's transferred traction (:mod:`.pairs`).
"""

from __future__ import annotations

import numpy as np

from ..contact.solution import ContactResult
from ..problem.conditions import Dirichlet, Roller
from .pairs import master_integrals
from .terms import neumann_residual
from .traction import CellStress

__all__ = ["further_traction_facets", "held_part_integrals"]


def held_part_integrals(
    result: ContactResult, stresses: CellStress, t: np.ndarray, w: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The facets of the roller and one-component Dirichlet parts, part after part, and
    ``‖(σ(u_h) n)_free‖²_F`` on each (stresses in the estimator's unit)."""
    mesh, out_facets, out = result.mesh, [], []
    for name, cond in result.problem.conditions.items():  # a loop over parts
        if isinstance(cond, Roller):
            free = None  # the tangent of the facet's geometry
        elif isinstance(cond, Dirichlet) and not all(cond.components):
            free = int(np.flatnonzero(~np.asarray(cond.components))[0])
        else:
            continue
        e = mesh.part_facets(name)
        values = np.zeros(e.size)
        for rows, sn, facets in stresses.on_facets(
            mesh.facet2cell[e, 0], mesh.facet_local[e, 0], t
        ):
            if free is None:
                n = facets.normals(t)
                tangent = np.stack([-n[..., 1], n[..., 0]], axis=-1)
                residual = np.einsum("eqc,eqc->eq", sn, tangent)[..., None] * tangent
            else:
                residual = np.zeros_like(sn)
                residual[..., free] = sn[..., free]
            values[rows] = neumann_residual(residual, w, facets.speeds(t))
        out_facets.append(e)
        out.append(values)
    if not out:
        return np.zeros(0, np.int64), np.zeros(0)
    return np.concatenate(out_facets), np.concatenate(out)


def further_traction_facets(
    result: ContactResult, stresses: CellStress, t: np.ndarray, w: np.ndarray, unit: float
) -> tuple[np.ndarray, np.ndarray]:
    """The boundary facets η3 integrates beyond the Neumann parts and its integrals on them:
    the masters of contact pairs (:func:`~.pairs.master_integrals`), then the parts that
    hold only part of the displacement (:func:`held_part_integrals`)."""
    masters, J_masters = master_integrals(result, stresses, t, w, unit)
    held, J_held = held_part_integrals(result, stresses, t, w)
    return np.concatenate([masters, held]), np.concatenate([J_masters, J_held])
