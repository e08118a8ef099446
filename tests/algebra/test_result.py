"""Steps and failures of an active set solve (signorini.algebra.result)."""

from __future__ import annotations

import numpy as np

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
