// varslam viewer: the live (or finished) run streamed by the binary as server-sent events on /events.
// Map in three.js (SLAM world: x right, y down, z forward; shown with y up) with the dense map of the static scene as
// a layer of coloured surface points (runs with --dense-map), the current image with its keypoints coloured by fate, stage times, the Local BA alpha per keyframe and the run's events.
import * as THREE from 'three';
import { OrbitControls } from '/three/OrbitControls.js';

// What the page shows, for people reading the DOM and for the browser test.
const status = {
  connected: false, greeted: false, live: true, frames: 0, lastIndex: -1, state: '', maps: 0, points: 0,
  keyframes: 0, marks: 0, drawnMarks: 0, alphas: 0, events: 0, done: false, framesBeforeDone: 0, connections: 0,
  renders: 0, softwareWebGL: false, denseMessages: 0, denseRegions: 0, densePoints: 0, denseVisible: false,
};
window.viewerStatus = status;

const MARK = { UNMATCHED: 0, INLIER: 1, OUTLIER: 2, PERSON: 3 };
const DEPTH_EDGE_BIT = 8;
const MARK_COLOUR = ['#f0d060', '#3ddc84', '#ff3b3b', '#ff4fd8'];

function bytes(b64) {
  const bin = atob(b64 || '');
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; ++i) out[i] = bin.charCodeAt(i);
  return out;
}
const f32 = (b64) => new Float32Array(bytes(b64).buffer);
const i16 = (b64) => new Int16Array(bytes(b64).buffer);
const i32 = (b64) => new Int32Array(bytes(b64).buffer);

// ---------------------------------------------------------------- 3-D scene
const sceneEl = document.getElementById('scene');
// Software WebGL (SwiftShader, llvmpipe: a headless or GPU-less browser) renders on the CPU the SLAM shares: no
// multisampling and one pixel per CSS pixel there.
function softwareWebGL() {
  const gl = document.createElement('canvas').getContext('webgl');
  const info = gl && gl.getExtension('WEBGL_debug_renderer_info');
  const name = info ? String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL)) : '';
  return /swiftshader|llvmpipe|software/i.test(name);
}
const software = softwareWebGL();
status.softwareWebGL = software;
const renderer = new THREE.WebGLRenderer({ antialias: !software, preserveDrawingBuffer: true });
renderer.setPixelRatio(software ? 1 : window.devicePixelRatio);
renderer.setClearColor(0x15181c);
sceneEl.prepend(renderer.domElement);
const scene = new THREE.Scene();
const world = new THREE.Group();  // the SLAM frame: flipped so that its y-down shows as up
world.rotation.x = Math.PI;
scene.add(world);
const camera = new THREE.PerspectiveCamera(60, 1, 0.01, 500);
camera.position.set(0, 2, -4);
const controls = new OrbitControls(camera, renderer.domElement);
controls.addEventListener('change', () => requestRender());
scene.add(new THREE.AxesHelper(0.3));

const pointsGeometry = new THREE.BufferGeometry();
const points = new THREE.Points(pointsGeometry, new THREE.PointsMaterial({ size: 2.5, sizeAttenuation: false, vertexColors: true }));
world.add(points);
const line = (colour, opacity = 1) => {
  const l = new THREE.LineSegments(new THREE.BufferGeometry(),
    new THREE.LineBasicMaterial({ color: colour, transparent: opacity < 1, opacity }));
  world.add(l);
  return l;
};
const keyframeLines = line(0x5b7bff);
const covisibilityLines = line(0x3ddc84, 0.25);
const treeLines = line(0xb46bff, 0.6);
const liveLine = line(0xff9f1c);
const finalLine = line(0x4ea1ff);
const gtLine = line(0xb0b0b0, 0.8);
const cameraLines = line(0x3ddc84);

