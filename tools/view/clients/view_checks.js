// What the view's clients check of the messages they received, live
// (check_view.js) or from a recording (check_mcap.js): the schemas against
// Foxglove's own (@foxglove/schemas), every message against its schema (ajv),
// and the values against independent references: the poses against
// `cdcr-runtime --replay` of the very cable lengths the view reported, the
// scene's geometry against the poses, the following error against the cables.
"use strict";

const { spawn, spawnSync } = require("child_process");
const fs = require("fs");
const os = require("os");
const path = require("path");
const Ajv = require("ajv");
const foxgloveSchemas = require("@foxglove/schemas/jsonschema");

// The channels a view must offer, and their schema names.
const kChannels = {
  "/scene": "foxglove.SceneUpdate",
  "/tf": "foxglove.FrameTransforms",
  "/tip/pose": "foxglove.PoseInFrame",
  "/tip/nominal_pose": "foxglove.PoseInFrame",
  "/tip/uncertainty": "cdcr.TipUncertainty",
  "/target": "foxglove.PoseInFrame",
  "/cables": "cdcr.Cables",
  "/cables/following_error": "cdcr.FollowingError",
  "/status": "cdcr.Status",
  "/ik_report": "cdcr.IkReport",
};

class CheckError extends Error {}
function fail(message) {
  throw new CheckError(message);
}

function officialSchema(name) {
  const short = name.replace(/^foxglove\./, "");
  return name.startsWith("foxglove.") ? foxgloveSchemas[short] : undefined;
}

// The type an official property has: its `type`, or that of its oneOf
// constants (an enum as Foxglove writes it).
function officialType(schema) {
  if (schema.type) return schema.type;
  if (Array.isArray(schema.oneOf) && schema.oneOf.every((c) => Number.isInteger(c.const))) return "integer";
  return undefined;
}

// Every field the view declares exists in Foxglove's schema with the same
// type, and every field Foxglove requires is declared.
function compareSchema(ours, official, where) {
  const type = officialType(official);
  if (ours.type !== type) fail(`${where}: the view declares ${ours.type}, Foxglove's schema ${type}`);
  if (ours.type === "object") {
    const properties = ours.properties || {};
    for (const [name, property] of Object.entries(properties)) {
      if (!official.properties || !official.properties[name]) fail(`${where}.${name}: not in Foxglove's schema`);
      compareSchema(property, official.properties[name], `${where}.${name}`);
    }
    for (const name of official.required || []) {
      if (!properties[name]) fail(`${where}: Foxglove requires ${name}, the view's schema lacks it`);
    }
  }
  if (ours.type === "array" && ours.items) compareSchema(ours.items, official.items, `${where}[]`);
}

// Checks a channel's advertised schema; returns a validator of its messages
// (Foxglove's schema for Foxglove's types, the advertised one for the rest).
function channelValidator(topic, schemaName, schemaText, encoding, schemaEncoding) {
  if (!(topic in kChannels)) fail(`unexpected channel ${topic}`);
  if (schemaName !== kChannels[topic]) fail(`${topic}: schema ${schemaName}, expected ${kChannels[topic]}`);
  if (encoding !== "json") fail(`${topic}: message encoding ${encoding}, expected json`);
  if (schemaEncoding !== "jsonschema") fail(`${topic}: schema encoding ${schemaEncoding}, expected jsonschema`);
  let schema;
  try {
    schema = JSON.parse(schemaText);
  } catch (e) {
    fail(`${topic}: the schema is not JSON: ${e.message}`);
  }
  if (schema.title !== schemaName) fail(`${topic}: the schema's title is ${schema.title}, not ${schemaName}`);
  const official = officialSchema(schemaName);
  if (official) compareSchema(schema, official, schemaName);
  // The project's own types: every field required, none other allowed.
  const strict = (s) => {
    if (s.type === "object" && s.properties) {
      const properties = Object.fromEntries(Object.entries(s.properties).map(([k, v]) => [k, strict(v)]));
      return { ...s, properties, required: Object.keys(properties), additionalProperties: false };
    }
    if (s.type === "array" && s.items) return { ...s, items: strict(s.items) };
    return s;
  };
  const ajv = new Ajv({ strict: false, allErrors: false });
  const validate = ajv.compile(official || strict(schema));
  return (message, where) => {
    if (!validate(message)) fail(`${where}: ${topic}: ${ajv.errorsText(validate.errors)}`);
  };
}

function timeKey(stamp) {
  return `${stamp.sec}.${String(stamp.nsec).padStart(9, "0")}`;
}

