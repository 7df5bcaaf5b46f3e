// One-off generator of the MCAP fixtures (run by hand; CI never runs it).
//
// Reads build/scene.json (written by make_fixtures.py: the same messages as every other fixture) and
// writes mcap_none / mcap_zstd / mcap_lz4 / mcap_nosummary / mcap_bigendian.mcap with @mcap/core's
// McapWriter. The CDR payloads are encoded here with @foxglove/cdr's CdrWriter (independent of the
// Python encoder in ros2_cdr.py), field by field in ROS 2 Humble message order.
//   cd tests/data/bags && /usr/bin/python3 make_fixtures.py && npm ci && node make_mcap_fixtures.mjs
import { readFileSync, writeFileSync } from "node:fs";
import { McapWriter, TempBuffer } from "@mcap/core";
import { CdrWriter, EncapsulationKind } from "@foxglove/cdr";
import zstd from "@foxglove/wasm-zstd";
import lz4js from "lz4js";

const here = new URL(".", import.meta.url).pathname;
const scene = JSON.parse(readFileSync(here + "build/scene.json", "utf8"));
const bytes = (b64) => Uint8Array.from(Buffer.from(b64.base64, "base64"));

function header(w, h) {
  w.int32(h.stamp.sec);
  w.uint32(h.stamp.nanosec);
  w.string(h.frame_id);
}
const vector3 = (w, v) => { w.float64(v.x); w.float64(v.y); w.float64(v.z); };
const quaternion = (w, q) => { w.float64(q.x); w.float64(q.y); w.float64(q.z); w.float64(q.w); };

const encoders = {
  "sensor_msgs/msg/PointCloud2": (w, m, data) => {
    header(w, m.header);
    w.uint32(m.height);
    w.uint32(m.width);
    w.sequenceLength(m.fields.length);
    for (const f of m.fields) {
      w.string(f.name);
      w.uint32(f.offset);
      w.uint8(f.datatype);
      w.uint32(f.count);
    }
    w.uint8(m.is_bigendian ? 1 : 0);
    w.uint32(m.point_step);
    w.uint32(m.row_step);
    w.sequenceLength(data.length);
    w.uint8Array(data, false);
    w.uint8(m.is_dense ? 1 : 0);
  },
  "sensor_msgs/msg/Imu": (w, m) => {
    header(w, m.header);
    quaternion(w, m.orientation);
    w.float64Array(m.orientation_covariance, false);
    vector3(w, m.angular_velocity);
    w.float64Array(m.angular_velocity_covariance, false);
    vector3(w, m.linear_acceleration);
    w.float64Array(m.linear_acceleration_covariance, false);
  },
  "tf2_msgs/msg/TFMessage": (w, m) => {
    w.sequenceLength(m.transforms.length);
    for (const t of m.transforms) {
      header(w, t.header);
      w.string(t.child_frame_id);
      vector3(w, t.transform.translation);
      quaternion(w, t.transform.rotation);
    }
  },
};

function encode(entry, bigEndian) {
  const w = new CdrWriter({ kind: bigEndian ? EncapsulationKind.CDR_BE : EncapsulationKind.CDR_LE });
  const m = { ...entry.message };
  let data;
  if (entry.type === "sensor_msgs/msg/PointCloud2") {
    data = bytes(bigEndian ? entry.big_endian_data : m.data);
    m.is_bigendian = bigEndian;
  }
  encoders[entry.type](w, m, data);
  return w.data.slice();
}

const compressors = {
  none: undefined,
  zstd: (chunk) => ({ compression: "zstd", compressedData: zstd.compress(chunk, 19) }),
  lz4: (chunk) => ({ compression: "lz4", compressedData: Uint8Array.from(lz4js.compress(chunk)) }),
};

async function writeFixture(name, compression) {
  const summary = name !== "mcap_nosummary.mcap";
  const bigEndian = name === "mcap_bigendian.mcap";
  const buffer = new TempBuffer();
  const writer = new McapWriter({
    writable: buffer, useChunks: true, chunkSize: 64 * 1024, compressChunk: compressors[compression],
    useStatistics: summary, useSummaryOffsets: summary, useChunkIndex: summary, useMessageIndex: summary,
    useAttachmentIndex: summary, useMetadataIndex: summary, repeatSchemas: summary, repeatChannels: summary,
  });
  await writer.start({ profile: "ros2", library: "mlidar make_mcap_fixtures.mjs (@mcap/core 2.2.2)" });
  const channels = {};
  const sequences = {};
  for (const entry of scene.messages) {
    if (!(entry.topic in channels)) {
      const schemaId = await writer.registerSchema({
        name: entry.type, encoding: "ros2msg", data: new TextEncoder().encode(scene.schemas[entry.type]),
      });
      channels[entry.topic] = await writer.registerChannel({
        topic: entry.topic, schemaId, messageEncoding: "cdr", metadata: new Map(),
      });
      sequences[entry.topic] = 0;
    }
    const time = BigInt(entry.receive_ns);
    await writer.addMessage({
      channelId: channels[entry.topic], sequence: sequences[entry.topic]++, logTime: time, publishTime: time,
      data: encode(entry, bigEndian),
    });
  }
  await writer.end();
  writeFileSync(here + name, buffer.get());
  console.log(`${name}: ${buffer.get().length} bytes`);
}

await zstd.isLoaded;
for (const [name, compression] of Object.entries(scene.fixtures)) await writeFixture(name, compression);
