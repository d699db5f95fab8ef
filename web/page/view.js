// The browser view of a running sandbox (docs/reference/web.md): the level's
// model (a binary glTF, once), then states (JSON) that move the robots and the
// movable actors. Z is up, as in the sandbox's world frame.
import * as THREE from '/three/build/three.module.js';
import { OrbitControls } from '/three/examples/jsm/controls/OrbitControls.js';
import { GLTFLoader } from '/three/examples/jsm/loaders/GLTFLoader.js';

const canvas = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true });
renderer.setPixelRatio(window.devicePixelRatio);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x8fb4d8);
scene.add(new THREE.HemisphereLight(0xdde8ff, 0x4a4030, 0.9));
const sun = new THREE.DirectionalLight(0xffffff, 0.7);
sun.position.set(0.4, 0.3, 1.0);
scene.add(sun);
const camera = new THREE.PerspectiveCamera(50, 1, 0.1, 50000);
camera.up.set(0, 0, 1);
camera.position.set(40, -40, 30);
const controls = new OrbitControls(camera, canvas);

// What a test reads (tests/web): the state drawn last and how far along the page is.
const view = { connected: false, levelLoaded: false, tick: -1, framesDrawn: 0, states: 0,
               received: 0, robots: {}, firstFrameMs: null, held: false, camera: null,
               masked: false };
let pendingState = null;  // the newest state, not yet shown
window.sandboxView = view;
// What scripts and tests may call (apart, so that sandboxView stays plain data).
const control = {};
window.sandboxControl = control;

// For tests and scripts: three.js, the scene and the level model.
control.three = THREE;
control.scene = scene;
control.camera = camera;
control.levelModel = () => level;
// Stop (and resume) showing new states.
control.hold = (on) => { view.held = on; };
// Looks from a sandbox camera pose (x forward, y left, z up: p, q as w, x, y,
// z) with a vertical field of view in degrees; null: the mouse's camera again.
control.setCamera = (p, q, fovDeg) => {
  view.camera = p ? { p, q, fovDeg } : null;
  if (!p) return;
  camera.position.set(p[0], p[1], p[2]);
  // three.js looks down its -z with y up: that is the sandbox camera's x
  // forward and z up, so its axes are (-y, z, -x) of the sandbox camera.
  const toGl = new THREE.Quaternion().setFromRotationMatrix(new THREE.Matrix4().set(
    0, 0, -1, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1));
  camera.quaternion.set(q[1], q[2], q[3], q[0]).multiply(toGl);
  camera.fov = fovDeg;
  camera.updateProjectionMatrix();
};
// Draws the robots alone, white on black, unlit (a mask to compare with the
// sandbox's own segmentation image); false: as before.
const maskMaterial = new THREE.MeshBasicMaterial({ color: 0xffffff, skinning: true });
control.mask = (on) => {
  view.masked = on;
  scene.background = new THREE.Color(on ? 0x000000 : 0x8fb4d8);
  document.getElementById('panel').style.display = on ? 'none' : '';
  for (const cloud of sampleClouds.values()) cloud.visible = !on;
  for (const entry of cameraFrusta.values()) entry.group.visible = !on;
  if (!level) return;
  level.traverse((object) => {
    if (object.name === 'axes') object.visible = !on;
    if (!object.isMesh) return;
    let robot = false;
    object.traverseAncestors((a) => { robot = robot || a.name.startsWith('sandbox_robot'); });
    if (!robot) {
      object.visible = !on;
      return;
    }
    if (on && !object.userData.material) object.userData.material = object.material;
    if (object.userData.material) object.material = on ? maskMaterial : object.userData.material;
  });
};

// name -> { index, group, joints }: a robot is the level model's node
// "sandbox_robot<index>" (its meshes skinned to the joint nodes under it,
// which each state places), with axes at its body frame.
const robots = new Map();
let level = null;  // the glTF scene
const follow = document.getElementById('follow');

function robotEntry(name, index) {
  const entry = { index, group: null, joints: [] };
  const option = document.createElement('option');
  option.value = option.textContent = name;
  follow.appendChild(option);
  attachRobot(entry);
  return entry;
}

