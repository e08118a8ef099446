"""The contact quantities of a 3D solution per constraint row of its face contact set, and
at the nodes (docs/method.md, *Three dimensions: contact on faces*, "What a 3D contact run
shows"): what the VTU file and the figures of a 3D contact run read
(:meth:`FaceContactSet.fields <signorini.contact.face_contact.FaceContactSet.fields>`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

__all__ = ["FaceFields"]


@dataclass(frozen=True)
class FaceFields:
    """The contact quantities of a 3D solution, one entry per constraint row of its
    :class:`~.face_contact.FaceContactSet` (docs/method.md, *Three dimensions: contact on
    faces*, "What a 3D contact run shows").

    Attributes
    ----------
    node, part : (k,) int arrays
        The row's P2 node and contact part (index into ``contact.parts``).
    normal : (k, 3) float array
        ``n_z``, the row's unit direction (the node frame's first axis).
    gap : (k,) float array
        ``u_h(z)·n_z − ψ(z)``: 0 in contact, negative where the body is off the obstacle,
        positive where it penetrates.
    contact_force : (k,) float array
        ``Λ_z`` (3.17), force units.
    pressure : (k,) float array
        The transformed basis's nodal pressure ``p̃_z = Λ̃_z / w̃_z`` of condition (b);
        NaN for condition (a), where the P2 vertex weights vanish.
    recovered_pressure : (k,) float array
        The P1-lumped recovered pressure of either condition, exact for a constant pressure.
    active : (k,) bool array
        The row's constraint is in the final active set (for (b): the transformed
        coefficient at its bound).
    """

    node: np.ndarray
    part: np.ndarray
    normal: np.ndarray
    gap: np.ndarray
    contact_force: np.ndarray
    pressure: np.ndarray
    recovered_pressure: np.ndarray
    active: np.ndarray

    #: each scalar field and its value at a node without a row (off Γ_C)
    SCALARS: ClassVar[dict[str, float]] = {
        "gap": np.nan,
        "contact_force": 0.0,
        "pressure": 0.0,
        "recovered_pressure": 0.0,
        "active": 0.0,
    }

    def at_nodes(self, n_nodes: int) -> dict[str, np.ndarray]:
        """The fields at every P2 node: the scalars of :data:`SCALARS` (a node of several
        rows takes the largest value of its rows, as 2D corners do; a node without a row the
        value in :data:`SCALARS`) and ``normal (n_nodes, 3)``, the node's first row's
        direction (0 without a row)."""
        out = {}
        for name, outside in self.SCALARS.items():  # a loop over the fields
            value = np.full(n_nodes, outside)
            value[self.node] = -np.inf
            with np.errstate(invalid="ignore"):  # NaN rows (pressure of (a)) stay NaN
                np.maximum.at(value, self.node, getattr(self, name).astype(np.float64))
            out[name] = value
        normal = np.zeros((n_nodes, 3))
        nodes, first = np.unique(self.node, return_index=True)
        normal[nodes] = self.normal[first]
        out["normal"] = normal
        return out
