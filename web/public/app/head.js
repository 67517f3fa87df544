// The robot in the world: its parts hung from the links of the head's tree (doc.robot.links,
// posed by state.frames.links), each eye
// camera's frustum with its live image on a plane inside it (in front of the optical centre
// or behind it, flipped, as a real image plane), the rays from both optical centres to the
// fixation point and to the triangulated target, the clicked point, and the dome a click
// on the empty sky hits.
import * as THREE from 'three';
import { instantiate, matrixFrom, positionOf, scaledMatrix } from './scene.js';


const kFrustumDepth = 0.25;  // metres: how far the frustum's lines reach at least
const kDomeRadius = 4.0;     // metres around the cyclopean point

function marker(color, radius) {
  const mesh = new THREE.Mesh(new THREE.SphereGeometry(radius, 16, 12),
    new THREE.MeshBasicMaterial({ color }));
  mesh.visible = false;
  return mesh;
}

function line(color) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(new Float32Array(6), 3));
  const l = new THREE.Line(geometry, new THREE.LineBasicMaterial({ color }));
  l.visible = false;
  l.frustumCulled = false;
  return l;
}

function setLine(l, a, b) {
  const p = l.geometry.attributes.position;
  p.setXYZ(0, a.x, a.y, a.z);
  p.setXYZ(1, b.x, b.y, b.z);
  p.needsUpdate = true;
  l.visible = true;
}

/** One eye camera: frustum lines and the image plane, in the camera's optical frame. */
class CameraRig {
  constructor(camera) {
    this.camera = camera;  // /api/scene.cameras entry
    this.group = new THREE.Group();
    this.group.matrixAutoUpdate = false;
    this.group.name = `camera:${camera.name}`;
    // A half-size copy of the live image (a smaller texture uploads faster), in a CPU canvas
    // (willReadFrequently): a GPU canvas made the page wait for the GPU process at every copy
    // (seconds at a time with a software GPU: bench/gui_page.mjs).
    this.canvas = document.createElement('canvas');
    this.canvas.width = Math.max(1, Math.round(camera.width / 2));
    this.canvas.height = Math.max(1, Math.round(camera.height / 2));
    this.context = this.canvas.getContext('2d', { willReadFrequently: true });
    this.texture = new THREE.CanvasTexture(this.canvas);
    this.texture.colorSpace = THREE.NoColorSpace;
    this.texture.minFilter = THREE.LinearFilter;
    this.texture.generateMipmaps = false;
    this.plane = new THREE.Mesh(new THREE.BufferGeometry(), new THREE.MeshBasicMaterial({
      map: this.texture, side: THREE.DoubleSide, transparent: true, opacity: 0.9,
    }));
    this.plane.visible = false;  // until the first image
    this.lines = new THREE.LineSegments(new THREE.BufferGeometry(),
      new THREE.LineBasicMaterial({ color: camera.name === 'left' ? 0x2060ff : 0xff4020 }));
    this.group.add(this.plane, this.lines);
    this.setDistance(0.3);
  }

  // The point of pixel (u, v) at depth z in the camera frame (x right, y down, z forward).
  point(u, v, z) {
    const [[fx, s, cx], [, fy, cy]] = this.camera.K;
    const y = (v - cy) / fy;
    const x = (u - cx - s * y) / fx;
    return new THREE.Vector3(x * z, y * z, z);
  }

  /** Puts the image plane at `d` metres along the optical axis (negative: behind). */
  setDistance(d) {
    const { width: w, height: h } = this.camera;
    const corners = (z) => [[0, 0], [w, 0], [w, h], [0, h]].map(([u, v]) => this.point(u, v, z));
    // The image plane: pixel (u, v) at its place; behind the centre the image comes out
    // flipped, as on a real image plane.
    const c = corners(d === 0 ? 1e-3 : d);
    const uv = [[0, 1], [1, 1], [1, 0], [0, 0]];  // texture flipped (flipY): v = 1 is row 0
    const plane = new THREE.BufferGeometry();
    plane.setAttribute('position', new THREE.Float32BufferAttribute(c.flatMap((p) => p.toArray()), 3));
    plane.setAttribute('uv', new THREE.Float32BufferAttribute(uv.flat(), 2));
    plane.setIndex([0, 1, 2, 0, 2, 3]);
    this.plane.geometry.dispose();
    this.plane.geometry = plane;
    // The frustum: centre to the corners and the rectangle, in front; through the centre to
    // the image plane when it is behind.
    const segments = [];
    const o = new THREE.Vector3();
    const rectangle = (cs) => {
      for (let i = 0; i < 4; i++) segments.push(o.clone(), cs[i], cs[i], cs[(i + 1) % 4]);
    };
    rectangle(corners(Math.max(kFrustumDepth, d)));
    if (d < 0) rectangle(c);
    const lines = new THREE.BufferGeometry().setFromPoints(segments);
    this.lines.geometry.dispose();
    this.lines.geometry = lines;
  }

  /** The camera pose X_WC (a 4x4 matrix, row by row). */
  setPose(X_WC) {
    this.group.matrix.copy(matrixFrom(X_WC));
    this.group.matrixWorldNeedsUpdate = true;
  }

