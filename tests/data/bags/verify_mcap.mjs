// Reads MCAP files with @mcap/core (not mcap_io.py) to check the Python MCAP writer and the fixtures.
//   node verify_mcap.mjs FILE.mcap ...
// For each file: the stream reader (validateCrcs) walks every record; if the file has a summary the
// indexed reader (validateCrcs) reads all messages through the chunk and message indexes; both must see
// the same messages. Every message's CDR header (stamp, frame_id) is decoded with @foxglove/cdr; per topic
// it prints the count and the first header stamp. Exits 1 on any error.
import { readFileSync } from "node:fs";
import { McapIndexedReader, McapStreamReader, TempBuffer } from "@mcap/core";
import { loadDecompressHandlers } from "@mcap/support";
import { CdrReader } from "@foxglove/cdr";

const decompressHandlers = await loadDecompressHandlers();

function firstStamp(schemaName, data) {
  const r = new CdrReader(data);
  if (schemaName === "tf2_msgs/msg/TFMessage") {
    if (r.sequenceLength() === 0) return "-";
  }
  const sec = r.int32();
  const nanosec = r.uint32();
  return `${sec}.${String(nanosec).padStart(9, "0")} ${r.string()}`;
}

async function verify(path) {
  const bytes = new Uint8Array(readFileSync(path));
  const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  stream.append(bytes);
  const schemas = new Map();
  const channels = new Map();
  const streamed = [];
  let footer;
  for (let rec; (rec = stream.nextRecord()); ) {
    if (rec.type === "Schema") schemas.set(rec.id, rec);
    if (rec.type === "Channel") channels.set(rec.id, rec);
    if (rec.type === "Message") streamed.push(`${rec.channelId}:${rec.sequence}:${rec.logTime}`);
    if (rec.type === "Footer") footer = rec;
  }
  if (!stream.done()) throw new Error("stream reader did not reach the end magic");
  const perTopic = new Map();
  let indexed = "no summary";
  if (footer && footer.summaryStart !== 0n) {
    const buffer = new TempBuffer(bytes);
    const reader = await McapIndexedReader.Initialize({ readable: buffer, decompressHandlers });
    const seen = [];
    for await (const m of reader.readMessages({ validateCrcs: true })) {
      seen.push(`${m.channelId}:${m.sequence}:${m.logTime}`);
      const channel = reader.channelsById.get(m.channelId);
      const schema = reader.schemasById.get(channel.schemaId);
      const entry = perTopic.get(channel.topic) ?? { count: 0, first: firstStamp(schema.name, m.data), type: schema.name };
      entry.count += 1;
      perTopic.set(channel.topic, entry);
    }
    const same = [...seen].sort().join() === [...streamed].sort().join();
    if (!same) throw new Error("indexed and stream readers see different messages");
    indexed = `indexed reader: ${seen.length} messages, ${reader.chunkIndexes.length} chunks, statistics ${reader.statistics?.messageCount}`;
  }
  console.log(`ok  ${path}: stream reader ${streamed.length} messages, ${schemas.size} schemas, ${channels.size} channels; ${indexed}`);
  for (const [topic, e] of perTopic) console.log(`      ${topic} ${e.type} x${e.count}, first stamp ${e.first}`);
}

let failed = 0;
for (const path of process.argv.slice(2)) {
  try {
    await verify(path);
  } catch (error) {
    failed += 1;
    console.log(`FAIL ${path}: ${error.message}`);
  }
}
process.exit(failed ? 1 : 0);
