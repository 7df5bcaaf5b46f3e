#!/usr/bin/python3
"""Regenerate the Python-made fixtures: ROS 1 bags (python3-rosbag), rosbag2_db3/, build/scene.json (the
input of make_mcap_fixtures.mjs) and expected.json. Run from anywhere; writes next to this file.

    /usr/bin/python3 make_fixtures.py && npm ci && node make_mcap_fixtures.mjs
"""
import base64
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import fixture_scene as scene  # noqa: E402
import pointcloud as pc  # noqa: E402
import ros1_bags  # noqa: E402
import ros2_cdr  # noqa: E402
import rosbag2_db3  # noqa: E402

MCAP_FIXTURES = {"mcap_none.mcap": "none", "mcap_zstd.mcap": "zstd", "mcap_lz4.mcap": "lz4",
                 "mcap_nosummary.mcap": "zstd", "mcap_bigendian.mcap": "none"}


def topic_table(entries, ros1):
    """[{name, type, message_count, frame_id}] in TOPIC_ORDER for the entries present."""
    out = []
    for topic in scene.TOPIC_ORDER:
        mine = [e for e in entries if e["topic"] == topic]
        if not mine:
            continue
        type_name = mine[0]["type"].replace("/msg/", "/") if ros1 else mine[0]["type"]
        header = mine[0]["message"].get("header")
        out.append({"name": topic, "type": type_name, "message_count": len(mine),
                    "frame_id": header["frame_id"] if header else None})
    return out


def cloud_records(entries, indexes):
    """The expected.json record of every PointCloud2 among entries; indexes[i] = index of entries[i] in its topic."""
    out = []
    for entry, index in zip(entries, indexes):
        if entry["type"] != "sensor_msgs/msg/PointCloud2":
            continue
        m = entry["message"]
        out.append(dict({"topic": entry["topic"], "index": index, "stamp": m["header"]["stamp"],
                         "receive_ns": entry["receive_ns"], "frame_id": m["header"]["frame_id"]}, **pc.summary(m)))
    return out


def topic_indexes(entries):
    seen, out = {}, []
    for e in entries:
        out.append(seen.get(e["topic"], 0))
        seen[e["topic"]] = out[-1] + 1
    return out


def fixture_record(fmt, compression, entries, ros1=False, **extra):
    return dict({"format": fmt, "compression": compression, "topics": topic_table(entries, ros1),
                 "pointclouds": cloud_records(entries, topic_indexes(entries))}, **extra)


def make_ros1(entries, expected):
    for compression in ("none", "bz2", "lz4"):
        name = f"ros1_{compression}.bag"
        ros1_bags.write_bag(os.path.join(HERE, name), entries, compression)
        expected[name] = fixture_record("ros1", compression, entries, ros1=True)
    full = os.path.join(HERE, "ros1_lz4.bag")
    cut = ros1_bags.truncation_point(full)
    whole = ros1_bags.whole_messages(full, cut)
    with open(full, "rb") as src, open(os.path.join(HERE, "ros1_truncated.bag"), "wb") as dst:
        dst.write(src.read(cut))
    keys = {(e["topic"], e["receive_ns"]) for e in entries}
    if len(keys) != len(entries) or not set(whole) <= keys:
        raise SystemExit("topic + receive time must identify each message")
    kept = [e for e in entries if (e["topic"], e["receive_ns"]) in set(whole)]
    indexes = [i for e, i in zip(entries, topic_indexes(entries)) if (e["topic"], e["receive_ns"]) in set(whole)]
    expected["ros1_truncated.bag"] = dict(
        fixture_record("ros1", "lz4", kept, ros1=True, truncated_from="ros1_lz4.bag", truncated_at_byte=cut,
                       whole_messages=[{"topic": e["topic"], "index": i, "receive_ns": e["receive_ns"]}
                                       for e, i in zip(kept, indexes)]),
        pointclouds=cloud_records(kept, indexes))


