#!/usr/bin/env python3
"""Fleet throughput: the same jobs run directly one after the other, then as a fleet on 1 and on N Dask workers.

    PYTHONPATH=build/python python3 bench/fleet_scaling.py --mlidar build/apps/mlidar/mlidar --jobs 4 --workers 2

Prints the wall times, the speed-up of N workers over one (throughput scaling), the engine's overhead per job:
(fleet on one worker - the same jobs called directly) / jobs, with and without the local cluster's start and stop
(timed on their own), and the jobs' own time inside the fleet against direct calls.
"""

import argparse
import json
import logging
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from distributed import Client, LocalCluster

import mlidar
from mlidar.fleet import run_fleet


def simulate(mlidar_bin: str, root: Path, frames: int, seed: int) -> Path:
    out = root / "recording"
    subprocess.run([mlidar_bin, "simulate", "drive", "--rig", "rhd", "--scene", "campus", "--trajectory", "handheld",
                    "--frames", str(frames), "--seed", str(seed), "--out", str(out)], check=True, capture_output=True)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mlidar", default="build/apps/mlidar/mlidar")
    parser.add_argument("--jobs", type=int, default=4)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--frames", type=int, default=60)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--repeat", type=int, default=3, help="interleaved rounds; the medians are printed")
    parser.add_argument("--task", default="slam", choices=["slam", "calibrate-auto", "doctor"])
    options = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        root = Path(folder)
        # Identical jobs (one recording, one task), so that the speed-up measures the engine and the machine rather
        # than how evenly jobs of different lengths share the workers.
        recording = simulate(options.mlidar, root, options.frames, options.seed)
        recordings = [recording] * options.jobs
        (root / "jobs.yaml").write_text("jobs:\n" + "".join(
            f"  - {{id: job{k}, vehicle: v, recording: {recording.name}, task: {options.task}}}\n" for k in range(options.jobs)))
        call = {"slam": lambda r, o: mlidar.slam(dataset=r, out=o, threads=1),
                "calibrate-auto": lambda r, o: mlidar.calibrate_auto(dataset=r, out=o, threads=1),
                "doctor": lambda r, o: mlidar.doctor(r)}[options.task]
        runs = [_measure(root, recordings, call, options) for _ in range(options.repeat)]
    result = {"task": options.task, "jobs": options.jobs, "frames": options.frames, "workers": options.workers,
              "repeat": options.repeat, **{key: statistics.median(run[key] for run in runs) for key in runs[0]}}
    print(json.dumps(result, indent=2))


def _measure(root: Path, recordings: list, call, options) -> dict:
    """One interleaved round: direct calls, the fleet on one worker, on N workers, a bare cluster's start and stop."""
    tag = len(list(root.glob("fleet1-*")))
    started = time.perf_counter()
    for k, recording in enumerate(recordings):
        call(recording, root / f"direct{tag}-{k}")
    direct = time.perf_counter() - started
    walls, job_seconds = {}, {}
    for workers in (1, options.workers):
        started = time.perf_counter()
        summary = run_fleet(root / "jobs.yaml", root / f"fleet{workers}-{tag}", local=workers, report=lambda line: None)
        walls[workers] = time.perf_counter() - started
        job_seconds[workers] = sum(job["seconds"] for job in summary["jobs"])
    started = time.perf_counter()
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None,
                      silence_logs=logging.ERROR) as cluster, Client(cluster):
        pass
    cluster_s = time.perf_counter() - started
    jobs = options.jobs
    return {"direct_s": direct, "fleet_1_worker_s": walls[1], "fleet_n_workers_s": walls[options.workers],
            "speedup": walls[1] / walls[options.workers], "overhead_per_job_s": (walls[1] - direct) / jobs,
            "cluster_start_stop_s": cluster_s, "overhead_per_job_without_cluster_s": (walls[1] - cluster_s - direct) / jobs,
            "job_seconds_in_fleet_1": job_seconds[1], "job_seconds_in_fleet_n": job_seconds[options.workers]}


if __name__ == "__main__":
    main()
