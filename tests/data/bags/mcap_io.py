"""A small MCAP writer and reader (MCAP format spec, mcap.dev/spec, version 0 / magic 0x89 'MCAP0' CR LF).

Records are opcode (uint8), content length (uint64), content; all integers little-endian; strings are
uint32 length + UTF-8; bytes fields are uint32 length + bytes (Chunk records uint64); maps and arrays are
uint32 byte length + entries. The writer puts Schema and Channel records first in the data section, then
Chunk records (compression '', 'zstd' or 'lz4' = LZ4 frame format), each followed by one Message Index
per channel; then Data End (CRC-32 of the data section), a summary (Schema, Channel, Statistics,
Chunk Index groups), Summary Offsets and the Footer (CRC-32 of the summary). Compression uses the
Debian packages python3-zstandard and python3-lz4, imported only when needed.
"""
import struct
import zlib

MAGIC = b"\x89MCAP0\r\n"
OP = {"header": 0x01, "footer": 0x02, "schema": 0x03, "channel": 0x04, "message": 0x05, "chunk": 0x06,
      "message_index": 0x07, "chunk_index": 0x08, "statistics": 0x0B, "summary_offset": 0x0E, "data_end": 0x0F}


def _str(text):
    raw = text.encode("utf-8")
    return struct.pack("<I", len(raw)) + raw


def _map(pairs, key, value):
    body = b"".join(key(k) + value(v) for k, v in pairs)
    return struct.pack("<I", len(body)) + body


def record(opcode, content):
    return struct.pack("<BQ", opcode, len(content)) + content


def compress(data, compression):
    if compression == "":
        return data
    if compression == "zstd":
        import zstandard
        return zstandard.ZstdCompressor(level=3).compress(data)
    if compression == "lz4":
        import lz4.frame
        return lz4.frame.compress(data)
    raise ValueError(f"MCAP chunk compression {compression!r} (use '', 'zstd' or 'lz4')")


def decompress(data, compression, size):
    if compression == "":
        return data
    if compression == "zstd":
        import zstandard
        return zstandard.ZstdDecompressor().decompress(data, max_output_size=size)
    if compression == "lz4":
        import lz4.frame
        return lz4.frame.decompress(data)
    raise ValueError(f"unknown MCAP chunk compression {compression!r}")


