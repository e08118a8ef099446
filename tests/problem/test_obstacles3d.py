"""Obstacles of space: gaps, directions and closest points against brute force."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.problem.obstacles3d import Ball, Cylinder, HalfSpace, SignedDistance3D


def _sphere_samples(m: int) -> np.ndarray:
    """``(m, 3)`` Fibonacci points on the unit sphere."""
    k = np.arange(m) + 0.5
    polar = np.arccos(1 - 2 * k / m)
    azimuth = np.pi * (1 + 5**0.5) * k
    return np.stack(
        [np.sin(polar) * np.cos(azimuth), np.sin(polar) * np.sin(azimuth), np.cos(polar)], axis=1
    )


def _brute_distance(x: np.ndarray, surface: np.ndarray) -> np.ndarray:
    return np.sqrt(((x[:, None, :] - surface[None, :, :]) ** 2).sum(axis=2)).min(axis=1)


RNG = np.random.default_rng(38)
POINTS = RNG.uniform(-2.0, 2.0, size=(40, 3))


def _check(obstacle, surface: np.ndarray, on_surface, spacing: float) -> None:
    psi, n = obstacle.gap_and_direction(POINTS)
    q = obstacle.closest_point(POINTS)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-14)
    np.testing.assert_allclose(on_surface(q), 0.0, atol=1e-13)
    np.testing.assert_allclose(np.linalg.norm(q - POINTS, axis=1), np.abs(psi), atol=1e-13)
    brute = _brute_distance(POINTS, surface)
    assert (brute >= np.abs(psi) - 1e-12).all()  # no surface point is closer than q
    assert (brute <= np.abs(psi) + spacing).all()  # and the samples approach it


def test_ball_against_brute_force() -> None:
    center, radius = np.array([0.2, -0.1, 0.3]), 0.7
    ball = Ball(center, radius)
    surface = center + radius * _sphere_samples(40000)
    _check(ball, surface, lambda q: np.linalg.norm(q - center, axis=1) - radius, 0.02)
    psi, _ = ball.gap_and_direction(POINTS)
    assert np.array_equal(psi < 0, np.linalg.norm(POINTS - center, axis=1) < radius)


def test_cylinder_against_brute_force() -> None:
    point, axis, radius = np.array([0.1, 0.0, -0.2]), np.array([1.0, 2.0, 2.0]) / 3, 0.6
    cylinder = Cylinder(point, 3 * axis, radius)
    u = np.cross(axis, [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(axis, u)
    angle = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    s = np.linspace(-6, 6, 1201)
    ring = radius * (np.cos(angle)[:, None] * u + np.sin(angle)[:, None] * v)
    surface = (point + s[:, None, None] * axis + ring[None]).reshape(-1, 3)

    def on_surface(q):
        r = q - point
        return np.linalg.norm(r - np.outer(r @ axis, axis), axis=1) - radius

    _check(cylinder, surface, on_surface, 0.02)


def test_half_space_and_signed_distance() -> None:
    plane = HalfSpace([0.0, 0.0, -0.5], [1.0, 1.0, 1.0])
    psi, n = plane.gap_and_direction(POINTS)
    np.testing.assert_allclose(psi, (POINTS - [0, 0, -0.5]) @ np.ones(3) / 3**0.5, atol=1e-15)
    np.testing.assert_allclose(n, np.broadcast_to(-np.ones(3) / 3**0.5, n.shape), atol=1e-16)
    center = np.array([0.0, 0.0, 3.0])
    sdf = SignedDistance3D(lambda x: np.linalg.norm(x - center, axis=1) - 1.0)
    ball_psi, ball_n = Ball(center, 1.0).gap_and_direction(POINTS)
    psi, n = sdf.gap_and_direction(POINTS)
    np.testing.assert_allclose(psi, ball_psi, atol=1e-15)
    np.testing.assert_allclose(n, ball_n, atol=1e-9)


def test_moved_and_refusals() -> None:
    ball = Ball([0.0, 0.0, 1.0], 0.5)
    moved = ball.moved([0.0, 0.1, 0.0]).moved([0.0, 0.0, 0.2])
    np.testing.assert_array_equal(moved.displacement, [0.0, 0.1, 0.2])
    np.testing.assert_allclose(
        moved.gap_and_direction(POINTS)[0],
        Ball([0.0, 0.1, 1.2], 0.5).gap_and_direction(POINTS)[0],
        atol=1e-15,
    )
    np.testing.assert_array_equal(ball.displacement, np.zeros(3))
    with pytest.raises(ValueError, match=r"shape \(n, 3\)"):
        ball.gap_and_direction(POINTS[:, :2])
    with pytest.raises(ValueError, match="centre"):
        ball.gap_and_direction([[0.0, 0.0, 1.0]])
    with pytest.raises(ValueError, match=r"shape \(3,\)"):
        ball.moved([0.1, 0.2])
    with pytest.raises(ValueError, match="not a signed distance"):
        SignedDistance3D(lambda x: (x**2).sum(axis=1) - 1.0).gap_and_direction(POINTS + 5)
