// Writes a realsense-ros 4.x-style recording with the reference TypeScript library (@mcap/core, messages by
// @foxglove/rosmsg2-serialization, zstd chunks by @foxglove/wasm-zstd): a static wall 2 m ahead of a camera on
// a robot driving +x at 1 m/s, 5 frames at 10 Hz, 64x48, /tf (odom -> base_link), /tf_static (base_link ->
// camera_link -> camera_depth_optical_frame). Usage: write_mcap.cjs OUT.mcap 16UC1|32FC1 [zstd|none] [MODE]
// MODE: summary (default), nosummary, badschema (an image schema that does not parse), short (images cut short).
const fs = require("fs");
const { McapWriter } = require("@mcap/core");
const { FileHandleWritable } = require("@mcap/nodejs");
const { parse } = require("@foxglove/rosmsg");
const { MessageWriter } = require("@foxglove/rosmsg2-serialization");
const zstd = require("@foxglove/wasm-zstd");

const SEP = "=".repeat(80) + "\n";
const TIME = "int32 sec\nuint32 nanosec\n";
const HEADER = "builtin_interfaces/Time stamp\nstring frame_id\n";
const DEFS = {
  "sensor_msgs/msg/Image": "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\nuint32 step\nuint8[] data\n" +
    SEP + "MSG: std_msgs/Header\n" + HEADER + SEP + "MSG: builtin_interfaces/Time\n" + TIME,
  "sensor_msgs/msg/CameraInfo": "std_msgs/Header header\nuint32 height\nuint32 width\nstring distortion_model\nfloat64[] d\n" +
    "float64[9] k\nfloat64[9] r\nfloat64[12] p\nuint32 binning_x\nuint32 binning_y\nsensor_msgs/RegionOfInterest roi\n" +
    SEP + "MSG: std_msgs/Header\n" + HEADER + SEP + "MSG: builtin_interfaces/Time\n" + TIME +
    SEP + "MSG: sensor_msgs/RegionOfInterest\nuint32 x_offset\nuint32 y_offset\nuint32 height\nuint32 width\nbool do_rectify\n",
  "tf2_msgs/msg/TFMessage": "geometry_msgs/TransformStamped[] transforms\n" +
    SEP + "MSG: geometry_msgs/TransformStamped\nstd_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform\n" +
    SEP + "MSG: std_msgs/Header\n" + HEADER + SEP + "MSG: builtin_interfaces/Time\n" + TIME +
    SEP + "MSG: geometry_msgs/Transform\ngeometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n" +
    SEP + "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n" +
    SEP + "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n",
};
const QOS = (latched) => `- history: keep_last\n  depth: 1\n  reliability: reliable\n  durability: ${latched ? "transient_local" : "volatile"}\n`;

async function main() {
  const [out, encoding, compression = "zstd", summary = "summary"] = process.argv.slice(2);
  await zstd.isLoaded;
  const handle = await fs.promises.open(out, "w");
  const full = summary !== "nosummary";
  if (summary === "badschema") DEFS["sensor_msgs/msg/Image"] = "%%% not ros2msg\n" + DEFS["sensor_msgs/msg/Image"];
  const writer = new McapWriter({
    writable: new FileHandleWritable(handle), chunkSize: 16 * 1024,
    useStatistics: full, useSummaryOffsets: full, useChunkIndex: full, useMessageIndex: full,
    useMetadataIndex: full, useAttachmentIndex: full, repeatSchemas: full, repeatChannels: full,
    compressChunk: compression === "zstd" ? (data) => ({ compression: "zstd", compressedData: zstd.compress(data, 3) }) : undefined,
  });
  await writer.start({ profile: "ros2", library: "write_mcap.cjs" });
  const channels = {};
  const writers = {};
  for (const [topic, type, latched] of [["/camera/camera/depth/image_rect_raw", "sensor_msgs/msg/Image"],
      ["/camera/camera/depth/camera_info", "sensor_msgs/msg/CameraInfo"], ["/tf", "tf2_msgs/msg/TFMessage"],
      ["/tf_static", "tf2_msgs/msg/TFMessage", true]]) {
    const schemaId = await writer.registerSchema({ name: type, encoding: "ros2msg", data: new TextEncoder().encode(DEFS[type]) });
    channels[topic] = await writer.registerChannel({ topic, schemaId, messageEncoding: "cdr",
      metadata: new Map([["offered_qos_profiles", QOS(latched)]]) });
    writers[topic] = new MessageWriter(parse(DEFS[type].replace("%%% not ros2msg\n", ""), { ros2: true }));
  }
  let sequence = 0;
  const put = async (topic, t, msg) => {
    const ns = BigInt(Math.round(t * 1e9));
    let data = writers[topic].writeMessage(msg);
    if (summary === "short" && topic.endsWith("image_rect_raw")) data = data.slice(0, 60);
    await writer.addMessage({ channelId: channels[topic], sequence: sequence++, logTime: ns, publishTime: ns, data });
  };
  const stamp = (t) => ({ sec: Math.floor(t), nanosec: Math.round((t - Math.floor(t)) * 1e9) });
  const tf = (t, parent, child, x, y, z, q) => ({ header: { stamp: stamp(t), frame_id: parent }, child_frame_id: child,
    transform: { translation: { x, y, z }, rotation: { x: q[0], y: q[1], z: q[2], w: q[3] } } });
  const t0 = 100.0, W = 64, H = 48;
  // Optical frame: z forward, x right, y down; camera_link -> optical is the usual (-90 deg about z, -90 about x).
  await put("/tf_static", t0, { transforms: [tf(t0, "base_link", "camera_link", 0.1, 0, 0.5, [0, 0, 0, 1]),
    tf(t0, "camera_link", "camera_depth_optical_frame", 0, 0, 0, [-0.5, 0.5, -0.5, 0.5])] });
  for (let i = 0; i < 5; i++) {
    const t = t0 + 0.1 * i;
    await put("/tf", t, { transforms: [tf(t, "odom", "base_link", 0.1 * i, 0, 0, [0, 0, 0, 1])] });
    await put("/camera/camera/depth/camera_info", t, { header: { stamp: stamp(t), frame_id: "camera_depth_optical_frame" },
      height: H, width: W, distortion_model: "plumb_bob", d: [0, 0, 0, 0, 0], k: [50, 0, 31.5, 0, 50, 23.5, 0, 0, 1],
      r: [1, 0, 0, 0, 1, 0, 0, 0, 1], p: [50, 0, 31.5, 0, 0, 50, 23.5, 0, 0, 0, 1, 0], binning_x: 0, binning_y: 0,
      roi: { x_offset: 0, y_offset: 0, height: 0, width: 0, do_rectify: false } });
    const wall_m = 2.0 - 0.1 * i;  // the robot approaches the wall
    let data;
    if (encoding === "32FC1") {
      const f = new Float32Array(W * H).fill(wall_m);
      f[0] = NaN;  // no return
      data = new Uint8Array(f.buffer);
    } else {
      const u = new Uint16Array(W * H).fill(Math.round(wall_m * 1000));
      u[0] = 0;
      data = new Uint8Array(u.buffer);
    }
    await put("/camera/camera/depth/image_rect_raw", t, { header: { stamp: stamp(t), frame_id: "camera_depth_optical_frame" },
      height: H, width: W, encoding, is_bigendian: 0, step: W * (encoding === "32FC1" ? 4 : 2), data });
  }
  await writer.end();
  await handle.close();
}
main().catch((e) => { console.error(e); process.exit(1); });
