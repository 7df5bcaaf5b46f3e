"""Shared fixtures: the mlidar executable (the CLI the bindings are compared with) and small simulated datasets."""

import os
import subprocess
from pathlib import Path

import pytest


def mlidar_bin() -> str:
    return os.environ.get("MLIDAR_BIN", "mlidar")


def run_cli(*arguments, check=True) -> subprocess.CompletedProcess:
    """Runs the mlidar CLI; with `check`, fails the test on a non-zero exit, showing its output."""
    result = subprocess.run([mlidar_bin(), *map(str, arguments)], capture_output=True, text=True)
    if check and result.returncode != 0:
        pytest.fail(f"mlidar {' '.join(map(str, arguments))} exited {result.returncode}:\n{result.stdout}\n{result.stderr}")
    return result


@pytest.fixture(scope="session")
def drive(tmp_path_factory) -> Path:
    """An 8-frame simulated rv/campus drive (four LiDARs), as the CLI's odometry tests use."""
    out = tmp_path_factory.mktemp("drive") / "sim"
    run_cli("simulate", "drive", "--rig", "rv", "--scene", "campus", "--trajectory", "vehicle", "--frames", 8, "--seed", 5,
            "--out", out)
    return out


@pytest.fixture(scope="session")
def handheld(tmp_path_factory) -> Path:
    """A 30-frame simulated rhd/campus walk, enough motion for hand-eye calibration."""
    out = tmp_path_factory.mktemp("handheld") / "sim"
    run_cli("simulate", "drive", "--rig", "rhd", "--scene", "campus", "--trajectory", "handheld", "--frames", 30, "--seed",
            1, "--out", out)
    return out