  /** The camera view shows a new picture (`bitmap`, decoded): the image plane copies it. */
  imageUpdated(bitmap) {
    this.context.drawImage(bitmap, 0, 0, this.canvas.width, this.canvas.height);
    this.texture.needsUpdate = true;
    this.plane.visible = true;
  }
}

/**
 * The robot and the cameras' drawings. `views` maps camera name -> the camera view's canvas:
 * the cameras with a view get a frustum and an image plane.
 */
export class Head {
  constructor(scene, doc, models, views) {
    this.scene = scene;
    this.links = new Map();       // link name -> Group posed by state.frames.links
    this.draggables = [];         // meshes of the links a drag moves
    // The links a joint moves: below some joint other than a fixed one (the root never is).
    const moved = new Set();
    const jointOf = new Map((doc.head?.joints ?? []).map((j) => [j.link, j.name]));
    for (const link of doc.robot?.links ?? []) {
      if (jointOf.has(link.name) || (link.parent && moved.has(link.parent))) moved.add(link.name);
    }
    for (const link of doc.robot?.links ?? []) {
      const group = new THREE.Group();
      group.name = link.name;
      group.matrixAutoUpdate = false;
      group.visible = false;  // until the first state
      this.links.set(link.name, group);
      scene.add(group);
    }
    if (doc.robot?.visible !== false) {
      for (const part of doc.robot?.parts ?? []) {
        const group = this.links.get(part.link);
        if (!group) continue;
        const mesh = instantiate(models[part.model], part.link);
        mesh.matrixAutoUpdate = false;
        mesh.matrix.copy(scaledMatrix(part.X_LinkPart, part.scale));
        mesh.traverse((m) => { m.userData.link = part.link; });
        group.add(mesh);
        if (moved.has(part.link)) this.draggables.push(...mesh.children);
      }
    }
    // The eye cameras (those with a pose in the state: left and right).
    this.rigs = new Map();
    for (const camera of doc.cameras ?? []) {
      if (!views[camera.name]) continue;
      const rig = new CameraRig(camera);
      this.rigs.set(camera.name, rig);
      rig.group.visible = false;
      scene.add(rig.group);
    }
    // Rays to the fixation point (yellow) and the target (cyan); the clicked point (magenta).
    this.fixationRays = [line(0xffd000), line(0xffd000)];
    this.targetRays = [line(0x00d0ff), line(0x00d0ff)];
    this.fixationMarker = marker(0xffd000, 0.015);
    this.targetMarker = marker(0x00d0ff, 0.025);
    this.clickMarker = marker(0xff00ff, 0.02);
    scene.add(...this.fixationRays, ...this.targetRays, this.fixationMarker, this.targetMarker,
      this.clickMarker);
    // The dome: invisible, only its far (inner) side is hit by a click.
    this.dome = new THREE.Mesh(new THREE.SphereGeometry(kDomeRadius, 48, 24),
      new THREE.MeshBasicMaterial({ side: THREE.BackSide, colorWrite: false, depthWrite: false }));
    this.dome.name = 'dome';
    this.dome.visible = true;
    scene.add(this.dome);
  }

  /** Poses links, cameras, rays and markers from a state message. */
  update(state) {
    const f = state.frames ?? {};
    for (const [link, group] of this.links) {
      const pose = f.links?.[link];
      if (!pose) continue;
      group.matrix.copy(matrixFrom(pose));
      group.matrixWorldNeedsUpdate = true;
      group.visible = true;
    }
    if (f.X_WC) this.dome.position.copy(positionOf(f.X_WC));
    const centres = [];
    for (const [name, rig] of this.rigs) {
      if (!f[name]) continue;
      rig.setPose(f[name]);
      rig.group.visible = true;
      centres.push(positionOf(f[name]));
    }
    const show = (rays, markerMesh, p) => {
      const visible = Array.isArray(p) && centres.length > 0;
      rays.forEach((r, i) => {
        if (visible && centres[i]) setLine(r, centres[i], new THREE.Vector3(...p));
        else r.visible = false;
      });
      markerMesh.visible = visible;
      if (visible) markerMesh.position.set(...p);
    };
    show(this.fixationRays, this.fixationMarker, state.fixation_W);
    show(this.targetRays, this.targetMarker, state.target?.valid ? state.target.p_W : null);
  }

  setImageDistance(d) {
    for (const rig of this.rigs.values()) rig.setDistance(d);
  }

  /** Camera `camera`'s image plane (a test hook): its canvas and whether it is shown. */
  imagePlane(camera) {
    const rig = this.rigs.get(camera);
    return rig && { canvas: rig.canvas, visible: rig.plane.visible };
  }

  /** Camera `camera`'s view shows a new picture (`bitmap`, decoded); see CameraRig. */
  imageUpdated(camera, bitmap) {
    this.rigs.get(camera)?.imageUpdated(bitmap);
  }

  showClick(p) {
    this.clickMarker.position.copy(p);
    this.clickMarker.visible = true;
  }
}
