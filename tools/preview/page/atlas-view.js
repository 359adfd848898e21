// The `atlas` view: one lightmap atlas as a flat 2D image in an orthographic camera whose
// world units are texels (x right, y = -row). Layers: lightmap (E/pi x 2^EV, tone mapped),
// invalid (the same with exactly-0 texels magenta), checker (the UV1 triangles with the checker material on a dark
// blue "no chart" background). The atlas sits at integer pixel offsets with an integer zoom
// (or 1/k), so texel (x, y) covers pixels originX + x*zoom .. + zoom exactly.
import * as THREE from 'three';
import { invalidMaterial, checkerMaterial, atlasLayoutGeometry } from './materials.js';

export const ATLAS_BACKGROUND = 0x141428; // sRGB (20, 20, 40): texels no chart covers

export class AtlasView {
  constructor(atlases, chartMeshes) {
    this.atlases = atlases;
    this.chartMeshes = chartMeshes; // [{atlas, checkerGeometry, scaleOffset (the mesh's rectangle in the atlas), rects (an InstancedMesh's: one per copy) or null}]
    this.camera = new THREE.OrthographicCamera(0, 1, 0, -1, -10, 10);
    this.scenes = new Map();
    this.atlas = 0; this.layer = 'lightmap'; this.zoom = 1; this.originX = 0; this.originY = 0;
  }

  sceneFor(atlasIndex, layer) {
    const k = atlasIndex + ':' + layer;
    if (this.scenes.has(k)) return this.scenes.get(k);
    const a = this.atlases[atlasIndex];
    const scene = new THREE.Scene();
    scene.background = new THREE.Color(ATLAS_BACKGROUND);
    if (layer === 'checker') {
      const mat = checkerMaterial(a);
      for (const cm of this.chartMeshes) if (cm.atlas === atlasIndex) scene.add(new THREE.Mesh(atlasLayoutGeometry(cm.checkerGeometry, a, cm.rects || cm.scaleOffset), mat));
    } else {
      const g = new THREE.BufferGeometry();
      const w = a.width, h = a.height;
      g.setAttribute('position', new THREE.BufferAttribute(new Float32Array([0, 0, 0, w, 0, 0, w, -h, 0, 0, -h, 0]), 3));
      g.setAttribute('uv1', new THREE.BufferAttribute(new Float32Array([0, 0, 1, 0, 1, 1, 0, 1]), 2));
      g.setIndex([0, 2, 1, 0, 3, 2]);
      // E/pi: a texel x toLux (pi when the files hold E/pi, extras.lightmap.scale radiance)
      scene.add(new THREE.Mesh(g, invalidMaterial(a, a.toLux, { nearest: true, showInvalid: layer === 'invalid' })));
    }
    this.scenes.set(k, scene);
    return scene;
  }

  // zoom: pixels per texel (number, or null to fit); centre: texel to centre on (or null).
  layout(width, height, zoom = null, centre = null) {
    const a = this.atlases[this.atlas];
    if (!zoom) {
      const fit = Math.min(width / a.width, height / a.height);
      zoom = fit >= 1 ? Math.floor(fit) : 1 / Math.ceil(1 / fit);
    }
    this.zoom = zoom;
    const cx = centre ? centre[0] + 0.5 : a.width / 2, cy = centre ? centre[1] + 0.5 : a.height / 2;
    this.originX = Math.round(width / 2 - cx * zoom);
    this.originY = Math.round(height / 2 - cy * zoom);
    this.updateCamera(width, height);
  }

  updateCamera(width, height) {
    const c = this.camera, z = this.zoom;
    c.left = -this.originX / z; c.right = (width - this.originX) / z;
    c.top = this.originY / z; c.bottom = -(height - this.originY) / z;
    c.updateProjectionMatrix();
  }

  pan(dx, dy, width, height) { this.originX += Math.round(dx); this.originY += Math.round(dy); this.updateCamera(width, height); }

  zoomAt(factor, px, py, width, height) {
    const tx = (px - this.originX) / this.zoom, ty = (py - this.originY) / this.zoom;
    let z = this.zoom * factor;
    z = z >= 1 ? Math.round(z) : 1 / Math.round(1 / z);
    if (z === this.zoom) z = factor > 1 ? (this.zoom >= 1 ? this.zoom + 1 : 1 / (1 / this.zoom - 1)) : (this.zoom > 1 ? this.zoom - 1 : 1 / (1 / this.zoom + 1));
    this.zoom = Math.min(64, Math.max(1 / 16, z));
    this.originX = Math.round(px - tx * this.zoom); this.originY = Math.round(py - ty * this.zoom);
    this.updateCamera(width, height);
  }

  // Texel under a pixel position (CSS pixels from the canvas's top-left), or null.
  texelAt(px, py) {
    const a = this.atlases[this.atlas];
    const x = Math.floor((px - this.originX) / this.zoom), y = Math.floor((py - this.originY) / this.zoom);
    if (x < 0 || y < 0 || x >= a.width || y >= a.height) return null;
    return { atlas: this.atlas, x, y, rgb: Array.from(a.data.subarray(4 * (y * a.width + x), 4 * (y * a.width + x) + 3), (v) => v * a.toLux) };
  }

  // Pixel (float, top-left origin) where the centre of texel (x, y) is drawn.
  texelToScreen(x, y) { return { x: this.originX + (x + 0.5) * this.zoom, y: this.originY + (y + 0.5) * this.zoom }; }

  render(renderer) { renderer.render(this.sceneFor(this.atlas, this.layer), this.camera); }
}
