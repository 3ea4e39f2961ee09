// The robot's scene (/scene, foxglove.SceneUpdate) drawn with three.js, seen
// from the front: an orthographic camera looking along +y, world +x to the
// right and +z up. The page speaks just enough of the Foxglove WebSocket
// protocol (JSON encoding) for that one topic.
//
// In a desktop browser: serve this directory with three at /three/, e.g.
//   node tools/view/clients/screenshot.js --serve
// start `cdcr-runtime ... --view 0`, and open the printed address with
//   ?ws=ws://127.0.0.1:PORT&cx=0&cz=0.25&ppm=1000
// (cx, cz: the metres at the window's centre; ppm: pixels per metre).
//
// window.cdcrView = {scenes, sceneTime} counts the scenes drawn and gives the
// last one's time; setting window.cdcrView.frozen = true stops drawing, so a
// screenshot shows exactly the scene of sceneTime.
import * as THREE from '/three/build/three.module.js';

// The background, uniform: check_screenshot.js tells the robot from it (and
// holds the same value).
export const BACKGROUND = 0xf2f2f2;

const params = new URLSearchParams(location.search);
const number = (name, fallback) => (params.has(name) ? Number(params.get(name)) : fallback);
const cx = number('cx', 0), cz = number('cz', 0.25), ppm = number('ppm', 1000);
const status = document.getElementById('status');