// ---------------------------------------------------------------- the dense map's layer
// One THREE.Points per region of the map (the server resends a region when its surface changed; none: it is empty).
const denseGroup = new THREE.Group();
world.add(denseGroup);
const denseRegions = new Map();
const denseMaterial = new THREE.PointsMaterial({ size: 0.04, sizeAttenuation: true, vertexColors: true });
// Vertex colours are linear in three.js: the image's sRGB bytes converted once.
const SRGB_TO_LINEAR = Float32Array.from({ length: 256 }, (_, v) => {
  const c = v / 255;
  return c <= 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4;
});

function showDense(d) {
  const old = denseRegions.get(d.key);
  if (old) {
    denseGroup.remove(old);
    old.geometry.dispose();
    denseRegions.delete(d.key);
  }
  if (d.count > 0) {
    const q = i16(d.xyz), rgb = bytes(d.rgb);
    const xyz = new Float32Array(d.count * 3), colours = new Float32Array(d.count * 3);
    for (let i = 0; i < d.count * 3; ++i) {
      xyz[i] = d.origin[i % 3] + q[i] * d.unit;
      colours[i] = SRGB_TO_LINEAR[rgb[i]];
    }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(xyz, 3));
    g.setAttribute('color', new THREE.BufferAttribute(colours, 3));
    g.computeBoundingSphere();
    const pts = new THREE.Points(g, denseMaterial);
    pts.userData.count = d.count;
    denseGroup.add(pts);
    denseRegions.set(d.key, pts);
  }
  denseMaterial.size = d.cell * 1.5;  // overlapping a little: reads as a surface
  document.getElementById('dense-toggle').hidden = false;
  status.denseMessages += 1;
  status.denseRegions = denseRegions.size;
  status.densePoints = 0;
  for (const p of denseRegions.values()) status.densePoints += p.userData.count;
  requestRender();
}

function clearDense() {
  for (const p of denseRegions.values()) p.geometry.dispose();
  denseRegions.clear();
  denseGroup.clear();
  status.denseRegions = status.densePoints = 0;
}

function setSegments(obj, array) {
  obj.geometry.dispose();
  obj.geometry = new THREE.BufferGeometry();
  obj.geometry.setAttribute('position', new THREE.Float32BufferAttribute(array, 3));
}

// A path as segments (a polyline would need a separate object per map segment).
function pathSegments(xyz) {
  const out = [];
  for (let i = 3; i < xyz.length; i += 3) out.push(xyz[i - 3], xyz[i - 2], xyz[i - 1], xyz[i], xyz[i + 1], xyz[i + 2]);
  return out;
}

// Camera frustum in the camera frame, as 8 segments; pose: 9 rotation (row-major) + 3 translation, camera-to-world.
function frustum(out, pose, size) {
  const w = size, h = size * 0.75, d = size * 0.8;
  const local = [[0, 0, 0], [-w, -h, d], [w, -h, d], [w, h, d], [-w, h, d]];
  const p = local.map(([x, y, z]) => [
    pose[0] * x + pose[1] * y + pose[2] * z + pose[9],
    pose[3] * x + pose[4] * y + pose[5] * z + pose[10],
    pose[6] * x + pose[7] * y + pose[8] * z + pose[11]]);
  for (const [a, b] of [[0, 1], [0, 2], [0, 3], [0, 4], [1, 2], [2, 3], [3, 4], [4, 1]]) out.push(...p[a], ...p[b]);
}

let lastMap = null;
let lastPath = null;  // the camera path (final, else live), for framing the view
let currentPose = null;
let fitted = false;