class McapWriter:
    """Usage: w = McapWriter(file, 'zstd'); sid = w.schema(...); cid = w.channel(...); w.message(...); w.finish()."""

    def __init__(self, stream, compression="", chunk_size=512 * 1024, profile="ros2", library="mlidar tests"):
        self.out, self.compression, self.chunk_size = stream, compression, chunk_size
        self.pos, self.crc = 0, 0  # bytes written so far and their running CRC-32 (the Data End / summary CRCs)
        self.schemas, self.channels, self.chunk_indexes = [], [], []
        self.counts, self.times = {}, []
        self._chunk, self._index, self._chunk_times = bytearray(), {}, []
        self._emit(MAGIC + record(OP["header"], _str(profile) + _str(library)))

    def _emit(self, data):
        self.pos += len(data)
        self.crc = zlib.crc32(data, self.crc)
        self.out.write(data)

    def schema(self, name, encoding, data):
        sid = len(self.schemas) + 1
        rec = record(OP["schema"], struct.pack("<H", sid) + _str(name) + _str(encoding) + struct.pack("<I", len(data)) + data)
        self.schemas.append(rec)
        self._emit(rec)
        return sid

    def channel(self, topic, schema_id, message_encoding="cdr", metadata=()):
        cid = len(self.channels)
        rec = record(OP["channel"], struct.pack("<HH", cid, schema_id) + _str(topic) + _str(message_encoding)
                     + _map(sorted(metadata), _str, _str))
        self.channels.append(rec)
        self.counts[cid] = 0
        self._emit(rec)
        return cid

    def message(self, channel_id, log_time, publish_time, data):
        sequence = self.counts[channel_id]
        self.counts[channel_id] += 1
        self._index.setdefault(channel_id, []).append((log_time, len(self._chunk)))
        self._chunk += record(OP["message"], struct.pack("<HIQQ", channel_id, sequence, log_time, publish_time) + data)
        self._chunk_times.append(log_time)
        self.times.append(log_time)
        if len(self._chunk) >= self.chunk_size:
            self._flush()

    def _flush(self):
        if not self._chunk:
            return
        raw = bytes(self._chunk)
        packed = compress(raw, self.compression)
        start_time, end_time = min(self._chunk_times), max(self._chunk_times)
        chunk = record(OP["chunk"], struct.pack("<QQQI", start_time, end_time, len(raw), zlib.crc32(raw))
                       + _str(self.compression) + struct.pack("<Q", len(packed)) + packed)
        chunk_start = self.pos
        self._emit(chunk)
        index_start, offsets = self.pos, []
        for cid in sorted(self._index):
            offsets.append((cid, self.pos))
            entries = b"".join(struct.pack("<QQ", t, o) for t, o in self._index[cid])
            self._emit(record(OP["message_index"], struct.pack("<HI", cid, len(entries)) + entries))
        self.chunk_indexes.append(record(OP["chunk_index"], struct.pack("<QQQQ", start_time, end_time, chunk_start, len(chunk))
                                         + _map(offsets, lambda k: struct.pack("<H", k), lambda v: struct.pack("<Q", v))
                                         + struct.pack("<Q", self.pos - index_start) + _str(self.compression)
                                         + struct.pack("<QQ", len(packed), len(raw))))
        self._chunk, self._index, self._chunk_times = bytearray(), {}, []

    def finish(self):
        self._flush()
        self._emit(record(OP["data_end"], struct.pack("<I", self.crc)))
        summary_start, self.crc = self.pos, 0
        stats = struct.pack("<QHIIII", sum(self.counts.values()), len(self.schemas), len(self.channels), 0, 0,
                            len(self.chunk_indexes))
        stats += struct.pack("<QQ", min(self.times, default=0), max(self.times, default=0))
        stats += _map(sorted(self.counts.items()), lambda k: struct.pack("<H", k), lambda v: struct.pack("<Q", v))
        groups = [(OP["schema"], self.schemas), (OP["channel"], self.channels),
                  (OP["statistics"], [record(OP["statistics"], stats)]), (OP["chunk_index"], self.chunk_indexes)]
        placed = []
        for opcode, records in groups:
            if records:
                placed.append((opcode, self.pos, sum(len(r) for r in records)))
                self._emit(b"".join(records))
        offset_start = self.pos
        for opcode, start, length in placed:
            self._emit(record(OP["summary_offset"], struct.pack("<BQQ", opcode, start, length)))
        footer_head = struct.pack("<BQQQ", OP["footer"], 20, summary_start, offset_start)
        crc = zlib.crc32(footer_head, self.crc)  # summary section + footer fields before summary_crc
        self._emit(footer_head + struct.pack("<I", crc) + MAGIC)


class _Cursor:
    def __init__(self, data, pos=0):
        self.data, self.pos = data, pos

    def take(self, fmt):
        values = struct.unpack_from("<" + fmt, self.data, self.pos)
        self.pos += struct.calcsize("<" + fmt)
        return values if len(values) > 1 else values[0]

    def bytes(self, length_fmt="I"):
        n = self.take(length_fmt)
        self.pos += n
        return self.data[self.pos - n:self.pos]

    def string(self):
        return self.bytes().decode("utf-8")


def _records(data, pos, end):
    while pos < end:
        opcode, length = struct.unpack_from("<BQ", data, pos)
        if pos + 9 + length > end:
            raise ValueError(f"record at {pos} (opcode {opcode:#x}) runs past the end")
        yield pos, opcode, data[pos + 9:pos + 9 + length]
        pos += 9 + length


