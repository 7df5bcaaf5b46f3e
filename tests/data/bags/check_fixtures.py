#!/usr/bin/python3
"""Re-read every fixture with libraries that are not mlidar's C++ readers and compare with expected.json.

ROS 1: python3-rosbag (the truncated bag is reindexed on a temporary copy with rosbag's own reindex()).
MCAP: mcap_io.read_mcap (checks CRCs, Statistics, Chunk and Message Indexes) + ros2_cdr.decode.
rosbag2 sqlite3: rosbag2_db3.read_db3_bag (Python sqlite3) + ros2_cdr.decode.
Prints one line per fixture and exits non-zero on the first mismatch.
"""
import json
import os
import shutil
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import genpy  # noqa: E402
import rosbag  # noqa: E402

import make_fixtures as made  # noqa: E402
import mcap_io  # noqa: E402
import ros1_bags  # noqa: E402
import ros2_cdr  # noqa: E402
import rosbag2_db3  # noqa: E402


def ros1_to_dict(value):
    """A genpy message as nested dicts in the ROS 2 naming used by fixture_scene (stamp sec / nanosec)."""
    if isinstance(value, genpy.Time):
        return {"sec": value.secs, "nanosec": value.nsecs}
    if hasattr(value, "__slots__"):
        return {k: ros1_to_dict(getattr(value, k)) for k in value.__slots__ if k != "seq"}
    if isinstance(value, (list, tuple)):
        return [ros1_to_dict(v) for v in value]
    return value


def entry(topic, type_name, receive_ns, message):
    return {"topic": topic, "type": type_name, "receive_ns": receive_ns, "message": message}


def read_ros1(path):
    out = []
    for topic, type_name, msg, t_ns in ros1_bags.read_bag(path):
        out.append(entry(topic, type_name.replace("/", "/msg/"), t_ns, ros1_to_dict(msg)))
    return out


def read_truncated(path):
    try:
        rosbag.Bag(path).close()
        raise AssertionError(f"{path}: rosbag opened it without reindexing (it should have no index)")
    except rosbag.ROSBagUnindexedException:
        pass
    with tempfile.TemporaryDirectory() as tmp:
        copy = os.path.join(tmp, "copy.bag")
        shutil.copyfile(path, copy)
        with rosbag.Bag(copy, "a", allow_unindexed=True) as bag:
            for _ in bag.reindex():
                pass
        return read_ros1(copy)


def read_mcap(path, expect):
    mcap = mcap_io.read_mcap(path)
    assert mcap["profile"] == "ros2", mcap["profile"]
    assert mcap["has_summary"] == expect["summary"], f"summary present: {mcap['has_summary']}"
    out = []
    for cid, seq, log_time, pub_time, data in mcap["messages"]:
        topic, sid, encoding = mcap["channels"][cid]
        type_name, schema_encoding, schema_text = mcap["schemas"][sid]
        assert encoding == "cdr" and schema_encoding == "ros2msg", (encoding, schema_encoding)
        assert schema_text == ros2_cdr.ROS2MSG[type_name], f"schema text of {type_name}"
        message, big = ros2_cdr.decode(type_name, data)
        assert big == expect["cdr_big_endian"], f"{topic}: CDR big-endian {big}"
        assert ros2_cdr.encode(type_name, message, big) == data, f"{topic}: @foxglove/cdr and ros2_cdr.py bytes differ"
        assert pub_time == log_time
        out.append(entry(topic, type_name, log_time, message))
    for topic in {e["topic"] for e in out}:  # sequences count 0, 1, 2, ... per channel
        seqs = [m[1] for m in mcap["messages"] if mcap["channels"][m[0]][0] == topic]
        assert seqs == list(range(len(seqs))), f"{topic}: sequence numbers"
    return out


def read_db3(folder):
    bag = rosbag2_db3.read_db3_bag(folder)
    meta = bag["metadata"]
    assert meta["storage_identifier"] == "sqlite3" and meta["version"] >= 5, meta
    assert meta["message_count"] == len(bag["messages"])
    out = []
    for tid, ns, data in bag["messages"]:
        topic, type_name, fmt = bag["topics"][tid]
        assert fmt == "cdr"
        message, big = ros2_cdr.decode(type_name, data)
        assert not big and data[:4] == b"\x00\x01\x00\x00", f"{topic}: expected little-endian CDR"
        out.append(entry(topic, type_name, ns, message))
    counts = {t["topic_metadata"]["name"]: t["message_count"] for t in meta["topics_with_message_count"]}
    assert counts == {n: sum(1 for e in out if e["topic"] == n) for n in counts}, counts
    return out


def compare(name, entries, expect, expected):
    times = [e["receive_ns"] for e in entries]
    assert times == sorted(times), f"{name}: messages are not in receive-time order"
    ros1 = expect["format"] == "ros1"
    got = {"topics": made.topic_table(entries, ros1),
           "pointclouds": made.cloud_records(entries, made.topic_indexes(entries))}
    for key in ("topics", "pointclouds"):
        if got[key] != expect[key]:
            for i, (a, b) in enumerate(zip(got[key], expect[key])):
                if a != b:
                    raise AssertionError(f"{name}: {key}[{i}] differs:\n got      {a}\n expected {b}")
            raise AssertionError(f"{name}: {key} has {len(got[key])} entries, expected {len(expect[key])}")
    tf = [e["message"] for e in entries if e["topic"] == "/tf_static"]
    if tf:
        got_tf = [{"parent": t["header"]["frame_id"], "child": t["child_frame_id"],
                   "translation": [t["transform"]["translation"][k] for k in "xyz"],
                   "rotation_xyzw": [t["transform"]["rotation"][k] for k in "xyzw"]} for t in tf[0]["transforms"]]
        assert got_tf == expected["tf_static"], f"{name}: /tf_static differs: {got_tf}"
    if "whole_messages" in expect:
        whole = [{"topic": e["topic"], "index": i, "receive_ns": e["receive_ns"]}
                 for e, i in zip(entries, made.topic_indexes(entries))]
        key = lambda m: (m["receive_ns"], m["topic"])  # noqa: E731 (equal times may come in either order)
        assert sorted(whole, key=key) == sorted(expect["whole_messages"], key=key), \
            f"{name}: recovered messages differ from whole_messages"
    else:
        imu = sum(1 for e in entries if e["topic"] == "/imu")
        assert imu == expected["imu_count"], f"{name}: {imu} /imu messages"
    return sum(t["message_count"] for t in got["topics"]), len(got["pointclouds"])


def main():
    with open(os.path.join(HERE, "expected.json")) as f:
        expected = json.load(f)
    failures = 0
    for name, expect in sorted(expected["fixtures"].items()):
        path = os.path.join(HERE, name)
        try:
            if name == "ros1_truncated.bag":
                entries = read_truncated(path)
            elif expect["format"] == "ros1":
                entries = read_ros1(path)
            elif expect["format"] == "mcap":
                entries = read_mcap(path, expect)
            else:
                entries = read_db3(path)
            count, clouds = compare(name, entries, expect, expected)
            print(f"ok    {name}: {count} messages, {clouds} PointCloud2 match expected.json")
        except Exception as error:  # report every fixture, then fail
            failures += 1
            print(f"FAIL  {name}: {type(error).__name__}: {error}")
    print(f"{len(expected['fixtures']) - failures} passed, {failures} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
