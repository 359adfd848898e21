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
//  3. that point against the front view, judged by what each shows (viewScore): a 16 x 12 grid
//     of rays through the view (a ray meeting the back of a wall first sees nothing), scored by how much of
//     the level's surface is in frame, how many objects (meshes with 2% of the frame or more)
//     and how little one object fills it. The front view wins when it shows 1.5x as much: a
//     level in centimetres, whose 1.7-unit eye sits on the floor looking at one wall, or an open
//     box; a closed room, whose outside walls hide it, keeps the inside;
//  4. null: the caller uses the front view.
// The probes of 2. and 3. see both sides of every face (materials are made double-sided while they run).
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

// The front view: looking along -Z at the centre of box, from where its +Z face fills 1/1.1 of
// the view height (or width, if narrower). { position, target }.
export function frontViewPose(box, aspect, fovDegrees) {
  const size = box.getSize(new THREE.Vector3()), centre = box.getCenter(new THREE.Vector3());
  const tanHalf = Math.tan(THREE.MathUtils.degToRad(fovDegrees / 2));
  const half = 1.1 * Math.max(size.y / 2, size.x / 2 / aspect);
  return { position: new THREE.Vector3(centre.x, centre.y, centre.z + size.z / 2 + half / tanHalf), target: centre.clone() };
}

// The surface area of every mesh under root, world units (an InstancedMesh: times its copies,
// at the first copy's scale).
function surfaceArea(root) {
  let total = 0;
  const a = new THREE.Vector3(), b = new THREE.Vector3(), c = new THREE.Vector3();
  root.traverse((o) => {
    if (!o.isMesh || !o.geometry.attributes.position) return;
    const pos = o.geometry.attributes.position, idx = o.geometry.index;
    const n = idx ? idx.count : pos.count;
    let area = 0;
    for (let k = 0; k + 2 < n; k += 3) {
      const [i, j, l] = idx ? [idx.getX(k), idx.getX(k + 1), idx.getX(k + 2)] : [k, k + 1, k + 2];
      a.fromBufferAttribute(pos, i).applyMatrix4(o.matrixWorld);
      b.fromBufferAttribute(pos, j).applyMatrix4(o.matrixWorld);
      c.fromBufferAttribute(pos, l).applyMatrix4(o.matrixWorld);
      area += b.sub(a).cross(c.sub(a)).length() / 2;
    }
    total += area * (o.isInstancedMesh ? o.count : 1);
  });
  return total;
}

// What a view shows, from a 16 x 12 grid of rays through it (run with every face double-sided: a
// ray whose first surface is a face's back is looking at a wall from outside, through which a
// one-sided wall lets the page see, and counts for nothing): { score, seen (the share of the level's surface in frame: each ray's hit stands for
// d^2 / |cos| x its solid angle), objects (meshes with 2% of the frame or more), dominant (the
// largest mesh's share of what is seen) }; score = seen x sqrt(objects) x (1 - dominant / 2).
export function viewScore(root, pose, aspect, fovDegrees, area = surfaceArea(root)) {
  const cam = new THREE.PerspectiveCamera(fovDegrees, aspect, 1e-6, 1e9);
  cam.position.copy(pose.position);
  cam.lookAt(pose.target);
  cam.updateMatrixWorld(true);
  const ray = new THREE.Raycaster();
  const W = 16, H = 12, hits = new Map();
  const tanHalf = Math.tan(THREE.MathUtils.degToRad(fovDegrees / 2));
  const solid = ((2 * tanHalf) / H) * ((2 * tanHalf * aspect) / W); // per ray, at the view's centre
  let covered = 0, seen = 0;
  for (let j = 0; j < H; j++)
    for (let i = 0; i < W; i++) {
      ray.setFromCamera(new THREE.Vector2(((i + 0.5) / W) * 2 - 1, ((j + 0.5) / H) * 2 - 1), cam);
      const h = ray.intersectObject(root, true).find((x) => x.object.isMesh);
      if (!h) continue;
      const n = h.face ? h.face.normal.clone().transformDirection(h.object.matrixWorld) : null;
      if (n && n.dot(ray.ray.direction) > 0) continue; // the back of a wall: looking in from outside
      covered++;
      hits.set(h.object, (hits.get(h.object) || 0) + 1);
      const cos = n ? Math.abs(n.dot(ray.ray.direction)) : 1;
      seen += (solid * h.distance * h.distance) / Math.max(0.2, cos);
    }
  const counts = [...hits.values()];
  const objects = counts.filter((c) => c >= 0.02 * W * H).length;
  const dominant = covered ? Math.max(...counts) / covered : 1;
  const share = area > 0 ? Math.min(1, seen / area) : 0;
  return { score: share * Math.sqrt(objects) * (1 - dominant / 2), seen: share, covered: covered / (W * H), objects, dominant };
}

// The front view replaces an inside start when it shows this much more (a closed room's
// cutaway front view can show about as much as its inside; the inside is where a person stands).
const FRONT_MARGIN = 1.5;

// { position, target, from: 'camera' | 'inside' | 'front' } or null.
export function startView(gltf, root, box, aspect = 4 / 3, fovDegrees = 45) {
  root.updateMatrixWorld(true);
  if (gltf.cameras && gltf.cameras.length) {
    const cam = gltf.cameras[0];
    cam.updateMatrixWorld(true);
    const position = new THREE.Vector3().setFromMatrixPosition(cam.matrixWorld);
    const forward = new THREE.Vector3(0, 0, -1).transformDirection(cam.matrixWorld);
    const size = box.getSize(new THREE.Vector3()).length();
    return { position, target: position.clone().addScaledVector(forward, Math.max(size * 0.1, 1e-3)), from: 'camera' };
  }
  const within = doubleSided(root, () => inside(root, box));
  if (!within) return null;
  const front = frontViewPose(box, aspect, fovDegrees), area = surfaceArea(root);
  const scores = doubleSided(root, () => ({ inside: viewScore(root, within, aspect, fovDegrees, area),
    front: viewScore(root, front, aspect, fovDegrees, area) }));
  startView.scores = scores;
  return scores.front.score > FRONT_MARGIN * scores.inside.score ? { ...front, from: 'front' } : within;
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
