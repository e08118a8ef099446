"""Friction laws as objects, asked by the contact layer, the solver and the estimator alike.

A friction law bounds the friction force of a contact node by its slip bound ``s ≥ 0``
(docs/method.md, *Friction*): ``|Λ_t| ≤ s``, stick below the bound, slip along the friction
force at it. In 3D the same bound is the radius of the ball the tangential force lies in; the
law only gives the radius. :class:`FrictionLaw` is what a law answers, vectorized over nodes:

- ``nodal_weight(integrate, size)``: the law's data as one number per node (Tresca: the nodal
  bound ``∫ s ψ_z ds``; Coulomb: the coefficient ``F``), asked once by the contact layer;
- ``slip_bound(weight, normal_force, in_contact)``: ``s`` from the weight and the normal
  force ``Λ_n`` (Tresca: the weight, where it acts; Coulomb: ``F max(Λ_n, 0)``);
- ``bound_derivative(weight, in_contact)``: ``∂s/∂Λ_n`` in contact (Tresca 0, Coulomb ``F``).
  The laws are affine in ``Λ_n ≥ 0`` in contact, ``s = s(0) + s' Λ_n``, which the
  semismooth Newton system imposes on slipping nodes; a non-zero ``s'`` makes it
  non-symmetric;
- ``symmetric``: whether ``s'`` is 0 at every node (the systems then stay symmetric);
- ``everywhere``: whether the bound acts on nodes out of contact too (classical Tresca) or
  only in contact.

The estimator's slip bound as a stress is ``s_z / w_z`` with the pressure's ``Λ_z``
(:meth:`LawGroups.slip_bound` divided by ``w_z``). Frictionless contact is no law at all: a
node without a law has ``s = s' = 0``, and a problem without laws is the frictionless
problem of :func:`~.pdas.solve_pdas`, not a frictional one with a zero bound.

:class:`LawGroups` holds the laws of one problem: a few law objects and the index of each
node's law, evaluated law by law (a loop over the laws, never over nodes).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Protocol, runtime_checkable

import numpy as np

from ..qp import check_vector

__all__ = ["FrictionLaw", "LawGroups", "check_laws"]


@runtime_checkable
class FrictionLaw(Protocol):
    """What a friction law answers (module docstring; docs/method.md, *Friction*).

    Arrays are ``(m,)`` over the law's nodes: ``weight`` float (what :meth:`nodal_weight`
    gave), ``normal_force`` float (``Λ_n``, force units), ``in_contact`` bool.
    """

    #: whether ``bound_derivative`` is 0 everywhere (symmetric semismooth Newton systems)
    symmetric: bool
    #: whether the bound acts out of contact too (else only where ``in_contact``)
    everywhere: bool

    def nodal_weight(
        self, integrate: Callable[[Callable[[np.ndarray], np.ndarray]], np.ndarray], size: int
    ) -> np.ndarray:
        """The law's data per node, ``(size,)``: ``integrate(f)`` is ``∫ f ψ_z ds`` over the
        law's part for a function ``f(x)`` of points ``x (n, d)``."""
        ...

    def slip_bound(
        self, weight: np.ndarray, normal_force: np.ndarray, in_contact: np.ndarray
    ) -> np.ndarray:
        """The slip bound ``s ≥ 0`` per node (force units)."""
        ...

    def bound_derivative(self, weight: np.ndarray, in_contact: np.ndarray) -> np.ndarray:
        """``∂s/∂Λ_n`` per node in contact (dimensionless)."""
        ...


