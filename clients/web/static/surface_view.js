// A surface in 3-D: the predicted heights as a mesh coloured by height, its
// jammed cells outlined in black and pinned nodes as red balls, and the goal
// (the same mesh, goal heights) beside it. three.js comes from Debian's
// libjs-three at /three/; without it or without WebGL, the same picture is
// drawn from above on a 2-D canvas (view.kind says which).
import { cssColour, heightColour, rangeOf } from './colours.js';
import { cellOutline, gridOf, nodePoint } from './surface_grid.js';

const GAP_MM = 30;  // between the predicted surface and the goal
const BACKGROUND = 0xf4f4f0;

export async function createSurfaceView(container) {
  const canvas = document.createElement('canvas');
  canvas.className = 'surface-canvas';
  container.replaceChildren(canvas);
  try {
    const THREE = await import('/three/build/three.module.js');
    const { OrbitControls } = await import('/three/examples/jsm/controls/OrbitControls.js');
    return new ThreeView(THREE, OrbitControls, canvas);
  } catch (e) {
    console.warn('hapticjam: 3-D view unavailable, drawing on a 2-D canvas:', e);
    return new FlatView(canvas, String(e.message || e));
  }
}

// What one picture shows: {snapshot, goalHeights (or null), rows, cols, range: [lo, hi] mm}.
function pictureRange(picture) {
  return picture.range || rangeOf([picture.snapshot.heights_mm, picture.goalHeights]);
}

class ThreeView {
  constructor(THREE, OrbitControls, canvas) {
    this.THREE = THREE;
    this.kind = 'webgl';
    this.canvas = canvas;
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(BACKGROUND);
    this.scene.add(new THREE.AmbientLight(0xffffff, 0.55));
    const sun = new THREE.DirectionalLight(0xffffff, 0.6);
    sun.position.set(-1, 3, 2);
    this.scene.add(sun);
    this.camera = new THREE.PerspectiveCamera(40, 1, 1, 10000);
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.addEventListener('change', () => this.render());
    this.content = new THREE.Group();
    this.scene.add(this.content);
    this.framed = null;
    new ResizeObserver(() => this.resize()).observe(canvas);
  }

  resize() {
    const w = this.canvas.clientWidth || 600, h = this.canvas.clientHeight || 400;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.render();
  }

  render() { this.renderer.render(this.scene, this.camera); }

  show(picture) {
    const THREE = this.THREE;
    const grid = gridOf(picture.snapshot, picture.rows, picture.cols);
    const range = pictureRange(picture);
    this.content.children.slice().forEach((c) => {
      this.content.remove(c);
      c.geometry.dispose();
      c.material.dispose();
    });
    this.content.add(this.surfaceMesh(grid, picture.snapshot.heights_mm, range, 0, true));
    for (const [row, col] of picture.snapshot.jammed_cells) this.content.add(this.outline(grid, picture.snapshot, row, col));
    for (const [a, b] of picture.snapshot.pinned_nodes) this.content.add(this.pin(grid, picture.snapshot, a, b));
    if (picture.goalHeights && picture.goalHeights.length === grid.nx * grid.ny)
      this.content.add(this.surfaceMesh(grid, picture.goalHeights, range, grid.widthMm + GAP_MM, false));
    this.frame(grid, !!picture.goalHeights);
    this.render();
  }

  // Scene axes: x = array x, y = height, z = -array y (so +y points away).
  surfaceMesh(grid, heights, [lo, hi], offsetX, moved) {
    const THREE = this.THREE;
    const n = grid.nx * grid.ny;
    const positions = new Float32Array(3 * n), colours = new Float32Array(3 * n);
    for (let k = 0; k < n; k++) {
      positions.set([offsetX + (moved ? grid.x(k) : grid.restX(k)), heights[k], -(moved ? grid.y(k) : grid.restY(k))], 3 * k);
      colours.set(heightColour((heights[k] - lo) / (hi - lo)), 3 * k);
    }
    const index = [];
    for (let i = 0; i + 1 < grid.ny; i++)
      for (let j = 0; j + 1 < grid.nx; j++) {
        const a = grid.index(i, j), b = a + 1, c = a + grid.nx, d = c + 1;
        index.push(a, b, d, a, d, c);
      }
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
    geometry.setAttribute('color', new THREE.BufferAttribute(colours, 3));
    geometry.setIndex(index);
    geometry.computeVertexNormals();
    const material = new THREE.MeshLambertMaterial({ vertexColors: THREE.VertexColors || true, side: THREE.DoubleSide });
    return new THREE.Mesh(geometry, material);
  }

