// Reads an MCAP file with Foxglove's own reader (npm @mcap/core), as an
// independent check of the sandbox's writer: the indexed reader (footer,
// summary CRC, summary offsets, statistics, chunk indexes, message indexes,
// chunk CRCs) and the streaming reader (every record in file order), plus the
// data section's CRC computed here with @foxglove/crc. Prints, as JSON, every
// LCM message in file order (topic, log time, SHA-256 of its bytes), every
// JSON message (topic, log time, schema name, the message parsed) and the
// channels' schemas; exits 1 naming what disagrees.
//
//   NODE_PATH=build/node/node_modules node mcap_check.cjs FILE.mcap
"use strict";
const fs = require("fs");
const crypto = require("crypto");
const { McapIndexedReader, McapStreamReader } = require("@mcap/core");
const { crc32 } = require("@foxglove/crc");
const fzstd = require("fzstd");
const lz4 = require("lz4js");

const decompressHandlers = {
  zstd: (buffer, size) => fzstd.decompress(buffer, new Uint8Array(Number(size))),
  lz4: (buffer) => lz4.decompress(buffer),
};

function fail(why) {
  process.stderr.write(`mcap_check: ${why}\n`);
  process.exit(1);
}

function sha(data) {
  return crypto.createHash("sha256").update(data).digest("hex");
}

async function main() {
  const path = process.argv[2];
  const bytes = new Uint8Array(fs.readFileSync(path));
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
  };
  const indexed = await McapIndexedReader.Initialize({ readable, decompressHandlers });

  // Every record in file order, chunks opened, their CRCs checked.
  const stream = new McapStreamReader({ includeChunks: true, decompressHandlers, validateCrcs: true });
  stream.append(bytes);
  const messages = [], views = [], all = [];
  const counts = {};
  const channels = new Map();
  const schemas = new Map();
  let chunks = 0, messageIndexes = 0, dataEnd = null;
  for (let record; (record = stream.nextRecord()); ) {
    if (record.type === "Schema") schemas.set(record.id, record);
    if (record.type === "Channel") channels.set(record.id, record);
    if (record.type === "Chunk") chunks++;
    if (record.type === "MessageIndex") messageIndexes++;
    if (record.type === "DataEnd") dataEnd = record;
    if (record.type === "Message") {
      const channel = channels.get(record.channelId);
      if (channel.messageEncoding === "json") {  // Foxglove's schemas, decoded as Foxglove does
        const schema = schemas.get(channel.schemaId);
        views.push([channel.topic, record.logTime.toString(), schema.name,
                    JSON.parse(new TextDecoder().decode(record.data))]);
      } else {
        messages.push([channel.topic, record.logTime.toString(), sha(record.data)]);
      }
      all.push([channel.topic, record.logTime.toString(), sha(record.data)]);
      counts[record.channelId] = (counts[record.channelId] || 0) + 1;
    }
  }
  if (!stream.done()) fail("the stream reader did not reach the footer and closing magic");
  if (dataEnd === null) fail("no data end record");

  // The data section's CRC: every byte before the data end record.
  const dataCrc = crc32(bytes.subarray(0, Number(indexed.dataEndOffset)));
  if (dataEnd.dataSectionCrc !== dataCrc) {
    fail(`data section CRC ${dataEnd.dataSectionCrc}, computed ${dataCrc}`);
  }

  // The summary against what the stream holds.
  const stats = indexed.statistics;
  if (stats === undefined) fail("no statistics record");
  if (stats.messageCount !== BigInt(all.length)) {
    fail(`statistics say ${stats.messageCount} messages, the file has ${all.length}`);
  }
  if (stats.chunkCount !== chunks || indexed.chunkIndexes.length !== chunks) {
    fail(`statistics say ${stats.chunkCount} chunks, ${indexed.chunkIndexes.length} chunk ` +
         `indexes, the file has ${chunks}`);
  }
  if (stats.channelCount !== channels.size || stats.schemaCount !== schemas.size) {
    fail("the statistics' channel or schema count is not the file's");
  }
  for (const [id, count] of stats.channelMessageCounts) {
    if (BigInt(counts[id] || 0) !== count) fail(`channel ${id}: ${count} messages in the statistics`);
  }
  let indexEntries = 0;
  for (const chunkIndex of indexed.chunkIndexes) {
    const head = bytes[Number(chunkIndex.chunkStartOffset)];
    if (head !== 0x06) fail(`chunk index points at opcode ${head}, not a chunk`);
    for (const [, offset] of chunkIndex.messageIndexOffsets) {
      if (bytes[Number(offset)] !== 0x07) fail("a message index offset points elsewhere");
      indexEntries++;
    }
  }
  if (indexEntries !== messageIndexes) {
    fail(`${messageIndexes} message indexes, the chunk indexes point at ${indexEntries}`);
  }

  // Every message through the indexes (time order, CRCs checked).
  const viaIndex = [];
  for await (const message of indexed.readMessages({ validateCrcs: true })) {
    const topic = indexed.channelsById.get(message.channelId).topic;
    viaIndex.push([topic, message.logTime.toString(), sha(message.data)]);
  }
  const key = (m) => m.join(" ");
  const sorted = (list) => list.map(key).sort();
  if (JSON.stringify(sorted(viaIndex)) !== JSON.stringify(sorted(all))) {
    fail(`the indexed reader found ${viaIndex.length} messages, not the stream's ${all.length}`);
  }

  const channelSchemas = {};
  for (const channel of indexed.channelsById.values()) {
    const schema = indexed.schemasById.get(channel.schemaId);
    channelSchemas[channel.topic] = {
      message_encoding: channel.messageEncoding,
      schema: schema ? schema.name : null,
      schema_encoding: schema ? schema.encoding : null,
      schema_text: schema ? new TextDecoder().decode(schema.data) : null,
    };
  }
  process.stdout.write(JSON.stringify({
    messages, views, channels: channelSchemas, chunks,
    compression: [...new Set(indexed.chunkIndexes.map((c) => c.compression))],
  }));
}

main().catch((e) => fail(e.stack || String(e)));
