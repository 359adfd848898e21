// Fly mode for the 3D views: W/A/S/D (or arrows) move, Q/E down/up, Shift 4x faster,
// drag with the left mouse button to look around. Speed scales with the scene size.
import * as THREE from 'three';

export class Fly {
  constructor(camera, dom, speed) {
    this.camera = camera; this.dom = dom; this.speed = speed;
    this.enabled = false; this.keys = new Set(); this.drag = null;
    this.euler = new THREE.Euler(0, 0, 0, 'YXZ');
    addEventListener('keydown', (e) => { if (this.enabled && !isInput(e)) this.keys.add(e.code); });
    addEventListener('keyup', (e) => this.keys.delete(e.code));
    addEventListener('blur', () => this.keys.clear());
    dom.addEventListener('pointerdown', (e) => { if (this.enabled && e.button === 0) this.drag = [e.clientX, e.clientY]; });
    addEventListener('pointerup', () => { this.drag = null; });
    addEventListener('pointermove', (e) => {
      if (!this.enabled || !this.drag) return;
      this.euler.setFromQuaternion(this.camera.quaternion);
      this.euler.y -= (e.clientX - this.drag[0]) * 0.004;
      this.euler.x = Math.max(-1.55, Math.min(1.55, this.euler.x - (e.clientY - this.drag[1]) * 0.004));
      this.camera.quaternion.setFromEuler(this.euler);
      this.drag = [e.clientX, e.clientY];
      this.moved = true;
    });
  }

  // Moves the camera for dt seconds of held keys; returns true if anything changed.
  update(dt) {
    const k = this.keys, v = new THREE.Vector3();
    if (k.has('KeyW') || k.has('ArrowUp')) v.z -= 1;
    if (k.has('KeyS') || k.has('ArrowDown')) v.z += 1;
    if (k.has('KeyA') || k.has('ArrowLeft')) v.x -= 1;
    if (k.has('KeyD') || k.has('ArrowRight')) v.x += 1;
    if (k.has('KeyE')) v.y += 1;
    if (k.has('KeyQ')) v.y -= 1;
    const moved = this.moved; this.moved = false;
    if (!this.enabled || v.lengthSq() === 0) return moved;
    const fast = k.has('ShiftLeft') || k.has('ShiftRight') ? 4 : 1;
    v.normalize().multiplyScalar(this.speed * fast * Math.min(dt, 0.1)).applyQuaternion(this.camera.quaternion);
    this.camera.position.add(v);
    return true;
  }
}

function isInput(e) { return e.target && ['INPUT', 'SELECT', 'TEXTAREA'].includes(e.target.tagName); }
