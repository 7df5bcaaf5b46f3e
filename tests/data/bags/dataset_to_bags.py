#!/usr/bin/python3
"""Convert an mlidar dataset folder into bags, for reader tests at test time.

    /usr/bin/python3 dataset_to_bags.py DATASET OUTDIR [--formats ros1,mcap,db3] [--compression none|bz2|lz4|zstd]

Writes OUTDIR/dataset.bag (ROS 1 bag 2.0, python3-rosbag), OUTDIR/dataset.mcap (ROS 2 MCAP, cdr/ros2msg,
mcap_io.py) and OUTDIR/dataset_db3/ (rosbag2 sqlite3: metadata.yaml + dataset_db3_0.db3, rosbag2_db3.py).
Needs only Python 3 and Debian packages: python3-yaml, plus python3-rosbag python3-sensor-msgs
python3-tf2-msgs (ros1), python3-roslz4 (ros1 lz4), python3-zstandard / python3-lz4 (mcap zstd / lz4).

Mapping (see README.md): frame k of LiDAR NAME (scans/NAME/*.pcd, binary PCD) becomes one
sensor_msgs/PointCloud2 on /NAME/points, frame_id NAME, its fields, offsets and bytes copied from the PCD
(t stays float64), width/height from the PCD, is_dense = every x, y, z finite. header.stamp = times.txt
line k read as an exact decimal and rounded to the nearest nanosecond (ties to even); the bag / log /
rosbag2 time is the same stamp. A frame whose scan file is missing is not written. One /tf_static
tf2_msgs/TFMessage (at the first stamp) holds base -> NAME for every LiDAR with an initial_extrinsic
(other than the base itself). Compression: ros1 none|bz2|lz4, mcap none|zstd|lz4; db3 is never compressed.
"""
import argparse
import decimal
import math
import os
import re
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import pcd_binary  # noqa: E402

COMPRESSIONS = {"ros1": ("none", "bz2", "lz4"), "mcap": ("none", "zstd", "lz4"), "db3": ("none",)}


def fail(message):
    sys.exit(f"dataset_to_bags: {message}")


def stamp_ns(text, where):
    """Seconds written as decimal text -> integer ns, round to nearest (ties to even), exactly (no float)."""
    try:
        ns = (decimal.Decimal(text) * 10**9).to_integral_value(rounding=decimal.ROUND_HALF_EVEN)
    except decimal.InvalidOperation:
        fail(f"{where}: '{text}' is not a number of seconds")
    if not ns.is_finite() or ns < 0 or ns >= 2**32 * 10**9:
        fail(f"{where}: stamp {text} is outside what bags hold (0 <= t < 2^32 s)")
    return int(ns)


def read_times(path):
    stamps = []
    with open(path) as f:
        for number, line in enumerate(f, 1):
            line = line.strip()
            if line and not line.startswith("#"):
                stamps.append(stamp_ns(line, f"{path} line {number}"))
    return stamps


def frame_files(folder, frames):
    """[path or None] per frame: clouds in natural order if there is one per frame, else by frame number."""
    if not os.path.isdir(folder):
        fail(f"{folder}: no such scans folder")
    names = sorted((n for n in os.listdir(folder) if n.lower().endswith(".pcd")),
                   key=lambda n: [int(p) if p.isdigit() else p for p in re.split(r"(\d+)", n)])
    others = [n for n in os.listdir(folder) if n.lower().endswith((".ply", ".bin"))]
    if others:
        fail(f"{folder}: only .pcd scans are converted (found {others[0]})")
    if len(names) == frames:
        return [os.path.join(folder, n) for n in names]
    if len(names) > frames:
        fail(f"{folder}: {len(names)} scans for {frames} stamps")
    by_frame = [None] * frames
    for n in names:
        stem = os.path.splitext(n)[0]
        if not stem.isdigit() or int(stem) >= frames:
            fail(f"{folder}/{n}: with scans missing, each file must be named by its frame number (0 to {frames - 1})")
        by_frame[int(stem)] = os.path.join(folder, n)
    return by_frame


def is_dense(cloud):
    by_name = {f["name"]: f for f in cloud["fields"]}
    codes = {7: "f", 8: "d"}
    for axis in ("x", "y", "z"):
        f = by_name.get(axis)
        if f is None or f["datatype"] not in codes:
            continue
        fmt = "<" + codes[f["datatype"]]
        for i in range(cloud["width"] * cloud["height"]):
            if not math.isfinite(struct.unpack_from(fmt, cloud["data"], i * cloud["point_step"] + f["offset"])[0]):
                return False
    return True


def load_dataset(folder):
    import yaml
    with open(os.path.join(folder, "dataset.yaml")) as f:
        spec = yaml.safe_load(f)
    if not isinstance(spec, dict) or "base" not in spec or not spec.get("lidars"):
        fail(f"{folder}/dataset.yaml: needs 'base' and a non-empty 'lidars' list")
    times = read_times(os.path.join(folder, spec.get("times", "times.txt")))
    return spec, times


