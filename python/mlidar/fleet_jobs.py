"""The jobs file of `mlidar fleet run`: which task runs on which recording of which vehicle.

```yaml
defaults:                      # optional: options every job gets unless it sets its own
  threads: 1
jobs:
  - vehicle: van1              # a name of letters, digits, '.', '_' or '-'
    recording: van1/2026-12-01 # a dataset folder or a bag; relative paths from this file's folder
    date: 2026-12-01T09:00     # optional: orders a vehicle's recordings (else their order here)
    task: calibrate-auto       # calibrate-auto | slam | eval | doctor
    id: van1-mon-calib         # optional: the job's run folder name; default VEHICLE-RECORDING-TASK
    options: {stage: all}      # the task's options: the Python call's keywords (`mlidar.calibrate_auto(...)`)
  - {vehicle: van1, recording: van1/2026-12-01, task: eval, options: {of: van1-mon-slam}}
```

`eval` evaluates the trajectory of the job named by `of` (a slam job of this file), or a TUM file `estimate`,
against `groundtruth` (default RECORDING/groundtruth/trajectory.tum). Every key is checked: an unknown or repeated
key, a missing one or a wrong type is an InputError naming the file and the field (`jobs[2].options.stage`).
"""

from __future__ import annotations

import dataclasses
import inspect
import re
from pathlib import Path
from typing import Any, Optional

import yaml

from mlidar import _mlidar

TASKS = ("calibrate-auto", "slam", "eval", "doctor")
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]*$")  # starts with a letter or digit: never '.', '..' or hidden
_JOB_KEYS = {"id", "vehicle", "recording", "date", "task", "options"}
# Options that the fleet sets itself for every job.
_FLEET_OWNED = {"out", "dataset", "bag", "input", "progress", "overwrite", "arguments", "gt", "est"}
_EVAL_OWN = {"of", "estimate", "groundtruth"}
# Options that name a file: relative paths are from the jobs file's folder.
_PATH_OPTIONS = {"config", "init", "extrinsics", "estimate", "groundtruth"}


@dataclasses.dataclass(frozen=True)
class Job:
    id: str
    vehicle: str
    recording: Path        # absolute
    task: str
    date: str              # "" when not given
    order: int             # position in the file
    options: dict[str, Any]

    @property
    def depends_on(self) -> Optional[str]:
        return self.options.get("of") if self.task == "eval" else None


class _UniqueKeyLoader(yaml.SafeLoader):
    """YAML whose mappings refuse a key given twice (the C++ readers' rule)."""


def _construct_unique_mapping(loader, node, deep=False):
    seen = set()
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        if not isinstance(key, (str, int, float, bool)) and key is not None:
            raise yaml.constructor.ConstructorError(None, None, "a key must be a text", key_node.start_mark)
        if key in seen:
            raise yaml.constructor.ConstructorError(None, None, f"key '{key}' given twice", key_node.start_mark)
        seen.add(key)
    return loader.construct_mapping(node, deep=deep)


_UniqueKeyLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_unique_mapping)
# Dates stay text (`date` only orders recordings): no timestamp parsing, so no calendar errors.
_UniqueKeyLoader.yaml_implicit_resolvers = {
    first: [(tag, pattern) for tag, pattern in resolvers if tag != "tag:yaml.org,2002:timestamp"]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()}


def _error(path: Path, field: str, problem: str) -> _mlidar.InputError:
    error = _mlidar.InputError(f"{path}: {field}: {problem}")
    error.file, error.field = str(path), field
    return error


def task_options(task: str) -> set[str]:
    """The options a task takes: its Python call's keywords less those the fleet sets."""
    import mlidar

    if task == "eval":
        return (set(inspect.signature(mlidar.eval_traj).parameters) - _FLEET_OWNED - {"covariance"}) | _EVAL_OWN
    function = {"calibrate-auto": mlidar.calibrate_auto, "slam": mlidar.slam, "doctor": mlidar.doctor}[task]
    return set(inspect.signature(function).parameters) - _FLEET_OWNED


def _text(path: Path, field: str, value: Any) -> str:
    if isinstance(value, (dict, list)) or value is None:
        raise _error(path, field, "expected a text or a number")
    return str(value)


def _name(path: Path, field: str, value: Any) -> str:
    text = _text(path, field, value)
    if not _NAME.match(text):
        raise _error(path, field, f"'{text}' is not a name (letters, digits, '.', '_' and '-', starting with a letter or digit)")
    return text


