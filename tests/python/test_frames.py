"""FrameSource: a dataset folder or a folder of clouds, frame by frame, as the jobs read it."""

import numpy as np
import pytest

import mlidar


def test_a_dataset_gives_each_frame_every_lidars_scan(drive):
    source = mlidar.FrameSource.dataset(drive)
    assert len(source) == 8
    assert [lidar["name"] for lidar in source.lidars] == ["top", "front", "left", "right"]
    assert all(lidar["model"] == "RS-LiDAR-16" and lidar["rings"] == 16 for lidar in source.lidars)
    np.testing.assert_allclose(np.diff(source.stamps), source.period)
    frames = list(source)
    assert [frame["index"] for frame in frames] == list(range(8))
    assert [frame["stamp"] for frame in frames] == list(source.stamps)
    scan = frames[3]["scans"]["front"]
    assert scan["points"].dtype == np.float32 and scan["points"].shape[1] == 3 and len(scan["points"]) > 1000
    assert scan["ring"].max() < 16 and len(scan["ring"]) == len(scan["points"])
    assert len(scan["time"]) == len(scan["points"]) and scan["time"].min() >= 0.0


def test_a_frames_scan_holds_the_points_of_its_file(drive):
    # The simulated clouds have no invalid point, so the scan keeps every point of the file, in order.
    cloud = mlidar.read_cloud(str(sorted((drive / "scans" / "left").iterdir())[0]))
    scan = mlidar.FrameSource.dataset(drive, ["left"])[0]["scans"]["left"]
    np.testing.assert_array_equal(scan["points"], np.stack([cloud["x"], cloud["y"], cloud["z"]], axis=1))


def test_indices_count_from_either_end_and_stop_at_the_last_frame(drive):
    source = mlidar.FrameSource.dataset(drive, ["top"])
    assert source[-1]["index"] == 7
    with pytest.raises(IndexError):
        source[8]


def test_a_folder_of_clouds_is_one_lidar_at_the_given_period(drive):
    source = mlidar.FrameSource.scans(drive / "scans" / "top", period=0.5, model="RS-LiDAR-16")
    assert len(source) == 8
    np.testing.assert_allclose(source.stamps, np.arange(8) * 0.5)


def test_a_lidar_the_dataset_lacks_and_a_missing_folder_are_refused(drive, tmp_path):
    with pytest.raises(mlidar.UsageError, match="rear"):
        mlidar.FrameSource.dataset(drive, ["rear"])
    with pytest.raises(mlidar.InputError) as raised:
        mlidar.FrameSource.dataset(tmp_path / "nothing")
    assert "nothing" in raised.value.file


def test_doctor_gives_the_clis_findings(drive, tmp_path):
    import json

    from conftest import run_cli

    findings = mlidar.doctor(drive)
    run_cli("doctor", drive, "--json", tmp_path / "doctor.json")
    assert findings == json.loads((tmp_path / "doctor.json").read_text())
    assert findings["failed"] is False and {f["check"] for f in findings["findings"]} >= {"stamps", "extrinsics"}
    broken = mlidar.doctor(tmp_path / "nowhere.bag", topics="/top/points:top")
    assert broken["failed"] is True and broken["findings"][0]["check"] == "open" and "nowhere.bag" in broken["findings"][0]["message"]
    with pytest.raises(mlidar.UsageError):  # the CLI's exit 2: a bag needs its topics
        mlidar.doctor(tmp_path / "nowhere.bag")
