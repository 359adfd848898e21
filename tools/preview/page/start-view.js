// Where the preview starts looking from (view=start, the default): a level's front view shows
// its outside walls, so start where a person would look from. In order:
//  1. the file's first camera (glTF cameras, placed by their nodes);
//  2. a point inside the level. Candidates are the bounding box's centre and 5 x 5 points over
//     it at the centre's height (off any regular spacing), each dropped onto the floor below it and raised to eye height
//     (1.7 units, glTF's metres, or a third of the room's height if that is less). From a
//     candidate, 16 horizontal rays probe the space. A candidate counts when it is not inside
//     geometry (most rays meeting a back face first: a pillar, a crate; a one-sided wall seen from
//     behind is fine) and it is enclosed (13 of the 16 meet a wall). It
//     must also be roomy (their median distance at least 1 unit, a space a person stands in).
//     The roomiest candidate wins, looking along its longest ray that meets a wall. That rules
//     out a point among the blocks of an open box or in front of an object;
//  3. null: the caller uses the front view.
// Probes see both sides of every face (materials are made double-sided while they run).
import * as THREE from 'three';

const DIRECTIONS = 16;

// Runs fn with every material of root double-sided, then puts the sides back.
function doubleSided(root, fn) {
  const saved = [];
  root.traverse((o) => {
    for (const m of [].concat(o.material || [])) { saved.push([m, m.side]); m.side = THREE.DoubleSide; }
  });
  try { return fn(); } finally { for (const [m, side] of saved) m.side = side; }
}

// { position, target, from: 'camera' | 'inside' } or null.
export function startView(gltf, root, box) {
  root.updateMatrixWorld(true);
  if (gltf.cameras && gltf.cameras.length) {
    const cam = gltf.cameras[0];
    cam.updateMatrixWorld(true);
    const position = new THREE.Vector3().setFromMatrixPosition(cam.matrixWorld);
    const forward = new THREE.Vector3(0, 0, -1).transformDirection(cam.matrixWorld);
    const size = box.getSize(new THREE.Vector3()).length();
    return { position, target: position.clone().addScaledVector(forward, Math.max(size * 0.1, 1e-3)), from: 'camera' };
  }
  return doubleSided(root, () => inside(root, box));
}

function inside(root, box) {
  const ray = new THREE.Raycaster();
  // the first surface along dir: { distance, back } (back: its back face: the origin is inside)
  const first = (origin, dir) => {
    ray.set(origin, dir);
    const h = ray.intersectObject(root, true)[0];
    if (!h) return { distance: Infinity, back: false };
    const n = h.face ? h.face.normal.clone().transformDirection(h.object.matrixWorld) : null;
    return { distance: h.distance, back: n ? n.dot(dir) > 0 : false };
  };
  const centre = box.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3());
  const candidates = [centre.clone()];
  // off the regular spacing levels are built on (a grid point on a wall's plane sees nothing)
  const f = [0.1213, 0.3014, 0.4871, 0.6695, 0.8532];
  for (const fx of f)
    for (const fz of f)
      candidates.push(new THREE.Vector3(box.min.x + size.x * fx, centre.y, box.min.z + size.z * fz));
  let best = null;
  const probes = [];
  for (const c of candidates) {
    const down = first(c, new THREE.Vector3(0, -1, 0));
    if (!Number.isFinite(down.distance) || down.back) continue;
    const floorY = c.y - down.distance;
    const floor = new THREE.Vector3(c.x, floorY + 1e-4 * size.length(), c.z);
    const up = first(floor, new THREE.Vector3(0, 1, 0));
    const ceilingY = Number.isFinite(up.distance) ? floorY + up.distance : box.max.y;
    const eye = new THREE.Vector3(c.x, floorY + Math.min(1.7, (ceilingY - floorY) / 3), c.z);
    let backs = 0, longest = null, longestDistance = -1;
    const distances = [];
    for (let k = 0; k < DIRECTIONS; k++) {
      const a = (2 * Math.PI * k) / DIRECTIONS;
      const dir = new THREE.Vector3(Math.sin(a), 0, -Math.cos(a));
      const h = first(eye, dir);
      backs += h.back;
      distances.push(h.distance);
      if (Number.isFinite(h.distance) && h.distance > longestDistance) { longestDistance = h.distance; longest = dir; }
    }
    const blocked = backs > DIRECTIONS / 2; // inside a pillar or a crate (a one-sided wall's back is fine)
    const walls = distances.filter(Number.isFinite).sort((x, y) => x - y);
    const median = walls.length ? walls[walls.length >> 1] : 0;
    probes.push({ eye: eye.toArray(), blocked, walls: walls.length, median });
    if (blocked || walls.length < 13 || median < 1 || !longest) continue;
    if (!best || median > best.median) best = { eye, dir: longest, distance: longestDistance, median };
  }
  startView.last = probes;
  if (!best) return null;
  return { position: best.eye, target: best.eye.clone().addScaledVector(best.dir, Math.max(best.distance * 0.5, 1e-3)), from: 'inside' };
}
