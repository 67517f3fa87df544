// The reference MCAP implementation (Foxglove's @mcap/core, zstd through @mcap/support) for
// saccade's recording tests (tests/record/mcap_reference_test.cc):
//
//   node mcap_reference.mjs read FILE    # prints what the file holds, as JSON
//   node mcap_reference.mjs write FILE   # writes the test's messages with @mcap/core's writer
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

try {
  if (command === 'read') await read();
  else if (command === 'write') await write();
  else throw new Error('usage: mcap_reference.mjs read|write FILE');
} catch (error) {
  console.error(`mcap_reference: ${error.message}`);
  process.exit(1);
}
