// saccade's browser GUI: loads the scene from the server, builds the 3D world and the head,
// connects the WebSocket, and wires the views, controls, plots and mouse. Exposes
// window.saccadeGui for the browser tests (web/tests/gui.test.mjs).
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { AccessError, Connection, fetchApi, token } from './connection.js';
import { checkSceneDocument } from './protocol.js';
import { buildWorld, loadModels, updateObjects } from './scene.js';
import { Head } from './head.js';
import { MapView } from './map.js';
import { installInteraction, kDragGainDegPerPx } from './interact.js';
import { CameraView, Controls, log } from './views.js';
import { Plot } from './plots.js';

const $ = (id) => document.getElementById(id);
const kDeg = 180 / Math.PI;
// The joints' plot colours, in the head's joint order (POPEYE's pan, tilt, left, right first).
const kJointColors = ['#d03030', '#2a8a2a', '#2050e0', '#c07000', '#803090', '#108080', '#806000'];

// The test hooks (see the file comment).
const gui = window.saccadeGui = {
  ready: false,
  accessDenied: false,
  state: null,
  hello: null,
  framesReceived: { left: 0, right: 0 },
  framesShown: { left: 0, right: 0 },
  framesDone: 0,             // frames the page finished with (acknowledged: frame_ack)
  mapsReceived: 0,           // `map` messages drawn
  pageFps: { left: 0, right: 0 },
  lastClick: null,
  errors: [],
  protocolErrors: [],        // messages refused for breaking the protocol (protocol.js), each named
  messagesChecked: 0,        // messages checked against it
  dragGainDegPerPx: kDragGainDegPerPx,
  tokenPresent: !!token,
};

function showAccessDenied() {
  gui.accessDenied = true;
  $('access').hidden = false;
  $('layout').hidden = true;
  $('connection').textContent = 'access denied';
  $('connection').className = 'badge bad';
}