def tf_static(spec, first_ns):
    transforms = []
    for lidar in spec["lidars"]:
        extrinsic = lidar.get("initial_extrinsic")
        if not extrinsic or lidar["name"] == spec["base"]:
            continue
        t, q = extrinsic["translation"], extrinsic["quaternion_wxyz"]
        transforms.append({"header": {"stamp": {"sec": first_ns // 10**9, "nanosec": first_ns % 10**9},
                                      "frame_id": str(spec["base"])},
                           "child_frame_id": lidar["name"],
                           "transform": {"translation": dict(zip("xyz", map(float, t))),
                                         "rotation": {"x": float(q[1]), "y": float(q[2]), "z": float(q[3]), "w": float(q[0])}}})
    return transforms


def entries(folder, spec, times):
    """Messages in the fixture_scene entry form, in time order (tf_static first, then frame by frame)."""
    transforms = tf_static(spec, times[0]) if times else []
    if transforms:
        yield {"topic": "/tf_static", "type": "tf2_msgs/msg/TFMessage", "receive_ns": times[0],
               "message": {"transforms": transforms}}
    files = {lidar["name"]: frame_files(os.path.join(folder, lidar["scans"]), len(times)) for lidar in spec["lidars"]}
    for k, ns in enumerate(times):
        for lidar in spec["lidars"]:
            path = files[lidar["name"]][k]
            if path is None:
                continue
            try:
                cloud = pcd_binary.read_pcd(path)
            except pcd_binary.PcdError as error:
                fail(str(error))
            message = {"header": {"stamp": {"sec": ns // 10**9, "nanosec": ns % 10**9}, "frame_id": lidar["name"]},
                       "height": cloud["height"], "width": cloud["width"], "fields": cloud["fields"],
                       "is_bigendian": False, "point_step": cloud["point_step"],
                       "row_step": cloud["width"] * cloud["point_step"], "data": cloud["data"], "is_dense": is_dense(cloud)}
            yield {"topic": f"/{lidar['name']}/points", "type": "sensor_msgs/msg/PointCloud2", "receive_ns": ns,
                   "message": message}


def topic_list(spec, times):
    topics = [("/tf_static", "tf2_msgs/msg/TFMessage", True)] if times and tf_static(spec, times[0]) else []
    return topics + [(f"/{lidar['name']}/points", "sensor_msgs/msg/PointCloud2", False) for lidar in spec["lidars"]]


def write_mcap(path, messages, topics, compression):
    import mcap_io
    import ros2_cdr
    with open(path, "wb") as out:
        writer = mcap_io.McapWriter(out, "" if compression == "none" else compression, library="mlidar dataset_to_bags.py")
        channels = {}
        for name, type_name, _ in topics:
            sid = writer.schema(type_name, "ros2msg", ros2_cdr.ROS2MSG[type_name].encode())
            channels[name] = writer.channel(name, sid, "cdr")
        for e in messages:
            writer.message(channels[e["topic"]], e["receive_ns"], e["receive_ns"], ros2_cdr.encode(e["type"], e["message"]))
        writer.finish()


def write_db3(folder, messages, topics):
    import ros2_cdr
    import rosbag2_db3
    index = {name: i for i, (name, _, _) in enumerate(topics)}
    rows = ((index[e["topic"]], e["receive_ns"], ros2_cdr.encode(e["type"], e["message"])) for e in messages)
    return rosbag2_db3.write_db3_bag(folder, topics, rows)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("dataset")
    parser.add_argument("outdir")
    parser.add_argument("--formats", default="ros1,mcap,db3", help="comma-separated: ros1, mcap, db3")
    parser.add_argument("--compression", default="none", choices=("none", "bz2", "lz4", "zstd"))
    args = parser.parse_args(argv)
    formats = [f for f in args.formats.split(",") if f]
    for fmt in formats:
        if fmt not in COMPRESSIONS:
            fail(f"unknown format {fmt!r} (use ros1, mcap, db3)")
        if fmt != "db3" and args.compression not in COMPRESSIONS[fmt]:
            fail(f"{fmt} cannot use --compression {args.compression} (choose {', '.join(COMPRESSIONS[fmt])})")
    spec, times = load_dataset(args.dataset)
    os.makedirs(args.outdir, exist_ok=True)
    topics = topic_list(spec, times)
    for fmt in formats:
        messages = entries(args.dataset, spec, times)  # re-read per format: memory stays at one cloud
        if fmt == "ros1":
            import ros1_bags
            path = os.path.join(args.outdir, "dataset.bag")
            ros1_bags.write_bag(path, messages, args.compression)
        elif fmt == "mcap":
            path = os.path.join(args.outdir, "dataset.mcap")
            write_mcap(path, messages, topics, args.compression)
        else:
            path = write_db3(os.path.join(args.outdir, "dataset_db3"), messages, topics)
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
