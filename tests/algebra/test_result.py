"""Steps and failures of an active set solve (signorini.algebra.result)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from signorini.algebra import PDASConvergenceError, PDASStep


def test_step_between_two_active_sets():
    previous = np.array([True, True, False, False])
    active = np.array([True, False, True, True])
    step = PDASStep.between(3, "pdas", previous, active)
    assert (step.n_active, step.n_added, step.n_removed) == (3, 2, 1)
    assert str(step) == "  3 pdas: |A| = 3, +2 -1"


def test_error_message_shows_the_last_twenty_steps():
    empty = np.zeros(2, dtype=bool)
    history = [PDASStep.between(i, "pdas", empty, empty) for i in range(1, 26)]
    err = PDASConvergenceError("PDAS cycles", history, "cycling")
    text = str(err)
    assert text.startswith("PDAS cycles\niteration history:\n  (5 earlier steps not shown)")
    assert (
        "  6 pdas" in text and "  5 pdas" not in text and text.endswith(" 25 pdas: |A| = 0, +0 -0")
    )
    assert err.reason == "cycling" and len(err.history) == 25


def test_both_convergence_errors_share_one_exported_base():
    import signorini
    from signorini.algebra import ConvergenceError, FrictionConvergenceError

    assert signorini.ConvergenceError is ConvergenceError
    assert signorini.FrictionConvergenceError is FrictionConvergenceError
    assert issubclass(PDASConvergenceError, ConvergenceError)
    assert issubclass(FrictionConvergenceError, ConvergenceError)
    err = FrictionConvergenceError("no", [], "max_iter", x=np.ones(3))
    assert isinstance(err, ConvergenceError) and err.reason == "max_iter" and err.x.size == 3


def test_both_solvers_report_the_same_counters_and_named_kkt_columns():
    """The frictionless and the frictional report are read by the same names, the history's
    KKT columns included (the tangential ones only with friction)."""
    from signorini.algebra import (
        FrictionResult,
        PDASResult,
        SolveReport,
        check_friction,
        solve_friction,
        solve_pdas,
    )
    from signorini.loop.record import COLUMNS
    from signorini.problem import Coulomb

    K = sp.csr_matrix([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 2.0]])
    F = np.array([1.0, 0.5, 0.0])
    pdas = solve_pdas(K, F, [0], 0.1)
    friction = solve_friction(check_friction(K, F, [0], [1], 0.1, laws=Coulomb(0.3), weight=0.3))
    for report in (pdas, friction):
        assert isinstance(report, SolveReport)
        counts = [report.iterations, report.n_solves, report.n_factorizations, report.n_analyses]
        assert min(counts) >= 1 and report.n_updates >= 0 and report.backend
        assert set(report.kkt.columns()) <= set(COLUMNS) and report.kkt.max < 1e-12
    assert isinstance(pdas, PDASResult) and isinstance(friction, FrictionResult)
    assert pdas.n_updates == 1 and friction.n_updates == 0  # one bordered update in PDAS
    assert set(friction.kkt.columns()) - set(pdas.kkt.columns()) == {
        "kkt_tangential_bound",
        "kkt_tangential_complementarity",
    }