def _parse_job(path: Path, index: int, entry: Any, defaults: dict) -> Job:
    where = f"jobs[{index}]"
    if not isinstance(entry, dict):
        raise _error(path, where, "expected a mapping {vehicle, recording, task, ...}")
    for key in entry:
        if key not in _JOB_KEYS:
            raise _error(path, f"{where}.{key}", f"unknown key (known: {', '.join(sorted(_JOB_KEYS))})")
    for key in ("vehicle", "recording", "task"):
        if key not in entry:
            raise _error(path, f"{where}.{key}", "missing")
    task = _text(path, f"{where}.task", entry["task"])
    if task not in TASKS:
        raise _error(path, f"{where}.task", f"unknown task '{task}' (known: {', '.join(TASKS)})")
    vehicle = _name(path, f"{where}.vehicle", entry["vehicle"])
    recording = (path.parent / _text(path, f"{where}.recording", entry["recording"])).resolve()
    if not recording.exists():
        raise _error(path, f"{where}.recording", f"'{recording}' does not exist (give a dataset folder or a bag)")
    options = entry.get("options", {})
    if not isinstance(options, dict):
        raise _error(path, f"{where}.options", "expected a mapping of the task's options")
    known = task_options(task)
    merged = {key: value for key, value in defaults.items() if key in known}
    for key, value in options.items():
        if key not in known:
            raise _error(path, f"{where}.options.{key}", f"not an option of {task} (known: {', '.join(sorted(known))})")
        merged[key] = value
    for key in _PATH_OPTIONS & merged.keys():
        merged[key] = str((path.parent / _text(path, f"{where}.options.{key}", merged[key])).resolve())
    if task == "eval" and ("of" in merged) == ("estimate" in merged):
        raise _error(path, f"{where}.options", "eval needs exactly one of 'of' (a slam job's id) and 'estimate' (a TUM file)")
    if "id" in entry:
        job_id = _name(path, f"{where}.id", entry["id"])
    elif not _NAME.match(default_id := f"{vehicle}-{recording.name}-{task}"):
        raise _error(path, f"{where}.id", f"missing, and '{default_id}' (vehicle-recording-task) is not a name: give the job an id")
    else:
        job_id = default_id
    return Job(job_id, vehicle, recording, task, str(entry.get("date", "")), index, merged)


def _check_defaults(path: Path, defaults: Any) -> dict:
    if not isinstance(defaults, dict):
        raise _error(path, "defaults", "expected a mapping of options")
    known = set().union(*(task_options(task) for task in TASKS))
    for key in defaults:
        if key not in known:
            raise _error(path, f"defaults.{key}", f"not an option of any task (known: {', '.join(sorted(known))})")
    return defaults


def _check_links(path: Path, jobs: list[Job]) -> None:
    by_id: dict[str, Job] = {}
    for job in jobs:
        if job.id in by_id:
            raise _error(path, f"jobs[{job.order}].id", f"'{job.id}' is also the id of jobs[{by_id[job.id].order}] "
                         "(give each job its own id)")
        by_id[job.id] = job
    for job in jobs:
        target = job.depends_on
        if target is None:
            continue
        if target not in by_id or by_id[target].task != "slam":
            raise _error(path, f"jobs[{job.order}].options.of", f"'{target}' is not the id of a slam job in this file")


def read_jobs(path: str | Path) -> list[Job]:
    """The jobs of a jobs file, checked; InputError naming the file and field otherwise."""
    path = Path(path).resolve()
    try:
        document = yaml.load(path.read_text(), Loader=_UniqueKeyLoader)
    except OSError as error:
        raise _error(path, "file", f"cannot be read ({error.strerror})") from None
    except UnicodeDecodeError as error:
        raise _error(path, "file", f"not UTF-8 text (byte {error.start}): save it as UTF-8") from None
    except (yaml.YAMLError, ValueError, TypeError, RecursionError) as error:
        raise _error(path, "yaml", f"not valid YAML ({error})") from None
    if not isinstance(document, dict) or "jobs" not in document:
        raise _error(path, "jobs", "missing (the file holds `jobs:`, a list of {vehicle, recording, task})")
    for key in document:
        if key not in ("jobs", "defaults"):
            raise _error(path, str(key), "unknown key (known: defaults, jobs)")
    if not isinstance(document["jobs"], list) or not document["jobs"]:
        raise _error(path, "jobs", "expected a non-empty list of jobs")
    defaults = _check_defaults(path, document.get("defaults", {}))
    jobs = [_parse_job(path, index, entry, defaults) for index, entry in enumerate(document["jobs"])]
    _check_links(path, jobs)
    return jobs
