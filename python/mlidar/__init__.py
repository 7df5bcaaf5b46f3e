"""mlidar for Python: the C++ library's clouds, frame sources, jobs and evaluation.

Every job runs the same code as the command line and writes the same run folder
(trajectory.tum, metrics.json, report.html, run.json, ...); what it returns is a
RunResult holding the job's summary and the folder's JSON with the keys of the
files. Errors are InputError (bad file: `.file`, `.field`), UsageError and
OutputError. Long calls release the GIL; `progress(done, total)` is called
after each frame, and Ctrl-C stops a job and removes its unfinished folder.
"""

from __future__ import annotations

import dataclasses
import json
import os
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np

from mlidar._mlidar import (
    FrameSource,
    InputError,
    OutputError,
    UsageError,
    __version__,
    read_cloud,
    read_extrinsics,
    write_cloud,
)
from mlidar import _mlidar

__all__ = [
    "FrameSource",
    "InputError",
    "OutputError",
    "RunResult",
    "UsageError",
    "__version__",
    "calibrate_auto",
    "calibrate_planes",
    "doctor",
    "eval_traj",
    "odometry",
    "read_cloud",
    "read_extrinsics",
    "read_tum",
    "slam",
    "write_cloud",
]

Progress = Optional[Callable[[int, int], None]]


@dataclasses.dataclass
class RunResult:
    """What a job wrote into its run folder `out`.

    exit_code: the CLI's (0 ok; 1 ran but should not be trusted: frames lost, a
    LiDAR not calibrated or not converged). summary: the job's counts as the CLI
    prints them. metrics: metrics.json (calibration.json for calibrate_auto).
    trajectory: (N, 8) stamp tx ty tz qx qy qz qw of trajectory.tum, or None.
    extrinsics: extrinsics.yaml as read_extrinsics gives it, or None.
    """

    out: Path
    exit_code: int
    summary: dict
    metrics: dict
    trajectory: Optional[np.ndarray] = None
    extrinsics: Optional[dict] = None

    @property
    def trusted(self) -> bool:
        return self.exit_code == 0


def read_tum(path: os.PathLike | str) -> np.ndarray:
    """A TUM trajectory file as an (N, 8) array: stamp tx ty tz qx qy qz qw."""
    rows = [line.split() for line in Path(path).read_text().splitlines() if line.strip() and not line.startswith("#")]
    return np.array(rows, dtype=np.float64).reshape(-1, 8)


def _job_arguments(job: str, options: dict) -> list[str]:
    """The call as run.json records it: the function, then key=value for every option given."""
    return [f"mlidar.{job}"] + [f"{key}={value}" for key, value in options.items() if key != "progress"]


def _native_options(options: dict) -> dict:
    """Options as the extension takes them: None left out (its default), paths as strings, names as lists."""
    native = {}
    for key, value in options.items():
        if value is None or (key == "progress"):
            continue
        if isinstance(value, os.PathLike):
            value = os.fspath(value)
        if key == "lidars" and isinstance(value, str):
            value = [name for name in value.split(",") if name]
        native[key] = value
    return native


def _run(job: str, metrics_file: str, options: dict, progress: Progress) -> RunResult:
    summary = getattr(_mlidar, job)(**_native_options(options), progress=progress, arguments=_job_arguments(job, options))
    out = Path(summary.pop("out"))
    summary.pop("trajectory", None)
    metrics = json.loads((out / metrics_file).read_text())
    trajectory = read_tum(out / "trajectory.tum") if (out / "trajectory.tum").exists() else None
    extrinsics = read_extrinsics(str(out / "extrinsics.yaml")) if (out / "extrinsics.yaml").exists() else None
    return RunResult(out, summary.pop("exit_code"), summary, metrics, trajectory, extrinsics)


def odometry(*, out, dataset=None, scans=None, bag=None, period: float = 0.1, times=None, model: str = None,
             lidars=None, threads: int = 0, max_base_gaps: float = None, config=None, extrinsics=None,
             topics: str = None, base: str = None, stamp_at: str = None, models=None, start: float = None,
             duration: float = None, overwrite: bool = False, progress: Progress = None) -> RunResult:
    """`mlidar odometry`: scan-to-map odometry from all LiDARs at once; the keywords are the CLI's options."""
    options = dict(locals())
    return _run("odometry", "metrics.json", options, options.pop("progress"))


def slam(*, out, dataset=None, bag=None, config=None, calibrate: str = "online", threads: int = 0,
         max_base_gaps: float = None, extrinsics=None, topics: str = None, base: str = None, stamp_at: str = None,
         models=None, start: float = None, duration: float = None, overwrite: bool = False,
         progress: Progress = None) -> RunResult:
    """`mlidar slam`: odometry with online calibration of every LiDAR (calibrate: online, refine or fixed)."""
    options = dict(locals())
    return _run("slam", "metrics.json", options, options.pop("progress"))


def calibrate_auto(*, out, dataset=None, bag=None, base: str = None, stage: str = "all", init=None, config=None,
                   pair_stride: int = None, threads: int = 0, max_base_gaps: float = None, extrinsics=None,
                   topics: str = None, stamp_at: str = None, models=None, start: float = None,
                   duration: float = None, overwrite: bool = False, progress: Progress = None) -> RunResult:
    """`mlidar calibrate auto`: hand-eye from motion, then appearance refinement, for every LiDAR."""
    options = dict(locals())
    return _run("calibrate_auto", "calibration.json", options, options.pop("progress"))


def eval_traj(gt, est, *, format: str = None, align: str = "se3", max_dt: float = 0.01, delta: float = 1.0,
              delta_unit: str = "frames", covariance=None, out=None, overwrite: bool = False) -> dict[str, Any]:
    """`mlidar eval traj`: ATE, RPE (and KITTI drift, NEES with `covariance`) as eval.json's dict; `out` also
    writes the run folder the CLI's --out writes."""
    options = dict(locals())
    native = _native_options({key: value for key, value in options.items() if key not in ("gt", "est")})
    return _mlidar.eval_traj(os.fspath(gt), os.fspath(est), **native, arguments=_job_arguments("eval_traj", options))


def calibrate_planes(ref, target, *, init=None, config=None, out=None, report=None) -> dict[str, Any]:
    """`mlidar calibrate planes`: T_ref_target from a wall corner seen by both LiDARs, as --report's dict plus
    T_ref_target_matrix (4x4) and covariance_matrix (6x6); `out` writes the pair's extrinsics YAML."""
    options = _native_options(dict(init=init, config=config, out=out, report=report))
    return _mlidar.calibrate_planes(os.fspath(ref), os.fspath(target), **options)


def doctor(input, *, topics: str = None, base: str = None, stamp_at: str = None, extrinsics=None,
           models: str = None) -> dict[str, Any]:
    """`mlidar doctor`: a dataset folder or bag checked before a long run, as `doctor --json`'s dict
    {input, failed, findings: [{check, lidar, severity, message}]}; `failed` is the CLI's exit 1."""
    options = _native_options(dict(topics=topics, base=base, stamp_at=stamp_at, extrinsics=extrinsics, models=models))
    return _mlidar.doctor(os.fspath(input), **options)
