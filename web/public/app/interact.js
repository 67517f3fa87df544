// The mouse on the 3D view. Direct kinematics: dragging a part of the head turns the nearest
// driven joint above the part's link (any head: scene.robot.links and scene.head.joints) by
// kDragGainDegPerPx per pixel (a prismatic one by a millimetre per pixel), clamped to the
// joint's limits, sending at most one command per kSendIntervalMs. A joint whose axis stands
// upright on the screen turns with a sideways drag, one lying across it with an up-down drag;
// a joint of a symmetric pair (scene.head.symmetric: POPEYE's eyes) moves its partner with it.
// Inverse kinematics: a click (no drag) on an object, the ground or the dome fixates that point.
import * as THREE from 'three';

export const kDragGainDegPerPx = 0.5;
const kDragGainMetresPerPx = 0.001;
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
    if (!l) return value;
    return Math.min(l.max ?? Infinity, Math.max(l.min ?? -Infinity, value));
  };

  // The driven joint a drag on `link` turns: its own joint, else its parent's, up the tree.
  const links = new Map((app.doc?.robot?.links ?? []).map((l) => [l.name, l]));
  const joints = new Map((app.doc?.head?.joints ?? []).map((j) => [j.name, j]));
  const jointAbove = (link) => {
    for (let l = links.get(link); l; l = links.get(l.parent)) {
      const j = l.joint && joints.get(l.joint);
      if (j && j.driven) return j;
    }
    return null;
  };
  const partnerOf = (name) => {
    for (const [a, b, sign] of app.doc?.head?.symmetric ?? []) {
      if (a === name) return { name: b, sign };
      if (b === name) return { name: a, sign: 1 / sign };
    }
    return null;
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

  // How a drag turns `joint`: its axis (now, in the world) seen on the screen. Upright on the
  // screen: a sideways drag, the side that the axis's rotation carries the part towards; else
  // an up-down drag. Returns {along: 'x' | 'y', sign}.
  const dragRule = (joint) => {
    const state = app.latestState();
    const pose = state?.frames?.links?.[joint.link];
    // The axis is fixed in the link it moves: in the world, the link's rotation now.
    const axis = new THREE.Vector3(...(joint.axis ?? [0, 0, 1]));
    if (pose) axis.applyMatrix4(new THREE.Matrix4().extractRotation(new THREE.Matrix4().set(...pose.flat())));
    const view = new THREE.Vector3();
    app.camera.getWorldDirection(view);
    const up = app.camera.up.clone();
    const right = new THREE.Vector3().crossVectors(view, up).normalize();
    const screenUp = new THREE.Vector3().crossVectors(right, view).normalize();
    const upright = Math.abs(axis.dot(screenUp)) >= Math.abs(axis.dot(right));
    if (joint.type === 'prismatic') return { along: upright ? 'y' : 'x', sign: 1, prismatic: true };
    // A positive turn about an upright axis pointing up moves the near side of the part to the
    // left as seen from the camera: drag right = negative turn (for the camera in front of it,
    // the other way round).
    if (upright) return { along: 'x', sign: axis.dot(screenUp) >= 0 ? -1 : 1 };
    return { along: 'y', sign: axis.dot(right) >= 0 ? 1 : -1 };
  };

  canvas.addEventListener('pointerdown', (event) => {
    if (event.button !== 0) return;
    press = { x: event.clientX, y: event.clientY };
    const hit = ray(event).intersectObjects(app.head.draggables, false)[0];
    const link = hit?.object.userData.link;
    if (!link) return;
    const joint = jointAbove(link);
    if (!joint) return;
    const state = app.latestState();
    const targets = state?.joints?.targets ?? state?.joints?.positions;
    if (!targets) return;
    press.drag = { link, joint, start: { ...targets }, rule: dragRule(joint) };
    app.controls.enabled = false;  // OrbitControls must not rotate while a joint is dragged
    canvas.setPointerCapture(event.pointerId);
  });

  canvas.addEventListener('pointermove', (event) => {
    if (!press?.drag) return;
    const { joint, start, rule } = press.drag;
    const pixels = rule.along === 'x' ? event.clientX - press.x : event.clientY - press.y;
    const gain = rule.prismatic ? kDragGainMetresPerPx : kDragGainDegPerPx * kDeg;
    let v = clamp(joint.name, start[joint.name] + rule.sign * gain * pixels);
    const partner = partnerOf(joint.name);
    if (partner) {
      // Both within their limits: the partner's clamp limits this joint too.
      v = clamp(partner.name, partner.sign * v) / partner.sign;
      queue({ [joint.name]: v, [partner.name]: partner.sign * v });
    } else {
      queue({ [joint.name]: v });
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
