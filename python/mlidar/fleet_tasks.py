"""One fleet job on a worker: the task Dask runs, through the same bindings as a notebook.

Each job writes the run folder FLEET/jobs/ID, published whole by the job (a staging folder renamed in place), so a
folder that exists is complete. A job holds FLEET/jobs/.ID.lock (flock: released by the kernel when its process
dies) while it looks at and writes its folder: a second start of the same job, on this worker or another one that
shares the folder, waits and then finds the folder complete instead of running again. Under the lock the job also
removes what a killed earlier start left behind (its staging folders), and appends what it did to FLEET/jobs/.ID.log
(one JSON line per start, finish, reuse or failure), from which the summary counts starts and completed runs.
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import json
import os
import shutil
import socket
import time
from pathlib import Path
from typing import Any, Optional

import mlidar
from mlidar import _mlidar
from mlidar.fleet_files import write_text_atomically
from mlidar.fleet_jobs import Job

# Errors that say the job's input or options are wrong: the same on every worker, so never retried.
_DETERMINISTIC = (_mlidar.InputError, _mlidar.UsageError)
# Written into a job's run folder once it is complete: the job as run and its exit code.
_MARKER = "fleet_job.json"
_RESULT_FILES = {"calibrate-auto": "calibration.json", "slam": "metrics.json", "eval": "eval.json", "doctor": "doctor.json"}


def job_folder(fleet_out: Path, job: Job) -> Path:
    return fleet_out / "jobs" / job.id


@contextlib.contextmanager
def job_lock(fleet_out: Path, job: Job):
    path = fleet_out / "jobs" / f".{job.id}.lock"
    with open(path, "a") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def job_log_path(fleet_out: Path, job: Job) -> Path:
    """The job's JSON-lines log: one line per start, finish, reuse or failure, over every fleet run."""
    return fleet_out / "jobs" / f".{job.id}.log"


def _log(fleet_out: Path, job: Job, event: str, **fields) -> None:
    entry = {"event": event, "host": socket.gethostname(), "pid": os.getpid(), "time": time.time(), **fields}
    with open(job_log_path(fleet_out, job), "a") as log:
        log.write(json.dumps(entry) + "\n")
        log.flush()
        os.fsync(log.fileno())


def _remove_leftovers(fleet_out: Path, job: Job) -> None:
    """Staging folders of earlier starts of this job that died (we hold its lock: nobody else writes them)."""
    for stale in (fleet_out / "jobs").glob(f".{job.id}.mlidar-stage-*"):
        shutil.rmtree(stale, ignore_errors=True)
    for stale in (fleet_out / "jobs").glob(f".{job.id}.fleet-stage-*"):
        shutil.rmtree(stale, ignore_errors=True)


def _fingerprint(job: Job, inputs: dict) -> dict:
    """What makes two runs of a job the same: its task, recording and options, and the content of the files an eval
    reads (a trajectory that another job of the fleet wrote again)."""
    digests = {key: hashlib.sha256(Path(value).read_bytes()).hexdigest() for key, value in inputs.items()
               if job.task == "eval" and isinstance(value, Path) and value.is_file()}
    return json.loads(json.dumps({"task": job.task, "recording": str(job.recording), "options": job.options,
                                  "inputs": {key: str(value) for key, value in inputs.items()}, "sha256": digests},
                                 default=str))


def _recording_keyword(job: Job) -> dict:
    return {"dataset": job.recording} if job.recording.is_dir() else {"bag": job.recording}


def _eval_inputs(job: Job, fleet_out: Path) -> dict:
    options = dict(job.options)
    gt = options.pop("groundtruth", None) or job.recording / "groundtruth" / "trajectory.tum"
    inputs = {"gt": Path(gt)}
    if "of" in options:
        evaluated = fleet_out / "jobs" / options.pop("of")
        inputs["est"] = evaluated / "trajectory.tum"
        inputs["covariance"] = evaluated / "pose_covariance.txt"
    else:
        inputs["est"] = Path(options.pop("estimate"))
    return {**inputs, **options}


def _run_doctor(job: Job, out: Path) -> int:
    """doctor.json and run.json, written into a staging folder and renamed into place (as the jobs do)."""
    findings = mlidar.doctor(job.recording, **job.options)
    stage = out.parent / f".{out.name}.fleet-stage-{os.getpid()}"
    stage.mkdir()
    (stage / "doctor.json").write_text(json.dumps(findings, indent=2) + "\n")
    arguments = ["mlidar.doctor", f"input={job.recording}"] + [f"{key}={value}" for key, value in job.options.items()]
    run = {"tool": "mlidar", "version": mlidar.__version__, "command": "doctor", "arguments": arguments}
    (stage / "run.json").write_text(json.dumps(run, indent=2) + "\n")
    for name in ("doctor.json", "run.json"):
        with open(stage / name, "rb") as handle:
            os.fsync(handle.fileno())
    _publish(stage, out)
    return 1 if findings["failed"] else 0


