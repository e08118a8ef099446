"""The manufactured full-contact cube under uniform refinement (Kuhn cubes n³): the energy error
and η_h both decay like N^{-2/3} and the efficiency index stays in a band, for the transformed
face basis (b); the nodal constraints (a) beside it, whose η6 drifts (the vertex trap: vertices
lift off between active midpoints; docs/method.md, *Three dimensions: the estimator on
tetrahedra and faces*)."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.contact.solution import solve
from signorini.contact.solution3d import errors_3d
from signorini.estimator.residual import estimate

from .cube import cube_problem, full_contact_fields


def _table(sizes, alpha):
    rows = []
    for n in sizes:
        result = solve(cube_problem(full_contact_fields(), n, alpha))
        est = estimate(result)
        error = errors_3d(result, degree=6)["error_energy"]
        rows.append((n, result.ndof, error, est.eta, *est.eta_terms[:7]))
    return np.array(rows)


def _print(name, table):
    print(f"\n{name}:   n      N     error       eta   eta/err  eta5/err  eta6/err  eta7/err")
    for n, N, err, eta, *terms in table:
        print(
            f"{int(n):10d} {int(N):6d} {err:.3e} {eta:.3e} {eta / err:8.3f} "
            f"{terms[4] / err:9.3f} {terms[5] / err:9.3f} {terms[6] / err:9.2e}"
        )


def _check(table, band):
    N, err, eta = table[:, 1], table[:, 2], table[:, 3]
    slope = [np.polyfit(np.log(N[-3:]), np.log(v[-3:]), 1)[0] for v in (err, eta)]
    assert max(slope) <= -0.6, slope
    ratio = eta / err
    assert np.abs(ratio / ratio.mean() - 1).max() <= band, ratio


def test_full_contact_the_transformed_basis_keeps_its_efficiency():
    """n = 2, 3, 4 (300 to 1 944 free unknowns), variant (b): slopes of the error and of η_h
    ≤ −0.6, η_h/error within ±30 % of its mean (measured 22.35, 23.63, 24.10), η6 = 0."""
    b = _table((2, 3, 4), None)
    _print("(b) transformed", b)
    _check(b, 0.30)
    assert (b[:, 9] == 0).all()  # η6


@pytest.mark.slow
def test_full_contact_the_efficiency_stays_in_its_band_to_26_000_unknowns():
    """n = 2, 3, 4, 6, 8, 10 (300 to 26 460 free unknowns), (b) and (a) side by side: (b)
    within ±30 % of its mean (measured 22.35 … 24.39, ±5 % over the last four levels), slopes
    −0.68; (a) the same slopes, its η6/error growing (0.30 → 0.47: the vertex trap)."""
    sizes = (2, 3, 4, 6, 8, 10)
    b, a = _table(sizes, None), _table(sizes, 0.0)
    _print("(b) transformed", b)
    _print("(a) nodal", a)
    _check(b, 0.30)
    _check(b[2:], 0.05)
    _check(a, 0.30)
    assert (b[:, 9] == 0).all()
    eta6 = a[:, 9] / a[:, 2]
    assert (np.diff(eta6) > 0).all(), eta6
