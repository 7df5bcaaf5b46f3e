"""The shared, deterministic content of every bag fixture (same messages in every format).

A 10 x 8 x 3 m box room (x in [-5, 5], y in [-4, 4], z in [0, 3]); base_link stands still at
ROOM_FROM_BASE, three LiDARs are mounted on it by TF_STATIC. Every point is a ray cast from its LiDAR
to the room's walls, floor or ceiling (with 1 cm range noise), so the clouds are in each LiDAR's frame.
Times are integer nanoseconds; receive time (bag / log time) = header stamp + 5 ms.
Messages are ROS 2 style dicts (stamp.sec / stamp.nanosec); make_ros1_fixtures.py maps them to ROS 1.
"""
import math
import random
import struct

import pointcloud as pc

T0_NS = 1_700_000_000 * 10**9          # top's first sweep starts here
RECEIVE_DELAY_NS = 5_000_000           # receive time = header stamp + 5 ms
SEED = 20240611
ROOM_MIN, ROOM_MAX = (-5.0, -4.0, 0.0), (5.0, 4.0, 3.0)
ROOM_FROM_BASE = (0.4, -0.3, 0.9)      # base_link origin in the room, axes aligned with the room
TOPIC_ORDER = ["/tf_static", "/imu", "/top/points", "/left/points", "/right/points"]  # tie-break at equal times
TYPES = {"/tf_static": "tf2_msgs/msg/TFMessage", "/imu": "sensor_msgs/msg/Imu", "/top/points": "sensor_msgs/msg/PointCloud2",
         "/left/points": "sensor_msgs/msg/PointCloud2", "/right/points": "sensor_msgs/msg/PointCloud2"}


def f32(value):
    """Round to the nearest float32 (what the bytes will hold)."""
    return struct.unpack("<f", struct.pack("<f", value))[0]


def quat_rpy(roll_deg, pitch_deg, yaw_deg):
    """Quaternion (x, y, z, w) of R = Rz(yaw) Ry(pitch) Rx(roll) (ROS convention)."""
    r, p, y = (math.radians(a) / 2 for a in (roll_deg, pitch_deg, yaw_deg))
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)


def rotate(q, v):
    """Rotate vector v by unit quaternion q = (x, y, z, w)."""
    x, y, z, w = q
    tx, ty, tz = 2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0])
    return (v[0] + w * tx + y * tz - z * ty, v[1] + w * ty + z * tx - x * tz, v[2] + w * tz + x * ty - y * tx)


# base_link -> LiDAR mounts: (translation, quaternion xyzw)
MOUNTS = {
    "top": ((0.10, 0.00, 0.45), quat_rpy(0.0, 3.0, 0.0)),
    "left": ((0.25, 0.40, 0.20), quat_rpy(40.0, 0.0, 10.0)),
    "right": ((0.25, -0.40, 0.20), quat_rpy(0.0, 0.0, -30.0)),
}


