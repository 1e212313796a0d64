// Rewrites one of our rosbag2 exports (an MCAP file) as ROS 2 itself writes bags, with the reference library
// (@mcap/core). Usage: ros2_variants.cjs IN.mcap MSG_DIR OUT_DIR. Writes to OUT_DIR:
//  - jazzy.mcap: the same channels and messages, each schema the text `ros2 bag record` embeds: the type's own .msg
//    file from MSG_DIR (<pkg>/msg/<Type>.msg: comments, constants, defaults and all), then for each dependency, in
//    the order of rosbag2's LocalMessageDefinitionSource (a depth-first walk, each type's dependencies sorted, each
//    type once), "\n" + 80 '=' + "\nMSG: pkg/Type\n" + its text. A type whose definition MSG_DIR lacks in full
//    (nav_msgs/msg/Odometry, rosgraph_msgs/msg/Clock: not in ../shared/ros2_msgs) keeps the export's own schema.
//  - skip.mcap: jazzy.mcap plus, one message after each depth image, every kind of topic a replay must list and
//    skip (skipTopics below: service events, action topics, JSON, ros2idl, protobuf, no schema, a ros2msg schema
//    that does not parse, a pkg/idl/Type);
//  - dump.json + dump.bin for write_db3_variants.py: the topics (type, QoS, the jazzy definition and its encoding)
//    with the skipped ones, and every message as u16 topic index, u64 log time (ns), u32 size, bytes.
const fs = require("fs");
const path = require("path");
const { McapStreamReader, McapWriter } = require("@mcap/core");
const { FileHandleWritable } = require("@mcap/nodejs");
const zstd = require("@foxglove/wasm-zstd");
const lz4mod = require("@foxglove/wasm-lz4");
const lz4 = lz4mod.default ?? lz4mod;

const RULE = "=".repeat(80);
const PRIMITIVES = new Set(["bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32",
  "uint32", "int64", "uint64", "string"]);
// A field's type at the start of a line (rosbag2 finds dependencies so: "pkg/Type" in "pkg/Type[] name").
const FIELD_TYPE = /(?:^|\n)\s*([a-zA-Z0-9_/]+)(?:\[[^\]]*\])?\s+/g;

class MissingDefinition extends Error {}

// The .msg text of "pkg/Type" or "pkg/msg/Type".
function msgText(msgDir, type) {
  const parts = type.split("/");
  const file = path.join(msgDir, parts[0], "msg", parts[parts.length - 1] + ".msg");
  if (!fs.existsSync(file)) throw new MissingDefinition(type);
  return fs.readFileSync(file, "utf8");
}

function dependencies(text, pkg) {
  const found = new Set();
  for (const m of text.matchAll(FIELD_TYPE)) {
    if (PRIMITIVES.has(m[1])) continue;
    found.add(m[1].includes("/") ? m[1] : pkg + "/" + m[1]);
  }
  return [...found].sort();
}

// The complete ros2msg definition of `root` as rosbag2 writes it, or null when MSG_DIR lacks a type of it.
function ros2Definition(msgDir, root) {
  const seen = new Set();
  const walk = (type) => {
    const text = msgText(msgDir, type);
    let out = text;
    for (const dep of dependencies(text, type.split("/")[0])) {
      if (seen.has(dep)) continue;
      seen.add(dep);
      out += "\n" + RULE + "\nMSG: " + dep + "\n" + walk(dep);
    }
    return out;
  };
  try {
    return walk(root);
  } catch (e) {
    if (e instanceof MissingDefinition) return null;
    throw e;
  }
}

