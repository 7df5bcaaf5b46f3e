"""ROS 2 CDR (XCDR1 plain) encoder and decoder for the few message types the fixtures use.

Implements the OMG CDR rules as ROS 2 (Fast-CDR, rmw) applies them:
  * a 4-byte encapsulation header: 00 01 = CDR little-endian, 00 00 = CDR big-endian, then 2 option bytes 00 00;
  * each primitive is aligned to its own size (1, 2, 4, 8), offsets counted from the end of that header;
  * string = uint32 length including the terminating NUL, the bytes, the NUL;
  * sequence (T[]) = uint32 element count, then the elements; a fixed array (T[N]) has no count;
  * bool and uint8 take one byte; nested messages are laid out inline, field by field.
Only the Python standard library is used.
"""
import struct

PRIMITIVES = {  # ROS 2 type -> (struct code, size)
    "bool": ("?", 1), "int8": ("b", 1), "uint8": ("B", 1), "byte": ("B", 1), "char": ("B", 1),
    "int16": ("h", 2), "uint16": ("H", 2), "int32": ("i", 4), "uint32": ("I", 4),
    "int64": ("q", 8), "uint64": ("Q", 8), "float32": ("f", 4), "float64": ("d", 8),
}

# Field lists (name, type) of the ROS 2 messages used, in declaration order (ROS 2 Humble definitions).
MESSAGES = {
    "builtin_interfaces/Time": [("sec", "int32"), ("nanosec", "uint32")],
    "std_msgs/Header": [("stamp", "builtin_interfaces/Time"), ("frame_id", "string")],
    "sensor_msgs/PointField": [("name", "string"), ("offset", "uint32"), ("datatype", "uint8"), ("count", "uint32")],
    "sensor_msgs/PointCloud2": [
        ("header", "std_msgs/Header"), ("height", "uint32"), ("width", "uint32"),
        ("fields", "sensor_msgs/PointField[]"), ("is_bigendian", "bool"), ("point_step", "uint32"),
        ("row_step", "uint32"), ("data", "uint8[]"), ("is_dense", "bool")],
    "geometry_msgs/Vector3": [("x", "float64"), ("y", "float64"), ("z", "float64")],
    "geometry_msgs/Quaternion": [("x", "float64"), ("y", "float64"), ("z", "float64"), ("w", "float64")],
    "geometry_msgs/Transform": [("translation", "geometry_msgs/Vector3"), ("rotation", "geometry_msgs/Quaternion")],
    "geometry_msgs/TransformStamped": [
        ("header", "std_msgs/Header"), ("child_frame_id", "string"), ("transform", "geometry_msgs/Transform")],
    "tf2_msgs/TFMessage": [("transforms", "geometry_msgs/TransformStamped[]")],
    "sensor_msgs/Imu": [
        ("header", "std_msgs/Header"), ("orientation", "geometry_msgs/Quaternion"),
        ("orientation_covariance", "float64[9]"), ("angular_velocity", "geometry_msgs/Vector3"),
        ("angular_velocity_covariance", "float64[9]"), ("linear_acceleration", "geometry_msgs/Vector3"),
        ("linear_acceleration_covariance", "float64[9]")],
}


def short_type(type_name):
    """'sensor_msgs/msg/PointCloud2' -> 'sensor_msgs/PointCloud2' (the key of MESSAGES)."""
    return type_name.replace("/msg/", "/")


def _split_array(type_name):
    """'T[]' -> ('T', None, True); 'T[9]' -> ('T', 9, True); 'T' -> ('T', None, False)."""
    if not type_name.endswith("]"):
        return type_name, None, False
    base, size = type_name[:-1].split("[")
    return base, (int(size) if size else None), True


class CdrWriter:
    """Appends CDR-encoded values to a buffer that starts with the encapsulation header."""

    def __init__(self, big_endian=False):
        self.order = ">" if big_endian else "<"
        self.buf = bytearray(b"\x00\x00\x00\x00" if big_endian else b"\x00\x01\x00\x00")

    def _align(self, size):
        pad = (-(len(self.buf) - 4)) % size
        self.buf += b"\x00" * pad

    def primitive(self, type_name, value):
        code, size = PRIMITIVES[type_name]
        self._align(size)
        self.buf += struct.pack(self.order + code, value)

    def string(self, text):
        raw = text.encode("utf-8") + b"\x00"
        self.primitive("uint32", len(raw))
        self.buf += raw

    def value(self, type_name, value):
        base, size, is_array = _split_array(type_name)
        if is_array:
            if size is None:
                self.primitive("uint32", len(value))
            elif len(value) != size:
                raise ValueError(f"{type_name}: expected {size} elements, got {len(value)}")
            if base in ("uint8", "byte", "char"):
                self.buf += bytes(value)
            else:
                for element in value:
                    self.value(base, element)
        elif type_name in PRIMITIVES:
            self.primitive(type_name, value)
        elif type_name == "string":
            self.string(value)
        else:
            for field, field_type in MESSAGES[type_name]:
                self.value(field_type, value[field])