function colourPoints() {
  if (!lastMap) return;
  const p = lastMap.points;
  const n = p.length / 5;
  const colours = new Float32Array(n * 3);
  const byFlagged = document.getElementById('colour-by').value === 'flagged';
  let maxKf = 1;
  for (let i = 0; i < n; ++i) maxKf = Math.max(maxKf, p[i * 5 + 3]);
  const c = new THREE.Color();
  for (let i = 0; i < n; ++i) {
    if (byFlagged) {
      const s = Math.min(1, p[i * 5 + 4] / 0.5);  // half its matches flagged: fully red
      c.setRGB(0.85, 0.85 * (1 - s) + 0.1, 0.85 * (1 - s) + 0.1);
    } else {
      c.setHSL(0.66 * (1 - p[i * 5 + 3] / maxKf), 0.8, 0.55);  // old blue, new red
    }
    colours.set([c.r, c.g, c.b], i * 3);
  }
  pointsGeometry.setAttribute('color', new THREE.BufferAttribute(colours, 3));
}

function showMap(m) {
  const pts = f32(m.points);
  const kfs = f32(m.keyframes);
  lastMap = { points: pts, keyframes: kfs };
  const n = pts.length / 5;
  const xyz = new Float32Array(n * 3);
  for (let i = 0; i < n; ++i) xyz.set(pts.subarray(i * 5, i * 5 + 3), i * 3);
  pointsGeometry.dispose();
  pointsGeometry.setAttribute('position', new THREE.BufferAttribute(xyz, 3));
  pointsGeometry.computeBoundingSphere();
  colourPoints();

  const centres = new Map();
  const fr = [];
  for (let k = 0; k < kfs.length / 13; ++k) {
    const pose = kfs.subarray(k * 13 + 1, k * 13 + 13);
    centres.set(kfs[k * 13], [pose[9], pose[10], pose[11]]);
    frustum(fr, pose, 0.05);
  }
  setSegments(keyframeLines, fr);
  const edgeSegments = (b64) => {
    const e = i32(b64), out = [];
    for (let i = 0; i < e.length; i += 2) {
      const a = centres.get(e[i]), b = centres.get(e[i + 1]);
      if (a && b) out.push(...a, ...b);
    }
    return out;
  };
  setSegments(covisibilityLines, edgeSegments(m.covisibility));
  setSegments(treeLines, edgeSegments(m.spanning_tree));
  const live = f32(m.live), final = f32(m.final_trajectory);
  lastPath = final.length ? final : live;
  setSegments(liveLine, pathSegments(live));
  setSegments(finalLine, pathSegments(final));
  setSegments(gtLine, pathSegments(f32(m.groundtruth)));
  applyVisibility();
  status.maps += 1;
  status.points = n;
  status.keyframes = kfs.length / 13;
  if (!fitted && n > 0) fitView();
  requestRender();
}

// The points' robust centre (median) and extent (80th percentile of distances), in the scene's frame: a few far
// points must not push the view away.
function robustExtent() {
  const pos = pointsGeometry.getAttribute('position');
  if (!pos || pos.count === 0) return null;
  const median = (k) => Float32Array.from({ length: pos.count }, (_, i) => pos.array[i * 3 + k]).sort()[pos.count >> 1];
  const c = new THREE.Vector3(median(0), median(1), median(2));
  const d = Float32Array.from({ length: pos.count }, (_, i) =>
    Math.hypot(pos.array[i * 3] - c.x, pos.array[i * 3 + 1] - c.y, pos.array[i * 3 + 2] - c.z)).sort();
  world.updateMatrixWorld();
  return { centre: c.applyMatrix4(world.matrixWorld), radius: Math.max(d[Math.floor(pos.count * 0.8)], 0.5) };
}

function fitView() {
  const e = robustExtent();
  if (!e) return;
  // Frame the points and the camera path together: the path is where the user looks first.
  let centre = e.centre, r = e.radius;
  const path = lastPath;
  if (path && path.length >= 3) {
    const p = new THREE.Vector3();
    for (let i = 0; i < path.length; i += 3) p.add(new THREE.Vector3(path[i], path[i + 1], path[i + 2]));
    p.multiplyScalar(3 / path.length).applyMatrix4(world.matrixWorld);
    r = Math.max(r, p.distanceTo(centre) * 0.75);
    centre = centre.clone().add(p).multiplyScalar(0.5);
  }
  controls.target.copy(centre);
  // From behind and above the first camera (the SLAM camera looks along -z here).
  camera.position.copy(centre).add(new THREE.Vector3(0, r * 1.2, r * 1.8));
  controls.update();
  fitted = true;
  requestRender();
}