const cdr = (...bytes) => new Uint8Array([0, 1, 0, 0, ...bytes]);
const utf8 = (s) => new TextEncoder().encode(s);
// Topics a replay does not use, as ROS 2 tools record them. schemaEncoding null: a channel without a schema.
const skipTopics = [
  { topic: "/add_two_ints/_service_event", type: "example_interfaces/srv/AddTwoInts_Event", schemaEncoding: "ros2msg",
    schema: "int64 a\nint64 b\n---\nint64 sum\n", messageEncoding: "cdr", data: cdr(1, 0, 0, 0, 0, 0, 0, 0) },
  { topic: "/fibonacci/_action/feedback", type: "example_interfaces/action/Fibonacci_FeedbackMessage",
    schemaEncoding: "ros2msg", schema: "unique_identifier_msgs/UUID goal_id\nFibonacci_Feedback feedback\n\n" + RULE +
      "\nMSG: unique_identifier_msgs/UUID\n# A universally unique identifier (UUID).\nuint8[16] uuid\n\n" + RULE +
      "\nMSG: example_interfaces/Fibonacci_Feedback\nint32[] sequence\n",
    messageEncoding: "cdr", data: cdr(...new Array(16).fill(7), 1, 0, 0, 0, 5, 0, 0, 0) },
  { topic: "/fibonacci/_action/status", type: "action_msgs/msg/GoalStatusArray", schemaEncoding: "ros2msg",
    schema: "# An array of goal statuses.\nGoalStatus[] status_list\n\n" + RULE + "\nMSG: action_msgs/GoalStatus\n" +
      "int8 STATUS_UNKNOWN   = 0\nint8 STATUS_ACCEPTED  = 1\nint8 STATUS_SUCCEEDED = 4 # done\n\n" +
      "# Goal info (contains ID and timestamp).\nGoalInfo goal_info\nint8 status\n\n" + RULE +
      "\nMSG: action_msgs/GoalInfo\nunique_identifier_msgs/UUID goal_id\nbuiltin_interfaces/Time stamp\n\n" + RULE +
      "\nMSG: unique_identifier_msgs/UUID\nuint8[16] uuid\n\n" + RULE + "\nMSG: builtin_interfaces/Time\n" +
      "int32 sec\nuint32 nanosec\n",
    messageEncoding: "cdr", data: cdr(0, 0, 0, 0) },
  { topic: "/diagnostics_json", type: "my_msgs/msg/Status", schemaEncoding: "jsonschema",
    schema: '{"type": "object", "properties": {"level": {"type": "integer"}}}', messageEncoding: "json",
    data: utf8('{"level": 1}') },
  { topic: "/idl_schema", type: "my_msgs/msg/IdlOnly", schemaEncoding: "ros2idl",
    schema: RULE + "\nIDL: my_msgs/msg/IdlOnly\nmodule my_msgs {\n  module msg {\n    struct IdlOnly {\n" +
      "      int32 value;\n    };\n  };\n};\n", messageEncoding: "cdr", data: cdr(42, 0, 0, 0) },
  { topic: "/proto_log", type: "foxglove.Log", schemaEncoding: "protobuf",
    schema: "\x0a\x0d\x0a\x09Log.proto\x12\x00", messageEncoding: "protobuf", data: new Uint8Array([8, 1, 18, 2, 104, 105]) },
  { topic: "/no_schema", type: "my_msgs/msg/Unknown", schemaEncoding: null, schema: "", messageEncoding: "cdr",
    data: cdr(1, 2, 3, 4) },
  { topic: "/broken_schema", type: "my_msgs/msg/Broken", schemaEncoding: "ros2msg", schema: "%%% not ros2msg\nint32 x\n",
    messageEncoding: "cdr", data: cdr(1, 0, 0, 0) },
  { topic: "/idl_type", type: "my_msgs/idl/Thing", schemaEncoding: "ros2msg", schema: "int32 x\n", messageEncoding: "cdr",
    data: cdr(3, 0, 0, 0) },
];

function readExport(file) {
  const decompressHandlers = {
    zstd: (data, size) => zstd.decompress(data, Number(size)),
    lz4: (data, size) => lz4(data, Number(size)),
  };
  const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  stream.append(fs.readFileSync(file));
  const schemas = new Map(), channels = new Map(), messages = [];
  for (let r; (r = stream.nextRecord()); ) {
    if (r.type === "Schema") schemas.set(r.id, r);
    if (r.type === "Channel") channels.set(r.id, r);
    if (r.type === "Message") messages.push(r);
  }
  return { schemas, channels, messages };
}

