// Where the preview starts looking from (view=start, the default): a level's front view shows
// its outside walls, so start where a person would look from. In order:
//  1. the file's first camera (glTF cameras, placed by their nodes);
//  2. a point inside the level: the bounding box's centre dropped onto the floor below it, at eye
//     height (1.7 units, glTF's metres, or a third of the room's height if that is less),
//     looking along the horizontal direction, of 16, whose ray runs longest before it meets a
//     wall; used only when at least 13 of the 16 meet one (the point is enclosed) and their
//     median distance is at least 1 unit (a space a person stands in, in glTF's metres): inside
//     a level, not among the blocks of an open box or in front of an object;
//  3. null: the caller uses the front view.
import * as THREE from 'three';

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
  const centre = box.getCenter(new THREE.Vector3());
  const ray = new THREE.Raycaster();
  const first = (origin, dir) => {
    ray.set(origin, dir);
    ray.far = Infinity;
    const hits = ray.intersectObject(root, true);
    return hits.length ? hits[0].distance : Infinity;
  };
  const down = first(centre, new THREE.Vector3(0, -1, 0));
  if (!Number.isFinite(down)) return null;
  const up = first(centre, new THREE.Vector3(0, 1, 0));
  const floorY = centre.y - down;
  const ceilingY = Number.isFinite(up) ? centre.y + up : box.max.y;
  const eye = new THREE.Vector3(centre.x, floorY + Math.min(1.7, (ceilingY - floorY) / 3), centre.z);
  let best = null, bestDistance = -1, enclosed = 0;
  const distances = [];
  for (let k = 0; k < 16; k++) {
    const a = (2 * Math.PI * k) / 16;
    const dir = new THREE.Vector3(Math.sin(a), 0, -Math.cos(a));
    const d = first(eye, dir);
    distances.push(d);
    if (!Number.isFinite(d)) continue;
    enclosed++;
    if (d > bestDistance) { bestDistance = d; best = dir; }
  }
  startView.last = { eye: eye.toArray(), distances };
  const walls = distances.filter(Number.isFinite).sort((x, y) => x - y);
  const median = walls.length ? walls[walls.length >> 1] : 0;
  if (enclosed < 13 || median < 1 || !best) return null;
  return { position: eye, target: eye.clone().addScaledVector(best, Math.max(bestDistance * 0.5, 1e-3)), from: 'inside' };
}
