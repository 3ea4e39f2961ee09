// Reads a recording of the view with the reference MCAP reader (@mcap/core)
// and checks it whole: the footer, summary and chunk indexes through the
// indexed reader, every record again in file order through the stream
// reader, every CRC, the statistics against what was read, and every
// message decoded and checked (view_checks.js).
//
//   node check_mcap.js FILE.mcap [--runtime cdcr-runtime --image model.img [--of-replay]]
//
// Without --runtime it checks the file and the schemas only (what the demo
// runs); with it also the values against `cdcr-runtime --replay`.
// --of-replay: a recording of --replay, which has only the drives' cables;
// --require TOPIC,...: the topics that must have messages (default: all);
// --poses POSES.csv: the recording of a replay, its tips row by row against
// that replay's own poses (the rows' lengths must be ones CABLE_FEEDBACK
// carries exactly: hundredths of a millimetre).
"use strict";

const fs = require("fs");
const { McapIndexedReader, McapStreamReader } = require("@mcap/core");
const { crc32 } = require("@foxglove/crc");
const { CheckError, fail, channelValidator, checkValues, kChannels, kReplayTopics } = require("./view_checks");

function parseArguments(argv) {
  const options = { file: undefined, runtime: undefined, image: undefined };
  for (let i = 0; i < argv.length; ++i) {
    if (argv[i] === "--of-replay") options.required = kReplayTopics;
    else if (argv[i] === "--require") options.required = argv[++i].split(",");
    else if (argv[i] === "--poses") options.poses = argv[++i];
    else if (argv[i] === "--runtime") options.runtime = argv[++i];
    else if (argv[i] === "--image") options.image = argv[++i];
    else if (!options.file && !argv[i].startsWith("--")) options.file = argv[i];
    else fail(`unknown argument ${argv[i]}`);
  }
  if (!options.file) fail("usage: node check_mcap.js FILE.mcap [--runtime PATH --image PATH [--of-replay]]");
  if (!options.runtime !== !options.image) fail("--runtime and --image go together");
  return options;
}

function compareRows(tips, posesPath) {
  const rows = fs.readFileSync(posesPath, "utf8").trim().split("\n").slice(1).map((line) => line.split(",").map(Number));
  if (rows.length !== tips.length) fail(`${tips.length} tip poses recorded for ${rows.length} rows of ${posesPath}`);
  let worst = 0;
  rows.forEach(([x, y, z], i) => {
    const p = tips[i].pose.position;
    worst = Math.max(worst, Math.hypot(p.x * 1e3 - x, p.y * 1e3 - y, p.z * 1e3 - z));
  });
  if (!(worst <= 1e-3)) fail(`the recorded tips differ from ${posesPath} by up to ${worst} mm`);
  return worst;
}

async function check(options) {
  let bytes;
  try {
    bytes = fs.readFileSync(options.file);
  } catch (e) {
    fail(`cannot read ${options.file}: ${e.message}`);
  }
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
  };
  const reader = await McapIndexedReader.Initialize({ readable });
  if (reader.dataSectionCrc !== undefined && reader.dataSectionCrc !== 0) {
    const computed = crc32(bytes.subarray(0, Number(reader.dataEndOffset)));
    if (computed !== reader.dataSectionCrc) fail(`data section CRC ${reader.dataSectionCrc}, the bytes give ${computed}`);
  } else {
    fail("the recording has no data section CRC");
  }
  if (!reader.statistics) fail("the recording has no statistics");
  if (reader.chunkIndexes.length === 0) fail("the recording has no chunk index");

  // The channels: every one the view offers, each schema checked.
  const validators = new Map();
  const topics = new Map();
  for (const [id, channel] of reader.channelsById) {
    const schema = reader.schemasById.get(channel.schemaId);
    if (!schema) fail(`channel ${channel.topic} on unknown schema ${channel.schemaId}`);
    const text = new TextDecoder().decode(schema.data);
    validators.set(id, channelValidator(channel.topic, schema.name, text, channel.messageEncoding, schema.encoding));
    topics.set(id, channel.topic);
  }
  for (const topic of Object.keys(kChannels)) {
    if (![...topics.values()].includes(topic)) fail(`the recording has no channel ${topic}`);
  }

  // Every message through the index, in time order, CRCs checked.
  const byTopic = {};
  const counts = new Map();
  let total = 0;
  let lastTime = -1n;
  for await (const message of reader.readMessages({ validateCrcs: true })) {
    if (message.logTime < lastTime) fail("the index gives messages out of time order");
    lastTime = message.logTime;
    const topic = topics.get(message.channelId);
    let parsed;
    try {
      parsed = JSON.parse(new TextDecoder().decode(message.data));
    } catch (e) {
      fail(`${topic}: message ${message.sequence} is not JSON: ${e.message}`);
    }
    validators.get(message.channelId)(parsed, `message ${message.sequence}`);
    (byTopic[topic] = byTopic[topic] || []).push(parsed);
    counts.set(message.channelId, (counts.get(message.channelId) || 0) + 1);
    ++total;
  }
  const statistics = reader.statistics;
  if (BigInt(total) !== statistics.messageCount) fail(`the index gives ${total} messages, the statistics ${statistics.messageCount}`);
  for (const [id, count] of statistics.channelMessageCounts) {
    if (BigInt(counts.get(id) || 0) !== count) fail(`${topics.get(id)}: ${counts.get(id) || 0} messages read, the statistics say ${count}`);
  }
  if (statistics.chunkCount !== reader.chunkIndexes.length) fail("the statistics' chunk count is not the chunk indexes'");

  // The whole file again in its order, as a streaming reader reads it.
  const stream = new McapStreamReader({ validateCrcs: true });
  stream.append(bytes);
  let streamed = 0, footers = 0;
  for (let record; (record = stream.nextRecord()); ) {
    if (record.type === "Message") ++streamed;
    if (record.type === "Footer") ++footers;
  }
  if (!stream.done()) fail("the stream reader did not reach the end of the file");
  if (streamed !== total || footers !== 1) fail(`the stream reader read ${streamed} messages and ${footers} footers`);

  const summary = { messages: total, chunks: reader.chunkIndexes.length, channels: topics.size };
  if (options.poses) summary.rowsWorstMm = compareRows(byTopic["/tip/pose"] || [], options.poses);
  if (options.runtime) Object.assign(summary, checkValues(byTopic, options));
  return summary;
}

async function main() {
  try {
    const options = parseArguments(process.argv.slice(2));
    const summary = await check(options);
    console.log(`check_mcap: ${options.file}: ${summary.messages} messages in ${summary.chunks} chunks on ${summary.channels} ` +
      "channels; the index, the statistics and every CRC agree with the data; every message decoded and valid against its schema");
    if (options.poses) {
      console.log(`check_mcap: every row's tip within ${summary.rowsWorstMm.toExponential(1)} mm of ${options.poses}`);
    }
    if (options.runtime) {
      console.log(`check_mcap: ${summary.scenes} scenes consistent with the poses; ${summary.compared} tip poses against ` +
        `cdcr-runtime --replay of their cables: within ${summary.worstMm.toExponential(1)} mm, ` +
        `${summary.worstQ.toExponential(1)} in the quaternion, r95 within ${summary.worstR95.toExponential(1)} mm`);
    }
  } catch (e) {
    // The reference reader's own refusals are one line too.
    console.error(`check_mcap: ${e instanceof CheckError ? e.message : `the MCAP reader refused the file: ${e.message || e}`}`);
    process.exit(1);
  }
}

main();