// Finds the robot's node and joints in the level model (once it has come).
function attachRobot(entry) {
  if (!level || entry.group) return;
  const node = level.getObjectByName('sandbox_robot' + entry.index);
  if (!node) return;
  entry.group = node;
  const axes = new THREE.AxesHelper(2.0);
  axes.name = 'axes';
  node.add(axes);
  node.visible = false;
  for (let k = 0; ; ++k) {
    const joint = node.getObjectByName('sandbox_robot' + entry.index + '_joint' + k);
    if (!joint) break;
    joint.matrixAutoUpdate = false;
    entry.joints.push(joint);
  }
  node.traverse((object) => { if (object.isSkinnedMesh) object.frustumCulled = false; });
}

function place(object, body) {
  object.position.set(body.p[0], body.p[1], body.p[2]);
  object.quaternion.set(body.q[1], body.q[2], body.q[3], body.q[0]);
}

const plot = document.getElementById('plot').getContext('2d');
const history = [];
function drawPlot() {
  const w = plot.canvas.width, h = plot.canvas.height;
  plot.clearRect(0, 0, w, h);
  const top = Math.max(1, ...history.map((s) => Math.max(s.tick_ms, s.late_ms)));
  for (const [key, colour] of [['tick_ms', '#ffffff'], ['late_ms', '#ff6060']]) {
    plot.strokeStyle = colour;
    plot.beginPath();
    history.forEach((s, i) => {
      const x = (i / Math.max(1, history.length - 1)) * w, y = h - (s[key] / top) * (h - 2);
      if (i === 0) plot.moveTo(x, y); else plot.lineTo(x, y);
    });
    plot.stroke();
  }
}

const inputRates = new Map();  // robot -> { at, received, rate }
function showState(state) {
  view.tick = state.tick;
  if (state.player) showPlayer(state.player, state.tick);
  view.states += 1;
  state.robots.forEach((r, index) => {
    if (!robots.has(r.name)) robots.set(r.name, robotEntry(r.name, index));
    const entry = robots.get(r.name);
    attachRobot(entry);
    if (entry.group) {
      entry.group.visible = r.has_pose;
      place(entry.group, r);
      entry.joints.forEach((joint, k) => {
        const m = r.joints.slice(12 * k, 12 * k + 12);
        if (m.length < 12) return;
        joint.matrix.set(m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8], m[9], m[10], m[11],
                         0, 0, 0, 1);
        joint.matrixWorldNeedsUpdate = true;
      });
    }
    view.robots[r.name] = { p: r.p, q: r.q, bones: r.bones, has_pose: r.has_pose,
                            rejected: r.rejected, stale: r.stale,
                            skinned: entry.joints.length > 0 };
  });
  if (level) {
    for (const a of state.actors) {
      const node = level.getObjectByName(a.name);
      if (node) place(node, a);
    }
  }
  document.getElementById('status').textContent =
    `tick ${state.tick}  t ${state.t.toFixed(2)} s  tick ${state.tick_ms.toFixed(2)} ms  late ${state.late_ms.toFixed(2)} ms`;
  // Each robot's input rate: its inputs received over the last second or so of states.
  const now = performance.now();
  document.getElementById('robots').innerHTML = state.robots.map((r) => {
    const seen = inputRates.get(r.name) || { at: now, received: r.received, rate: 0 };
    if (now - seen.at >= 1000) {
      seen.rate = ((r.received - seen.received) * 1000) / (now - seen.at);
      seen.at = now;
      seen.received = r.received;
    }
    inputRates.set(r.name, seen);
    view.robots[r.name].inputsPerSecond = seen.rate;
    return `<tr><td>${r.name}</td><td>${r.has_pose ? 'posed' : 'no pose'}</td>` +
      `<td>${seen.rate.toFixed(0)} inputs/s</td><td>${r.rejected} rejected</td>` +
      `<td>${r.stale.length ? 'stale: ' + r.stale.join(' ') : ''}</td></tr>`;
  }).join('');
  history.push(state);
  if (history.length > 240) history.shift();
  drawPlot();
  const followed = robots.get(follow.value);
  if (followed && followed.group) controls.target.copy(followed.group.position);
}

// The scan samples: a point cloud a sensor, coloured by occupancy (occupied
// red, free green) or by what they hit (a colour a surface id).
let pendingSamples = null;  // the newest samples message, not yet shown
const sampleClouds = new Map();  // "robot/sensor" -> THREE.Points
const colourBy = document.getElementById('colour');
let surfaces = new Map();  // id -> { kind, name }