function near(a, b, tolerance, what) {
  if (!(Math.abs(a - b) <= tolerance)) fail(`${what}: ${a} against ${b} (tolerance ${tolerance})`);
}

// The messages of each topic (in order, parsed), checked against each other
// and against `cdcr-runtime --replay` of the reported cable lengths.
// `required`: the topics that must have messages (all of them by default; a
// replay's recording has no setpoints, targets, STATUS or IK reports).
function checkValues(byTopic, { runtime, image, maxRows = 3000, required = Object.keys(kChannels) }) {
  for (const topic of required) {
    if (!byTopic[topic] || byTopic[topic].length === 0) fail(`no message on ${topic}`);
  }
  for (const topic of Object.keys(kChannels)) byTopic[topic] = byTopic[topic] || [];
  // A live client subscribes channel by channel: from the time every
  // channel of the tip and the scene had started, each message has the
  // others of its time.
  const stampOf = (m) => (m.entities ? m.entities[0].timestamp : m.timestamp);
  const seconds = (stamp) => stamp.sec + stamp.nsec * 1e-9;
  const paired = ["/scene", "/cables", "/tip/pose", "/tip/nominal_pose", "/tip/uncertainty"];
  const start = Math.max(...paired.map((topic) => seconds(stampOf(byTopic[topic][0]))));
  for (const topic of paired) byTopic[topic] = byTopic[topic].filter((m) => seconds(stampOf(m)) > start);
  const at = (topic) => new Map(byTopic[topic].map((m) => [timeKey(m.timestamp), m]));
  const cablesAt = at("/cables");
  const nominalAt = at("/tip/nominal_pose");
  const uncertaintyAt = at("/tip/uncertainty");
  const tipAt = at("/tip/pose");

  // The following error is setpoint - feedback of the cables of its time.
  for (const error of byTopic["/cables/following_error"]) {
    const cables = cablesAt.get(timeKey(error.timestamp));
    if (!cables) fail(`following error at ${timeKey(error.timestamp)} without its cables`);
    let largest = 0;
    error.cables_mm.forEach((e, i) => {
      near(e, cables.setpoints_mm[i] - cables.feedback_mm[i], 1e-9, `following error of cable ${i + 1}`);
      largest = Math.max(largest, Math.abs(e));
    });
    near(error.largest_mm, largest, 1e-12, "largest following error");
  }

  // The scene: the backbone from the base to the nominal tip without a gap,
  // the tip marker at the compensated tip, the r95 sphere its radius.
  let scenes = 0;
  for (const update of byTopic["/scene"]) {
    const entity = (id) => update.entities.find((e) => e.id === id);
    const backbone = entity("backbone");
    const tip = entity("tip");
    if (!backbone || !tip) fail("a scene without the backbone or the tip");
    const key = timeKey(backbone.timestamp);
    const nominal = nominalAt.get(key);
    const tipPose = tipAt.get(key);
    const uncertainty = uncertaintyAt.get(key);
    if (!nominal || !tipPose || !uncertainty) fail(`scene at ${key} without the tip of its time`);
    const strips = backbone.lines.filter((l) => l.points.length > 2);
    if (strips.length === 0) fail("a backbone without its line strips");
    let previous = { x: 0, y: 0, z: 0 };
    for (const [s, strip] of strips.entries()) {
      for (const axis of ["x", "y", "z"]) near(strip.points[0][axis], previous[axis], 1e-9, `segment ${s + 1}'s start ${axis}`);
      previous = strip.points[strip.points.length - 1];
    }
    for (const axis of ["x", "y", "z"]) {
      near(previous[axis], nominal.pose.position[axis], 1e-9, `backbone end vs nominal tip ${axis}`);
      near(tip.spheres[0].pose.position[axis], tipPose.pose.position[axis], 1e-12, `tip marker ${axis}`);
    }
    if (uncertainty.r95_mm > 0) near(tip.spheres[1].size.x, 2e-3 * uncertainty.r95_mm, 1e-12, "r95 sphere diameter");
    const red = tip.spheres[0].color.r > 0.5 && tip.spheres[0].color.g < 0.5;
    if (red !== uncertainty.extrapolating) fail(`scene at ${key}: the tip's colour does not follow the extrapolation flag`);
    ++scenes;
  }

  // The poses against cdcr-runtime --replay of the same cable lengths.
  const pairs = [];
  for (const tip of byTopic["/tip/pose"]) {
    const key = timeKey(tip.timestamp);
    const cables = cablesAt.get(key);
    const uncertainty = uncertaintyAt.get(key);
    if (!cables || !uncertainty) fail(`tip pose at ${key} without its cables`);
    pairs.push({ cables: cables.feedback_mm, tip, uncertainty });
  }
  const step = Math.max(1, Math.ceil(pairs.length / maxRows));
  const rows = pairs.filter((_, i) => i % step === 0);
  const cableCount = rows[0].cables.length;
  if (cableCount % 4 !== 0) fail(`${cableCount} cables: the comparison writes four-cable segments`);
  const header = [];
  for (let s = 1; s <= cableCount / 4; ++s) for (let c = 1; c <= 4; ++c) header.push(`l${s}_${c}`);
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), "cdcr-view-replay-"));
  try {
    const cablesCsv = path.join(dir, "cables.csv");
    const posesCsv = path.join(dir, "poses.csv");
    fs.writeFileSync(cablesCsv, [header.join(","), ...rows.map((r) => r.cables.map((v) => v.toPrecision(17)).join(","))].join("\n") + "\n");
    const replay = spawnSync(runtime, ["--image", image, "--replay", cablesCsv, "--out", posesCsv], { encoding: "utf8" });
    if (replay.status !== 0) fail(`cdcr-runtime --replay failed: ${replay.stderr.trim()}`);
    const lines = fs.readFileSync(posesCsv, "utf8").trim().split("\n").slice(1);
    if (lines.length !== rows.length) fail(`--replay wrote ${lines.length} poses for ${rows.length} rows`);
    let worstMm = 0, worstQ = 0, worstR95 = 0;
    lines.forEach((line, i) => {
      const [x, y, z, qw, qx, qy, qz, r95, , extrapolating] = line.split(",").map(Number);
      const { position, orientation } = rows[i].tip.pose;
      worstMm = Math.max(worstMm, Math.hypot(position.x * 1e3 - x, position.y * 1e3 - y, position.z * 1e3 - z));
      const d = (sign) => Math.hypot(orientation.w - sign * qw, orientation.x - sign * qx, orientation.y - sign * qy, orientation.z - sign * qz);
      worstQ = Math.max(worstQ, Math.min(d(1), d(-1)));
      worstR95 = Math.max(worstR95, Math.abs(rows[i].uncertainty.r95_mm - r95));
      if (rows[i].uncertainty.extrapolating !== (extrapolating === 1)) fail(`row ${i + 1}: the extrapolation flag differs from --replay's`);
    });
    // --replay prints 9 significant digits of the same float32 estimate.
    if (!(worstMm <= 1e-3)) fail(`tip position differs from --replay by up to ${worstMm} mm`);
    if (!(worstQ <= 1e-6)) fail(`tip orientation differs from --replay by up to ${worstQ}`);
    if (!(worstR95 <= 1e-5)) fail(`r95 differs from --replay by up to ${worstR95} mm`);
    return { scenes, compared: rows.length, worstMm, worstQ, worstR95 };
  } finally {
    fs.rmSync(dir, { recursive: true, force: true });
  }
}

