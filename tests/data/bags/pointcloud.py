"""sensor_msgs/PointCloud2 point layout helpers (ROS sensor_msgs/PointField datatypes 1..8).

Packs and unpacks the point bytes of a PointCloud2 from its fields, and computes the per-message
summary that expected.json records (first point of every field, finite-x count, sum of finite x).
"""
import math
import struct

# PointField.datatype -> (name, struct code, size)
DATATYPES = {1: ("INT8", "b", 1), 2: ("UINT8", "B", 1), 3: ("INT16", "h", 2), 4: ("UINT16", "H", 2),
             5: ("INT32", "i", 4), 6: ("UINT32", "I", 4), 7: ("FLOAT32", "f", 4), 8: ("FLOAT64", "d", 8)}
CODE_TO_DATATYPE = {"b": 1, "B": 2, "h": 3, "H": 4, "i": 5, "I": 6, "f": 7, "d": 8}


def field(name, offset, code):
    """A PointField dict (count 1) from a struct code."""
    return {"name": name, "offset": offset, "datatype": CODE_TO_DATATYPE[code], "count": 1}


def pack_points(fields, point_step, points, big_endian=False):
    """points: list of dicts name -> value; unnamed bytes (padding) are zero."""
    order = ">" if big_endian else "<"
    out = bytearray(point_step * len(points))
    for i, point in enumerate(points):
        for f in fields:
            code = DATATYPES[f["datatype"]][1]
            struct.pack_into(order + code, out, i * point_step + f["offset"], point[f["name"]])
    return bytes(out)


def unpack_point(cloud, index):
    """The field values of point index (row-major over height x width) as a dict."""
    order = ">" if cloud["is_bigendian"] else "<"
    base = index * cloud["point_step"]
    values = {}
    for f in cloud["fields"]:
        code = DATATYPES[f["datatype"]][1]
        values[f["name"]] = struct.unpack_from(order + code, cloud["data"], base + f["offset"])[0]
    return values


def byteswap_points(cloud):
    """The point bytes of cloud with every field's bytes reversed (padding stays in place)."""
    data = bytearray(cloud["data"])
    for i in range(cloud["width"] * cloud["height"]):
        for f in cloud["fields"]:
            size = DATATYPES[f["datatype"]][2]
            start = i * cloud["point_step"] + f["offset"]
            data[start:start + size] = data[start:start + size][::-1]
    return bytes(data)


def json_number(value):
    """Floats that JSON can hold stay numbers; NaN and infinities become strings."""
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    return value


def summary(cloud):
    """The per-message record of expected.json for a decoded PointCloud2 (ROS 1 or ROS 2 dict form)."""
    count = cloud["width"] * cloud["height"]
    if len(cloud["data"]) != cloud["row_step"] * cloud["height"] or cloud["row_step"] != cloud["width"] * cloud["point_step"]:
        raise ValueError("PointCloud2 data size does not match row_step * height")
    finite, total = 0, 0.0
    for i in range(count):
        x = unpack_point(cloud, i)["x"]
        if math.isfinite(x):
            finite += 1
            total += x  # summed in point order, float64
    first = unpack_point(cloud, 0) if count else {}
    return {
        "width": cloud["width"], "height": cloud["height"], "point_step": cloud["point_step"],
        "row_step": cloud["row_step"], "is_bigendian": bool(cloud["is_bigendian"]), "is_dense": bool(cloud["is_dense"]),
        "fields": [{k: f[k] for k in ("name", "offset", "datatype", "count")} for f in cloud["fields"]],
        "first_point": {k: json_number(v) for k, v in first.items()},
        "finite_x_count": finite, "finite_x_sum": total,
    }
