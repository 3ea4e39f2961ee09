// The project's page draws the robot where it is: a screenshot of the page
// (screenshot.js) taken while cdcr-runtime runs its targets, and the very
// scene it drew, received by the reference client (@foxglove/ws-protocol).
// Every backbone point, projected with the page's camera, must be painted;
// points well away from every entity, and the corners, must be background.
//
//   node check_screenshot.js --runtime build/bin/cdcr-runtime --image model.img --out view.png
'use strict';
const fs = require('fs');
const { FoxgloveClient } = require('@foxglove/ws-protocol');
const { PNG } = require('pngjs');
const WebSocket = require('ws');
const { openBrowser } = require('./screenshot');
const { startServedRuntime } = require('./view_checks');

// view.js's BACKGROUND, and how far an antialiased pixel may stray from it.
const BACKGROUND = [0xf2, 0xf2, 0xf2];
const BACKGROUND_TOLERANCE = 3;
// Off centre, so that a mirrored axis moves the robot by 100 px.
const CAMERA = { width: 800, height: 600, cx: 0.05, cz: 0.25, ppm: 1000 };
// Background points are this many pixels outside every primitive.
const CLEARANCE_PX = 20;

function option(name) {
  const i = process.argv.indexOf(`--${name}`);
  if (i < 0 || !process.argv[i + 1]) throw new Error(`--${name} is required (--runtime PATH --image PATH --out PNG)`);
  return process.argv[i + 1];
}

const pixelOf = ({ x, z }) => [CAMERA.width / 2 + (x - CAMERA.cx) * CAMERA.ppm, CAMERA.height / 2 - (z - CAMERA.cz) * CAMERA.ppm];

// A point of a primitive's frame in the scene's frame.
function transform(pose, p) {
  const { x: qx, y: qy, z: qz, w: qw } = pose.orientation;
  const tx = 2 * (qy * p.z - qz * p.y), ty = 2 * (qz * p.x - qx * p.z), tz = 2 * (qx * p.y - qy * p.x);
  return { x: pose.position.x + p.x + qw * tx + (qy * tz - qz * ty),
           y: pose.position.y + p.y + qw * ty + (qz * tx - qx * tz),
           z: pose.position.z + p.z + qw * tz + (qx * ty - qy * tx) };
}

// Every primitive as image segments (a sphere: one of length 0) with a radius.
function primitives(update) {
  const out = [];
  for (const entity of update.entities) {
    for (const line of entity.lines) {
      const points = line.points.map((p) => pixelOf(transform(line.pose, p)));
      for (let i = 0; i + 1 < points.length; ++i) out.push({ a: points[i], b: points[i + 1], r: (line.thickness / 2) * CAMERA.ppm });
    }
    for (const sphere of entity.spheres) {
      const c = pixelOf(sphere.pose.position);
      out.push({ a: c, b: c, r: (Math.max(sphere.size.x, sphere.size.y, sphere.size.z) / 2) * CAMERA.ppm });
    }
  }
  return out;
}

function distanceToSegment([px, py], { a: [ax, ay], b: [bx, by] }) {
  const dx = bx - ax, dy = by - ay, length2 = dx * dx + dy * dy;
  const t = length2 > 0 ? Math.min(1, Math.max(0, ((px - ax) * dx + (py - ay) * dy) / length2)) : 0;
  return Math.hypot(px - ax - t * dx, py - ay - t * dy);
}