// Starts `runtime args... --view 0` and resolves, once it prints its
// address, with the child, the port and a promise of its exit ({code,
// signal, stdout, stderr}); rejects when it exits first, cannot start, or
// prints no address in 15 s.
function startServedRuntime(runtime, args) {
  const child = spawn(runtime, [...args, "--view", "0"], { stdio: ["ignore", "pipe", "pipe"] });
  let stdout = "", stderr = "";
  child.stdout.on("data", (d) => (stdout += d));
  const exited = new Promise((resolve) => child.on("close", (code, signal) => resolve({ code, signal, stdout, stderr })));
  const port = new Promise((resolve, reject) => {
    const timer = setTimeout(() => {
      child.kill();
      reject(new CheckError("cdcr-runtime printed no view address in 15 s"));
    }, 15000);
    child.on("error", (e) => reject(new CheckError(`cannot start ${runtime}: ${e.message}`)));
    child.stderr.on("data", (d) => {
      stderr += d;
      const match = /^view: ws:\/\/127\.0\.0\.1:(\d+)/m.exec(stderr);
      if (match) {
        clearTimeout(timer);
        resolve(Number(match[1]));
      }
    });
    exited.then(({ code }) => reject(new CheckError(`cdcr-runtime exited (${code}) before serving: ${stderr.trim()}`)));
  });
  return port.then((p) => ({ child, port: p, exited }));
}

// What a recording of `cdcr-runtime --replay` has: the drives' cables only.
const kReplayTopics = ["/scene", "/tf", "/tip/pose", "/tip/nominal_pose", "/tip/uncertainty", "/cables"];

module.exports = { kChannels, kReplayTopics, startServedRuntime, CheckError, fail, channelValidator, checkValues, timeKey };
