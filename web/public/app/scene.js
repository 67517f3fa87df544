// The 3D world of /api/scene: background, lights, ground (a repeated canvas texture), and the scene's objects built from
// the binary meshes of /api/models/N.bin with their materials and textures. The renderer's
// colours are linear RGB, and so are the page's: textures and images are used as they are
// (NoColorSpace) and the canvas output is linear too, so the page shows what the simulator
// draws.
import * as THREE from 'three';
import { fetchApi } from './connection.js';

/** Whether `X` is a pose in the protocol's one form: a 4x4 matrix, row by row (rows of numbers). */
export function isPose(X) {
  return Array.isArray(X) && X.length === 4 &&
    X.every((row) => Array.isArray(row) && row.length === 4 && row.every(Number.isFinite));
}

/**
 * A THREE.Matrix4 from a pose in the protocol's one form (docs/gui-protocol.md, the C++
 * geometry/json.h): its 4x4 matrix, row by row, [[r00, r01, r02, x], ..., [0, 0, 0, 1]].
 * Throws on anything else, so that a change of form fails loudly rather than misplacing parts.
 */
export function matrixFrom(X) {
  if (!isPose(X)) throw new Error(`a pose must be a 4x4 matrix, row by row; got ${JSON.stringify(X)}`);
  return new THREE.Matrix4().set(...X[0], ...X[1], ...X[2], ...X[3]);
}

/** The translation of a pose (its last column): the frame's origin in the world. */
export function positionOf(X) {
  return new THREE.Vector3(X[0][3], X[1][3], X[2][3]);
}

/** X_WO * diag(sx, sy, sz). */
export function scaledMatrix(X, scale) {
  return matrixFrom(X).multiply(new THREE.Matrix4().makeScale(...scale));
}

// Three's lights divide by pi (physically based Lambert); the simulator's do not.
const kLightScale = Math.PI;

function linearColor(rgb) {
  return new THREE.Color().setRGB(rgb[0], rgb[1], rgb[2], THREE.LinearSRGBColorSpace);
}

/** Loads a texture from the API (with the token) as an image element; colours untouched. */
async function loadTexture(url) {
  const blob = await (await fetchApi(url)).blob();
  const bitmapUrl = URL.createObjectURL(blob);
  const image = new Image();
  image.src = bitmapUrl;
  await image.decode();
  URL.revokeObjectURL(bitmapUrl);
  const texture = new THREE.Texture(image);
  texture.colorSpace = THREE.NoColorSpace;
  texture.wrapS = texture.wrapT = THREE.RepeatWrapping;
  texture.anisotropy = 4;
  texture.needsUpdate = true;
  return texture;
}

/** Splits model N's binary file into one BufferGeometry per mesh (layout: protocol doc). */
function parseMeshes(buffer, meshes) {
  const geometries = [];
  let offset = 0;
  const floats = (count) => {
    const array = new Float32Array(buffer.slice(offset, offset + 4 * count));
    offset += 4 * count;
    return array;
  };
  for (const mesh of meshes) {
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(floats(mesh.vertices * 3), 3));
    geometry.setAttribute('normal', new THREE.BufferAttribute(floats(mesh.vertices * 3), 3));
    if (mesh.uvs) geometry.setAttribute('uv', new THREE.BufferAttribute(floats(mesh.vertices * 2), 2));
    const indices = new Uint32Array(buffer.slice(offset, offset + 4 * mesh.indices));
    offset += 4 * mesh.indices;
    geometry.setIndex(new THREE.BufferAttribute(indices, 1));
    geometry.computeBoundingSphere();
    geometries.push(geometry);
  }
  if (offset !== buffer.byteLength) {
    console.warn(`model: ${buffer.byteLength} bytes, expected ${offset}`);
  }
  return geometries;
}

/** Loads every model once: an array of {geometries, materials} to instance from. */
export async function loadModels(models) {
  const textures = new Map();  // url -> Promise<Texture>, shared by materials
  const texture = (url) => {
    if (!textures.has(url)) textures.set(url, loadTexture(url));
    return textures.get(url);
  };
  return Promise.all(models.map(async (model) => {
    const buffer = await (await fetchApi(model.url)).arrayBuffer();
    const geometries = parseMeshes(buffer, model.meshes);
    const materials = await Promise.all(model.materials.map(async (m) => {
      const [r, g, b, a = 1] = m.base_color;
      const material = new THREE.MeshPhongMaterial({
        color: linearColor([r, g, b]),
        specular: linearColor([m.specular ?? 0, m.specular ?? 0, m.specular ?? 0]),
        shininess: m.shininess ?? 32,
        side: THREE.DoubleSide,
        transparent: a < 1,
        opacity: a,
      });
      if (m.texture) material.map = await texture(m.texture);
      return material;
    }));
    return { geometries, materials, meshes: model.meshes };
  }));
}