def stamp(ns):
    return {"sec": ns // 10**9, "nanosec": ns % 10**9}


def cast(lidar, direction):
    """Range from the LiDAR origin to the room box along a unit direction given in the LiDAR frame."""
    t, q = MOUNTS[lidar]
    origin = tuple(ROOM_FROM_BASE[i] + t[i] for i in range(3))
    d = rotate(q, direction)
    ranges = []
    for i in range(3):
        if abs(d[i]) > 1e-12:
            wall = ROOM_MAX[i] if d[i] > 0 else ROOM_MIN[i]
            ranges.append((wall - origin[i]) / d[i])
    return min(r for r in ranges if r > 0)


def ray(rng, lidar, azimuth, elevation):
    """A noisy return (x, y, z, range) in the LiDAR frame."""
    d = (math.cos(elevation) * math.cos(azimuth), math.cos(elevation) * math.sin(azimuth), math.sin(elevation))
    r = cast(lidar, d) + rng.gauss(0.0, 0.01)
    return d[0] * r, d[1] * r, d[2] * r, r


def elevation(ring):
    return math.radians(-15.0 + 2.0 * ring)  # 16 rings, -15..+15 deg


def top_cloud(rng, k):
    """Velodyne style: stamp at sweep END, time float32 s in [-0.1, 0], packed point_step 22."""
    stamp_ns = T0_NS + (k + 1) * 100_000_000
    fields = [pc.field("x", 0, "f"), pc.field("y", 4, "f"), pc.field("z", 8, "f"), pc.field("intensity", 12, "f"),
              pc.field("ring", 16, "H"), pc.field("time", 18, "f")]
    samples = sorted((rng.random(), rng.randrange(16)) for _ in range(300))
    points = []
    for frac, ring in samples:
        x, y, z, _ = ray(rng, "top", 2 * math.pi * frac, elevation(ring))
        points.append({"x": f32(x), "y": f32(y), "z": f32(z), "intensity": f32(rng.uniform(0, 255)), "ring": ring,
                       "time": f32(-0.1 + 0.1 * frac)})
    return stamp_ns, cloud("top", stamp_ns, 1, 300, 22, fields, points, True)


def left_cloud(rng, k):
    """Ouster style: stamp at sweep START, t uint32 ns in [0, 1e8), organized 16 x 18, point_step 32 with padding at 12."""
    stamp_ns = T0_NS + 30_000_000 + k * 100_000_000
    fields = [pc.field("x", 0, "f"), pc.field("y", 4, "f"), pc.field("z", 8, "f"), pc.field("intensity", 16, "f"),
              pc.field("t", 20, "I"), pc.field("reflectivity", 24, "H"), pc.field("ring", 26, "H"),
              pc.field("range", 28, "I")]
    points = []
    for ring in range(16):
        for col in range(18):
            x, y, z, r = ray(rng, "left", 2 * math.pi * col / 18 + 0.01 * k, elevation(ring))
            points.append({"x": f32(x), "y": f32(y), "z": f32(z), "intensity": f32(rng.uniform(0, 1000)),
                           "t": col * 100_000_000 // 18, "reflectivity": rng.randrange(256), "ring": ring,
                           "range": int(round(r * 1000))})
    return stamp_ns, cloud("left", stamp_ns, 16, 18, 32, fields, points, True)


def right_cloud(rng, k):
    """Hesai style: stamp at sweep START, timestamp float64 absolute s, point_step 32, a few NaN points."""
    stamp_ns = T0_NS + 50_000_000 + k * 200_000_000
    fields = [pc.field("x", 0, "f"), pc.field("y", 4, "f"), pc.field("z", 8, "f"), pc.field("intensity", 12, "f"),
              pc.field("timestamp", 16, "d"), pc.field("ring", 24, "H")]
    samples = sorted((rng.random(), rng.randrange(16)) for _ in range(300))
    nan_rows = set(rng.sample(range(1, 300), 7))
    points = []
    for i, (frac, ring) in enumerate(samples):
        x, y, z, _ = ray(rng, "right", 2 * math.pi * frac, elevation(ring))
        if i in nan_rows:
            x = y = z = float("nan")
        points.append({"x": f32(x), "y": f32(y), "z": f32(z), "intensity": f32(rng.uniform(0, 255)),
                       "timestamp": (stamp_ns + int(frac * 200_000_000)) / 1e9, "ring": ring})
    return stamp_ns, cloud("right", stamp_ns, 1, 300, 32, fields, points, False)


def cloud(frame, stamp_ns, height, width, point_step, fields, points, dense):
    return {"header": {"stamp": stamp(stamp_ns), "frame_id": frame}, "height": height, "width": width,
            "fields": fields, "is_bigendian": False, "point_step": point_step, "row_step": width * point_step,
            "data": pc.pack_points(fields, point_step, points), "is_dense": dense}


def imu(k):
    stamp_ns = T0_NS + k * 10_000_000
    a = 0.01 * math.sin(0.1 * k)
    q = quat_rpy(math.degrees(a), 0.0, 0.0)
    return stamp_ns, {"header": {"stamp": stamp(stamp_ns), "frame_id": "imu"},
                      "orientation": dict(zip("xyzw", q)), "orientation_covariance": [0.0] * 9,
                      "angular_velocity": {"x": 0.001 * k, "y": -0.002, "z": 0.0005},
                      "angular_velocity_covariance": [1e-4, 0, 0, 0, 1e-4, 0, 0, 0, 1e-4],
                      "linear_acceleration": {"x": 0.02, "y": -0.01, "z": 9.81},
                      "linear_acceleration_covariance": [1e-2, 0, 0, 0, 1e-2, 0, 0, 0, 1e-2]}


def tf_static():
    transforms = []
    for child, (t, q) in MOUNTS.items():
        transforms.append({"header": {"stamp": stamp(T0_NS), "frame_id": "base_link"}, "child_frame_id": child,
                           "transform": {"translation": dict(zip("xyz", t)), "rotation": dict(zip("xyzw", q))}})
    return T0_NS, {"transforms": transforms}


def messages():
    """All messages as dicts {topic, type, receive_ns, stamp_ns, message}, sorted by receive time (ties: TOPIC_ORDER)."""
    rng = random.Random(SEED)
    out = []

    def add(topic, made):
        out.append({"topic": topic, "type": TYPES[topic], "stamp_ns": made[0],
                    "receive_ns": made[0] + RECEIVE_DELAY_NS, "message": made[1]})
    add("/tf_static", tf_static())
    for k in range(200):
        add("/imu", imu(k))
    for k in range(20):
        add("/top/points", top_cloud(rng, k))
    for k in range(20):
        add("/left/points", left_cloud(rng, k))
    for k in range(10):
        add("/right/points", right_cloud(rng, k))
    out.sort(key=lambda m: (m["receive_ns"], TOPIC_ORDER.index(m["topic"])))
    return out


def big_endian_copy(entry):
    """The same message with PointCloud2 point bytes big-endian and is_bigendian true (other types unchanged)."""
    if entry["type"] != "sensor_msgs/msg/PointCloud2":
        return entry
    msg = dict(entry["message"])
    msg["data"] = pc.byteswap_points(msg)
    msg["is_bigendian"] = True
    return dict(entry, message=msg)