function showCamera(pose) {
  currentPose = pose;
  const fr = [];
  if (pose) frustum(fr, pose, 0.12);
  setSegments(cameraLines, fr);
  if (pose && document.getElementById('follow').checked && fitted) {
    const p = new THREE.Vector3(pose[9], pose[10], pose[11]).applyMatrix4(world.matrixWorld);
    camera.position.add(p.clone().sub(controls.target));
    controls.target.copy(p);
    controls.update();
  }
  requestRender();
}

function applyVisibility() {
  const graph = document.getElementById('show-graph').checked;
  covisibilityLines.visible = graph;
  treeLines.visible = graph;
  keyframeLines.visible = document.getElementById('show-keyframes').checked;
  gtLine.visible = document.getElementById('show-gt').checked;
  denseGroup.visible = document.getElementById('show-dense').checked;
  status.denseVisible = denseGroup.visible;
  requestRender();
}

let renderQueued = false;
function requestRender() {
  if (renderQueued) return;
  renderQueued = true;
  requestAnimationFrame(() => {
    renderQueued = false;
    renderer.render(scene, camera);
    status.renders += 1;
  });
}

function resize() {
  const w = sceneEl.clientWidth, h = sceneEl.clientHeight;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
  requestRender();
}
new ResizeObserver(resize).observe(sceneEl);

// ---------------------------------------------------------------- image with keypoints
const imageCanvas = document.getElementById('image');
const ictx = imageCanvas.getContext('2d');

function drawOverlay(marks, people, scale) {
  let drawn = 0;
  ictx.lineWidth = 2;
  for (const p of people) {
    ictx.strokeStyle = '#ff9f1c';
    ictx.strokeRect(p.x * scale, p.y * scale, p.w * scale, p.h * scale);
    ictx.fillStyle = '#ff9f1c';
    ictx.font = '12px sans-serif';
    const label = p.depth_m > 0 ? `person ${p.depth_m.toFixed(2)} m ± ${p.band_m.toFixed(2)}` : 'person, no depth';
    ictx.fillText(label, p.x * scale + 3, p.y * scale + 13);
  }
  for (let i = 0; i < marks.length; i += 3) {
    const u = marks[i] * scale, v = marks[i + 1] * scale, m = marks[i + 2];
    const kind = m & 7;
    ictx.fillStyle = MARK_COLOUR[kind] || '#fff';
    if (kind === MARK.PERSON) {
      ictx.fillRect(u - 2, v - 2, 4, 4);
    } else {
      ictx.beginPath();
      ictx.arc(u, v, kind === MARK.UNMATCHED ? 1.5 : 2.5, 0, 2 * Math.PI);
      ictx.fill();
    }
    if (m & DEPTH_EDGE_BIT) {
      ictx.strokeStyle = '#35c9ff';
      ictx.lineWidth = 1;
      ictx.beginPath();
      ictx.arc(u, v, 4.5, 0, 2 * Math.PI);
      ictx.stroke();
    }
    ++drawn;
  }
  status.drawnMarks = drawn;
}

function showImage(jpegB64, width, height, then) {
  const img = new Image();
  img.onload = () => {
    if (imageCanvas.width !== width || imageCanvas.height !== height) {
      imageCanvas.width = width;
      imageCanvas.height = height;
      imageCanvas.style.height = `${(640 * height) / width}px`;
    }
    ictx.drawImage(img, 0, 0);
    if (then) then();
  };
  img.src = `data:image/jpeg;base64,${jpegB64}`;
}

