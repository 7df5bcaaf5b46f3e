"""Has this LiDAR moved? Extrinsics of one vehicle's LiDAR across recordings, compared pair by pair.

Two estimates T_a, T_b of T_base_lidar with covariances Σ_a, Σ_b (the extrinsics YAML's convention: [t, r] order,
T = (R Exp(r), t + dt), m and rad) differ by δ = [t_b - t_a, Log(R_aᵀ R_b)]. Independent estimates of one fixed
extrinsic give δ ~ N(0, Σ_a + Σ_b) to first order, so d² = δᵀ (Σ_a + Σ_b)⁻¹ δ follows χ²(6). A LiDAR counts as
moved between two recordings when the change is both significant (d² above the χ²(6) quantile of `confidence`) and
large enough to matter (more than `rotation_deg` or `translation_m`): a change the covariances cannot explain but
that is too small to matter is not a moved LiDAR, and neither is a large change that the covariances say is noise.
"""

from __future__ import annotations

import dataclasses
import math
from statistics import NormalDist
from typing import Optional

import numpy as np


@dataclasses.dataclass(frozen=True)
class DriftRule:
    rotation_deg: float = 0.5
    translation_m: float = 0.05
    confidence: float = 0.999


@dataclasses.dataclass(frozen=True)
class Estimate:
    recording: str
    T_base_lidar: np.ndarray            # 4x4
    covariance: Optional[np.ndarray]    # 6x6 [t, r], or None


def chi2_quantile(probability: float, dof: int) -> float:
    """The χ² quantile by Wilson and Hilferty's cube-root normal approximation (within 1 % at 6 dof, p >= 0.9)."""
    z = NormalDist().inv_cdf(probability)
    h = 2.0 / (9.0 * dof)
    return dof * (1.0 - h + z * math.sqrt(h)) ** 3


def rotation_log(R: np.ndarray) -> np.ndarray:
    """Log of a rotation matrix as a rotation vector (rad)."""
    cos_angle = np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0)
    angle = math.acos(cos_angle)
    axis = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if angle < 1e-9:
        return 0.5 * axis
    if math.pi - angle < 1e-6:  # near pi: the axis from the symmetric part
        w, v = np.linalg.eigh((R + R.T) / 2.0)
        return angle * v[:, np.argmax(w)]
    return angle / (2.0 * math.sin(angle)) * axis


def change(a: Estimate, b: Estimate, rule: DriftRule) -> dict:
    """The change from estimate a to b: its size, its d² under the two covariances and whether the LiDAR moved."""
    dt = b.T_base_lidar[:3, 3] - a.T_base_lidar[:3, 3]
    dr = rotation_log(a.T_base_lidar[:3, :3].T @ b.T_base_lidar[:3, :3])
    delta = np.concatenate([dt, dr])
    rotation_deg = math.degrees(float(np.linalg.norm(dr)))
    translation_m = float(np.linalg.norm(dt))
    large = rotation_deg > rule.rotation_deg or translation_m > rule.translation_m
    result = {"from": a.recording, "to": b.recording, "rotation_deg": rotation_deg, "translation_m": translation_m}
    if a.covariance is None or b.covariance is None:
        result.update(d2=None, significant=None, moved=large, note="no covariance: judged by size alone")
        return result
    d2 = float(delta @ np.linalg.pinv(a.covariance + b.covariance, hermitian=True) @ delta)
    significant = d2 > chi2_quantile(rule.confidence, 6)
    result.update(d2=d2, significant=significant, moved=bool(significant and large))
    return result


def lidar_drift(estimates: list[Estimate], rule: DriftRule) -> list[dict]:
    """Consecutive changes of one LiDAR's extrinsic over its recordings, in their order."""
    return [change(a, b, rule) for a, b in zip(estimates, estimates[1:])]
