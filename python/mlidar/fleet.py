"""`mlidar fleet run`: many recordings × tasks as Dask tasks, one run folder per job and one summary.

    python3 -m mlidar.fleet run --jobs jobs.yaml --out FLEET [--local N | --scheduler ADDRESS]

The jobs run through the Python bindings on Dask workers (distributed): a LocalCluster of N single-threaded worker
processes by default, or the workers of a running scheduler. FLEET/ holds fleet_run.json (what started it),
jobs/ID/ (each job's run folder, published whole), fleet.json and fleet.html (fleet_summary.py). Run the same
command again after a kill: complete jobs are reused, the others run. A job whose worker breaks (an exception
that is not the job's bad input, or the worker process dying) runs again on another worker; a bad input is
reported, not retried. Exit 0 when every job ran and is trusted and no LiDAR moved, 1 otherwise, 2 for a usage
error, 3 for a bad jobs file, 130/143 when interrupted.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import json
import logging
import os
import signal
import sys
import time
from pathlib import Path
from typing import Optional

import mlidar
from mlidar import _mlidar
from mlidar.fleet_files import utc_now, write_text_atomically
from mlidar.fleet_jobs import Job, read_jobs, task_options
from mlidar.fleet_summary import summarize, write_summary
from mlidar.fleet_tasks import run_job

_MARKER = "fleet_run.json"
_RETRIES = 2  # a job whose worker broke runs again on another worker, this many times at most


class FleetUsageError(Exception):
    """A command line or --out that cannot be acted on (exit 2)."""


def _is_within(inner: Path, outer: Path) -> bool:
    return inner == outer or outer in inner.parents


def prepare_out(out: Path, jobs: list[Job], jobs_file: Path, arguments: list[str]) -> dict:
    """Checks --out (new, empty or an earlier fleet run; never a recording or inside one) and writes fleet_run.json."""
    out = out.resolve()
    for job in jobs:
        if _is_within(out, job.recording) or _is_within(job.recording, out):
            raise FleetUsageError(f"--out {out}: overlaps the recording {job.recording} of job {job.id} "
                                  "(choose a folder outside the recordings)")
    if out.exists():
        if not out.is_dir():
            raise FleetUsageError(f"--out {out}: is a file, not a folder (give a folder for the fleet run)")
        if any(out.iterdir()) and not (out / _MARKER).exists():
            raise FleetUsageError(f"--out {out}: holds files that are not a fleet run (give a new or empty folder, or "
                                  "the folder of an earlier fleet run to resume it)")
    (out / "jobs").mkdir(parents=True, exist_ok=True)
    previous = json.loads((out / _MARKER).read_text()) if (out / _MARKER).exists() else {}
    run = {"tool": "mlidar", "version": mlidar.__version__, "command": "fleet run", "arguments": arguments,
           "jobs_file": str(jobs_file), "started_utc": utc_now(), "runs": previous.get("runs", 0) + 1}
    write_text_atomically(out / _MARKER, json.dumps(run, indent=2) + "\n")
    return run


@contextlib.contextmanager
def _client(scheduler: Optional[str], local: Optional[int]):
    """A distributed.Client: to the scheduler at `scheduler`, else on a LocalCluster of `local` worker processes
    (closed on the way out, its workers with it)."""
    from distributed import Client, LocalCluster

    if scheduler:
        try:
            client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError) as error:
            raise FleetUsageError(f"--scheduler {scheduler}: cannot reach a Dask scheduler there ({error}); start one "
                                  "with `dask scheduler` and workers with `dask worker ADDRESS`") from None
        with client:
            yield client
        return
    with LocalCluster(n_workers=local or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                      dashboard_address=None, silence_logs=logging.ERROR) as cluster, Client(cluster) as client:
        yield client


def _check_workers_see(client, out: Path) -> None:
    """Every worker must reach --out (and so the recordings) at the same path: a shared filesystem."""
    seen = client.run(os.path.isdir, str(out))
    missing = [worker for worker, ok in seen.items() if not ok]
    if missing:
        raise FleetUsageError(f"--out {out}: not visible to the Dask workers {', '.join(missing)} (every worker must "
                              "see the fleet folder and the recordings at the same paths: a shared filesystem)")


def _with_thread_default(job: Job) -> Job:
    """One thread per job unless the job says otherwise: the workers are the parallelism."""
    if "threads" in task_options(job.task) and "threads" not in job.options:
        return dataclasses.replace(job, options={**job.options, "threads": 1})
    return job


class _Scheduler:
    """Submits jobs as their dependencies end, retries a broken worker's job elsewhere, collects the records."""

    def __init__(self, client, jobs: list[Job], out: Path, report):
        self.client, self.out, self.report = client, out, report
        self.jobs = {job.id: job for job in jobs}
        self.records: dict[str, dict] = {}
        self.attempts = {job.id: 0 for job in jobs}
        self.excluded: dict[str, set] = {job.id: set() for job in jobs}
        self.futures = {}

    def submit(self, job: Job, dependency: Optional[dict] = None):
        self.attempts[job.id] += 1
        workers = [w for w in self.client.scheduler_info()["workers"] if w not in self.excluded[job.id]]
        future = self.client.submit(run_job, job, str(self.out), dependency, key=f"{job.id}-attempt-{self.attempts[job.id]}",
                                    pure=False, workers=workers or None, allow_other_workers=not workers)
        self.futures[future] = job.id
        return future

    def run(self) -> dict[str, dict]:
        from distributed import as_completed

        ready = [job for job in self.jobs.values() if job.depends_on is None]
        pending = as_completed([self.submit(job) for job in ready])
        for future in pending:
            job = self.jobs[self.futures.pop(future)]
            record = self._result(future, job)
            if record["status"] == "error" and self.attempts[job.id] <= _RETRIES:
                self.excluded[job.id].add(record.get("worker"))
                self.report(f"{job.id}: {record['error']['message']} on {record.get('worker')}; again on another worker")
                pending.add(self.submit(job))
                continue
            if record["status"] == "error":  # broke on every worker it was given
                record["status"] = "failed"
            record["attempts"] = self.attempts[job.id]
            self.records[job.id] = record
            self.report(_progress_line(len(self.records), len(self.jobs), job, record))
            for dependent in self.jobs.values():
                if dependent.depends_on == job.id:
                    pending.add(self.submit(dependent, record))
        return self.records

    def _result(self, future, job: Job) -> dict:
        try:
            return future.result()
        except Exception as error:  # the task could not run (e.g. it killed every worker it was given)
            return {"id": job.id, "status": "failed", "exit_code": None, "seconds": None,
                    "error": {"message": f"{type(error).__name__}: {error}", "file": "", "field": ""}}