function levelInfo(info) {
  view.levelName = info.name;
  surfaces = new Map(info.surfaces.map((s) => [s.id, s]));
  // --web-control: the page may steer the cameras.
  document.getElementById('steer').hidden = !info.camera_control;
  if (info.recorded) {
    view.recordedTicks = info.recorded.ticks;
    slider.max = tickInput.max = info.recorded.ticks - 1;
    document.getElementById('recorded').textContent =
      `${info.recorded.ticks} ticks, ${info.recorded.duration_s.toFixed(1)} s: ${info.recorded.log}`;
    document.getElementById('player').hidden = false;
  }
}

// A recorded run's player (sandbox view): its commands go to the sandbox,
// which moves one playhead for every page; the states say where it is.
const slider = document.getElementById('slider'), tickInput = document.getElementById('tick');
const playButton = document.getElementById('play'), speedSelect = document.getElementById('speed');
let socket = null, sliding = false;
// Sends a message to the sandbox; false (nothing sent) until the page is connected.
function send(message) {
  if (!socket || socket.readyState !== WebSocket.OPEN) return false;
  socket.send(JSON.stringify(message));
  return true;
}
function command(fields) {
  return send(Object.assign({ type: 'player' }, fields));
}
control.player = command;
// Steers the cameras as the live view's keys do (sandbox run --web-control).
control.steer = (key) => send({ type: 'camera', key });
for (const button of document.querySelectorAll('#steer button')) {
  button.addEventListener('click', () => control.steer(button.dataset.key));
}
playButton.addEventListener('click', () => command({ play: !view.playing }));
speedSelect.addEventListener('change', () => command({ speed: Number(speedSelect.value) }));
slider.addEventListener('input', () => { sliding = true; tickInput.value = slider.value; });
slider.addEventListener('change', () => { sliding = false; command({ seek: Number(slider.value) }); });
tickInput.addEventListener('change', () => command({ seek: Math.max(0, Math.floor(Number(tickInput.value))) }));

function showPlayer(player, tick) {
  view.playing = player.playing;
  playButton.textContent = player.playing ? 'pause' : 'play';
  if (!sliding) slider.value = tick;
  if (document.activeElement !== tickInput) tickInput.value = tick;
  if (document.activeElement !== speedSelect) speedSelect.value = String(player.speed);
}

function surfaceColour(id, colour) {
  if (id === 0) return colour.setRGB(0.5, 0.5, 0.5);
  // Golden-ratio hues: neighbouring ids far apart.
  return colour.setHSL((id * 0.618034) % 1, 0.75, 0.55);
}

// Which samples are drawn (and picked): all, the hits only (an index of
// them), or none.
const shownSamples = document.getElementById('shown');
function colourSamples(cloud) {
  const { hit, surface } = cloud.userData;
  const colours = cloud.geometry.getAttribute('color');
  const c = new THREE.Color();
  if (shownSamples.value === 'hits') {
    const hits = [];
    for (let i = 0; i < hit.length; ++i) if (hit[i]) hits.push(i);
    cloud.geometry.setIndex(hits);
  } else {
    cloud.geometry.setIndex(null);
  }
  for (let i = 0; i < hit.length; ++i) {
    if (colourBy.value === 'surface') surfaceColour(surface[i], c);
    else if (hit[i]) c.setRGB(0.95, 0.2, 0.15);
    else c.setRGB(0.2, 0.85, 0.3);
    colours.setXYZ(i, c.r, c.g, c.b);
  }
  colours.needsUpdate = true;
  cloud.visible = shownSamples.value !== 'none' && !view.masked;
}

function showSamples(buffer) {
  const length = new DataView(buffer).getUint32(4, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 8, length)));
  let offset = 8 + length;
  const seen = new Set();
  view.samples = {};
  for (const set of header.sets) {
    const n = set.count, key = set.robot + '/' + set.sensor;
    const xyz = new Float32Array(buffer, offset, 3 * n);
    offset += 12 * n;
    const surface = new Int32Array(buffer, offset, n);
    offset += 4 * n;
    const hit = new Uint8Array(buffer, offset, n);
    offset += (n + 3) & ~3;
    let cloud = sampleClouds.get(key);
    if (!cloud) {
      cloud = new THREE.Points(new THREE.BufferGeometry(),
                               new THREE.PointsMaterial({ size: 2, sizeAttenuation: false,
                                                          vertexColors: THREE.VertexColors }));
      cloud.name = 'samples:' + key;
      cloud.frustumCulled = false;
      sampleClouds.set(key, cloud);
      scene.add(cloud);
    }
    cloud.geometry.setAttribute('position', new THREE.BufferAttribute(xyz, 3));
    cloud.geometry.boundingSphere = null;  // recomputed for these (picking needs it)
    cloud.geometry.setAttribute('color', new THREE.BufferAttribute(new Float32Array(3 * n), 3));
    cloud.position.set(header.origin[0], header.origin[1], header.origin[2]);
    cloud.userData = { hit, surface, set, tick: header.tick };
    colourSamples(cloud);
    seen.add(key);
    view.samples[key] = { count: n, hits: hit.reduce((a, b) => a + b, 0), tick: header.tick };
  }
  for (const [key, cloud] of sampleClouds) {
    cloud.visible = seen.has(key) && !view.masked && shownSamples.value !== 'none';
  }
}
for (const select of [colourBy, shownSamples]) {
  select.addEventListener('change', () => { for (const cloud of sampleClouds.values()) colourSamples(cloud); });
}