class CdrReader:
    """Reads CDR values back; the byte order comes from the encapsulation header."""

    def __init__(self, data):
        self.data = bytes(data)
        if len(self.data) < 4 or self.data[0] != 0 or self.data[1] not in (0, 1):
            raise ValueError(f"not a plain CDR payload (encapsulation header {self.data[:4].hex()})")
        self.big_endian = self.data[1] == 0
        self.order = ">" if self.big_endian else "<"
        self.pos = 4

    def _align(self, size):
        self.pos += (-(self.pos - 4)) % size

    def _take(self, count):
        if self.pos + count > len(self.data):
            raise ValueError(f"CDR payload ends at {len(self.data)}, needed {self.pos + count}")
        chunk = self.data[self.pos:self.pos + count]
        self.pos += count
        return chunk

    def primitive(self, type_name):
        code, size = PRIMITIVES[type_name]
        self._align(size)
        return struct.unpack(self.order + code, self._take(size))[0]

    def string(self):
        length = self.primitive("uint32")
        raw = self._take(length)
        if length == 0 or raw[-1] != 0:
            raise ValueError("CDR string is not NUL-terminated")
        return raw[:-1].decode("utf-8")

    def value(self, type_name):
        base, size, is_array = _split_array(type_name)
        if is_array:
            count = self.primitive("uint32") if size is None else size
            if base in ("uint8", "byte", "char"):
                return self._take(count)
            return [self.value(base) for _ in range(count)]
        if type_name in PRIMITIVES:
            return self.primitive(type_name)
        if type_name == "string":
            return self.string()
        return {field: self.value(field_type) for field, field_type in MESSAGES[type_name]}


def encode(type_name, message, big_endian=False):
    """Serialize a message (nested dicts, bytes for uint8[]) of ROS 2 type type_name into CDR bytes."""
    writer = CdrWriter(big_endian)
    writer.value(short_type(type_name), message)
    return bytes(writer.buf)


def decode(type_name, data):
    """Deserialize CDR bytes of ROS 2 type type_name into nested dicts; also returns whether it was big-endian."""
    reader = CdrReader(data)
    message = reader.value(short_type(type_name))
    if len(data) - reader.pos >= 4:
        raise ValueError(f"{len(data) - reader.pos} bytes left after a {type_name}")
    return message, reader.big_endian


# ros2msg schema texts (the encoding rosbag2's MCAP writer stores): the type's .msg, then each dependency
# after a line of 80 '=' and 'MSG: package/Type'.
_SEP = "=" * 80 + "\n"
_TIME = "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"
_HEADER = "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n"
_POINTFIELD = ("MSG: sensor_msgs/PointField\nuint8 INT8    = 1\nuint8 UINT8   = 2\nuint8 INT16   = 3\n"
               "uint8 UINT16  = 4\nuint8 INT32   = 5\nuint8 UINT32  = 6\nuint8 FLOAT32 = 7\nuint8 FLOAT64 = 8\n"
               "string name\nuint32 offset\nuint8  datatype\nuint32 count\n")
_VECTOR3 = "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n"
_QUAT = "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n"
ROS2MSG = {
    "sensor_msgs/msg/PointCloud2": "std_msgs/Header header\nuint32 height\nuint32 width\nPointField[] fields\n"
    "bool    is_bigendian\nuint32  point_step\nuint32  row_step\nuint8[] data\nbool is_dense\n"
    + _SEP + _HEADER + _SEP + _TIME + _SEP + _POINTFIELD,
    "sensor_msgs/msg/Imu": "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\n"
    "float64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\n"
    "float64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\n"
    "float64[9] linear_acceleration_covariance\n" + _SEP + _HEADER + _SEP + _TIME + _SEP + _QUAT + _SEP + _VECTOR3,
    "tf2_msgs/msg/TFMessage": "geometry_msgs/TransformStamped[] transforms\n" + _SEP
    + "MSG: geometry_msgs/TransformStamped\nstd_msgs/Header header\nstring child_frame_id\nTransform transform\n"
    + _SEP + _HEADER + _SEP + _TIME + _SEP
    + "MSG: geometry_msgs/Transform\nVector3 translation\nQuaternion rotation\n" + _SEP + _VECTOR3 + _SEP + _QUAT,
}
