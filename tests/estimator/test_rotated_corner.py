"""η on a corner problem rotated by 0.7 rad: the adaptive loop runs, and η is the unrotated
one's to round-off (η7's continuity check is measured on the displacement's size, not on the
round-off size of a contact zone closed on both parts of a corner)."""

from __future__ import annotations

import numpy as np
from contact_problems import corner_problem

from signorini.loop import adaptive


def _etas(angle: float) -> np.ndarray:
    levels = adaptive(corner_problem(angle, shapes=True), max_levels=9)
    return np.array([[lev.record.ndof, lev.record.eta] for lev in levels])


def test_rotated_corner_problem_runs_and_gives_the_same_eta():
    ref, rot = _etas(0.0), _etas(0.7)
    assert ref.shape == rot.shape == (9, 2)
    assert np.array_equal(ref[:, 0], rot[:, 0])  # the same meshes, level by level
    err = np.abs(rot[:, 1] - ref[:, 1]).max() / ref[:, 1].max()
    print(f"rotation by 0.7: max |η_rot − η| / η = {err:.2e}")
    assert err < 1e-12, err
