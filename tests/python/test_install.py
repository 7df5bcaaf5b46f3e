"""`cmake --install` gives a package that imports from the prefix alone (a standard site-packages layout)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest


@pytest.mark.skipif("MLIDAR_BUILD_DIR" not in os.environ, reason="run by ctest, which names the build folder")
def test_the_installed_package_imports_and_reads_a_cloud_from_the_prefix(tmp_path):
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", os.environ["MLIDAR_BUILD_DIR"], "--prefix", str(prefix)], check=True,
                   capture_output=True)
    site = prefix / os.environ["MLIDAR_PYTHON_INSTALL_DIR"]
    assert (site / "mlidar" / "__init__.py").exists() and (site / "mlidar" / "_mlidar.pyi").exists()
    assert (prefix / "bin" / "mlidar").exists()
    script = (
        "import numpy as np, mlidar, sys\n"
        "assert mlidar.__file__.startswith(sys.argv[1]), mlidar.__file__\n"
        "xyz = {a: np.arange(4, dtype=np.float32) for a in 'xyz'}\n"
        "mlidar.write_cloud(sys.argv[2], xyz)\n"
        "print(mlidar.read_cloud(sys.argv[2])['z'].tolist())\n"
    )
    environment = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    environment["PYTHONPATH"] = str(site)
    result = subprocess.run([sys.executable, "-c", script, str(site), str(tmp_path / "c.ply")], env=environment,
                            capture_output=True, text=True, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "[0.0, 1.0, 2.0, 3.0]"

    # The installed executable's `fleet run` starts Python on the installed package (not the build tree's): a jobs
    # file naming a missing recording is the package's exit 3, naming the field.
    jobs = tmp_path / "jobs.yaml"
    jobs.write_text("jobs:\n  - {vehicle: v, recording: nowhere, task: doctor}\n")
    fleet = subprocess.run([str(prefix / "bin" / "mlidar"), "fleet", "run", "--jobs", str(jobs), "--out", str(tmp_path / "f")],
                           env=environment, capture_output=True, text=True, cwd=tmp_path)
    assert fleet.returncode == 3, fleet.stderr
    assert "jobs[0].recording" in fleet.stderr
    assert (prefix / os.environ["MLIDAR_PYTHON_INSTALL_DIR"] / "mlidar" / "fleet.py").exists()

    # `detect run` of the installed mlidar runs the installed mlidar-detect (libexec/mlidar), not the build tree's:
    # a missing model folder is its exit 3, naming --model.
    if (Path(os.environ["MLIDAR_BUILD_DIR"]) / "apps" / "mlidar" / "mlidar-detect").exists():
        assert (prefix / "libexec" / "mlidar" / "mlidar-detect").exists()
        detect = subprocess.run([str(prefix / "bin" / "mlidar"), "detect", "run", "--model", str(tmp_path / "no_model"),
                                 "--dataset", str(tmp_path), "--out", str(tmp_path / "pred")],
                                capture_output=True, text=True, cwd=tmp_path)
        assert detect.returncode == 3, detect.stderr
        assert "--model" in detect.stderr