const renderer = new THREE.WebGLRenderer({ antialias: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setClearColor(BACKGROUND);
document.body.appendChild(renderer.domElement);

const scene = new THREE.Scene();
scene.add(new THREE.AmbientLight(0xffffff, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
sun.position.set(-1, -2, 1.5); // from the camera's side, upper left
scene.add(sun);

const camera = new THREE.OrthographicCamera();
camera.up.set(0, 0, 1);
camera.position.set(cx, -10, cz);
camera.lookAt(cx, 0, cz);
camera.near = 1;
camera.far = 20;

function resize() {
  const w = window.innerWidth, h = window.innerHeight;
  renderer.setSize(w, h);
  Object.assign(camera, { left: -w / 2 / ppm, right: w / 2 / ppm, top: h / 2 / ppm, bottom: -h / 2 / ppm });
  camera.updateProjectionMatrix();
  requestDraw();
}

// Every solid primitive is an instance of one of two meshes, a unit cylinder
// along +y and a unit ball: two draw calls a frame, as SwiftShader (headless
// Chromium's WebGL) spends its time per call. Translucent spheres are meshes
// of their own, drawn after the solid.
const CAPACITY = 4096; // instances of each; more are not drawn
function instanced(geometry) {
  const mesh = new THREE.InstancedMesh(geometry, new THREE.MeshLambertMaterial(), CAPACITY);
  mesh.instanceMatrix.setUsage(THREE.DynamicDrawUsage);
  mesh.frustumCulled = false; // its bounds are the unit geometry's, not the instances'
  mesh.count = 0;
  scene.add(mesh);
  return mesh;
}
const ball = new THREE.SphereGeometry(0.5, 20, 12);
const pieces = instanced(new THREE.CylinderGeometry(0.5, 0.5, 1, 20)), balls = instanced(ball);
const translucent = new THREE.Group();
scene.add(translucent);

const yAxis = new THREE.Vector3(0, 1, 0);
const vector = (p) => new THREE.Vector3(p.x, p.y, p.z);
const srgb = ({ r, g, b }) => new THREE.Color().setRGB(r, g, b, THREE.SRGBColorSpace);
const poseMatrix = ({ position: p, orientation: q }) =>
  new THREE.Matrix4().compose(vector(p), new THREE.Quaternion(q.x, q.y, q.z, q.w), new THREE.Vector3(1, 1, 1));

function add(mesh, frame, position, quaternion, scale, color) {
  if (mesh.count >= CAPACITY) return;
  mesh.setMatrixAt(mesh.count, frame.clone().multiply(new THREE.Matrix4().compose(position, quaternion, scale)));
  mesh.setColorAt(mesh.count, color);
  mesh.count += 1;
}

// WebGL draws lines 1 px wide, so each piece of a line is a cylinder of the
// line's thickness, with a ball at each point to round the joints (a little
// narrower than the line, so that the cylinders hide the balls' facets). A
// line's alpha is not drawn.
function addLine(line) {
  const frame = poseMatrix(line.pose), color = srgb(line.color);
  const d = line.scale_invariant ? line.thickness / ppm : line.thickness; // pixels, or metres
  const points = line.points.map(vector);
  const step = line.type === 2 ? 2 : 1; // LINE_LIST: pairs; LINE_STRIP, LINE_LOOP: a chain
  const pairs = [];
  for (let i = 0; i + 1 < points.length; i += step) pairs.push([points[i], points[i + 1]]);
  if (line.type === 1 && points.length > 2) pairs.push([points[points.length - 1], points[0]]);
  for (const [a, b] of pairs) {
    const length = a.distanceTo(b);
    if (!(length > 0)) continue;
    const direction = new THREE.Quaternion().setFromUnitVectors(yAxis, b.clone().sub(a).divideScalar(length));
    add(pieces, frame, a.clone().add(b).multiplyScalar(0.5), direction, new THREE.Vector3(d, length, d), color);
  }
  const joint = new THREE.Vector3(d, d, d).multiplyScalar(0.95);
  for (const p of points) add(balls, frame, p, new THREE.Quaternion(), joint, color);
}

function addSphere({ pose, size, color }) {
  if (color.a >= 1) return add(balls, poseMatrix(pose), new THREE.Vector3(), new THREE.Quaternion(), vector(size), srgb(color));
  const mesh = new THREE.Mesh(ball, new THREE.MeshLambertMaterial({ color: srgb(color), transparent: true, opacity: color.a, depthWrite: false }));
  mesh.applyMatrix4(poseMatrix(pose));
  mesh.scale.copy(vector(size));
  translucent.add(mesh);
}

// The entities by id, each redrawn whole; all in the frame "base", the world here.
const entities = new Map();
let pendingTime = null;
function applySceneUpdate(update, time) {
  for (const deletion of update.deletions) {
    if (deletion.type === 1) entities.clear();
    else entities.delete(deletion.id);
  }
  for (const entity of update.entities) entities.set(entity.id, entity);
  pieces.count = balls.count = 0;
  translucent.children.forEach((mesh) => mesh.material.dispose());
  translucent.clear();
  for (const entity of entities.values()) {
    entity.lines.forEach(addLine);
    entity.spheres.forEach(addSphere);
  }
  for (const mesh of [pieces, balls]) {
    mesh.instanceMatrix.needsUpdate = true;
    if (mesh.instanceColor) mesh.instanceColor.needsUpdate = true;
  }
  pendingTime = time;
  requestDraw();
}

window.cdcrView = { scenes: 0, sceneTime: null, frozen: false };
let drawQueued = false;
function requestDraw() {
  if (drawQueued) return;
  drawQueued = true;
  requestAnimationFrame(() => {
    drawQueued = false;
    renderer.render(scene, camera);
    if (pendingTime) {
      window.cdcrView.scenes += 1;
      window.cdcrView.sceneTime = pendingTime;
      pendingTime = null;
    }
  });
}

// The Foxglove WebSocket protocol: JSON ops as text, messages as binary
// frames (op 0x01, u32 subscription id, u64 time ns, then the payload).
function connect(url) {
  const ws = new WebSocket(url, ['foxglove.websocket.v1']);
  ws.binaryType = 'arraybuffer';
  const sceneSubscription = 1;
  const text = new TextDecoder();
  ws.onmessage = (event) => {
    if (typeof event.data === 'string') {
      const op = JSON.parse(event.data);
      const channel = op.op === 'advertise' && op.channels.find((c) => c.topic === '/scene');
      if (channel) {
        ws.send(JSON.stringify({ op: 'subscribe', subscriptions: [{ id: sceneSubscription, channelId: channel.id }] }));
      }
      return;
    }
    const frame = new DataView(event.data);
    if (frame.getUint8(0) !== 0x01 || frame.getUint32(1, true) !== sceneSubscription) return;
    if (window.cdcrView.frozen) return;
    const ns = frame.getBigUint64(5, true);
    status.hidden = true;
    applySceneUpdate(JSON.parse(text.decode(new Uint8Array(event.data, 13))),
                     { sec: Number(ns / 1000000000n), nsec: Number(ns % 1000000000n) });
  };
  ws.onerror = () => console.error(`view: WebSocket error on ${url}`);
  ws.onclose = () => {
    if (window.cdcrView.frozen) return;
    status.hidden = false;
    status.textContent = `${url}: closed`;
  };
}

window.addEventListener('resize', resize);
resize();
if (params.has('ws')) connect(params.get('ws'));
else status.textContent = 'no ?ws=ws://HOST:PORT given';
