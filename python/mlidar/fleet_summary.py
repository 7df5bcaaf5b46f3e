"""fleet.json and fleet.html: each recording's verdict and, per vehicle and LiDAR, whether the extrinsic moved.

The extrinsic estimates come from each recording's calibrate-auto job (every LiDAR it calibrated) or, without one,
its slam job with online calibration (every LiDAR that converged); given extrinsics (`--calibrate fixed`, a LiDAR not
calibrated) are not estimates and are left out. drift.py compares a LiDAR's consecutive estimates.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Optional

import numpy as np

import mlidar
from mlidar import drift
from mlidar.fleet_files import utc_now, write_text_atomically
from mlidar.fleet_jobs import Job
from mlidar.fleet_tasks import job_log_path


def _log_counts(out: Path, job: Job) -> dict:
    """Starts and completed runs of a job in this fleet folder, over every fleet run (its .log)."""
    counts = {"starts": 0, "runs": 0, "reuses": 0}
    try:
        lines = job_log_path(out, job).read_text().splitlines()
    except OSError:
        return counts
    for line in lines:
        event = json.loads(line).get("event")
        counts["starts"] += event == "started"
        counts["runs"] += event == "finished"
        counts["reuses"] += event == "reused"
    return counts


def _verdict(record: dict) -> str:
    if record is None or record["status"] != "done":
        return "failed"
    return "trusted" if record["exit_code"] == 0 else "untrusted"


def _job_entry(job: Job, record: Optional[dict], out: Path) -> dict:
    record = record or {"status": "failed", "exit_code": None, "error": {"message": "not run"}}
    entry = {"id": job.id, "vehicle": job.vehicle, "recording": str(job.recording), "date": job.date, "task": job.task,
             "status": record["status"], "verdict": _verdict(record), "exit_code": record.get("exit_code"),
             "seconds": record.get("seconds"), "attempts": record.get("attempts"), "reused": record.get("reused", False),
             "worker": record.get("worker"), "out": f"jobs/{job.id}", "error": record.get("error")}
    entry.update(_log_counts(out, job))
    if entry["status"] == "done" and job.task == "eval":
        ate = json.loads((out / "jobs" / job.id / "eval.json").read_text()).get("ate", {})
        entry["ate_rmse_m"] = ate.get("translation_m", {}).get("rmse")
    return entry


def _estimates_of(job: Job, out: Path) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """LiDAR -> (T_base_lidar, covariance) that the job estimated (not given), base LiDAR left out."""
    folder = out / "jobs" / job.id
    extrinsics = mlidar.read_extrinsics(str(folder / "extrinsics.yaml"))
    if job.task == "calibrate-auto":
        report = json.loads((folder / "calibration.json").read_text())
        estimated = {l["name"] for l in report["lidars"] if l["usable"] and l["name"] != report["base"]}
    else:
        metrics = json.loads((folder / "metrics.json").read_text())
        estimated = set() if metrics.get("calibrate") == "fixed" else {
            name for name, lidar in metrics.get("per_lidar", {}).items() if lidar.get("converged_frame") is not None}
    found = {}
    for name, lidar in extrinsics["lidars"].items():
        if name in estimated and lidar.get("covariance") is not None:
            found[name] = (np.asarray(lidar["T_base_lidar"], dtype=float), np.asarray(lidar["covariance"], dtype=float))
    return found


def _drift(jobs: list[Job], records: dict, out: Path, rule: drift.DriftRule) -> dict:
    """vehicle -> LiDAR -> {estimates, changes, moved}: one estimate per recording, in date then file order."""
    chosen: dict[tuple[str, str], Job] = {}
    for job in sorted(jobs, key=lambda j: (j.task != "calibrate-auto", j.order)):
        usable = job.task in ("calibrate-auto", "slam") and (records.get(job.id) or {}).get("status") == "done"
        if usable:
            chosen.setdefault((job.vehicle, str(job.recording)), job)
    series: dict[str, dict[str, list[drift.Estimate]]] = {}
    for job in sorted(chosen.values(), key=lambda j: (j.date, j.order)):
        for lidar, (T, covariance) in _estimates_of(job, out).items():
            series.setdefault(job.vehicle, {}).setdefault(lidar, []).append(
                drift.Estimate(job.recording.name, T, covariance))
    result = {}
    for vehicle, lidars in series.items():
        result[vehicle] = {}
        for lidar, estimates in lidars.items():
            changes = drift.lidar_drift(estimates, rule)
            result[vehicle][lidar] = {"estimates": [_estimate_json(e, estimates[0]) for e in estimates],
                                      "changes": changes, "moved": any(c["moved"] for c in changes)}
    return result


def _estimate_json(estimate: drift.Estimate, first: drift.Estimate) -> dict:
    """An estimate with its 1σ and its change from the vehicle's first estimate of that LiDAR."""
    sigma = np.sqrt(np.clip(np.diag(estimate.covariance), 0.0, None))
    change = drift.change(first, estimate, drift.DriftRule())
    return {"recording": estimate.recording, "translation": estimate.T_base_lidar[:3, 3].tolist(),
            "rotation_from_first_deg": change["rotation_deg"], "translation_from_first_m": change["translation_m"],
            "sigma_translation_m": sigma[:3].tolist(), "sigma_rotation_deg": np.degrees(sigma[3:]).tolist()}


