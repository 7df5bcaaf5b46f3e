"""Reader for binary PCD files (PCL's PCD v0.7 format, pointclouds.org 'The PCD (Point Cloud Data) file format').

Header lines (# comments allowed): VERSION, FIELDS, SIZE, TYPE (I signed, U unsigned, F float), COUNT,
WIDTH, HEIGHT, VIEWPOINT, POINTS, then DATA. Only 'DATA binary' is read: the points follow the DATA line
as packed little-endian records of the fields in order (no padding). 'ascii' and 'binary_compressed'
are refused with a clear error. Fields named '_' are padding and are not reported as fields.
"""

# (TYPE, SIZE) -> sensor_msgs/PointField datatype
POINTFIELD_TYPE = {("I", 1): 1, ("U", 1): 2, ("I", 2): 3, ("U", 2): 4, ("I", 4): 5, ("U", 4): 6, ("F", 4): 7, ("F", 8): 8}
REQUIRED = ("FIELDS", "SIZE", "TYPE", "WIDTH", "HEIGHT", "POINTS", "DATA")


class PcdError(ValueError):
    pass


def read_pcd(path):
    """{'fields': [{name, offset, datatype, count}], 'width', 'height', 'point_step', 'data': bytes} of a binary PCD."""
    with open(path, "rb") as f:
        raw = f.read()
    header, pos = {}, 0
    while "DATA" not in header:
        end = raw.find(b"\n", pos)
        if end < 0:
            raise PcdError(f"{path}: PCD header has no DATA line")
        line = raw[pos:end].decode("ascii", "replace").strip()
        pos = end + 1
        if not line or line.startswith("#"):
            continue
        key, _, value = line.partition(" ")
        header[key.upper()] = value.split()
    for key in REQUIRED:
        if key not in header:
            raise PcdError(f"{path}: PCD header has no {key} line")
    mode = header["DATA"][0].lower() if header["DATA"] else ""
    if mode != "binary":
        raise PcdError(f"{path}: PCD 'DATA {mode}' is not supported (only DATA binary; convert with "
                       "'mlidar convert IN OUT.pcd --encoding binary')")
    names, sizes, types = header["FIELDS"], header["SIZE"], header["TYPE"]
    counts = header.get("COUNT", ["1"] * len(names))
    if not len(names) == len(sizes) == len(types) == len(counts):
        raise PcdError(f"{path}: FIELDS, SIZE, TYPE and COUNT have different lengths")
    fields, offset = [], 0
    for name, size, kind, count in zip(names, sizes, types, counts):
        size, count = int(size), int(count)
        if name != "_":
            if (kind.upper(), size) not in POINTFIELD_TYPE:
                raise PcdError(f"{path}: field {name}: TYPE {kind} SIZE {size} has no PointField datatype")
            fields.append({"name": name, "offset": offset, "datatype": POINTFIELD_TYPE[(kind.upper(), size)], "count": count})
        offset += size * count
    width, height, points = int(header["WIDTH"][0]), int(header["HEIGHT"][0]), int(header["POINTS"][0])
    if width * height != points:
        raise PcdError(f"{path}: WIDTH x HEIGHT = {width * height} but POINTS = {points}")
    data = raw[pos:pos + points * offset]
    if len(data) != points * offset:
        raise PcdError(f"{path}: {points} points of {offset} bytes need {points * offset} data bytes, the file has {len(data)}")
    return {"fields": fields, "width": width, "height": height, "point_step": offset, "data": data}
