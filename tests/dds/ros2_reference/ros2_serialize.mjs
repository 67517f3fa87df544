// An independent ROS 2 serializer for saccade's DDS wire tests (tests/dds/wire_bytes_test.cc):
// Foxglove's CDR writer (@foxglove/rosmsg2-serialization) with the ROS 2 definitions of
// common_interfaces (@foxglove/rosmsg-msgs-common, Humble), neither of them saccade's.
//
//   node ros2_serialize.mjs INPUT.json
//
// INPUT.json: [{"type": "sensor_msgs/Image", "message": {...}}, ...]; a uint8[] field may be
// given as {"base64": "..."}. Prints one line of lowercase hex per message: the serialized
// bytes with their 4-byte CDR encapsulation header, as a ROS 2 node would put them on the wire.
import { readFileSync } from "node:fs";
import { createRequire } from "node:module";

const require = createRequire(import.meta.url);
const { MessageWriter } = require("@foxglove/rosmsg2-serialization");
const { ros2humble } = require("@foxglove/rosmsg-msgs-common");

function decodeBytes(value) {
  if (value && typeof value === "object" && !Array.isArray(value)) {
    if (typeof value.base64 === "string") return new Uint8Array(Buffer.from(value.base64, "base64"));
    const out = {};
    for (const [k, v] of Object.entries(value)) out[k] = decodeBytes(v);
    return out;
  }
  if (Array.isArray(value)) return value.map(decodeBytes);
  return value;
}

const inputs = JSON.parse(readFileSync(process.argv[2], "utf8"));
const definitions = Object.values(ros2humble);
for (const { type, message } of inputs) {
  const root = ros2humble[type];
  if (!root) throw new Error(`unknown ROS 2 type ${type}`);
  const writer = new MessageWriter([root, ...definitions.filter((d) => d !== root)]);
  const bytes = writer.writeMessage(decodeBytes(message));
  process.stdout.write(Buffer.from(bytes).toString("hex") + "\n");
}
