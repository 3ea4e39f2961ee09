// The robot's scene (/scene, foxglove.SceneUpdate) drawn with three.js, seen
// from the front: an orthographic camera looking along +y, world +x to the
// right and +z up. The page speaks just enough of the Foxglove WebSocket
// protocol (JSON encoding) for that one topic.
//
// In a desktop browser: serve this directory with three at /three/, e.g.
//   node tools/view/clients/screenshot.js --serve
// start `cdcr-runtime ... --view 0`, and open the printed address with
//   ?ws=ws://localhost:PORT&cx=0&cz=0.25&ppm=1000
// (cx, cz: the metres at the window's centre; ppm: pixels per metre).
//
// window.cdcrView = {scenes, sceneTime} counts the scenes drawn and gives the
// last one's time; setting window.cdcrView.frozen = true stops drawing, so a
// screenshot shows exactly the scene of sceneTime.
import * as THREE from '/three/build/three.module.js';

// The background the screenshot test tells the robot from (check_screenshot.js).
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

// Unit primitives scaled per instance: a cylinder along +y and a sphere, both
// of diameter 1.
const cylinder = new THREE.CylinderGeometry(0.5, 0.5, 1, 20);
const ball = new THREE.SphereGeometry(0.5, 32, 16);
const yAxis = new THREE.Vector3(0, 1, 0);

function material({ r, g, b, a }) {
  const color = new THREE.Color().setRGB(r, g, b, THREE.SRGBColorSpace);
  return new THREE.MeshLambertMaterial({ color, transparent: a < 1, opacity: a, depthWrite: a >= 1 });
}

function place(object, pose) {
  const { position: p, orientation: q } = pose;
  object.position.set(p.x, p.y, p.z);
  object.quaternion.set(q.x, q.y, q.z, q.w);
}

// WebGL draws lines 1 px wide, so each piece of a line is a cylinder of the
// line's thickness, with a ball at each point to round the joints.
function addLine(group, line) {
  const lineGroup = new THREE.Group();
  place(lineGroup, line.pose);
  const mat = material(line.color);
  const points = line.points.map((p) => new THREE.Vector3(p.x, p.y, p.z));
  const d = line.thickness;
  const pairs = [];
  if (line.type === 2) for (let i = 0; i + 1 < points.length; i += 2) pairs.push([points[i], points[i + 1]]);
  else for (let i = 0; i + 1 < points.length; ++i) pairs.push([points[i], points[i + 1]]);
  if (line.type === 1 && points.length > 2) pairs.push([points[points.length - 1], points[0]]);
  for (const [a, b] of pairs) {
    const length = a.distanceTo(b);
    if (!(length > 0)) continue;
    const piece = new THREE.Mesh(cylinder, mat);
    piece.position.copy(a).add(b).multiplyScalar(0.5);
    piece.quaternion.setFromUnitVectors(yAxis, b.clone().sub(a).divideScalar(length));
    piece.scale.set(d, length, d);
    lineGroup.add(piece);
  }
  for (const p of points) {
    const joint = new THREE.Mesh(ball, mat);
    joint.position.copy(p);
    joint.scale.setScalar(d);
    lineGroup.add(joint);
  }
  group.add(lineGroup);
}

function addSphere(group, sphere) {
  const mesh = new THREE.Mesh(ball, material(sphere.color));
  place(mesh, sphere.pose);
  mesh.scale.set(sphere.size.x, sphere.size.y, sphere.size.z);
  mesh.renderOrder = sphere.color.a < 1 ? 1 : 0; // translucent ones after the solid
  group.add(mesh);
}

// Every entity is in the frame "base", the world here.
const entities = new Map();
function removeEntity(id) {
  const group = entities.get(id);
  if (!group) return;
  group.traverse((o) => o.material && o.material.dispose());
  scene.remove(group);
  entities.delete(id);
}

let pendingTime = null;
function applySceneUpdate(update, time) {
  for (const deletion of update.deletions) {
    if (deletion.type === 1) [...entities.keys()].forEach(removeEntity);
    else removeEntity(deletion.id);
  }
  for (const entity of update.entities) {
    removeEntity(entity.id);
    const group = new THREE.Group();
    entity.lines.forEach((line) => addLine(group, line));
    entity.spheres.forEach((sphere) => addSphere(group, sphere));
    entities.set(entity.id, group);
    scene.add(group);
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
  ws.onerror = () => console.error(`view: cannot connect to ${url}`);
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