// The cameras: each one's frustum, 6 m deep, at the pose its latest frame
// was rendered from, with that frame on its far end.
const cameraFrusta = new Map();  // name -> { group, image, texture }
const toGlCamera = new THREE.Quaternion().setFromRotationMatrix(new THREE.Matrix4().set(
  0, 0, -1, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1));
view.cameras = {};

function cameraFrustum(name) {
  const group = new THREE.Group();
  group.name = 'camera:' + name;
  const lines = new THREE.LineSegments(new THREE.BufferGeometry(),
                                       new THREE.LineBasicMaterial({ color: 0xffe060 }));
  const texture = new THREE.Texture();
  texture.minFilter = THREE.LinearFilter;  // any size: no mipmaps
  texture.generateMipmaps = false;
  const image = new THREE.Mesh(new THREE.PlaneBufferGeometry(1, 1),
                               new THREE.MeshBasicMaterial({ map: texture, side: THREE.DoubleSide }));
  group.add(lines, image);
  scene.add(group);
  const entry = { group, lines, image, texture };
  cameraFrusta.set(name, entry);
  return entry;
}

function showCameraFrame(buffer) {
  if (view.held) return;
  const length = new DataView(buffer).getUint32(4, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 8, length)));
  const jpeg = new Blob([new Uint8Array(buffer, 8 + length)], { type: 'image/jpeg' });
  const entry = cameraFrusta.get(header.camera) || cameraFrustum(header.camera);
  // In three.js's camera axes (x right, y up, looking down -z): the far end at z = -depth.
  const depth = 6, h = depth * Math.tan((header.fov_y_deg * Math.PI) / 360);
  const w = (h * header.width) / header.height;
  const corners = [[-w, -h], [w, -h], [w, h], [-w, h]].map(([x, y]) => [x, y, -depth]);
  const points = [];
  for (let i = 0; i < 4; ++i) points.push(0, 0, 0, ...corners[i], ...corners[i], ...corners[(i + 1) % 4]);
  entry.lines.geometry.setAttribute('position', new THREE.Float32BufferAttribute(points, 3));
  entry.image.scale.set(2 * w, 2 * h, 1);
  entry.image.position.set(0, 0, -depth);
  entry.group.position.set(header.p[0], header.p[1], header.p[2]);
  entry.group.quaternion.set(header.q[1], header.q[2], header.q[3], header.q[0]).multiply(toGlCamera);
  entry.group.visible = !view.masked;
  const shown = { tick: header.tick, bytes: jpeg.size, width: header.width, height: header.height,
                  p: header.p, q: header.q, fovDeg: header.fov_y_deg, decoded: false };
  view.cameras[header.camera] = shown;
  // WebGL does not flip an ImageBitmap on upload: flipped here, as three.js
  // would an image (the frame's top row at the plane's top).
  createImageBitmap(jpeg, { imageOrientation: 'flipY' }).then((bitmap) => {
    entry.texture.flipY = false;
    entry.texture.image = bitmap;
    entry.texture.needsUpdate = true;
    shown.decoded = bitmap.width === header.width && bitmap.height === header.height;
  });
}

// Draws one camera's latest frame alone, on black (its frustum's lines
// hidden): a test looks through it from the camera's own pose. null: all again.
control.cameraOnly = (name) => {
  view.masked = name !== null;
  scene.background = new THREE.Color(name !== null ? 0x000000 : 0x8fb4d8);
  document.getElementById('panel').style.display = name !== null ? 'none' : '';
  scene.traverse((object) => {
    if (object.isMesh || object.isPoints || object.isLine || object.name === 'axes') {
      let visible = name === null;
      object.traverseAncestors((a) => { if (a.name === 'camera:' + name) visible = object.isMesh; });
      object.visible = visible;
    }
  });
  for (const entry of cameraFrusta.values()) entry.group.visible = true;
};