def _progress_line(done: int, total: int, job: Job, record: dict) -> str:
    if record["status"] != "done":
        verdict = f"FAILED: {record['error']['message']}"
    else:
        verdict = "trusted" if record["exit_code"] == 0 else "NOT trusted (exit 1)"
        verdict += " (complete earlier run reused)" if record.get("reused") else f" in {record['seconds']:.1f} s"
    return f"[{done}/{total}] {job.id} ({job.task} on {job.recording.name}): {verdict}"


def run_fleet(jobs_file: str | Path, out: str | Path, *, scheduler: Optional[str] = None, local: Optional[int] = None,
              arguments: Optional[list[str]] = None, report=print) -> dict:
    """Runs every job of `jobs_file` into `out` and writes fleet.json and fleet.html; returns fleet.json's dict."""
    jobs_file, out = Path(jobs_file).resolve(), Path(out).resolve()
    jobs = [_with_thread_default(job) for job in read_jobs(jobs_file)]
    run = prepare_out(out, jobs, jobs_file, arguments or [])
    started = time.time()
    with _client(scheduler, local) as client:
        _check_workers_see(client, out)
        workers = len(client.scheduler_info()["workers"])
        report(f"fleet: {len(jobs)} jobs on {workers} Dask worker(s) ({scheduler or 'local cluster'}) into {out}")
        records = _Scheduler(client, jobs, out, report).run()
    summary = summarize(jobs, records, out, run, seconds=time.time() - started, workers=workers)
    write_summary(out, summary)
    return summary


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="mlidar fleet", description="Fleet runs on Dask")
    commands = parser.add_subparsers(dest="command", required=True)
    run = commands.add_parser("run", help="Run every job of a jobs file; resume an interrupted fleet run")
    run.add_argument("--jobs", required=True, help="jobs.yaml")
    run.add_argument("--out", required=True, help="Fleet folder: new, empty or an earlier fleet run (resumed)")
    where = run.add_mutually_exclusive_group()
    where.add_argument("--scheduler", help="Address of a running Dask scheduler (tcp://HOST:8786)")
    where.add_argument("--local", type=int, help="Worker processes of a local cluster (default: the cores)")
    return parser


def _exit_on_signal(signum, frame):
    raise KeyboardInterrupt(signum)


def main(argv: Optional[list[str]] = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    try:
        options = _parser().parse_args(argv)
    except SystemExit as exit:
        return 0 if exit.code == 0 else 2
    if options.local is not None and options.local < 1:
        print("mlidar fleet: --local: must be at least 1 worker", file=sys.stderr)
        return 2
    signal.signal(signal.SIGTERM, _exit_on_signal)
    try:
        summary = run_fleet(options.jobs, options.out, scheduler=options.scheduler, local=options.local,
                            arguments=["mlidar", "fleet", *argv])
    except _mlidar.InputError as error:
        print(f"mlidar fleet: {error}", file=sys.stderr)
        return 3
    except FleetUsageError as error:
        print(f"mlidar fleet: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as interrupt:
        signum = interrupt.args[0] if interrupt.args else signal.SIGINT
        print("mlidar fleet: interrupted; the jobs that finished are kept: run the same command again to resume",
              file=sys.stderr)
        return 128 + int(signum)
    for line in summary["terminal"]:
        print(line)
    return summary["exit_code"]


if __name__ == "__main__":
    sys.exit(main())
