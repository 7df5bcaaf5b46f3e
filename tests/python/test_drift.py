"""drift.py: has a LiDAR moved between two recordings? Checked on changes whose d² is worked out by hand."""

import math

import numpy as np
import pytest

from mlidar import drift


def pose(roll_deg=0.0, translation=(0.0, 0.0, 0.0)):
    angle = math.radians(roll_deg)
    T = np.eye(4)
    T[1:3, 1:3] = [[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]]
    T[:3, 3] = translation
    return T


def covariance(sigma_t, sigma_r_deg):
    return np.diag([sigma_t**2] * 3 + [math.radians(sigma_r_deg) ** 2] * 3)


def test_chi2_quantile_matches_tabulated_values():
    # chi2(6) quantiles from the tables: 0.95 -> 12.592, 0.99 -> 16.812, 0.999 -> 22.458.
    for probability, tabulated in ((0.95, 12.592), (0.99, 16.812), (0.999, 22.458)):
        assert drift.chi2_quantile(probability, 6) == pytest.approx(tabulated, rel=0.01)


def test_rotation_log_is_the_inverse_of_the_exponential():
    rng = np.random.default_rng(1)
    for _ in range(50):
        vector = rng.normal(size=3) * rng.uniform(0.0, 3.1) / 2.0
        angle = np.linalg.norm(vector)
        axis = vector / angle
        K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        R = np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K  # Rodrigues
        np.testing.assert_allclose(drift.rotation_log(R), vector, atol=1e-9)


def test_a_two_degree_turn_with_tight_covariances_is_a_move():
    a = drift.Estimate("mon", pose(40.0), covariance(0.01, 0.1))
    b = drift.Estimate("thu", pose(42.0), covariance(0.01, 0.1))
    change = drift.change(a, b, drift.DriftRule())
    # delta = [0, 0, 0, 2 deg, 0, 0]; (Sigma_a + Sigma_b) along roll = 2 (0.1 deg)^2: d2 = 2^2 / (2 * 0.1^2) = 200.
    assert change["rotation_deg"] == pytest.approx(2.0, abs=1e-9)
    assert change["d2"] == pytest.approx(200.0, rel=1e-9)
    assert change["significant"] and change["moved"]


def test_a_large_change_inside_the_covariances_is_not_a_move():
    a = drift.Estimate("mon", pose(40.0), covariance(0.01, 2.0))
    b = drift.Estimate("thu", pose(42.0), covariance(0.01, 2.0))
    change = drift.change(a, b, drift.DriftRule())
    assert change["d2"] == pytest.approx(0.5, rel=1e-9)  # 2^2 / (2 * 2^2)
    assert not change["significant"] and not change["moved"]


def test_a_significant_change_too_small_to_matter_is_not_a_move():
    a = drift.Estimate("mon", pose(40.0, (0.0, 0.0, 0.0)), covariance(0.0005, 0.01))
    b = drift.Estimate("thu", pose(40.2, (0.01, 0.0, 0.0)), covariance(0.0005, 0.01))
    change = drift.change(a, b, drift.DriftRule())
    assert change["significant"] and not change["moved"]
    assert change["translation_m"] == pytest.approx(0.01)


def test_without_covariances_only_the_size_decides():
    a = drift.Estimate("mon", pose(0.0), None)
    moved = drift.change(a, drift.Estimate("thu", pose(0.0, (0.2, 0.0, 0.0)), None), drift.DriftRule())
    stayed = drift.change(a, drift.Estimate("fri", pose(0.1), None), drift.DriftRule())
    assert moved["moved"] and moved["d2"] is None and not stayed["moved"]


def test_a_series_flags_only_the_recordings_between_which_it_moved():
    rng = np.random.default_rng(3)
    rolls = [40.0, 40.0, 40.0, 42.0, 42.0, 42.0]
    estimates = [drift.Estimate(f"day{k}", pose(roll + rng.normal(0, 0.05)), covariance(0.01, 0.1)) for k, roll in enumerate(rolls)]
    changes = drift.lidar_drift(estimates, drift.DriftRule())
    assert [c["moved"] for c in changes] == [False, False, True, False, False]
    assert (changes[2]["from"], changes[2]["to"]) == ("day2", "day3")