// Pick: a click on a sample shows what it is.
const picker = new THREE.Raycaster();
picker.params.Points.threshold = 0.5;
canvas.addEventListener('click', (event) => {
  const rect = canvas.getBoundingClientRect();
  const ndc = new THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1,
                                -((event.clientY - rect.top) / rect.height) * 2 + 1);
  view.picked = pick(ndc);
});

// The sample nearest the camera under normalised device coordinates ndc,
// or null; shown in the panel.
function pick(ndc) {
  picker.setFromCamera(ndc, camera);
  const clouds = [...sampleClouds.values()].filter((c) => c.visible);
  const hit = picker.intersectObjects(clouds)[0];
  const out = document.getElementById('picked');
  if (!hit) {
    out.textContent = '';
    return null;
  }
  const { userData } = hit.object, i = hit.index;
  const p = hit.object.geometry.getAttribute('position');
  const o = hit.object.position;
  const sample = { robot: userData.set.robot, sensor: userData.set.sensor, type: userData.set.type,
                   index: i, tick: userData.tick, hit: userData.hit[i] === 1,
                   surface: userData.surface[i],
                   p: [p.getX(i) + o.x, p.getY(i) + o.y, p.getZ(i) + o.z] };
  const s = surfaces.get(sample.surface);
  sample.surfaceName = s ? s.name : '';
  out.textContent = `${sample.robot}/${sample.sensor} #${i} (tick ${sample.tick}): ` +
    `${sample.hit ? 'hit ' + (sample.surfaceName || 'surface ' + sample.surface) : 'free'} at ` +
    sample.p.map((v) => v.toFixed(2)).join(', ');
  return sample;
}
control.pick = (x, y) => pick(new THREE.Vector2(x, y));

function frameLevel(object) {
  const box = new THREE.Box3().setFromObject(object);
  if (box.isEmpty()) return;
  const centre = box.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3()).length();
  controls.target.copy(centre);
  camera.position.copy(centre).add(new THREE.Vector3(0.5, -0.6, 0.45).multiplyScalar(size));
  camera.far = Math.max(1000, size * 10);
  camera.updateProjectionMatrix();
}

function connect() {
  socket = new WebSocket(`ws://${location.host}/stream`);
  socket.binaryType = 'arraybuffer';
  socket.onopen = () => { view.connected = true; };
  socket.onclose = () => {
    view.connected = false;
    document.getElementById('status').textContent = 'disconnected; retrying';
    setTimeout(connect, 1000);
  };
  socket.onmessage = (event) => {
    if (typeof event.data === 'string') {
      const message = JSON.parse(event.data);
      if (message.type === 'level') {
        levelInfo(message);
        return;
      }
      // Kept as it came: the newest is shown once a drawn frame (a page drawing
      // slower than states arrive skips the ones between).
      pendingState = message;
      view.received += 1;
      return;
    }
    const magic = new TextDecoder().decode(new Uint8Array(event.data, 0, 4));
    if (magic === 'SMPL') {
      pendingSamples = event.data;
      return;
    }
    if (magic === 'CAMF') {
      showCameraFrame(event.data);
      return;
    }
    new GLTFLoader().parse(event.data, '', (gltf) => {
      if (level) scene.remove(level);
      level = gltf.scene;
      scene.add(level);
      for (const entry of robots.values()) { entry.group = null; entry.joints = []; attachRobot(entry); }
      frameLevel(level);
      view.levelLoaded = true;
    }, (error) => { document.getElementById('status').textContent = 'bad level model: ' + error; });
  };
}

function resize() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  if (canvas.width !== w || canvas.height !== h) {
    renderer.setSize(w, h, false);
    camera.aspect = w / Math.max(1, h);
    camera.updateProjectionMatrix();
  }
}

function animate() {
  requestAnimationFrame(animate);
  if (pendingState !== null && !view.held) {
    showState(pendingState);
    pendingState = null;
  }
  if (pendingSamples !== null && !view.held) {
    showSamples(pendingSamples);
    pendingSamples = null;
  }
  resize();
  if (!view.camera) controls.update();
  renderer.render(scene, camera);
  view.framesDrawn += 1;
  // From the page's navigation (performance.now()'s origin) to its first frame with the level.
  if (view.firstFrameMs === null && view.levelLoaded) view.firstFrameMs = performance.now();
}
connect();
animate();
