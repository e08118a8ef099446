"""ESTIMATE and MARK (paper, Section 5; docs/method.md, *Estimator*).

- ``residual``: :class:`Estimate` and :func:`estimate`, the table of the terms of (5.1).
- ``terms``: one function per term η1 … η7 and the helpers that distribute them to nodes
  and cells.
- ``h_half_norm``: the H^{1/2}(Γ_C) norm of the penetration (η7).
- ``contact_facets``: η4, η5, η6, η8 on the contact facets, and the nodal data they read.
- ``owned``: the estimator on several MPI ranks (each integrates its own cells and facets).
- ``marking``: Dörfler marking.
- ``names``: the terms by name (:data:`TERMS`), from which the history columns and the
  figures' legends are derived.
"""

from .marking import mark_doerfler
from .names import TERM_TABLE, TERMS
from .residual import Estimate, estimate

__all__ = ["TERMS", "TERM_TABLE", "Estimate", "estimate", "mark_doerfler"]