@dataclass(frozen=True)
class LawGroups:
    """The friction laws of one problem: per-node law groups.

    Attributes
    ----------
    laws : tuple of FrictionLaw
    index : (m,) int64 array
        The law of each node, an index into ``laws``; ``-1`` for a node without friction.
    weight : (m,) float array
        Each node's :meth:`FrictionLaw.nodal_weight` (0 without friction).
    """

    laws: tuple
    index: np.ndarray
    weight: np.ndarray

    @property
    def size(self) -> int:
        return self.index.size

    @cached_property
    def groups(self) -> tuple[tuple[FrictionLaw, np.ndarray | slice], ...]:
        """``(law, nodes)`` for each law with nodes; ``nodes`` is ``slice(None)`` when the
        law holds every node."""
        out = []
        for k, law in enumerate(self.laws):
            nodes = np.flatnonzero(self.index == k)
            if nodes.size == self.size:
                out.append((law, slice(None)))
            elif nodes.size:
                out.append((law, nodes))
        return tuple(out)

    @property
    def any(self) -> bool:
        """Whether some node has a friction law."""
        return bool(self.groups)

    @property
    def symmetric(self) -> bool:
        """Whether every law in play has a slip bound independent of ``Λ_n``."""
        return all(law.symmetric for law, _ in self.groups)

    def slip_bound(self, normal_force: np.ndarray, in_contact: np.ndarray) -> np.ndarray:
        """``s (m,)``: each node's law at ``Λ_n = normal_force``, 0 without a law."""
        return self._ask("slip_bound", normal_force, in_contact)

    def bound_derivative(self, in_contact: np.ndarray) -> np.ndarray:
        """``∂s/∂Λ_n (m,)`` of each node's law, 0 without a law."""
        return self._ask("bound_derivative", in_contact)

    @cached_property
    def everywhere(self) -> np.ndarray:
        """``(m,)`` bool: the node's law acts out of contact too."""
        out = np.zeros(self.size, dtype=bool)
        for law, nodes in self.groups:
            out[nodes] = bool(law.everywhere)
        return out

    @cached_property
    def can_rub(self) -> np.ndarray:
        """``(m,)`` bool: the node's bound can be positive (``s(0) > 0`` or ``s' > 0`` in
        contact); elsewhere the node never sticks nor has a slip direction."""
        zero, contact = np.zeros(self.size), np.ones(self.size, dtype=bool)
        return (self.slip_bound(zero, contact) > 0) | (self.bound_derivative(contact) > 0)

    def _ask(self, method: str, *arrays: np.ndarray) -> np.ndarray:
        if len(self.groups) == 1 and isinstance(self.groups[0][1], slice):
            law = self.groups[0][0]
            return np.asarray(getattr(law, method)(self.weight, *arrays), dtype=np.float64)
        out = np.zeros(self.size)
        for law, nodes in self.groups:
            args = [a[nodes] for a in arrays]
            out[nodes] = getattr(law, method)(self.weight[nodes], *args)
        return out


def check_laws(laws: object, law_index: object, weight: object, m: int) -> LawGroups:
    """Per-node law groups from a law or a sequence of laws, the law of each node and the
    weights (checked, a :class:`ValueError` naming the argument).

    Parameters
    ----------
    laws : FrictionLaw or sequence of FrictionLaw
    law_index : (m,) int array or None
        Index into ``laws`` per node, ``-1`` for no friction; default every node the first law.
    weight : float or (m,) float array
        Finite and ``≥ 0``.
    m : int
        Number of nodes.
    """
    seq = (laws,) if isinstance(laws, FrictionLaw) else laws
    if not isinstance(seq, Sequence) or not all(isinstance(law, FrictionLaw) for law in seq):
        raise ValueError(
            "laws must be a friction law or a sequence of them (objects with symmetric, "
            f"everywhere, nodal_weight, slip_bound and bound_derivative), got {laws!r}"
        )
    seq = tuple(seq)
    if law_index is None:
        index = np.zeros(m, dtype=np.int64)
    else:
        index = np.asarray(law_index)
        if index.shape != (m,) or (index.size and not np.issubdtype(index.dtype, np.integer)):
            raise ValueError(f"law_index must be an integer array of shape ({m},)")
        index = index.astype(np.int64)
    if index.size and (index.min() < -1 or index.max() >= len(seq)):
        raise ValueError(f"law_index must lie in [-1, {len(seq)}) (-1: no friction)")
    w = check_vector(weight, m, "weight", allow_scalar=True)
    if (w < 0).any():
        raise ValueError(f"weight must be non-negative, got min {w.min():.3g}")
    return LawGroups(seq, index, w)
