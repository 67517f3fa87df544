// ROS 2 messages from outside saccade, for its reader of ros2msg schemas (tests/record/
// ros_message_test.cc): each message serialized by Foxglove's CDR writer
// (@foxglove/rosmsg2-serialization) with the definitions of common_interfaces (Humble, from
// @foxglove/rosmsg-msgs-common), and the definition as rosbag2 stores it in a schema (the .msg
// fields and constants of the type, then each type it uses after a line of '=' and "MSG:").
//
//   node ros2_sample.mjs INPUT.json   # [{"type": "sensor_msgs/Imu", "message": {...}}, ...]
//   node ros2_sample.mjs INPUT.json OUT.mcap
//
// The second form writes the messages into an MCAP file with @mcap/core's writer instead, as a
// ROS 2 recorder would (profile ros2, a ros2msg schema and a cdr channel per type, each input's
// "topic"), the i-th logged at i * 40 ms; an input with "json" instead of "type" goes on a JSON
// channel.
// A uint8[] field may be given as {"bytes": [...]}, 64-bit integers as {"bigints": ["...", ...]}
// (decimal strings: exact beyond 2^53). Prints a JSON line per message: {"hex": "...", "definition": "..."}.
import { readFileSync, writeFileSync } from 'node:fs';
import { McapWriter, TempBuffer } from '@mcap/core';
import { MessageWriter } from '@foxglove/rosmsg2-serialization';
import rosmsgMsgsCommon from '@foxglove/rosmsg-msgs-common';

const { ros2humble } = rosmsgMsgsCommon;

function fieldsText(definition) {
  return definition.definitions.map((f) => {
    const type = f.type + (f.isArray ? `[${f.arrayLength ?? ''}]` : '');
    if (f.isConstant) return `${type} ${f.name}=${f.valueText ?? f.value}\n`;
    return `${type} ${f.name}\n`;
  }).join('');
}

function definitionText(root) {
  let text = fieldsText(root);
  const seen = new Set([root.name]);
  const queue = [root];
  while (queue.length > 0) {
    for (const f of queue.shift().definitions) {
      if (!f.isComplex || seen.has(f.type)) continue;
      seen.add(f.type);
      const used = ros2humble[f.type];
      text += `${'='.repeat(80)}\nMSG: ${f.type}\n${fieldsText(used)}`;
      queue.push(used);
    }
  }
  return text;
}

const inputs = JSON.parse(readFileSync(process.argv[2], 'utf8'));
const definitions = Object.values(ros2humble);
const revive = (message) => JSON.parse(JSON.stringify(message), (key, v) =>
  v && typeof v === 'object' && Array.isArray(v.bytes) ? new Uint8Array(v.bytes)
    : v && typeof v === 'object' && Array.isArray(v.bigints) ? v.bigints.map(BigInt) : v);
const serialize = (type, message) => {
  const root = ros2humble[type];
  if (!root) throw new Error(`unknown ROS 2 type ${type}`);
  const writer = new MessageWriter([root, ...definitions.filter((d) => d !== root)]);
  return { bytes: writer.writeMessage(revive(message)), definition: definitionText(root) };
};

if (process.argv[3]) {
  const buffer = new TempBuffer();
  const writer = new McapWriter({ writable: buffer });
  await writer.start({ profile: 'ros2', library: '@mcap/core' });
  const encoder = new TextEncoder();
  const channels = new Map();
  let i = 0;
  for (const input of inputs) {
    const key = input.topic;
    if (!channels.has(key)) {
      let schemaId = 0;
      if (input.type) {
        const [pkg, name] = input.type.split('/');
        schemaId = await writer.registerSchema({ name: `${pkg}/msg/${name}`, encoding: 'ros2msg',
          data: encoder.encode(serialize(input.type, input.message).definition) });
      }
      channels.set(key, await writer.registerChannel({ schemaId, topic: input.topic,
        messageEncoding: input.type ? 'cdr' : 'json', metadata: new Map() }));
    }
    const data = input.type ? serialize(input.type, input.message).bytes
      : encoder.encode(JSON.stringify(input.json));
    const time = BigInt(i) * 40000000n;
    await writer.addMessage({ channelId: channels.get(key), sequence: i, logTime: time,
      publishTime: time, data });
    i += 1;
  }
  await writer.end();
  writeFileSync(process.argv[3], buffer.get());
} else {
  for (const { type, message } of inputs) {
    const { bytes, definition } = serialize(type, message);
    console.log(JSON.stringify({ hex: Buffer.from(bytes).toString('hex'), definition }));
  }
}