function showFrame(f) {
  status.frames += 1;
  status.lastIndex = f.index;
  status.state = f.state;
  const marks = f32(f.marks);
  status.marks = marks.length / 3;
  if (f.image) showImage(f.image.jpeg, f.image.width, f.image.height, () => drawOverlay(marks, f.people, 1));
  showCamera(f.T_wc);
  const line = document.getElementById('state-line');
  line.className = `state ${f.state}`;
  line.textContent = `frame ${f.index}  t=${f.t.toFixed(3)}  ${f.state}  ${f.inliers} inliers / ${f.keypoints} keypoints` +
    `  map ${f.map_keyframes} KF, ${f.map_points} points  ${f.fps.toFixed(1)} fps`;
  const t = f.timings;
  const rows = [
    ['frames per second', f.fps.toFixed(1), 'keypoints', f.keypoints],
    ['extract ms', t.extract_ms.toFixed(1), 'inliers', f.inliers],
    ['person filter ms', t.filter_ms.toFixed(1), 'depth-edge drops', f.depth_edge_rejected],
    ['match ms', t.match_ms.toFixed(1), 'person filter', f.person_filter ? (f.have_detections ? `on, boxes ${(f.box_age_s * 1000).toFixed(0)} ms old` : 'waiting for the detector') : 'off'],
    ['pose ms', t.pose_ms.toFixed(1), 'keyframe', f.keyframe ? 'yes' : ''],
    ['tracking total ms', t.track_ms.toFixed(1), 'map', `${f.map_keyframes} KF / ${f.map_points} pts`],
  ];
  document.getElementById('stats').innerHTML =
    rows.map((r) => `<tr>${r.map((c) => `<td>${c}</td>`).join('')}</tr>`).join('');
}

// ---------------------------------------------------------------- alpha plot and events
let alphas = [];
function drawAlpha() {
  const c = document.getElementById('alpha');
  const g = c.getContext('2d');
  g.clearRect(0, 0, c.width, c.height);
  if (!alphas.length) return;
  const lo = Math.min(-2, ...alphas.map((a) => a.alpha)), hi = 2;
  const y = (a) => 10 + ((hi - a) / (hi - lo)) * (c.height - 20);
  g.strokeStyle = '#39414a';
  g.fillStyle = '#9aa4ae';
  g.font = '11px sans-serif';
  for (const a of [hi, 0, lo]) {
    g.beginPath(); g.moveTo(30, y(a)); g.lineTo(c.width, y(a)); g.stroke();
    g.fillText(a.toFixed(1), 2, y(a) + 4);
  }
  const x = (i) => 30 + (alphas.length === 1 ? 0 : (i / (alphas.length - 1)) * (c.width - 40));
  g.strokeStyle = '#ff9f1c';
  g.beginPath();
  alphas.forEach((a, i) => (i ? g.lineTo(x(i), y(a.alpha)) : g.moveTo(x(i), y(a.alpha))));
  g.stroke();
  g.fillStyle = '#ff9f1c';
  alphas.forEach((a, i) => g.fillRect(x(i) - 1.5, y(a.alpha) - 1.5, 3, 3));
  g.fillText(`last: keyframe ${alphas[alphas.length - 1].keyframe}, alpha ${alphas[alphas.length - 1].alpha.toFixed(2)}`, 36, 12);
}

function addEvent(text) {
  const li = document.createElement('li');
  li.textContent = text;
  const list = document.getElementById('events');
  list.prepend(li);
  while (list.children.length > 100) list.lastChild.remove();
  status.events += 1;
}