def make_db3(entries, expected):
    topics = [(t, scene.TYPES[t], t == "/tf_static") for t in scene.TOPIC_ORDER]
    rows = [(scene.TOPIC_ORDER.index(e["topic"]), e["receive_ns"], ros2_cdr.encode(e["type"], e["message"]))
            for e in entries]
    rosbag2_db3.write_db3_bag(os.path.join(HERE, "rosbag2_db3"), topics, rows)
    expected["rosbag2_db3"] = fixture_record("rosbag2_sqlite3", "none", entries, storage_file="rosbag2_db3/rosbag2_db3_0.db3")


def to_json_message(message):
    """bytes -> base64 text so that make_mcap_fixtures.mjs can rebuild the message."""
    if isinstance(message, dict):
        return {k: to_json_message(v) for k, v in message.items()}
    if isinstance(message, list):
        return [to_json_message(v) for v in message]
    if isinstance(message, bytes):
        return {"base64": base64.b64encode(message).decode()}
    return message


def make_scene_json(entries, expected):
    os.makedirs(os.path.join(HERE, "build"), exist_ok=True)
    doc = {"schemas": ros2_cdr.ROS2MSG, "messages": [
        {"topic": e["topic"], "type": e["type"], "receive_ns": str(e["receive_ns"]), "message": to_json_message(e["message"]),
         "big_endian_data": to_json_message(scene.big_endian_copy(e)["message"]["data"]) if "data" in e["message"] else None}
        for e in entries], "fixtures": MCAP_FIXTURES}
    with open(os.path.join(HERE, "build", "scene.json"), "w") as out:
        json.dump(doc, out)
    for name, compression in MCAP_FIXTURES.items():
        big = name == "mcap_bigendian.mcap"
        shown = [scene.big_endian_copy(e) for e in entries] if big else entries
        expected[name] = fixture_record("mcap", compression, shown, summary=name != "mcap_nosummary.mcap",
                                        cdr_big_endian=big, profile="ros2", message_encoding="cdr", schema_encoding="ros2msg")


def dump_json(doc):
    """Indented JSON whose per-message records (pointclouds, whole_messages) are one compact line each."""
    lines = {}
    for fixture in doc["fixtures"].values():
        for key in ("pointclouds", "whole_messages"):
            for i, rec in enumerate(fixture.get(key, [])):
                mark = f"@@{len(lines)}@@"
                lines[mark] = json.dumps(rec, sort_keys=True, separators=(",", ":"))
                fixture[key][i] = mark
    text = json.dumps(doc, indent=1, sort_keys=True)
    for mark, line in lines.items():
        text = text.replace(f'"{mark}"', line)
    return text + "\n"


def main():
    entries = scene.messages()
    fixtures = {}
    make_ros1(entries, fixtures)
    make_db3(entries, fixtures)
    make_scene_json(entries, fixtures)
    tf = [{"parent": t["header"]["frame_id"], "child": t["child_frame_id"],
           "translation": [t["transform"]["translation"][k] for k in "xyz"],
           "rotation_xyzw": [t["transform"]["rotation"][k] for k in "xyzw"]}
          for t in scene.tf_static()[1]["transforms"]]
    expected = {
        "about": "Ground truth for tests/data/bags (see README.md). Times in ns since the Unix epoch; receive_ns is the "
                 "bag / MCAP log / rosbag2 timestamp = header stamp + 5 ms. finite_x_sum is a float64 sum in point order "
                 "(compare with a 1e-9 relative tolerance). Non-finite numbers are the strings 'nan' / 'inf'.",
        "tf_static": tf, "imu_count": sum(1 for e in entries if e["topic"] == "/imu"), "fixtures": fixtures}
    with open(os.path.join(HERE, "expected.json"), "w") as out:
        out.write(dump_json(expected))
    print(f"wrote {len(fixtures)} fixture records; now run: node make_mcap_fixtures.mjs")


if __name__ == "__main__":
    main()