  outline(grid, snapshot, row, col) {
    const THREE = this.THREE;
    const points = cellOutline(grid, row, col).map((k) => new THREE.Vector3(grid.x(k), snapshot.heights_mm[k] + 0.4, -grid.y(k)));
    const geometry = new THREE.BufferGeometry().setFromPoints(points);
    return new THREE.LineLoop(geometry, new THREE.LineBasicMaterial({ color: 0x111111 }));
  }

  pin(grid, snapshot, a, b) {
    const THREE = this.THREE;
    const k = nodePoint(grid, a, b);
    const ball = new THREE.Mesh(new THREE.SphereBufferGeometry(2.2, 12, 8), new THREE.MeshLambertMaterial({ color: 0xd01818 }));
    ball.position.set(grid.x(k), snapshot.heights_mm[k] + 1, -grid.y(k));
    return ball;
  }

  // Aims the camera at the content once per array size (later snapshots keep the user's view).
  frame(grid, withGoal) {
    const key = `${grid.nx}x${grid.ny}:${withGoal}`;
    if (this.framed === key) return;
    this.framed = key;
    const width = withGoal ? 2 * grid.widthMm + GAP_MM : grid.widthMm;
    const centre = new this.THREE.Vector3(width / 2, 0, -grid.depthMm / 2);
    const span = Math.max(width, grid.depthMm);
    this.camera.position.set(centre.x, span * 0.5, centre.z + span * 0.75);
    this.controls.target.copy(centre);
    this.controls.update();
    this.resize();
  }
}

// The 2-D fallback: the surface seen from above, one coloured quad per mesh
// square, jammed cells outlined and pinned nodes dotted, the goal beside it.
class FlatView {
  constructor(canvas, why) {
    this.kind = '2d';
    this.why = why;
    this.canvas = canvas;
  }

  show(picture) {
    const grid = gridOf(picture.snapshot, picture.rows, picture.cols);
    const range = pictureRange(picture);
    const w = this.canvas.clientWidth || 600, h = this.canvas.clientHeight || 400;
    this.canvas.width = w;
    this.canvas.height = h;
    const g = this.canvas.getContext('2d');
    g.fillStyle = '#f4f4f0';
    g.fillRect(0, 0, w, h);
    const panels = picture.goalHeights ? 2 : 1;
    const scale = Math.min((w - 20 * (panels + 1)) / (panels * grid.widthMm), (h - 40) / grid.depthMm);
    const draw = (heights, left) => {
      const at = (k) => [left + (k % grid.nx) * (grid.widthMm / (grid.nx - 1)) * scale,
                         h - 20 - Math.floor(k / grid.nx) * (grid.depthMm / (grid.ny - 1)) * scale];
      for (let i = 0; i + 1 < grid.ny; i++)
        for (let j = 0; j + 1 < grid.nx; j++) {
          const k = grid.index(i, j);
          const mean = (heights[k] + heights[k + 1] + heights[k + grid.nx] + heights[k + grid.nx + 1]) / 4;
          const [x0, y0] = at(k), [x1, y1] = at(k + grid.nx + 1);
          g.fillStyle = cssColour(heightColour((mean - range[0]) / (range[1] - range[0])));
          g.fillRect(x0, y1, x1 - x0 + 0.5, y0 - y1 + 0.5);
        }
      return at;
    };
    const at = draw(picture.snapshot.heights_mm, 20);
    g.strokeStyle = '#111';
    g.lineWidth = 2;
    for (const [row, col] of picture.snapshot.jammed_cells) {
      const [x0, y0] = at(grid.index(row * grid.p, col * grid.p));
      const [x1, y1] = at(grid.index((row + 1) * grid.p, (col + 1) * grid.p));
      g.strokeRect(x0, y1, x1 - x0, y0 - y1);
    }
    g.fillStyle = '#d01818';
    for (const [a, b] of picture.snapshot.pinned_nodes) {
      const [x, y] = at(nodePoint(grid, a, b));
      g.beginPath();
      g.arc(x, y, 4, 0, 2 * Math.PI);
      g.fill();
    }
    if (picture.goalHeights) draw(picture.goalHeights, 40 + grid.widthMm * scale);
  }
}
