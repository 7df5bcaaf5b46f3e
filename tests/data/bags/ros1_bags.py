"""ROS 1 bag (format 2.0) fixtures through python3-rosbag, and the truncated-bag analysis.

Spec: ROS bag format 2.0 (wiki.ros.org/Bags/Format/2.0). A bag is the '#ROSBAG V2.0' line, a bag header
record, then per chunk a CHUNK record (op 0x05) followed by its INDEX_DATA records (op 0x04), then the
CONNECTION and CHUNK_INFO records that the bag header's index_pos points at. Each record is
uint32 header_len, header, uint32 data_len, data (little-endian).
"""
import struct

import genpy
import rosbag
from geometry_msgs.msg import Quaternion, Transform, TransformStamped, Vector3
from sensor_msgs.msg import Imu, PointCloud2, PointField
from std_msgs.msg import Header
from tf2_msgs.msg import TFMessage

CHUNK_THRESHOLD = 64 * 1024


def ros_time(ns):
    return genpy.Time(ns // 10**9, ns % 10**9)


def header(h, seq):
    return Header(seq=seq, stamp=genpy.Time(h["stamp"]["sec"], h["stamp"]["nanosec"]), frame_id=h["frame_id"])


def to_ros1(entry, seq):
    """The ROS 1 message for a fixture_scene entry (ROS 2 dict form); seq = index within its topic."""
    m = entry["message"]
    if entry["type"] == "sensor_msgs/msg/PointCloud2":
        fields = [PointField(name=f["name"], offset=f["offset"], datatype=f["datatype"], count=f["count"]) for f in m["fields"]]
        return PointCloud2(header=header(m["header"], seq), height=m["height"], width=m["width"], fields=fields,
                           is_bigendian=m["is_bigendian"], point_step=m["point_step"], row_step=m["row_step"],
                           data=m["data"], is_dense=m["is_dense"])
    if entry["type"] == "sensor_msgs/msg/Imu":
        return Imu(header=header(m["header"], seq), orientation=Quaternion(**m["orientation"]),
                   orientation_covariance=m["orientation_covariance"], angular_velocity=Vector3(**m["angular_velocity"]),
                   angular_velocity_covariance=m["angular_velocity_covariance"],
                   linear_acceleration=Vector3(**m["linear_acceleration"]),
                   linear_acceleration_covariance=m["linear_acceleration_covariance"])
    if entry["type"] == "tf2_msgs/msg/TFMessage":
        return TFMessage(transforms=[
            TransformStamped(header=header(t["header"], 0), child_frame_id=t["child_frame_id"],
                             transform=Transform(translation=Vector3(**t["transform"]["translation"]),
                                                 rotation=Quaternion(**t["transform"]["rotation"])))
            for t in m["transforms"]])
    raise ValueError(entry["type"])


def write_bag(path, entries, compression="none", chunk_threshold=CHUNK_THRESHOLD):
    """Write entries (receive-time ordered) with bag time = receive time; /tf_static is latched."""
    seqs = {}
    with rosbag.Bag(path, "w", compression=compression, chunk_threshold=chunk_threshold) as bag:
        for entry in entries:
            seq = seqs.get(entry["topic"], 0)
            seqs[entry["topic"]] = seq + 1
            msg = to_ros1(entry, seq)
            latch = None
            if entry["topic"] == "/tf_static":  # a full connection header is needed to add latching
                latch = {"topic": entry["topic"], "type": msg._type, "md5sum": msg._md5sum,
                         "message_definition": msg._full_text, "callerid": "/mlidar_fixtures", "latching": "1"}
            bag.write(entry["topic"], msg, ros_time(entry["receive_ns"]), connection_header=latch)


def chunk_extents(path):
    """[(start, end, [(topic, receive_ns), ...])] for every CHUNK record of an indexed bag, in file order."""
    with rosbag.Bag(path) as bag:
        topic_of = {c.id: c.topic for c in bag._connections.values()}
        by_chunk = {}
        for conn_id, entries in bag._connection_indexes.items():
            for e in entries:
                by_chunk.setdefault(e.chunk_pos, []).append((e.offset, topic_of[conn_id], e.time.to_nsec()))
        extents = []
        with open(path, "rb") as raw:
            for info in bag._chunks:
                raw.seek(info.pos)
                header_len = struct.unpack("<I", raw.read(4))[0]
                raw.seek(info.pos + 4 + header_len)
                data_len = struct.unpack("<I", raw.read(4))[0]
                end = info.pos + 8 + header_len + data_len
                extents.append((info.pos, end, [(t, ns) for _, t, ns in sorted(by_chunk.get(info.pos, []))]))
    return extents


def truncation_point(path, fraction=0.6):
    """A byte count near fraction of the file that falls strictly inside a CHUNK record (not at a record edge)."""
    with open(path, "rb") as raw:
        size = len(raw.read())
    target = int(size * fraction)
    for start, end, _ in chunk_extents(path):
        if start < target < end:
            return target
        if start >= target:
            return (start + end) // 2
    raise ValueError("no chunk at or after the target")


def whole_messages(path, cut):
    """(topic, receive_ns) of the messages whose CHUNK record ends at or before byte cut, in file order."""
    return [m for start, end, msgs in chunk_extents(path) if end <= cut for m in msgs]


def read_bag(path):
    """[(topic, type, message, bag time ns)] in file order through rosbag (raises on an unindexed bag)."""
    with rosbag.Bag(path) as bag:
        return [(topic, msg._type, msg, t.to_nsec()) for topic, msg, t in bag.read_messages()]
