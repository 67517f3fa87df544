// The reference MCAP implementation (Foxglove's @mcap/core, zstd through @mcap/support) for
// saccade's recording tests (tests/record/mcap_reference_test.cc):
//
//   node mcap_reference.mjs read FILE    # prints what the file holds, as JSON
//   node mcap_reference.mjs write FILE   # writes the test's messages with @mcap/core's writer
//   node mcap_reference.mjs decode FILE  # every message decoded, as JSON
//   node mcap_reference.mjs summary FILE # what @mcap/core's indexed reader finds, for people
//
// `read` reads the file twice: with McapStreamReader from the first byte to the last, every CRC
// checked (data section, chunks, summary), and with McapIndexedReader through the footer, summary
// offsets, chunk indexes and message indexes. It prints the header, schemas, channels, the
// statistics record, each message (channel, sequence, times, size and the FNV-1a hash of its
// data, which the C++ test computes too) as the indexed reader gives them, and the record counts
// of the stream read.
import { readFileSync, writeFileSync } from 'node:fs';
import { McapIndexedReader, McapStreamReader, McapWriter, TempBuffer } from '@mcap/core';
import { loadDecompressHandlers } from '@mcap/support';
import { parse as parseMessageDefinition } from '@foxglove/rosmsg';
import { MessageReader } from '@foxglove/rosmsg2-serialization';
import rosmsgMsgsCommon from '@foxglove/rosmsg-msgs-common';

const { ros2humble } = rosmsgMsgsCommon;

const [command, file] = process.argv.slice(2);
// FNV-1a, 32 bits.
const fnv1a = (bytes) => {
  let h = 0x811c9dc5;
  for (const b of bytes) h = Math.imul(h ^ b, 0x01000193) >>> 0;
  return h >>> 0;
};
const decoder = new TextDecoder();

async function read() {
  const bytes = new Uint8Array(readFileSync(file));
  const decompressHandlers = await loadDecompressHandlers();
  const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  stream.append(bytes);
  const records = {};
  for (let r; (r = stream.nextRecord());) records[r.type] = (records[r.type] ?? 0) + 1;
  if (!stream.done()) throw new Error(`the stream reader stopped ${stream.bytesRemaining()} bytes before the end`);
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
  };
  const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
  const messages = [];
  for await (const m of reader.readMessages({ validateCrcs: true })) {
    messages.push({
      channel: m.channelId, sequence: m.sequence, log_time: String(m.logTime),
      publish_time: String(m.publishTime), size: m.data.length, fnv1a: fnv1a(m.data),
    });
  }
  const s = reader.statistics;
  console.log(JSON.stringify({
    header: reader.header,
    schemas: [...reader.schemasById.values()].map((x) => ({ id: x.id, name: x.name,
      encoding: x.encoding, data: decoder.decode(x.data) })),
    channels: [...reader.channelsById.values()].map((c) => ({ id: c.id, schema_id: c.schemaId,
      topic: c.topic, message_encoding: c.messageEncoding, metadata: Object.fromEntries(c.metadata) })),
    statistics: s && { message_count: String(s.messageCount), chunk_count: s.chunkCount,
      channel_count: s.channelCount, schema_count: s.schemaCount,
      message_start_time: String(s.messageStartTime), message_end_time: String(s.messageEndTime),
      channel_message_counts: Object.fromEntries([...s.channelMessageCounts].map(([k, v]) => [k, String(v)])) },
    chunk_indexes: reader.chunkIndexes.length,
    data_section_crc: reader.dataSectionCrc ?? null,
    records,
    messages,
  }));
}

// The test's messages: 300 on two channels every 20 ms; message i holds i % 251 repeated
// (i * 37) % 5000 + 1 times (the C++ test makes the same bytes).
async function write() {
  const buffer = new TempBuffer();
  const writer = new McapWriter({ writable: buffer, chunkSize: 64 * 1024 });
  await writer.start({ profile: 'ros2', library: '@mcap/core' });
  const encoder = new TextEncoder();
  const schema = await writer.registerSchema({ name: 'std_msgs/msg/String', encoding: 'ros2msg',
    data: encoder.encode('string data\n') });
  const a = await writer.registerChannel({ schemaId: schema, topic: '/a', messageEncoding: 'cdr',
    metadata: new Map([['from', 'node']]) });
  const b = await writer.registerChannel({ schemaId: schema, topic: '/b', messageEncoding: 'cdr',
    metadata: new Map() });
  for (let i = 0; i < 300; i++) {
    const data = new Uint8Array((i * 37) % 5000 + 1).fill(i % 251);
    await writer.addMessage({ channelId: i % 2 ? b : a, sequence: i, logTime: BigInt(i) * 20000000n,
      publishTime: BigInt(i) * 20000000n + 5n, data });
  }
  await writer.end();
  writeFileSync(file, buffer.get());
}