def read_mcap(path):
    """Parse a whole MCAP file; check every CRC and, if there is a summary, that it agrees with the data.

    Returns {profile, schemas {id: (name, encoding, text)}, channels {id: (topic, schema_id, encoding)},
    messages [(channel_id, sequence, log_time, publish_time, data)] in file order, chunks, has_summary}.
    """
    data = open(path, "rb").read()
    if data[:8] != MAGIC or data[-8:] != MAGIC:
        raise ValueError(f"{path}: MCAP magic missing at the start or end")
    out = {"schemas": {}, "channels": {}, "messages": [], "chunks": {}, "has_summary": False}
    index_entries, summary = {}, None

    def content(opcode, body, chunk_pos=None, at=None):
        c = _Cursor(body)
        if opcode == OP["header"]:
            out["profile"] = c.string()
        elif opcode == OP["schema"]:
            sid = c.take("H")
            out["schemas"][sid] = (c.string(), c.string(), c.bytes().decode("utf-8"))
        elif opcode == OP["channel"]:
            cid, sid = c.take("HH")
            out["channels"][cid] = (c.string(), sid, c.string())
        elif opcode == OP["message"]:
            cid, seq, log_time, pub_time = c.take("HIQQ")
            out["messages"].append((cid, seq, log_time, pub_time, body[c.pos:]))
            if chunk_pos is not None:
                out["chunks"][chunk_pos]["offsets"][(cid, at)] = log_time

    for pos, opcode, body in _records(data, 8, len(data) - 8):
        if opcode == OP["chunk"]:
            c = _Cursor(body)
            start, end, size, crc = c.take("QQQI")
            compression = c.string()
            raw = decompress(c.bytes("Q"), compression, size)
            if len(raw) != size or (crc and zlib.crc32(raw) != crc):
                raise ValueError(f"{path}: chunk at {pos}: size or CRC mismatch")
            out["chunks"][pos] = {"start": start, "end": end, "offsets": {}, "length": 9 + len(body)}
            for at, op, inner in _records(raw, 0, len(raw)):
                content(op, inner, pos, at)
        elif opcode == OP["message_index"]:
            c = _Cursor(body)
            cid, n = c.take("HI")
            index_entries[pos] = {(cid, o): t for t, o in (struct.unpack_from("<QQ", body, c.pos + 16 * i) for i in range(n // 16))}
        elif opcode == OP["data_end"]:
            crc = struct.unpack("<I", body)[0]
            if crc and zlib.crc32(data[:pos]) != crc:
                raise ValueError(f"{path}: Data End CRC mismatch")
        elif opcode == OP["footer"]:
            summary = struct.unpack("<QQI", body)
        elif opcode == OP["statistics"]:
            out["statistics"] = _Cursor(body).take("QHIIIIQQ")
        elif opcode == OP["chunk_index"]:
            c = _Cursor(body)
            _, _, chunk_start, chunk_length = c.take("QQQQ")
            map_len = c.take("I")
            offsets = dict(struct.unpack_from("<HQ", body, c.pos + 10 * i) for i in range(map_len // 10))
            out.setdefault("chunk_index", []).append((chunk_start, chunk_length, offsets))
        else:
            content(opcode, body)
    if summary and summary[0]:
        out["has_summary"] = True
        _check_summary(path, data, out, summary, index_entries)
    return out


def _check_summary(path, data, out, footer, index_entries):
    summary_start, _, crc = footer
    if crc and zlib.crc32(data[summary_start:len(data) - 12]) != crc:
        raise ValueError(f"{path}: summary CRC mismatch")
    if "statistics" in out and out["statistics"][0] != len(out["messages"]):
        raise ValueError(f"{path}: Statistics message_count {out['statistics'][0]} != {len(out['messages'])} messages")
    for chunk_start, chunk_length, offsets in out.get("chunk_index", []):
        chunk = out["chunks"].get(chunk_start)
        if chunk is None or chunk["length"] != chunk_length:
            raise ValueError(f"{path}: Chunk Index points at {chunk_start}, where no chunk of that length is")
        indexed = {}
        for _, index_pos in offsets.items():
            indexed.update(index_entries[index_pos])
        if indexed != chunk["offsets"]:
            raise ValueError(f"{path}: Message Index of the chunk at {chunk_start} does not match its messages")