def _publish(stage: Path, out: Path) -> None:
    """`stage` takes the place of `out`; an earlier `out` is moved aside first and removed last (the CLI's rule)."""
    previous = out.parent / f".{out.name}.fleet-stage-old-{os.getpid()}"
    if out.exists():
        os.rename(out, previous)
    os.rename(stage, out)
    shutil.rmtree(previous, ignore_errors=True)


def _execute(job: Job, out: Path, inputs: dict) -> int:
    """Runs the job into `out` (an eval on its `_eval_inputs`); its exit code (0 trusted, 1 ran but not to be
    trusted)."""
    common = {"out": out, "overwrite": True, **job.options}
    if job.task == "doctor":
        return _run_doctor(job, out)
    if job.task == "eval":
        options = {key: value for key, value in inputs.items() if key not in ("gt", "est")}
        mlidar.eval_traj(inputs["gt"], inputs["est"], out=out, overwrite=True, **options)
        return 0
    function = mlidar.calibrate_auto if job.task == "calibrate-auto" else mlidar.slam
    return function(**_recording_keyword(job), **common).exit_code


def _completed_exit_code(out: Path, job: Job, fingerprint: dict) -> Optional[int]:
    """The exit code of a complete earlier run of exactly this job in `out`, or None."""
    try:
        record = json.loads((out / _MARKER).read_text())
    except (OSError, ValueError):
        return None
    if record.get("job") != fingerprint or not (out / _RESULT_FILES[job.task]).exists():
        return None
    return int(record["exit_code"])


def _mark_complete(out: Path, job: Job, fingerprint: dict, exit_code: int) -> None:
    record = {"id": job.id, "vehicle": job.vehicle, "date": job.date, "exit_code": exit_code, "job": fingerprint}
    write_text_atomically(out / _MARKER, json.dumps(record, indent=2) + "\n")


def _worker_address() -> str:
    from distributed import get_worker

    try:
        return get_worker().address
    except ValueError:  # called outside a Dask worker (a test, a notebook)
        return ""


def _record(job: Job, status: str, fleet_out: Path, started: float, **fields) -> dict[str, Any]:
    return {"id": job.id, "status": status, "seconds": time.time() - started, "host": socket.gethostname(),
            "pid": os.getpid(), "worker": _worker_address(), "out": str(job_folder(fleet_out, job).relative_to(fleet_out)),
            **fields}


def run_job(job: Job, fleet_out: str, dependency: Optional[dict] = None) -> dict[str, Any]:
    """The Dask task: runs `job` (or reuses its complete run) and says how it went; never raises for the job's own
    failure, so that the fleet can tell a bad input (not retried) from a broken worker (retried elsewhere)."""
    fleet_out = Path(fleet_out)
    started = time.time()
    # The CLI's heap settings (core/heap_settings.hpp): Dask's nanny starts workers with MALLOC_TRIM_THRESHOLD_=65536,
    # the opposite; mallopt overrides it for this worker process.
    _mlidar.keep_large_buffers_in_the_heap()
    if dependency is not None and dependency["status"] != "done":
        return _record(job, "failed", fleet_out, started, exit_code=None,
                       error={"message": f"not run: job {dependency['id']} that it evaluates failed", "file": "", "field": ""})
    out = job_folder(fleet_out, job)
    inputs = _eval_inputs(job, fleet_out) if job.task == "eval" else {"recording": job.recording}
    fingerprint = _fingerprint(job, inputs)
    with job_lock(fleet_out, job):
        previous = _completed_exit_code(out, job, fingerprint)
        if previous is not None:
            _log(fleet_out, job, "reused", exit_code=previous)
            return _record(job, "done", fleet_out, started, exit_code=previous, reused=True)
        _remove_leftovers(fleet_out, job)
        _log(fleet_out, job, "started")
        try:
            exit_code = _execute(job, out, inputs)
        except _DETERMINISTIC as error:
            _log(fleet_out, job, "failed", error=str(error))
            return _record(job, "failed", fleet_out, started, exit_code=3 if isinstance(error, _mlidar.InputError) else 2,
                           error={"message": str(error), "file": getattr(error, "file", ""), "field": getattr(error, "field", "")})
        except Exception as error:  # a broken worker or machine (disk, memory): the fleet retries elsewhere
            _log(fleet_out, job, "error", error=repr(error))
            return _record(job, "error", fleet_out, started, exit_code=None,
                           error={"message": repr(error), "file": "", "field": ""})
        _mark_complete(out, job, fingerprint, exit_code)
        _log(fleet_out, job, "finished", exit_code=exit_code)
        return _record(job, "done", fleet_out, started, exit_code=exit_code, reused=False)