async function start() {
  let doc;
  try {
    doc = await (await fetchApi('/api/scene')).json();
  } catch (e) {
    if (e instanceof AccessError) { showAccessDenied(); return; }
    throw e;
  }
  const sceneProblem = checkSceneDocument(doc);
  if (sceneProblem) {
    gui.protocolErrors.push(sceneProblem);
    throw new Error(`the server's /api/scene breaks the protocol: ${sceneProblem}`);
  }
  gui.scene = doc;
  $('scene-name').textContent = `${doc.name} (${doc.mode})`;
  document.title = `saccade · ${doc.name}`;
  const limits = Object.fromEntries((doc.head?.joints ?? []).map((j) => [j.name, j]));

  // The 3D view: z up, first seen from behind and above the head, the pictures beyond it.
  const canvas = $('world-canvas');
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  renderer.outputColorSpace = THREE.LinearSRGBColorSpace;  // the simulator's colours are linear
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  const scene = new THREE.Scene();
  const camera = new THREE.PerspectiveCamera(50, 1, 0.02, 100);
  camera.up.set(0, 0, 1);
  camera.position.set(-1.5, -0.7, 2.1);

  const models = await loadModels(doc.models ?? []);
  const world = buildWorld(scene, doc, models);
  const images = { left: $('image-left'), right: $('image-right') };
  const head = new Head(scene, doc, models, images);
  const mapView = new MapView(scene);  // the pipeline's map, when it has one

  let dirty = true;
  const redraw = () => { dirty = true; };
  let latest = null;

  // The connection: commands, replies and errors.
  const logElement = $('log');
  const send = async (type, fields = {}) => {
    const reply = await connection.send(type, fields);
    return reply;
  };
  const app = {
    camera, head, limits, pickables: world.pickables, doc,
    latestState: () => latest,
    send,
    onClick: (p) => {
      gui.lastClick = p.toArray();
      head.showClick(p);
      redraw();
      log(logElement, `fixate [${gui.lastClick.map((v) => v.toFixed(3)).join(', ')}]`);
      send('fixate', { p_W: gui.lastClick });
    },
  };
  installInteraction(canvas, app);  // before OrbitControls: a drag on the head disables them
  const controls = new OrbitControls(camera, canvas);
  controls.target.set(1.0, 0.0, 1.0);
  controls.update();
  controls.addEventListener('change', redraw);
  app.controls = controls;

  const controlsPanel = new Controls(document.body, send, (d) => { head.setImageDistance(d); redraw(); }, doc);
  // Flow control (docs/gui-protocol.md, frame_window): the server sends at most kFrameWindow
  // frames that the page has not finished with (shown, failed or replaced), so that a page
  // that draws slower than the server renders never lets frames, and the states and replies
  // behind them, queue up in the socket and the browser.
  // The page's address may set another (?frame_window=N, 0 .. 64; 0: none).
  const asked = new URLSearchParams(location.search).get('frame_window');
  const kFrameWindow = asked !== null && /^\d+$/.test(asked) && Number(asked) <= 64 ? Number(asked) : 4;
  const frameDone = () => {
    gui.framesDone++;
    if (connection.open) connection.send('frame_ack', { frames: gui.framesDone });
  };
  const views = {};
  for (const name of ['left', 'right']) {
    views[name] = new CameraView(images[name], $(`label-${name}`), name, (n, bitmap) => {
      gui.framesShown[n]++;
      head.imageUpdated(n, bitmap);
      redraw();
      maybeReady();
    }, frameDone);
  }

  // Plots: joints, fixation error, rates, step time.
  const plots = {
    // One series per joint of the head, in its order (POPEYE: pan, tilt, L, R).
    joints: new Plot($('plot-joints'), 'joints', (doc.head?.joints ?? []).map((j, i) => ({
      key: j.name,
      label: { left: 'L', right: 'R' }[j.name] ?? j.name,
      color: kJointColors[i % kJointColors.length],
    })), '°'),
    error: new Plot($('plot-error'), 'fixation error', [
      { key: 'left', label: 'L', color: '#2050e0' }, { key: 'right', label: 'R', color: '#c07000' }], '°'),
    rate: new Plot($('plot-rate'), 'rates', [
      { key: 'steps', label: 'steps', color: '#d03030' }, { key: 'fps', label: 'frames', color: '#2050e0' },
      { key: 'page', label: 'page', color: '#2a8a2a' }], '/s'),
    step: new Plot($('plot-step'), 'step', [{ key: 'ms', label: '', color: '#803090' },
      { key: 'rt', label: 'rt×', color: '#2a8a2a' }], 'ms'),
  };

  function maybeReady() {
    if (!gui.ready && latest && gui.framesShown.left > 0 && gui.framesShown.right > 0) {
      gui.ready = true;
      log(logElement, 'ready');
    }
  }

  const connection = new Connection({
    onHello: (m) => {
      gui.hello = m;
      $('connection').textContent = `connected · client ${m.client}`;
      $('connection').className = 'badge ok';
      connection.send('frame_window', { frames: kFrameWindow });
    },
    onState: (state) => {
      latest = state;
      gui.state = state;
      head.update(state);
      updateObjects(world.objects, state.objects);
      controlsPanel.reflect(state);
      const t = performance.now() / 1000;
      const p = state.joints?.positions ?? {};
      plots.joints.add(t, Object.fromEntries(Object.entries(p).map(([k, v]) => [k, v * kDeg])));
      const e = state.fixation_error_deg;
      plots.error.add(t, { left: e?.left, right: e?.right });
      const timing = state.timing ?? {};
      plots.rate.add(t, { steps: timing.steps_per_s, fps: timing.frames_per_s, page: gui.pageFps.left });
      plots.step.add(t, { ms: timing.step_ms, rt: timing.realtime_factor });
      $('sim-time').textContent = `step ${state.step} · t ${Number(state.time).toFixed(2)} s` +
        (state.paused ? ' · paused' : '') + (state.manual ? ' · manual' : '');
      redraw();
      maybeReady();
    },
    onMap: (m) => {
      gui.mapsReceived++;
      mapView.update(m);
      redraw();
    },
    onFrame: (header, blob) => {
      if (!(header.camera in views)) { frameDone(); return; }  // world cameras: not shown
      gui.framesReceived[header.camera]++;
      views[header.camera].frame(header, blob);
    },
    onError: (m) => {
      gui.errors.push(m);
      log(logElement, `error${m.id != null ? ` (#${m.id})` : ''}: ${m.error}`, 'error');
    },
    onEvent: (m) => log(logElement, m.message, m.level),
    onProtocolError: (problem, message, kind) => {
      // Refused: what the server sent does not match docs/gui-protocol.md.
      gui.protocolErrors.push(problem);
      log(logElement, `refused a message that breaks the protocol: ${problem}`, 'error');
      if (kind === 'frame') frameDone();  // dropped: the frame window counts it done
    },
    onClose: () => {
      $('connection').textContent = 'disconnected: retrying';
      $('connection').className = 'badge bad';
      log(logElement, 'connection closed; the page reloads once saccade serves again', 'error');
      // saccade may come back (restarted, perhaps on another scene): ask every 2 s and
      // reload the whole page when it answers, so that the scene is its new one.
      const retry = async () => {
        try {
          await fetchApi('/api/scene');
          location.reload();
        } catch (e) {
          if (e instanceof AccessError) { showAccessDenied(); return; }
          setTimeout(retry, 2000);
        }
      };
      setTimeout(retry, 2000);
    },
  });
  gui.connection = connection;
  Object.defineProperty(gui, 'messagesChecked', { get: () => connection.checked });

  // Page frame rates, once a second.
  let counted = { ...gui.framesShown }, countedAt = performance.now();
  setInterval(() => {
    const now = performance.now();
    for (const n of ['left', 'right']) {
      gui.pageFps[n] = (gui.framesShown[n] - counted[n]) / ((now - countedAt) / 1000);
    }
    counted = { ...gui.framesShown };
    countedAt = now;
  }, 1000);

  // Rendering: only when something changed; plots at ~4 Hz.
  const resize = () => {
    const w = canvas.clientWidth, h = canvas.clientHeight;
    if (canvas.width !== Math.round(w * renderer.getPixelRatio()) ||
        canvas.height !== Math.round(h * renderer.getPixelRatio())) {
      renderer.setSize(w, h, false);
      camera.aspect = w / Math.max(1, h);
      camera.updateProjectionMatrix();
      dirty = true;
    }
  };
  const render = () => {
    resize();
    renderer.render(scene, camera);
    dirty = false;
  };
  const loop = () => {
    resize();
    if (dirty) render();
    requestAnimationFrame(loop);
  };
  requestAnimationFrame(loop);
  setInterval(() => {
    const t = performance.now() / 1000;
    for (const plot of Object.values(plots)) plot.draw(t);
  }, 250);

  // The test hooks that need the world.
  const raycaster = new THREE.Raycaster();
  const pageOf = (p) => {
    const r = canvas.getBoundingClientRect();
    const ndc = p.clone().project(camera);
    return { x: r.left + (ndc.x + 1) / 2 * r.width, y: r.top + (1 - ndc.y) / 2 * r.height, ndc };
  };
  const belongsTo = (object, root) => {
    for (let o = object; o; o = o.parent) if (o === root) return true;
    return false;
  };
  // Page coordinates of an object's (or a robot link's) centre: its bounding box's centre
  // projected; when a raycast finds that point hidden by something else, the visible point of
  // the object nearest to it (a grid of rays over its projected box). {x, y, visible}.
  gui.screenPointOf = (name) => {
    render();
    const root = world.objects.get(name) ?? (head.links.get(name) ?? null);
    if (!root) throw new Error(`screenPointOf: no object or link named '${name}'`);
    root.updateMatrixWorld(true);
    const box = new THREE.Box3().setFromObject(root);
    const centre = box.isEmpty() ? new THREE.Vector3().setFromMatrixPosition(root.matrixWorld)
      : box.getCenter(new THREE.Vector3());
    const c = pageOf(centre);
    const targets = [...world.pickables, ...head.draggables,
      ...[...head.links.values()].flatMap((link) => link.children.flatMap((part) => part.children))];
    const sees = (ndcX, ndcY) => {
      if (Math.abs(ndcX) > 1 || Math.abs(ndcY) > 1) return false;
      raycaster.setFromCamera(new THREE.Vector2(ndcX, ndcY), camera);
      const hit = raycaster.intersectObjects(targets, false)[0];
      return !!hit && belongsTo(hit.object, root);
    };
    if (c.ndc.z < 1 && sees(c.ndc.x, c.ndc.y)) return { x: c.x, y: c.y, visible: true };
    if (box.isEmpty()) return { x: c.x, y: c.y, visible: false };
    // The projected box, sampled on a grid; the visible sample nearest the centre.
    const lo = new THREE.Vector2(Infinity, Infinity), hi = new THREE.Vector2(-Infinity, -Infinity);
    for (let i = 0; i < 8; i++) {
      const corner = new THREE.Vector3(i & 1 ? box.max.x : box.min.x, i & 2 ? box.max.y : box.min.y,
        i & 4 ? box.max.z : box.min.z).project(camera);
      lo.min(new THREE.Vector2(corner.x, corner.y));
      hi.max(new THREE.Vector2(corner.x, corner.y));
    }
    const n = 16;
    let best = null;
    for (let i = 0; i <= n; i++) {
      for (let j = 0; j <= n; j++) {
        const x = lo.x + ((hi.x - lo.x) * i) / n, y = lo.y + ((hi.y - lo.y) * j) / n;
        const d = Math.hypot(x - c.ndc.x, y - c.ndc.y);
        if ((!best || d < best.d) && sees(x, y)) best = { x, y, d };
      }
    }
    if (!best) return { x: c.x, y: c.y, visible: false };
    const r = canvas.getBoundingClientRect();
    return { x: r.left + ((best.x + 1) / 2) * r.width, y: r.top + ((1 - best.y) / 2) * r.height, visible: true };
  };
  // Sets the 3D view (position and target, world metres) and renders.
  gui.setView = (position, target) => {
    camera.position.set(...position);
    controls.target.set(...target);
    controls.update();
    render();
  };
  // The matrix the page placed an object or a head link with, row by row (the protocol's
  // form of a pose; an object's includes its scale): for the browser test.
  gui.placementOf = (name) => {
    const root = world.objects.get(name) ?? (head.links.get(name) ?? null);
    if (!root) throw new Error(`placementOf: no object or link named '${name}'`);
    const e = root.matrix.elements;  // column-major
    return [0, 1, 2, 3].map((r) => [0, 1, 2, 3].map((c) => e[4 * c + r]));
  };
  gui.send = (type, fields) => send(type, fields);
  gui.imagePlane = (name) => head.imagePlane(name);
  gui.render = render;
  // The map as the 3D scene holds it: points and inhibited places counted from its objects.
  gui.mapCounts = () => {
    const root = scene.getObjectByName('map');
    const points = root?.getObjectByName('map-points');
    const places = root?.getObjectByName('map-inhibited');
    return { ...mapView.counts(), points: points?.geometry.getAttribute('position').count ?? 0,
      inhibited: places?.children.filter((s) => s.isMesh && s.visible).length ?? 0 };
  };
  gui.setImageDistance = (d) => {
    const slider = $('plane-distance');
    slider.value = String(d);
    slider.dispatchEvent(new Event('input'));
  };
}

start().catch((e) => {
  console.error(e);
  const el = $('log');
  if (el) log(el, `error: ${e.message}`, 'error');
  gui.fatal = String(e.message ?? e);
});
