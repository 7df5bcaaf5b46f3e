#!/usr/bin/python3
"""Check dataset_to_bags.py output against its dataset: every bag in OUTDIR is re-read (rosbag for
dataset.bag, mcap_io.read_mcap for dataset.mcap, rosbag2_db3 for dataset_db3/) and each message must equal
the PCD it came from (fields, width, height, point bytes), with header stamp = bag time = times.txt stamp.

    /usr/bin/python3 check_dataset_bags.py DATASET OUTDIR
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import dataset_to_bags as conv  # noqa: E402
import mcap_io  # noqa: E402
import ros2_cdr  # noqa: E402
import rosbag2_db3  # noqa: E402


def read_outputs(outdir):
    """{format: [(topic, time_ns, message dict in ROS 2 naming)]} for the outputs present."""
    found = {}
    if os.path.exists(os.path.join(outdir, "dataset.bag")):
        import check_fixtures
        found["ros1"] = [(e["topic"], e["receive_ns"], e["message"])
                         for e in check_fixtures.read_ros1(os.path.join(outdir, "dataset.bag"))]
    if os.path.exists(os.path.join(outdir, "dataset.mcap")):
        mcap = mcap_io.read_mcap(os.path.join(outdir, "dataset.mcap"))
        assert mcap["has_summary"]
        found["mcap"] = []
        for cid, _, log_time, _, data in mcap["messages"]:
            topic, sid, _ = mcap["channels"][cid]
            found["mcap"].append((topic, log_time, ros2_cdr.decode(mcap["schemas"][sid][0], data)[0]))
    if os.path.isdir(os.path.join(outdir, "dataset_db3")):
        bag = rosbag2_db3.read_db3_bag(os.path.join(outdir, "dataset_db3"))
        found["db3"] = [(bag["topics"][t][0], ns, ros2_cdr.decode(bag["topics"][t][1], data)[0])
                        for t, ns, data in bag["messages"]]
    return found


def comparable(message):
    """Drop what ROS 1 and ROS 2 name differently or add (ROS 1 header seq is already dropped)."""
    return {k: bytes(v) if isinstance(v, (bytes, bytearray)) else v for k, v in message.items()}


def main(argv):
    if len(argv) != 2:
        sys.exit(__doc__)
    dataset, outdir = argv
    spec, times = conv.load_dataset(dataset)
    want = [(e["topic"], e["receive_ns"], comparable(e["message"])) for e in conv.entries(dataset, spec, times)]
    found = read_outputs(outdir)
    if not found:
        sys.exit(f"no dataset.bag, dataset.mcap or dataset_db3/ in {outdir}")
    failures = 0
    for fmt, got in sorted(found.items()):
        got = [(t, ns, comparable(m)) for t, ns, m in got]
        key = lambda m: (m[1], m[0])  # noqa: E731 (equal stamps of different topics may come in either order)
        ok = sorted(got, key=key) == sorted(want, key=key)
        stamps_ok = all(m["header"]["stamp"]["sec"] * 10**9 + m["header"]["stamp"]["nanosec"] == ns
                        for _, ns, m in got if "header" in m)
        clouds = sum(1 for t, _, _ in got if t.endswith("/points"))
        if ok and stamps_ok:
            print(f"ok    {fmt}: {len(got)} messages ({clouds} PointCloud2) equal the dataset's PCDs and stamps")
        else:
            failures += 1
            print(f"FAIL  {fmt}: {len(got)} messages read, {len(want)} expected; stamps match bag times: {stamps_ok}")
    print(f"{len(found) - failures} passed, {failures} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
