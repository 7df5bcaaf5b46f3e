"""The fleet's jobs file: every key checked, errors that name the file and the field."""

import textwrap

import pytest

import mlidar
from mlidar.fleet_jobs import read_jobs


def write(folder, text):
    (folder / "rec1").mkdir(exist_ok=True)
    (folder / "rec2").mkdir(exist_ok=True)
    (folder / "rec 3").mkdir(exist_ok=True)
    path = folder / "jobs.yaml"
    path.write_text(textwrap.dedent(text))
    return path


def test_jobs_take_defaults_ids_and_paths_from_the_files_folder(tmp_path):
    path = write(tmp_path, """\
        defaults: {threads: 2, config: calib.yaml}
        jobs:
          - {vehicle: van1, recording: rec1, task: calibrate-auto, date: 2026-12-01}
          - {vehicle: van1, recording: rec2, task: slam, id: van1-tue, options: {threads: 1, calibrate: fixed}}
          - {vehicle: van1, recording: rec2, task: eval, options: {of: van1-tue}}
          - {vehicle: van1, recording: rec2, task: doctor}
        """)
    calib, slam, evaluation, doctor = read_jobs(path)
    assert calib.id == "van1-rec1-calibrate-auto" and calib.recording == tmp_path / "rec1" and calib.date == "2026-12-01"
    assert calib.options == {"threads": 2, "config": str(tmp_path / "calib.yaml")}
    assert slam.id == "van1-tue" and slam.options["threads"] == 1 and slam.options["calibrate"] == "fixed"
    assert evaluation.depends_on == "van1-tue" and evaluation.options == {"of": "van1-tue"}
    assert doctor.options == {}  # doctor takes neither threads nor config


@pytest.mark.parametrize("text, field, words", [
    ("jobs:\n  - {vehicle: v, recording: rec1, task: dance}\n", "jobs[0].task", "unknown task 'dance'"),
    ("jobs:\n  - {vehicle: v, recording: rec1, task: slam, colour: red}\n", "jobs[0].colour", "unknown key"),
    ("jobs:\n  - {vehicle: v, task: slam}\n", "jobs[0].recording", "missing"),
    ("jobs:\n  - {vehicle: v, recording: nowhere, task: slam}\n", "jobs[0].recording", "does not exist"),
    ("jobs:\n  - {vehicle: v, recording: rec1, task: slam, options: {stage: all}}\n", "jobs[0].options.stage",
     "not an option of slam"),
    ("jobs:\n  - {vehicle: 'v 1', recording: rec1, task: slam}\n", "jobs[0].vehicle", "not a name"),
    ("jobs:\n  - {vehicle: v, recording: rec1, task: slam, id: ..}\n", "jobs[0].id", "not a name"),
    ("jobs:\n  - {vehicle: v, recording: 'rec 3', task: slam}\n", "jobs[0].id", "give the job an id"),
    ("jobs:\n  - {vehicle: v, recording: rec1, task: slam}\n  - {vehicle: v, recording: rec1, task: slam}\n", "jobs[1].id",
     "also the id of jobs[0]"),
    ("jobs:\n  - {vehicle: v, recording: rec1, task: eval}\n", "jobs[0].options", "exactly one of 'of'"),
    ("jobs:\n  - {vehicle: v, recording: rec1, task: eval, options: {of: x}}\n", "jobs[0].options.of", "not the id of a slam job"),
    ("defaults: {speed: 3}\njobs:\n  - {vehicle: v, recording: rec1, task: slam}\n", "defaults.speed", "not an option of any task"),
    ("jobs:\n  - {vehicle: v, vehicle: w, recording: rec1, task: slam}\n", "yaml", "given twice"),
    ("jobs: []\n", "jobs", "non-empty list"),
    ("job:\n  - {vehicle: v, recording: rec1, task: slam}\n", "jobs", "missing"),
])
def test_a_bad_jobs_file_is_an_input_error_naming_the_field(tmp_path, text, field, words):
    path = write(tmp_path, text)
    with pytest.raises(mlidar.InputError) as error:
        read_jobs(path)
    assert error.value.file == str(path) and error.value.field == field
    assert words in str(error.value) and str(path) in str(error.value)


def test_mutated_jobs_files_give_jobs_or_an_input_error_and_nothing_else(tmp_path):
    # The jobs file's fuzz test: bytes flipped, cut, repeated and spliced in a valid file (fixed seed).
    import random

    valid = write(tmp_path, """\
        defaults: {threads: 2}
        jobs:
          - {vehicle: van1, recording: rec1, task: calibrate-auto, date: 2026-12-01, options: {stage: all}}
          - {vehicle: van1, recording: rec2, task: slam, id: van1-tue, options: {calibrate: fixed}}
          - {vehicle: van1, recording: rec2, task: eval, options: {of: van1-tue, align: se3}}
        """).read_bytes()
    rng = random.Random(1)
    alphabet = b"{}[]:,-'\"\n #&*!|>%@`\t\x00\xff" + bytes(range(48, 123))
    path = tmp_path / "mutated.yaml"
    outcomes = {"jobs": 0, "error": 0}
    for _ in range(1500):
        data = bytearray(valid)
        for _ in range(rng.randint(1, 6)):
            k = rng.randrange(len(data) + 1)
            choice = rng.random()
            if choice < 0.4 and data:
                data[min(k, len(data) - 1)] = rng.choice(alphabet)
            elif choice < 0.6:
                del data[k:k + rng.randint(1, 20)]
            elif choice < 0.8:
                data[k:k] = bytes(rng.choice(alphabet) for _ in range(rng.randint(1, 5)))
            else:
                start = rng.randrange(len(valid))
                data[k:k] = valid[start:start + rng.randint(1, 40)]
        path.write_bytes(bytes(data))
        try:
            read_jobs(path)
            outcomes["jobs"] += 1
        except mlidar.InputError as error:
            assert error.file == str(path) and error.field
            outcomes["error"] += 1
    assert outcomes["jobs"] > 0 and outcomes["error"] > 0
