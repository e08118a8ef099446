"""The estimator's terms by name: η1 … η7 of (5.1) and the friction work η8 (docs/method.md,
*Estimator*), the one list every other list of terms is derived from.

:data:`TERMS` orders the rows of :attr:`Estimate.eta2_cell <signorini.Estimate.eta2_cell>`
and names the history columns ``eta_1 … eta_8``; :data:`TERM_TABLE` adds what a history
column holds (``loop/record.py``: ``COLUMNS``) and how a figure labels the term
(``plots/style.py``). This module imports nothing, so that the figures, which take plain data
only, may read it.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["FRICTION_TERMS", "TERMS", "TERM_TABLE", "Term"]


@dataclass(frozen=True)
class Term:
    """One term of the estimator.

    Attributes
    ----------
    name : str
        The history column and the key of :meth:`Estimate.as_dict
        <signorini.Estimate.as_dict>`, e.g. ``"eta_1"``.
    label : str
        The term in a figure (matplotlib mathtext), e.g. ``r"$\\eta_1$"``.
    description : str
        What the history column holds, with its unit (``history.md``).
    friction : bool
        A term of frictional problems only (0 without friction).
    """

    name: str
    label: str
    description: str
    friction: bool = False


#: the terms in the row order of ``Estimate.eta2_cell``
TERM_TABLE: tuple[Term, ...] = (
    *(
        Term(
            f"eta_{k}",
            rf"$\eta_{k}$",
            f"contribution η_{k} of the estimator, unsquared (η² = Σ η_k²), same unit as eta",
        )
        for k in range(1, 8)
    ),
    Term(
        "eta_8",
        r"$\eta_8$",
        'the friction work term η_8 (docs/method.md, *Estimator*, "With friction"), '
        "unsquared, same unit as eta; 0 without friction (with friction eta_4 is "
        "‖σ_t(u_h) + p_t,h‖ weighted as before)",
        friction=True,
    ),
)

#: the names of the terms of (5.1) and the friction work η8, in the row order of
#: ``Estimate.eta2_cell``
TERMS: tuple[str, ...] = tuple(term.name for term in TERM_TABLE)

#: the terms that are 0 without friction
FRICTION_TERMS: tuple[str, ...] = tuple(term.name for term in TERM_TABLE if term.friction)
