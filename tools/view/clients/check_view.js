// The live view against the reference Foxglove WebSocket client
// (@foxglove/ws-protocol): runs `cdcr-runtime --sim --circle --view 0`,
// subscribes to every channel it advertises, and checks the schemas, every
// message and the values (view_checks.js), the scene's rate, and that the
// runtime's own figures are those of the same run without the view.
//
//   node check_view.js --runtime PATH --image PATH
"use strict";

const { spawnSync } = require("child_process");
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const WebSocket = require("ws");
const { CheckError, fail, channelValidator, checkValues, kChannels, startServedRuntime } = require("./view_checks");

const kRunArguments = ["--sim", "--circle", "--circle-radius", "40", "--circle-speed", "50"];
const kSceneRateHz = 30;
const kTimeoutMs = 60000;

function parseArguments(argv) {
  const options = {};
  for (let i = 0; i < argv.length; i += 2) {
    if (argv[i] === "--runtime") options.runtime = argv[i + 1];
    else if (argv[i] === "--image") options.image = argv[i + 1];
    else fail(`unknown argument ${argv[i]}`);
  }
  if (!options.runtime || !options.image) fail("usage: node check_view.js --runtime PATH --image PATH");
  return options;
}

async function receive(port) {
  const client = new FoxgloveClient({ ws: new WebSocket(`ws://127.0.0.1:${port}`, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
  const validators = new Map(); // by subscription id
  const topics = new Map();
  const byTopic = {};
  let advertised = false, serverInfo = false, messages = 0;
  const errors = [];
  client.on("serverInfo", () => (serverInfo = true));
  client.on("advertise", (channels) => {
    try {
      for (const channel of channels) {
        const validate = channelValidator(channel.topic, channel.schemaName, channel.schema, channel.encoding, channel.schemaEncoding);
        const id = client.subscribe(channel.id);
        validators.set(id, validate);
        topics.set(id, channel.topic);
      }
      for (const topic of Object.keys(kChannels)) {
        if (![...topics.values()].includes(topic)) fail(`the view does not advertise ${topic}`);
      }
      advertised = true;
    } catch (e) {
      errors.push(e);
    }
  });
  client.on("message", ({ subscriptionId, timestamp, data }) => {
    try {
      const topic = topics.get(subscriptionId);
      if (!topic) fail(`a message on unknown subscription ${subscriptionId}`);
      const text = new TextDecoder().decode(data);
      const message = JSON.parse(text);
      validators.get(subscriptionId)(message, `message ${messages + 1}`);
      const stamp = message.timestamp || (message.entities && message.entities[0] && message.entities[0].timestamp) ||
        (message.transforms && message.transforms[0] && message.transforms[0].timestamp);
      if (stamp && BigInt(stamp.sec) * 1000000000n + BigInt(stamp.nsec) !== timestamp) {
        fail(`${topic}: the frame's timestamp ${timestamp} is not the message's`);
      }
      (byTopic[topic] = byTopic[topic] || []).push(message);
      ++messages;
    } catch (e) {
      errors.push(e);
    }
  });
  await new Promise((resolve, reject) => {
    client.on("close", resolve);
    client.on("error", (e) => reject(new CheckError(`the WebSocket client: ${e.message || e}`)));
    setTimeout(() => reject(new CheckError("the view did not close its connection within 60 s")), kTimeoutMs).unref();
  });
  if (errors.length > 0) throw errors[0];
  if (!serverInfo || !advertised) fail("no serverInfo or advertise from the view");
  return { byTopic, messages };
}

function withoutHostTiming(stdout) {
  // What the host's own speed decides, and the view's lines, differ between runs.
  return stdout
    .split("\n")
    .filter((line) => !line.startsWith("view:"))
    .map((line) => line.replace(/slowest cycle on this host [0-9.]+ us/, "slowest cycle on this host - us"))
    .join("\n");
}

async function main() {
  let runtime;
  try {
    const options = parseArguments(process.argv.slice(2));
    runtime = await startServedRuntime(options.runtime, ["--image", options.image, ...kRunArguments]);
    const { byTopic, messages } = await receive(runtime.port);
    const run = await runtime.exited;
    if (run.code !== 0) fail(`cdcr-runtime --view exited with ${run.code}: ${run.stderr.trim()}`);

    // The scene's rate over the frames' own time: the median gap between
    // scenes, and the count over the whole span.
    const scenes = byTopic["/scene"] || [];
    const time = (s) => s.entities[0].timestamp.sec + s.entities[0].timestamp.nsec * 1e-9;
    const seconds = scenes.length > 1 ? time(scenes[scenes.length - 1]) - time(scenes[0]) : 0;
    const gaps = scenes.slice(1).map((s, i) => time(s) - time(scenes[i])).sort((a, b) => a - b);
    const rate = gaps.length > 0 ? 1 / gaps[Math.floor(gaps.length / 2)] : 0;
    const countRate = seconds > 0 ? (scenes.length - 1) / seconds : 0;
    if (!(countRate >= 0.9 * kSceneRateHz)) fail(`${scenes.length} scenes in ${seconds.toFixed(2)} s: ${countRate.toFixed(2)} Hz`);
    if (!(Math.abs(rate - kSceneRateHz) <= 0.05 * kSceneRateHz)) fail(`the scene came at ${rate.toFixed(2)} Hz, not ${kSceneRateHz} Hz`);
    if (!(seconds >= 4)) fail(`scenes over only ${seconds.toFixed(2)} s of the run`);
    const values = checkValues(byTopic, options);

    // The same run without the view: the runtime's figures are the same.
    const plain = spawnSync(options.runtime, ["--image", options.image, ...kRunArguments], { encoding: "utf8" });
    if (plain.status !== 0) fail(`cdcr-runtime without the view exited with ${plain.status}: ${plain.stderr.trim()}`);
    if (withoutHostTiming(plain.stdout) !== withoutHostTiming(run.stdout)) {
      fail(`the runtime's report differs with the view attached:\n--- without\n${plain.stdout}--- with\n${run.stdout}`);
    }
    const summary = { messages, sceneRateHz: Number(rate.toFixed(2)), sceneSeconds: Number(seconds.toFixed(2)), ...values };
    console.log(`check_view: ${JSON.stringify(summary)}`);
    console.log("check_view: the runtime's report is the same with the view attached");
  } catch (e) {
    console.error(`check_view: ${e instanceof CheckError ? e.message : e.stack || e}`);
    process.exitCode = 1;
  } finally {
    if (runtime && runtime.child.exitCode === null) runtime.child.kill();
  }
}

main();