def summarize(jobs: list[Job], records: dict, out: Path, run: dict, *, seconds: float, workers: int,
              rule: drift.DriftRule = drift.DriftRule()) -> dict:
    entries = [_job_entry(job, records.get(job.id), out) for job in jobs]
    recordings: dict[tuple[str, str], dict] = {}
    for job, entry in zip(jobs, entries):
        key = (job.vehicle, str(job.recording))
        recording = recordings.setdefault(key, {"vehicle": job.vehicle, "recording": str(job.recording), "date": job.date,
                                                "jobs": [], "pages": [], "verdict": "trusted"})
        recording["jobs"].append(job.id)
        recording["pages"].append("doctor.json" if job.task == "doctor" else "report.html")
        order = ["trusted", "untrusted", "failed"]
        recording["verdict"] = max(recording["verdict"], entry["verdict"], key=order.index)
    drift_by_vehicle = _drift(jobs, records, out, rule)
    moved = [{"vehicle": v, "lidar": l, **c} for v, lidars in drift_by_vehicle.items() for l, d in lidars.items()
             for c in d["changes"] if c["moved"]]
    failed = [e["id"] for e in entries if e["status"] != "done"]
    untrusted = [e["id"] for e in entries if e["verdict"] == "untrusted"]
    summary = {"tool": "mlidar", "version": mlidar.__version__, "command": "fleet run", "arguments": run["arguments"],
               "jobs_file": run["jobs_file"], "started_utc": run["started_utc"],
               "finished_utc": utc_now(), "seconds": seconds,
               "workers": workers, "drift_rule": {"rotation_deg": rule.rotation_deg, "translation_m": rule.translation_m,
                                                  "confidence": rule.confidence},
               "jobs": entries, "recordings": list(recordings.values()), "drift": drift_by_vehicle, "moved": moved,
               "failed_jobs": failed, "untrusted_jobs": untrusted}
    summary["exit_code"] = 1 if failed or untrusted or moved else 0
    summary["terminal"] = _terminal_lines(summary)
    return summary


def _terminal_lines(summary: dict) -> list[str]:
    lines = [f"fleet: {len(summary['jobs'])} jobs, {len(summary['failed_jobs'])} failed, "
             f"{len(summary['untrusted_jobs'])} not trusted, in {summary['seconds']:.1f} s"]
    for job in summary["jobs"]:
        if job["status"] != "done":
            lines.append(f"failed  {job['id']}: {job['error']['message']}")
        elif job["verdict"] == "untrusted":
            page = "doctor.json" if job["task"] == "doctor" else "report.html"
            lines.append(f"not trusted  {job['id']}: exit {job['exit_code']}, {job['out']}/{page} says why")
    for m in summary["moved"]:
        lines.append(f"MOVED   {m['vehicle']} {m['lidar']}: between {m['from']} and {m['to']} by {m['rotation_deg']:.2f} deg, "
                     f"{m['translation_m'] * 100:.1f} cm (d2 {m['d2']:.0f})" if m["d2"] is not None else
                     f"MOVED   {m['vehicle']} {m['lidar']}: between {m['from']} and {m['to']} by {m['rotation_deg']:.2f} deg")
    if not summary["moved"]:
        checked = sum(len(lidars) for lidars in summary["drift"].values())
        lines.append(f"no LiDAR moved ({checked} vehicle-LiDAR series checked)")
    return lines


def write_summary(out: Path, summary: dict) -> None:
    from mlidar.fleet_html import fleet_html

    document = {key: value for key, value in summary.items() if key != "terminal"}
    write_text_atomically(out / "fleet.json", json.dumps(document, indent=2, default=_json_default) + "\n")
    write_text_atomically(out / "fleet.html", fleet_html(document))


def _json_default(value):
    if isinstance(value, (np.floating, np.integer, np.bool_)):
        return value.item()
    raise TypeError(f"{type(value).__name__} is not JSON")