/** A group of meshes showing `model` (shares the model's geometry and materials). */
export function instantiate(model, name) {
  const group = new THREE.Group();
  group.name = name;
  model.geometries.forEach((geometry, i) => {
    const material = model.materials[model.meshes[i].material] ?? model.materials[0];
    const mesh = new THREE.Mesh(geometry, material);
    mesh.name = name;
    group.add(mesh);
  });
  return group;
}

/** Ambient, directional and point lights as the scene lists them. */
export function addLights(scene, lights) {
  for (const l of lights) {
    const color = linearColor(l.color ?? [1, 1, 1]);
    const intensity = (l.intensity ?? 1) * kLightScale;
    if (l.type === 'ambient') {
      scene.add(new THREE.AmbientLight(color, intensity));
    } else if (l.type === 'directional') {
      const light = new THREE.DirectionalLight(color, intensity);
      const d = new THREE.Vector3(...l.direction).normalize();
      light.position.copy(d.multiplyScalar(-20));  // `direction` is the way the light travels
      scene.add(light, light.target);
    } else if (l.type === 'point') {
      // The simulator attenuates by 1 / (1 + a d^2); three.js cannot: no decay, and the
      // intensity it has at 2 m (about where the pictures are).
      const a = l.attenuation ?? 0;
      const light = new THREE.PointLight(color, intensity / (1 + a * 4), 0, 0);
      light.position.set(...l.position);
      scene.add(light);
    }
  }
}

/** A canvas texture for the ground: one grid cell (lines on its edges) or a 2x2 checker. */
function groundTexture(g) {
  const n = 256;
  const canvas = document.createElement('canvas');
  canvas.width = canvas.height = n;
  const ctx = canvas.getContext('2d');
  const css = (c) => `rgb(${c.map((v) => Math.round(255 * v)).join(',')})`;
  ctx.fillStyle = css(g.color);
  ctx.fillRect(0, 0, n, n);
  ctx.fillStyle = css(g.color2);
  if (g.pattern === 'checker') {
    ctx.fillRect(0, 0, n / 2, n / 2);
    ctx.fillRect(n / 2, n / 2, n / 2, n / 2);
  } else {
    // Half a line on each edge: neighbouring cells make it whole.
    const half = Math.max(0.5, (g.line_width / g.cell) * n / 2);
    ctx.fillRect(0, 0, n, half);
    ctx.fillRect(0, n - half, n, half);
    ctx.fillRect(0, 0, half, n);
    ctx.fillRect(n - half, 0, half, n);
  }
  const texture = new THREE.CanvasTexture(canvas);
  texture.colorSpace = THREE.NoColorSpace;
  texture.wrapS = texture.wrapT = THREE.RepeatWrapping;
  const cells = g.size / g.cell;
  texture.repeat.set(g.pattern === 'checker' ? cells / 2 : cells, g.pattern === 'checker' ? cells / 2 : cells);
  texture.anisotropy = 8;
  return texture;
}

/** The ground z = 0, centred on the origin: plain, grid or checker (a repeated texture). */
export function makeGround(g) {
  const group = new THREE.Group();
  group.name = 'ground';
  if (!g || !g.enabled) return group;
  const material = new THREE.MeshLambertMaterial({ color: linearColor(g.color) });
  if (g.pattern === 'grid' || g.pattern === 'checker') {
    material.color.setRGB(1, 1, 1);
    material.map = groundTexture(g);
  }
  const plane = new THREE.Mesh(new THREE.PlaneGeometry(g.size, g.size), material);
  plane.name = 'ground';
  group.add(plane);
  return group;
}

/**
 * The world: background, lights, ground and objects. Returns {objects: Map name -> Group,
 * pickables: meshes a click may hit}. Moving objects are updated by updateObjects().
 */
export function buildWorld(scene, doc, models) {
  scene.background = linearColor(doc.background ?? [0.62, 0.72, 0.82]);
  addLights(scene, doc.lights ?? []);
  const ground = makeGround(doc.ground);
  scene.add(ground);
  const objects = new Map();
  const pickables = [...ground.children.filter((c) => c.isMesh)];
  for (const o of doc.objects ?? []) {
    const group = instantiate(models[o.model], o.name);
    group.matrixAutoUpdate = false;
    group.matrix.copy(scaledMatrix(o.X_WO, o.scale));
    group.userData = { scale: o.scale, kind: 'object' };
    scene.add(group);
    objects.set(o.name, group);
    pickables.push(...group.children);
  }
  return { objects, pickables };
}

/** Moves the objects listed in a state (moving objects only). */
export function updateObjects(objects, stateObjects) {
  for (const o of stateObjects ?? []) {
    const group = objects.get(o.name);
    if (!group) continue;
    group.matrix.copy(scaledMatrix(o.X_WO, group.userData.scale));
    group.matrixWorldNeedsUpdate = true;
  }
}
