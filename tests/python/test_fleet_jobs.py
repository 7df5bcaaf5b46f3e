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