function checkPicture(png, update) {
  if (png.width !== CAMERA.width || png.height !== CAMERA.height) {
    throw new Error(`the screenshot is ${png.width}x${png.height}, not ${CAMERA.width}x${CAMERA.height}`);
  }
  const isBackground = (x, y) => {
    const i = 4 * (Math.round(y) * png.width + Math.round(x));
    return BACKGROUND.every((c, k) => Math.abs(png.data[i + k] - c) <= BACKGROUND_TOLERANCE);
  };
  const inside = ([x, y]) => x >= 0 && y >= 0 && x <= png.width - 1 && y <= png.height - 1;

  // The backbone: each point and, as far as the line is wide, 2 px around it.
  const backbone = update.entities.find((e) => e.id === 'backbone');
  if (!backbone) throw new Error('the scene has no backbone entity');
  const robot = [];
  for (const line of backbone.lines) {
    const reach = Math.max(0, Math.min(2, Math.floor((line.thickness / 2) * CAMERA.ppm - 1)));
    for (const p of line.points) robot.push({ at: pixelOf(transform(line.pose, p)), reach });
  }
  const missed = robot.filter(({ at: [x, y], reach }) => {
    if (!inside([x, y])) return true;
    for (const [dx, dy] of [[0, 0], [reach, 0], [-reach, 0], [0, reach], [0, -reach]]) {
      if (!inside([x + dx, y + dy]) || isBackground(x + dx, y + dy)) return true;
    }
    return false;
  });

  // The background: the corners and a grid, less what is near any primitive.
  const shapes = primitives(update);
  const empty = [[0, 0], [png.width - 1, 0], [0, png.height - 1], [png.width - 1, png.height - 1]];
  for (let y = 20; y < png.height; y += 40) for (let x = 20; x < png.width; x += 40) empty.push([x, y]);
  const far = empty.filter((p) => shapes.every((s) => distanceToSegment(p, s) > s.r + CLEARANCE_PX));
  const painted = far.filter(([x, y]) => !isBackground(x, y));
  return { robot, missed, far, painted };
}

async function main() {
  const [runtimePath, image, out] = [option('runtime'), option('image'), option('out')];
  if (!fs.existsSync(image)) throw new Error(`no image at ${image}`);
  let runtime = null, client = null, browser = null;
  try {
    // Chromium first, then a run long enough for a loaded host's browser to
    // start drawing (random targets, in real time while served), stopped
    // once the picture is checked.
    browser = await openBrowser({ width: CAMERA.width, height: CAMERA.height });
    const served = await startServedRuntime(runtimePath, ['--image', image, '--sim', '--seconds', '120']);
    runtime = served.child;
    const port = served.port;

    // The reference client's copy of every scene, by its time.
    const url = `ws://127.0.0.1:${port}`;
    const scenes = new Map();
    client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
    await new Promise((resolve, reject) => {
      const timer = setTimeout(() => reject(new Error(`no scene from ${url} in 10 s`)), 10000);
      let subscription = null;
      client.on('error', (e) => reject(new Error(`the client: ${e.message || e}`)));
      client.on('advertise', (channels) => {
        const channel = channels.find((c) => c.topic === '/scene');
        if (channel && subscription === null) subscription = client.subscribe(channel.id);
      });
      client.on('message', ({ subscriptionId, timestamp, data }) => {
        if (subscriptionId !== subscription) return;
        scenes.set(BigInt(timestamp), JSON.parse(Buffer.from(data.buffer, data.byteOffset, data.byteLength).toString()));
        clearTimeout(timer);
        resolve();
      });
    });

    const sceneTime = await browser.capture({ ws: url, out, ...CAMERA });
    const update = scenes.get(BigInt(sceneTime.sec) * 1000000000n + BigInt(sceneTime.nsec));
    const when = `${sceneTime.sec}.${String(sceneTime.nsec).padStart(9, '0')}`;
    if (!update) throw new Error(`the page drew a scene at ${when} s that the client never received`);

    const { robot, missed, far, painted } = checkPicture(PNG.sync.read(fs.readFileSync(out)), update);
    console.log(`check_screenshot: scene at ${when} s (${scenes.size} received): ${robot.length - missed.length} of ` +
      `${robot.length} backbone points drawn, ${far.length - painted.length} of ${far.length} points away from every entity background`);
    if (missed.length) {
      throw new Error(`${missed.length} backbone points not drawn, first at pixel (${missed[0].at.map(Math.round)}) in ${out}`);
    }
    if (painted.length) throw new Error(`${painted.length} points away from every entity painted, first at (${painted[0]}) in ${out}`);
    if (far.length < 100) throw new Error(`only ${far.length} background points: the scene covers the picture`);

    // Still running: it served the whole time.
    if (runtime.exitCode !== null) throw new Error(`cdcr-runtime exited with ${runtime.exitCode} before the check ended`);
  } finally {
    if (client) client.close();
    if (runtime && runtime.exitCode === null && runtime.signalCode === null) runtime.kill('SIGTERM');
    if (browser) await browser.close();
  }
}

main().then(() => process.exit(0), (e) => {
  console.error(`check_screenshot: ${e.message}`);
  process.exit(1);
});