// ---------------------------------------------------------------- finished run: scrub through frames
let replayPoses = null;
function setupReplay(h) {
  replayPoses = f32(h.frame_poses);
  const slider = document.getElementById('frame-slider');
  document.getElementById('scrub').hidden = false;
  slider.max = String(Math.max(0, h.frame_count - 1));
  const show = () => {
    const i = Number(slider.value);
    const pose = replayPoses.subarray(i * 12, i * 12 + 12);
    const tracked = !Number.isNaN(pose[0]);
    document.getElementById('frame-label').textContent =
      `frame ${i} of ${h.frame_count}  t=${h.stamps[i].toFixed(3)}${tracked ? '' : '  (not tracked)'}`;
    status.lastIndex = i;
    showCamera(tracked ? Array.from(pose) : null);
    fetch(`/frame?i=${i}`).then((r) => (r.ok ? r.arrayBuffer() : null)).then((buf) => {
      if (!buf) return;
      let bin = '';
      const u8 = new Uint8Array(buf);
      for (let k = 0; k < u8.length; k += 0x8000) bin += String.fromCharCode.apply(null, u8.subarray(k, k + 0x8000));
      showImage(btoa(bin), h.width, h.height, null);
      status.frames += 1;
    });
  };
  slider.addEventListener('input', show);
  show();
}

// ---------------------------------------------------------------- the stream
function connect() {
  const events = new EventSource('/events');
  const on = (name, fn) => events.addEventListener(name, (e) => fn(JSON.parse(e.data)));
  events.onopen = () => {
    status.connected = true;
    status.connections += 1;
  };
  events.onerror = () => {
    status.connected = false;
    const line = document.getElementById('state-line');
    line.className = 'state lost';
    line.textContent = status.done ? 'the run is over and the viewer closed' : 'disconnected from varslam, retrying…';
  };
  on('hello', (h) => {
    // A (re)connection starts over: the server sends the whole log again.
    status.greeted = true;
    status.live = h.live;
    alphas = [];
    clearDense();
    document.getElementById('events').innerHTML = '';
    document.getElementById('title').textContent = `${h.title || ''}  (varslam ${h.version}${h.live ? ', live' : ', finished run'})`;
    document.getElementById('state-line').textContent = h.live ? 'waiting for the first frame…' : 'finished run';
    if (!h.live && !replayPoses) setupReplay(h);
  });
  on('frame', showFrame);
  on('map', showMap);
  on('dense', showDense);
  on('alpha', (a) => {
    alphas.push(a);
    status.alphas = alphas.length;
    drawAlpha();
  });
  on('loop', (l) => addEvent(`t=${l.t.toFixed(2)} loop closed: keyframe ${l.query} with ${l.match}, ${l.inliers} inliers, ` +
    `correction ${(l.correction_m * 100).toFixed(1)} cm / ${l.correction_deg.toFixed(2)}°`));
  on('relocalization', (r) => addEvent(`t=${r.t.toFixed(2)} relocalized at frame ${r.index} against keyframe ${r.keyframe} (${r.inliers} inliers)`));
  on('segment', (s) => addEvent(`t=${s.t.toFixed(2)} tracking lost: new map segment at frame ${s.index}`));
  on('registration', (r) => addEvent(r.found ? `depth not registered to colour: warped (scale ${r.scale.toFixed(3)}, ` +
    `du ${r.du.toFixed(1)}, dv ${r.dv.toFixed(1)} px)` : `depth registration: ${r.mode}`));
  on('done', (d) => {
    if (!status.done) status.framesBeforeDone = status.frames;
    status.done = true;
    addEvent(`run finished: ${d.tracked}/${d.frames} frames tracked, ${d.keyframes} keyframes, ${d.map_points} points, ` +
      `${d.segments} segment(s), ${d.relocalizations} relocalization(s)`);
  });
}

for (const id of ['show-graph', 'show-keyframes', 'show-gt', 'show-dense']) document.getElementById(id).addEventListener('change', applyVisibility);
document.getElementById('colour-by').addEventListener('change', () => { colourPoints(); requestRender(); });
document.getElementById('reset-view').addEventListener('click', fitView);
resize();
applyVisibility();
connect();
// For debugging from the browser console.
window.viewerScene = { scene, camera, controls, finalLine, liveLine, gtLine, keyframeLines, points, denseGroup };
