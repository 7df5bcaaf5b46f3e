# Type stubs of the extension module mlidar._mlidar (python/src/*.cpp). The package mlidar wraps the jobs.
from os import PathLike
from typing import Any, Callable, Iterator, Optional, Sequence

import numpy as np

__version__: str

class InputError(ValueError):
    """Bad input data or configuration (the CLI's exit 3)."""
    file: str
    field: str

class UsageError(ValueError):
    """Options that cannot be acted on (the CLI's exit 2)."""
    file: str
    field: str

class OutputError(OSError):
    """An output could not be written."""
    file: str
    field: str

_Path = str | PathLike[str]
_Progress = Optional[Callable[[int, int], None]]

def read_cloud(path: str, drop_nan: bool = False, bin_floats_per_point: int = 0) -> dict[str, np.ndarray]: ...
def write_cloud(path: str, arrays: dict[str, np.ndarray], pcd_encoding: str = "binary") -> None: ...
def read_extrinsics(path: str) -> dict[str, Any]: ...

class FrameSource:
    @staticmethod
    def dataset(folder: _Path, lidars: Sequence[str] = ...) -> FrameSource: ...
    @staticmethod
    def scans(folder: _Path, period: float = 0.1, times: Optional[_Path] = None, model: str = "") -> FrameSource: ...
    @staticmethod
    def bag(path: _Path, topics: str = "", base: str = "", stamp_at: str = "auto", extrinsics: str = "", models: str = "",
            start: float = 0.0, duration: float = 0.0) -> FrameSource: ...
    def __len__(self) -> int: ...
    def __getitem__(self, k: int) -> dict[str, Any]:
        """{'index', 'stamp', 'scans': {lidar: {'stamp', 'points' (N, 3) float32, 'intensity', 'ring', 'time'} or None},
        'skipped': [{'lidar', 'reason', 'file', 'detail'}]}"""
    def __iter__(self) -> Iterator[dict[str, Any]]: ...
    @property
    def lidars(self) -> list[dict[str, Any]]: ...
    @property
    def stamps(self) -> np.ndarray: ...
    @property
    def period(self) -> float: ...
    @property
    def notes(self) -> list[str]: ...

def odometry(*, out: _Path, dataset: _Path = "", scans: _Path = "", bag: str = "", period: float = 0.1,
             times: Optional[_Path] = None, model: str = "", lidars: Sequence[str] = ..., threads: int = 0,
             max_base_gaps: float = ..., config: _Path = "", extrinsics: str = "", topics: str = "", base: str = "",
             stamp_at: str = "auto", models: str = "", start: float = 0.0, duration: float = 0.0, overwrite: bool = False,
             progress: _Progress = None, arguments: Sequence[str] = ...) -> dict[str, Any]: ...
def slam(*, out: _Path, dataset: _Path = "", bag: str = "", config: _Path = "", calibrate: str = "online", threads: int = 0,
         max_base_gaps: float = ..., extrinsics: str = "", topics: str = "", base: str = "", stamp_at: str = "auto",
         models: str = "", start: float = 0.0, duration: float = 0.0, overwrite: bool = False, progress: _Progress = None,
         arguments: Sequence[str] = ...) -> dict[str, Any]: ...
def calibrate_auto(*, out: _Path, dataset: _Path = "", bag: str = "", base: str = "", stage: str = "all", init: _Path = "",
                   config: _Path = "", pair_stride: Optional[int] = None, threads: int = 0, max_base_gaps: float = ...,
                   extrinsics: str = "", topics: str = "", stamp_at: str = "auto", models: str = "", start: float = 0.0,
                   duration: float = 0.0, overwrite: bool = False, progress: _Progress = None,
                   arguments: Sequence[str] = ...) -> dict[str, Any]: ...
def eval_traj(gt: _Path, est: _Path, *, format: str = "", align: str = "se3", max_dt: float = 0.01, delta: float = 1.0,
              delta_unit: str = "frames", covariance: _Path = "", out: _Path = "", overwrite: bool = False,
              arguments: Sequence[str] = ...) -> dict[str, Any]: ...
def calibrate_planes(ref: _Path, target: _Path, *, init: _Path = "", config: _Path = "", out: _Path = "",
                     report: _Path = "") -> dict[str, Any]: ...
def doctor(input: _Path, *, topics: str = "", base: str = "", stamp_at: str = "auto", extrinsics: str = "",
           models: str = "") -> dict[str, Any]: ...

def keep_large_buffers_in_the_heap() -> None: ...
