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
               received: 0, robots: {}, firstFrameMs: null };
let pendingState = null;  // the newest state's text, not yet shown
window.sandboxView = view;

const robots = new Map();  // name -> marker
let level = null;          // the glTF scene
const follow = document.getElementById('follow');

function robotMarker(name) {
  const marker = new THREE.Group();
  marker.name = 'robot:' + name;
  marker.add(new THREE.Mesh(new THREE.BoxGeometry(1.0, 0.5, 0.25),
                            new THREE.MeshLambertMaterial({ color: 0xf0a020 })));
  marker.add(new THREE.AxesHelper(2.0));
  scene.add(marker);
  const option = document.createElement('option');
  option.value = option.textContent = name;
  follow.appendChild(option);
  return marker;
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

function showState(state) {
  view.tick = state.tick;
  view.states += 1;
  for (const r of state.robots) {
    if (!robots.has(r.name)) robots.set(r.name, robotMarker(r.name));
    const marker = robots.get(r.name);
    marker.visible = r.has_pose;
    place(marker, r);
    view.robots[r.name] = { p: r.p, q: r.q, has_pose: r.has_pose, rejected: r.rejected, stale: r.stale };
  }
  if (level) {
    for (const a of state.actors) {
      const node = level.getObjectByName(a.name);
      if (node) place(node, a);
    }
  }
  document.getElementById('status').textContent =
    `tick ${state.tick}  t ${state.t.toFixed(2)} s  tick ${state.tick_ms.toFixed(2)} ms  late ${state.late_ms.toFixed(2)} ms`;
  document.getElementById('robots').innerHTML = state.robots.map((r) =>
    `<tr><td>${r.name}</td><td>${r.has_pose ? 'posed' : 'no pose'}</td><td>${r.rejected} rejected</td>` +
    `<td>${r.stale.length ? 'stale: ' + r.stale.join(' ') : ''}</td></tr>`).join('');
  history.push(state);
  if (history.length > 240) history.shift();
  drawPlot();
  const followed = robots.get(follow.value);
  if (followed) controls.target.copy(followed.position);
}

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
  const socket = new WebSocket(`ws://${location.host}/stream`);
  socket.binaryType = 'arraybuffer';
  socket.onopen = () => { view.connected = true; };
  socket.onclose = () => {
    view.connected = false;
    document.getElementById('status').textContent = 'disconnected; retrying';
    setTimeout(connect, 1000);
  };
  socket.onmessage = (event) => {
    if (typeof event.data === 'string') {
      // Kept as it came: the newest is read once a drawn frame (a page drawing
      // slower than states arrive skips the ones between).
      pendingState = event.data;
      view.received += 1;
      return;
    }
    new GLTFLoader().parse(event.data, '', (gltf) => {
      if (level) scene.remove(level);
      level = gltf.scene;
      scene.add(level);
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

const started = performance.now();
function animate() {
  requestAnimationFrame(animate);
  if (pendingState !== null) {
    showState(JSON.parse(pendingState));
    pendingState = null;
  }
  resize();
  controls.update();
  renderer.render(scene, camera);
  view.framesDrawn += 1;
  if (view.firstFrameMs === null && view.levelLoaded) view.firstFrameMs = performance.now() - started;
}
connect();
animate();
