// The map a pipeline builds (docs/gui-protocol.md, `map`), drawn in the 3D view: the occupied
// voxels' centres as points coloured by height (blue at the map's lowest voxel through cyan,
// green and yellow to red at its highest, as the DDS PointCloud2's rgb field) and sized by the
// voxel edge, and the places inhibition of return holds as translucent spheres whose opacity
// is their strength. Each message replaces the whole map (the server sends it at most every few
// steps, bounded in points).
import * as THREE from 'three';

// The point size when the map does not say its resolution (a map received over DDS), metres.
const kDefaultPointSize = 0.02;
// A place of strength s is drawn with opacity kMaxOpacity * s.
const kMaxOpacity = 0.6;

/** The height colour of t in [0, 1]: blue, cyan, green, yellow, red (linear RGB). */
export function heightColor(t) {
  const stops = [[0, 0, 1], [0, 1, 1], [0, 1, 0], [1, 1, 0], [1, 0, 0]];
  const x = Math.min(1, Math.max(0, Number.isFinite(t) ? t : 0)) * 4;
  const i = Math.min(3, Math.floor(x));
  const u = x - i;
  return stops[i].map((c, k) => c + u * (stops[i + 1][k] - c));
}

export class MapView {
  constructor(scene) {
    this.group = new THREE.Group();
    this.group.name = 'map';
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.Float32BufferAttribute([], 3));
    geometry.setAttribute('color', new THREE.Float32BufferAttribute([], 3));
    this.points = new THREE.Points(geometry, new THREE.PointsMaterial({
      size: kDefaultPointSize, sizeAttenuation: true, vertexColors: true }));
    this.points.name = 'map-points';
    this.points.frustumCulled = false;  // its bounds change with every message
    this.inhibited = new THREE.Group();
    this.inhibited.name = 'map-inhibited';
    this.sphere = new THREE.SphereGeometry(1, 24, 16);
    this.group.add(this.points, this.inhibited);
    scene.add(this.group);
    this.latest = null;
  }

  /** Draws `m`, a `map` message, in place of the last. */
  update(m) {
    this.latest = { time: m.time, frame: m.frame, total: m.total, points: m.points.length / 3, inhibited: m.inhibited.length };
    const n = m.points.length / 3;
    let zMin = Infinity, zMax = -Infinity;
    for (let i = 0; i < n; i++) {
      zMin = Math.min(zMin, m.points[3 * i + 2]);
      zMax = Math.max(zMax, m.points[3 * i + 2]);
    }
    const range = zMax > zMin ? zMax - zMin : 1;
    const colors = new Float32Array(3 * n);
    for (let i = 0; i < n; i++) colors.set(heightColor((m.points[3 * i + 2] - zMin) / range), 3 * i);
    const geometry = this.points.geometry;
    geometry.setAttribute('position', new THREE.Float32BufferAttribute(m.points, 3));
    geometry.setAttribute('color', new THREE.Float32BufferAttribute(colors, 3));
    geometry.computeBoundingSphere();
    this.points.material.size = m.resolution_m > 0 ? m.resolution_m : kDefaultPointSize;

    for (const old of [...this.inhibited.children]) {
      this.inhibited.remove(old);
      old.material.dispose();
    }
    for (const place of m.inhibited) {
      const sphere = new THREE.Mesh(this.sphere, new THREE.MeshBasicMaterial({
        color: 0xff40c0, transparent: true, opacity: kMaxOpacity * place.strength, depthWrite: false }));
      sphere.position.set(...place.p_W);
      sphere.scale.setScalar(Math.max(place.radius_m, 1e-3));
      sphere.userData.strength = place.strength;
      this.inhibited.add(sphere);
    }
  }

  /** What the 3D scene holds now, counted from its objects (for the browser tests). */
  counts() {
    return {
      points: this.points.geometry.getAttribute('position').count,
      inhibited: this.inhibited.children.length,
      opacities: this.inhibited.children.map((s) => s.material.opacity),
      radii: this.inhibited.children.map((s) => s.scale.x),
      pointSize: this.points.material.size,
      message: this.latest,
    };
  }
}
