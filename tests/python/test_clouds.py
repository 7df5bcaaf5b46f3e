"""read_cloud / write_cloud / read_extrinsics: numpy arrays in and out, every field and dtype kept, errors that name
the file and field."""

import os
from pathlib import Path

import numpy as np
import pytest

import mlidar

SHARED = Path(os.environ.get("MLIDAR_SHARED_DATA", Path(__file__).parents[3] / "shared" / "data"))
REAL_PCD = SHARED / "real" / "scan_pair" / "251370668.pcd"


def numpy_pcd(path: Path) -> np.ndarray:
    """An independent decoder of a binary PCD of float32 fields: the header, then the records as numpy reads them."""
    data = path.read_bytes()
    header_end = data.index(b"DATA binary\n") + len(b"DATA binary\n")
    header = dict(line.split(" ", 1) for line in data[:header_end].decode().splitlines() if not line.startswith("#"))
    fields = header["FIELDS"].split()
    points = int(header["POINTS"])
    records = np.frombuffer(data, dtype=np.float32, count=points * len(fields), offset=header_end)
    return records.reshape(points, len(fields)), fields


@pytest.mark.skipif(not REAL_PCD.exists(), reason=f"the shared real data is not at {REAL_PCD}")
def test_a_real_pcd_reads_as_numpy_reads_its_bytes_without_a_copy():
    cloud = mlidar.read_cloud(str(REAL_PCD))
    expected, fields = numpy_pcd(REAL_PCD)
    assert list(cloud) == fields == ["x", "y", "z", "intensity"]
    for k, name in enumerate(fields):
        assert cloud[name].dtype == np.float32
        np.testing.assert_array_equal(cloud[name], expected[:, k])
        assert not cloud[name].flags.owndata  # a view of the table read, kept alive by its base
    assert cloud["x"].base is not None


def random_fields(points: int) -> dict:
    generator = np.random.default_rng(3)
    return {
        "x": generator.normal(size=points).astype(np.float32),
        "y": generator.normal(size=points).astype(np.float32),
        "z": generator.normal(size=points).astype(np.float32),
        "intensity": generator.uniform(0, 255, size=points).astype(np.float32),
        "ring": generator.integers(0, 64, size=points).astype(np.uint16),
        "t": generator.uniform(0, 0.1, size=points).astype(np.float64),
        "label": generator.integers(-5, 5, size=points).astype(np.int32),
    }


@pytest.mark.parametrize("name,encoding", [("c.pcd", "binary"), ("c.pcd", "binary_compressed"), ("c.pcd", "ascii"),
                                           ("c.ply", "binary")])
def test_every_field_round_trips_bit_for_bit(tmp_path, name, encoding):
    fields = random_fields(1000)
    path = tmp_path / name
    mlidar.write_cloud(str(path), fields, pcd_encoding=encoding)
    back = mlidar.read_cloud(str(path))
    assert list(back) == list(fields)
    for key, values in fields.items():
        assert back[key].dtype == values.dtype, key
        np.testing.assert_array_equal(back[key], values, err_msg=key)


def test_a_field_of_several_values_per_point_is_a_2d_array(tmp_path):
    fields = random_fields(50)
    fields["normal"] = np.arange(150, dtype=np.float32).reshape(50, 3)
    mlidar.write_cloud(str(tmp_path / "n.pcd"), fields)
    back = mlidar.read_cloud(str(tmp_path / "n.pcd"))
    assert back["normal"].shape == (50, 3)
    np.testing.assert_array_equal(back["normal"], fields["normal"])


def test_an_empty_cloud_round_trips(tmp_path):
    empty = {axis: np.zeros(0, dtype=np.float32) for axis in "xyz"}
    mlidar.write_cloud(str(tmp_path / "e.pcd"), empty)
    back = mlidar.read_cloud(str(tmp_path / "e.pcd"))
    assert all(back[axis].shape == (0,) for axis in "xyz")


def test_a_truncated_cloud_is_an_input_error_naming_the_file(tmp_path):
    path = tmp_path / "cut.pcd"
    mlidar.write_cloud(str(path), random_fields(100))
    path.write_bytes(path.read_bytes()[:-37])
    with pytest.raises(mlidar.InputError) as raised:
        mlidar.read_cloud(str(path))
    assert raised.value.file == str(path)
    assert raised.value.field
    assert isinstance(raised.value, ValueError)
    assert str(path) in str(raised.value)


def test_arrays_that_cannot_be_a_cloud_are_refused_and_nothing_is_written(tmp_path):
    fields = random_fields(10)
    fields["y"] = fields["y"][:9]
    with pytest.raises(ValueError, match="'y'"):
        mlidar.write_cloud(str(tmp_path / "bad.pcd"), fields)
    with pytest.raises(ValueError, match="'x'"):
        mlidar.write_cloud(str(tmp_path / "bad.pcd"), {"y": np.zeros(3, np.float32)})
    with pytest.raises(ValueError, match="'name'"):
        mlidar.write_cloud(str(tmp_path / "bad.pcd"), {**random_fields(3), "name": np.array(["a", "b", "c"])})
    with pytest.raises(mlidar.InputError):
        mlidar.write_cloud(str(tmp_path / "bad.xyz"), random_fields(3))
    assert list(tmp_path.iterdir()) == []


def test_extrinsics_read_with_their_covariance(drive):
    extrinsics = mlidar.read_extrinsics(str(drive / "groundtruth" / "extrinsics.yaml"))
    assert list(extrinsics["lidars"]) == ["top", "front", "left", "right"]
    for lidar in extrinsics["lidars"].values():
        T = lidar["T_base_lidar"]
        assert T.shape == (4, 4)
        np.testing.assert_allclose(T[:3, :3] @ T[:3, :3].T, np.eye(3), atol=1e-9)
        np.testing.assert_array_equal(T[3], [0, 0, 0, 1])