async function writeMcap(file, exported, topics, withSkipped) {
  const handle = await fs.promises.open(file, "w");
  const writer = new McapWriter({ writable: new FileHandleWritable(handle), chunkSize: 64 * 1024,
    compressChunk: (data) => ({ compression: "zstd", compressedData: zstd.compress(data, 3) }) });
  await writer.start({ profile: "ros2", library: "ros2_variants.cjs" });
  const ids = new Map();
  for (const t of topics) {
    if (t.skipped && !withSkipped) continue;
    const schemaId = t.schemaEncoding === null ? 0 :
      await writer.registerSchema({ name: t.type, encoding: t.schemaEncoding, data: utf8(t.schema) });
    ids.set(t.topic, await writer.registerChannel({ topic: t.topic, schemaId, messageEncoding: t.messageEncoding,
      metadata: new Map(t.qos ? [["offered_qos_profiles", t.qos]] : []) }));
  }
  let sequence = 0;
  for (const m of exported.messages) {
    const topic = exported.channels.get(m.channelId).topic;
    await writer.addMessage({ channelId: ids.get(topic), sequence: sequence++, logTime: m.logTime,
      publishTime: m.publishTime, data: m.data });
    if (!withSkipped || !topic.endsWith("/depth/image_rect_raw")) continue;
    for (const t of topics.filter((x) => x.skipped))
      await writer.addMessage({ channelId: ids.get(t.topic), sequence: sequence++, logTime: m.logTime,
        publishTime: m.logTime, data: t.data });
  }
  await writer.end();
  await handle.close();
}

function writeDump(outDir, exported, topics) {
  const index = new Map(topics.map((t, i) => [t.topic, i]));
  const parts = [];
  const record = (topic, logTime, data) => {
    const head = Buffer.alloc(14);
    head.writeUInt16LE(index.get(topic), 0);
    head.writeBigUInt64LE(BigInt(logTime), 2);
    head.writeUInt32LE(data.length, 10);
    parts.push(head, Buffer.from(data));
  };
  for (const m of exported.messages) {
    const topic = exported.channels.get(m.channelId).topic;
    record(topic, m.logTime, m.data);
    if (topic.endsWith("/depth/image_rect_raw"))
      for (const t of topics.filter((x) => x.skipped)) record(t.topic, m.logTime, t.data);
  }
  fs.writeFileSync(path.join(outDir, "dump.bin"), Buffer.concat(parts));
  const json = topics.map(({ data, ...t }) => t);
  fs.writeFileSync(path.join(outDir, "dump.json"), JSON.stringify(json, null, 1));
}

async function main() {
  const [input, msgDir, outDir] = process.argv.slice(2);
  await zstd.isLoaded;
  await lz4.isLoaded;
  fs.mkdirSync(outDir, { recursive: true });
  const exported = readExport(input);
  const topics = [];
  for (const channel of exported.channels.values()) {
    const schema = exported.schemas.get(channel.schemaId);
    const text = ros2Definition(msgDir, schema.name);
    topics.push({ topic: channel.topic, type: schema.name, schemaEncoding: "ros2msg", messageEncoding: "cdr",
      schema: text ?? new TextDecoder().decode(schema.data), ros2Text: text !== null,
      qos: channel.metadata.get("offered_qos_profiles") ?? "", skipped: false });
    console.log(`${channel.topic} ${schema.name}: ${text !== null ? "ROS 2's own .msg texts" : "the export's schema (not in " + msgDir + ")"}`);
  }
  for (const t of skipTopics) topics.push({ ...t, qos: "", ros2Text: false, skipped: true });
  await writeMcap(path.join(outDir, "jazzy.mcap"), exported, topics, false);
  await writeMcap(path.join(outDir, "skip.mcap"), exported, topics, true);
  writeDump(outDir, exported, topics);
}
main().catch((e) => { console.error(e); process.exit(1); });