// A decoded value as JSON: byte arrays as their length and FNV-1a hash, other typed arrays as
// arrays (doubles print exactly: JSON's shortest round-trip form), 64-bit integers as strings.
function plain(value) {
  if (value instanceof Uint8Array) return { length: value.length, fnv1a: fnv1a(value) };
  if (ArrayBuffer.isView(value)) return Array.from(value, plain);
  if (Array.isArray(value)) return value.map(plain);
  if (typeof value === 'bigint') return String(value);
  if (value && typeof value === 'object') {
    return Object.fromEntries(Object.entries(value).map(([k, v]) => [k, plain(v)]));
  }
  return value;
}

// How a schema's parsed definitions differ from the ROS 2 (Humble) definitions of
// common_interfaces as @foxglove/rosmsg-msgs-common has them: [] when they agree.
function schemaDifferences(name, definitions) {
  const differences = [];
  const fields = (d) => JSON.stringify(d.definitions.filter((f) => !f.isConstant).map((f) => [
    f.name, f.type.replace('/msg/', '/'), f.isArray ?? false, f.arrayLength ?? null]));
  definitions.forEach((d, i) => {
    const typeName = i === 0 ? name.replace('/msg/', '/') : d.name.replace('/msg/', '/');
    const reference = ros2humble[typeName];
    if (!reference) differences.push(`${typeName}: not in common_interfaces`);
    else if (fields(d) !== fields(reference)) differences.push(`${typeName}: ${fields(d)} != ${fields(reference)}`);
  });
  return differences;
}

async function decode() {
  const bytes = new Uint8Array(readFileSync(file));
  const decompressHandlers = await loadDecompressHandlers();
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
  };
  const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
  const readers = new Map();
  const schemas = {};
  for (const [id, schema] of reader.schemasById) {
    if (schema.encoding !== 'ros2msg') continue;
    const definitions = parseMessageDefinition(decoder.decode(schema.data), { ros2: true });
    readers.set(id, new MessageReader(definitions));
    schemas[schema.name] = schemaDifferences(schema.name, definitions);
  }
  const messages = [];
  for await (const m of reader.readMessages({ validateCrcs: true })) {
    const channel = reader.channelsById.get(m.channelId);
    let value;
    if (channel.messageEncoding === 'cdr') value = readers.get(channel.schemaId).readMessage(m.data);
    else if (channel.messageEncoding === 'json') value = JSON.parse(decoder.decode(m.data));
    messages.push({ topic: channel.topic, log_time: String(m.logTime),
      publish_time: String(m.publishTime), value: plain(value) });
  }
  const s = reader.statistics;
  console.log(JSON.stringify({
    schemas, messages,
    message_count: String(s.messageCount),
    metadata: Object.fromEntries(await (async () => {
      const out = [];
      for await (const m of reader.readMetadata()) out.push([m.name, Object.fromEntries(m.metadata)]);
      return out;
    })()),
  }));
}

async function summary() {
  const bytes = new Uint8Array(readFileSync(file));
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
  };
  const reader = await McapIndexedReader.Initialize({ readable,
    decompressHandlers: await loadDecompressHandlers() });
  const s = reader.statistics;
  const seconds = Number(s.messageEndTime - s.messageStartTime) / 1e9;
  console.log(`@mcap/core ${file.split('/').pop()}: profile ${reader.header.profile}, library ` +
    `${reader.header.library}, ${s.messageCount} messages in ${s.chunkCount} chunks, ` +
    `${seconds.toFixed(2)} s`);
  for (const m of await (async () => { const a = []; for await (const x of reader.readMetadata()) a.push(x); return a; })()) {
    console.log(`metadata ${m.name}: ${[...m.metadata].map(([k, v]) => `${k}=${v}`).join(', ')}`);
  }
  for (const c of reader.channelsById.values()) {
    const schema = reader.schemasById.get(c.schemaId);
    console.log(`  ${c.topic.padEnd(30)} ${(schema ? `${schema.name} (${schema.encoding})` : c.messageEncoding).padEnd(40)} ` +
      `${String(s.channelMessageCounts.get(c.id) ?? 0n).padStart(5)}`);
  }
}

try {
  if (command === 'read') await read();
  else if (command === 'summary') await summary();
  else if (command === 'decode') await decode();
  else if (command === 'write') await write();
  else throw new Error('usage: mcap_reference.mjs read|write|decode|summary FILE');
} catch (error) {
  console.error(`mcap_reference: ${error.message}`);
  process.exit(1);
}
