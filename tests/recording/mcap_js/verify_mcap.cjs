// Reads an MCAP file with the reference TypeScript library (@mcap/core + @mcap/nodejs): the whole file as a
// stream with CRC checks, then through its summary (indexed reader), and decodes every message with
// @foxglove/rosmsg2-serialization from the schema embedded in the file. Prints one JSON line (per topic: type,
// count, durability, first decoded message's key fields); exits 1 with the reason on any failure.
const fs = require("fs");
const { McapIndexedReader, McapStreamReader } = require("@mcap/core");
const { FileHandleReadable } = require("@mcap/nodejs");
const { parse } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");
const zstd = require("@foxglove/wasm-zstd");
const lz4mod = require("@foxglove/wasm-lz4");
const lz4 = lz4mod.default ?? lz4mod;

function fail(why) {
  console.error("verify_mcap: FAIL: " + why);
  process.exit(1);
}

async function main() {
  const path = process.argv[2];
  await zstd.isLoaded;
  await lz4.isLoaded;
  const decompressHandlers = {
    zstd: (data, size) => zstd.decompress(data, Number(size)),
    lz4: (data, size) => lz4(data, Number(size)),
  };
  // 1. The stream reader over every byte, CRCs validated.
  const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true, includeChunks: false });
  stream.append(fs.readFileSync(path));
  const kinds = {};
  let streamed = 0, footer = false;
  for (let r; (r = stream.nextRecord()); ) {
    kinds[r.type] = (kinds[r.type] ?? 0) + 1;
    if (r.type === "Message") streamed++;
    if (r.type === "Footer") footer = true;
  }
  if (!stream.done()) fail("the stream reader did not reach the end of the file");
  if (!footer) fail("no footer");
  // 2. The indexed reader: summary, statistics, chunk indexes; every message decoded.
  const handle = await fs.promises.open(path, "r");
  const reader = await McapIndexedReader.Initialize({ readable: new FileHandleReadable(handle), decompressHandlers });
  if (reader.header.profile !== "ros2") fail("profile " + reader.header.profile);
  if (!reader.statistics) fail("no statistics in the summary");
  if (reader.chunkIndexes.length === 0) fail("no chunk indexes");
  const readers = new Map();
  const topics = {};
  let decoded = 0;
  for await (const m of reader.readMessages()) {
    const channel = reader.channelsById.get(m.channelId);
    const schema = reader.schemasById.get(channel.schemaId);
    if (channel.messageEncoding !== "cdr") fail(channel.topic + ": encoding " + channel.messageEncoding);
    if (schema.encoding !== "ros2msg") fail(channel.topic + ": schema encoding " + schema.encoding);
    if (!readers.has(schema.id)) {
      const text = new TextDecoder().decode(schema.data);
      readers.set(schema.id, new MessageReader(parse(text, { ros2: true })));
    }
    const msg = readers.get(schema.id).readMessage(m.data);
    const t = (topics[channel.topic] ??= { type: schema.name, count: 0, qos: channel.metadata.get("offered_qos_profiles") ?? "" });
    t.count++;
    decoded++;
    const name = schema.name;
    if (name === "sensor_msgs/msg/Image" && msg.data.length !== msg.step * msg.height) fail(channel.topic + ": data length");
    if (name === "sensor_msgs/msg/PointCloud2" && msg.data.length !== msg.row_step * msg.height) fail(channel.topic + ": cloud length");
    if (name === "nav_msgs/msg/OccupancyGrid" && msg.data.length !== msg.info.width * msg.info.height) fail(channel.topic + ": grid length");
    if (name === "nav_msgs/msg/Path")
      for (const p of msg.poses)
        if (p.header.frame_id !== msg.header.frame_id || p.header.stamp.sec !== msg.header.stamp.sec ||
            p.header.stamp.nanosec !== msg.header.stamp.nanosec)
          fail(channel.topic + ": a pose's header differs from the path's");
    if (msg.header && BigInt(msg.header.stamp.sec) * 1000000000n + BigInt(msg.header.stamp.nanosec) !== m.logTime)
      fail(channel.topic + ": header stamp differs from the log time");
    if (t.count === 1) {
      if (name === "sensor_msgs/msg/Image") t.first = { width: msg.width, height: msg.height, encoding: msg.encoding, frame_id: msg.header.frame_id };
      if (name === "sensor_msgs/msg/CameraInfo") t.first = { k: Array.from(msg.k), frame_id: msg.header.frame_id };
      if (name === "tf2_msgs/msg/TFMessage") t.first = { edges: msg.transforms.map((x) => x.header.frame_id + "->" + x.child_frame_id) };
      if (name === "sensor_msgs/msg/PointCloud2") t.first = { fields: msg.fields.map((f) => f.name).join(""), point_step: msg.point_step };
      if (name === "nav_msgs/msg/Path")
        t.first = { frame_id: msg.header.frame_id, poses: msg.poses.map((p) => [p.pose.position.x, p.pose.position.y,
          p.pose.position.z, p.pose.orientation.x, p.pose.orientation.y, p.pose.orientation.z, p.pose.orientation.w]) };
      if (name === "geometry_msgs/msg/Twist") t.first = { linear: [msg.linear.x, msg.linear.y, msg.linear.z],
        angular: [msg.angular.x, msg.angular.y, msg.angular.z] };
      if (name === "nav_msgs/msg/OccupancyGrid") t.first = { frame_id: msg.header.frame_id, width: msg.info.width,
        height: msg.info.height, resolution: msg.info.resolution, data: msg.data.length <= 4096 ? Array.from(msg.data) : [] };
    }
  }
  await handle.close();
  const stats = reader.statistics;
  if (Number(stats.messageCount) !== decoded) fail("statistics say " + stats.messageCount + " messages, decoded " + decoded);
  if (streamed !== decoded) fail("stream reader saw " + streamed + " messages, indexed reader " + decoded);
  for (const [name, t] of Object.entries(topics)) {
    t.durability = /durability: (\w+)/.exec(t.qos)?.[1] ?? "";
    delete t.qos;
  }
  console.log(JSON.stringify({ messages: decoded, chunks: reader.chunkIndexes.length, records: kinds, topics }));
}
main().catch((e) => fail(e && e.stack ? e.stack : String(e)));
