// The mouse on the 3D view. Direct kinematics: dragging a part of the head turns its joint
// (neck: pan, cyclopean: tilt, an eye: vergence, symmetric) by kDragGainDegPerPx per pixel,
// clamped to the joint's limits, sending at most one command per kSendIntervalMs. Inverse
// kinematics: a click (no drag) on an object, the ground or the dome fixates that point.
import * as THREE from 'three';

export const kDragGainDegPerPx = 0.5;
const kSendIntervalMs = 50;   // at most ~20 commands per second while dragging
const kClickSlopPx = 4;       // a press that moves less than this is a click

const kDeg = Math.PI / 180;

/**
 * Installs the handlers on `canvas` (before OrbitControls, so that a drag on the head can
 * switch the controls off before they see the press). `app` gives camera, controls, head,
 * pickables, limits, latestState(), send(type, fields), onClick(point).
 */
export function installInteraction(canvas, app) {
  const raycaster = new THREE.Raycaster();
  let press = null;  // {x, y, drag?: {link, start, sign}}
  let lastSent = 0;
  let pendingTimer = null;
  let pendingPositions = null;

  const ray = (event) => {
    const r = canvas.getBoundingClientRect();
    const ndc = new THREE.Vector2(((event.clientX - r.left) / r.width) * 2 - 1,
      -((event.clientY - r.top) / r.height) * 2 + 1);
    raycaster.setFromCamera(ndc, app.camera);
    return raycaster;
  };

  const clamp = (joint, value) => {
    const l = app.limits[joint];
    return l ? Math.min(l.max, Math.max(l.min, value)) : value;
  };

  const flush = () => {
    pendingTimer = null;
    if (!pendingPositions) return;
    app.send('joints', { positions: pendingPositions });
    pendingPositions = null;
    lastSent = performance.now();
  };

  const queue = (positions) => {
    pendingPositions = positions;
    const wait = kSendIntervalMs - (performance.now() - lastSent);
    if (wait <= 0) flush();
    else if (!pendingTimer) pendingTimer = setTimeout(flush, wait);
  };

  // Which way a drag to the right turns the head: seen from behind the head (the camera
  // looking along the neck's x), dragging right turns it right (pan decreases).
  const viewSign = () => {
    const state = app.latestState();
    const n = state?.frames?.X_WN;
    if (!n) return 1;
    const forward = new THREE.Vector3();
    app.camera.getWorldDirection(forward);
    return forward.x * n[0][0] + forward.y * n[1][0] >= 0 ? 1 : -1;  // the neck's x axis
  };

  canvas.addEventListener('pointerdown', (event) => {
    if (event.button !== 0) return;
    press = { x: event.clientX, y: event.clientY };
    const hit = ray(event).intersectObjects(app.head.draggables, false)[0];
    const link = hit?.object.userData.link;
    if (!link) return;
    const state = app.latestState();
    const joints = state?.joints?.targets ?? state?.joints?.positions;
    if (!joints) return;
    press.drag = { link, start: { ...joints }, sign: viewSign() };
    app.controls.enabled = false;  // OrbitControls must not rotate while a joint is dragged
    canvas.setPointerCapture(event.pointerId);
  });

  canvas.addEventListener('pointermove', (event) => {
    if (!press?.drag) return;
    const { link, start, sign } = press.drag;
    const dx = event.clientX - press.x;
    const dy = event.clientY - press.y;
    const g = kDragGainDegPerPx * kDeg;
    if (link === 'neck') {
      queue({ pan: clamp('pan', start.pan - sign * g * dx) });
    } else if (link === 'cyclopean') {
      queue({ tilt: clamp('tilt', start.tilt + g * dy) });  // dragging down looks down
    } else if (link === 'left_eye' || link === 'right_eye') {
      // Symmetric vergence: the left eye turns by v, the right by -v.
      let v = start.left - sign * g * dx;
      v = clamp('left', v);
      v = -clamp('right', -v);
      queue({ left: v, right: -v });
    }
  });

  const release = (event) => {
    if (!press) return;
    const p = press;
    press = null;
    if (p.drag) {
      if (pendingTimer) { clearTimeout(pendingTimer); flush(); }
      app.controls.enabled = true;
      return;
    }
    if (event.type !== 'pointerup') return;
    if (Math.hypot(event.clientX - p.x, event.clientY - p.y) > kClickSlopPx) return;  // orbit
    const r = ray(event);
    const hit = r.intersectObjects(app.pickables, false)[0] ?? r.intersectObject(app.head.dome, false)[0];
    if (hit) app.onClick(hit.point.clone());
  };
  canvas.addEventListener('pointerup', release);
  canvas.addEventListener('pointercancel', release);
}
