"""No convergence figure states a rate for noise: levels whose η_h is at its round-off level
(the history's ``eta_roundoff``) are drawn below that level, out of every fit."""

from __future__ import annotations

import numpy as np

from signorini.plots import plot_adaptive_vs_uniform, plot_contributions, plot_estimator


def noise_history() -> dict[str, np.ndarray]:
    """A run refining noise, as stacked-blocks did: η_h grows like N^0.41 below its level."""
    ndof = np.array([640, 900, 1500, 3000, 6500, 14000, 30000, 62000])
    eta = 2.2e-14 * (ndof / 640.0) ** 0.41 * np.array([1, 1.3, 0.8, 1.2, 0.9, 1.1, 1.0, 1.2])
    h = {"ndof": ndof, "n_cells": ndof // 4, "eta": eta}
    h["eta_roundoff"] = 1.1e-12 * np.sqrt(ndof / 640.0)
    for k in range(1, 8):
        h[f"eta_{k}"] = eta / (1.5 * k)
    h["eta_6"] = np.zeros(ndof.size)
    return h


def test_no_rate_is_printed_for_noise(tmp_path, captured):
    h = noise_history()
    plot_estimator(h, tmp_path / "e")
    plot_contributions(h, tmp_path / "c")
    estimator, contributions = captured
    for info in captured:
        assert not any("slope" in t for t in info["legend"]), info["legend"]
        assert not info["patches"]  # no reference triangle drawn on noise
        assert "slopes:" not in info["caption"] + info["legend_title"]
    assert estimator["legend"] == [
        r"$\eta_h$ (noise)",
        r"round-off level of $\eta_h$: below it, noise (no rate)",
    ]
    x, y = estimator["lines"][r"round-off level of $\eta_h$: below it, noise (no rate)"]
    assert np.array_equal(x, h["ndof"]) and np.array_equal(y, h["eta_roundoff"])
    x, y = estimator["lines"][r"$\eta_h$ (noise)"]
    assert np.array_equal(y, h["eta"])  # drawn where it is, as markers without a line
    assert r"$\eta_1$ (noise)" in contributions["legend"]


def test_levels_above_the_round_off_level_keep_their_rate(tmp_path, captured):
    h = noise_history()
    h["eta"] = 3.0 / h["ndof"]
    plot_estimator(h, tmp_path / "e")
    (info,) = captured
    assert info["legend"] == [r"$\eta_h$, slope −1.00"]


def test_adaptive_against_uniform_states_no_rate_for_noise(tmp_path, captured):
    noise = noise_history()
    uniform = {key: value[::2] for key, value in noise.items()}
    plot_adaptive_vs_uniform({"adaptive": noise, "uniform": uniform}, tmp_path / "a")
    (info,) = captured
    assert info["legend"][:2] == ["adaptive (noise)", "uniform (noise)"]
    assert not any("slope" in t for t in info["legend"]) and not info["patches"]
