// The notebook's RViz in the browser: an anywidget module that draws what the kernel sends.
//
// The kernel (course_lib/notebook/rviz/view.py) does the ROS and the geometry; this draws its
// items with three.js, in the fixed frame (ROS axes: z up). Messages from the kernel:
//   {kind: "layers", seq, layers: {name: [item, ...]}}, arrays as binary buffers
//     ({buffer: i, dtype, shape}); a layer not named keeps what it shows.
// Each time a message's layers are on screen the browser answers {kind: "drawn", seq, frames,
// render_ms}: the kernel sends the next one only then (newest wins; nothing queues).
// The camera comes from the `camera` trait, the displays' status lines from `displays`.
import * as THREE from "three";
import { OrbitControls } from "three/addons/controls/OrbitControls.js";
import { mergeGeometries } from "three/addons/utils/BufferGeometryUtils.js";

// Colours are used as the messages give them (0-255 per channel on screen), as RViz shows them.
THREE.ColorManagement.enabled = false;

const BACKGROUND = 0x303030; // RViz's background, (48, 48, 48)
const LEVEL_COLORS = { ok: "#2e7d32", warn: "#b26a00", error: "#c62828" };

function unitShapes() {
  const cylinder = new THREE.CylinderGeometry(0.5, 0.5, 1, 20).rotateX(Math.PI / 2); // along z
  // The unit arrow along +x: shaft 0.77 long of diameter 0.5, head of diameter 1.
  const shaft = new THREE.CylinderGeometry(0.25, 0.25, 0.77, 16).translate(0, 0.385, 0);
  const head = new THREE.ConeGeometry(0.5, 0.23, 16).translate(0, 0.885, 0);
  const arrow = mergeGeometries([shaft, head]).rotateZ(-Math.PI / 2);
  return {
    cube: new THREE.BoxGeometry(1, 1, 1),
    sphere: new THREE.SphereGeometry(0.5, 20, 14),
    cylinder,
    arrow,
  };
}

function typedArray(ref, buffers) {
  const view = buffers[ref.buffer];
  const bytes = view.buffer.slice(view.byteOffset, view.byteOffset + view.byteLength);
  return ref.dtype === "uint8" ? new Uint8Array(bytes) : new Float32Array(bytes);
}

function textSprite(text, color, height) {
  const canvas = document.createElement("canvas");
  const context = canvas.getContext("2d");
  const font = "48px sans-serif";
  context.font = font;
  canvas.width = Math.ceil(context.measureText(text).width) + 8;
  canvas.height = 64;
  context.font = font;
  context.fillStyle = `rgba(${color[0]},${color[1]},${color[2]},${color[3] / 255})`;
  context.textBaseline = "middle";
  context.fillText(text, 4, 32);
  const texture = new THREE.CanvasTexture(canvas);
  const sprite = new THREE.Sprite(new THREE.SpriteMaterial({ map: texture, depthTest: false }));
  sprite.scale.set((height * canvas.width) / canvas.height, height, 1);
  return sprite;
}

class Scene {
  constructor(el, width, height) {
    this.width = width;
    this.height = height;
    this.renderer = new THREE.WebGLRenderer({ antialias: false });
    this.renderer.outputColorSpace = THREE.LinearSRGBColorSpace; // colours as the messages give them
    this.renderer.setPixelRatio(1);
    this.renderer.setSize(width, height);
    this.renderer.domElement.className = "rviz-canvas";
    this.renderer.domElement.style.display = "block";
    el.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(BACKGROUND);
    this.scene.add(new THREE.AmbientLight(0xffffff, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.4);
    sun.position.set(1, 2, 5);
    this.scene.add(sun);
    this.shapes = unitShapes();
    this.layers = new Map();
    this.frames = 0;
    this.renderMs = 0;
    this.dirty = true;
  }

  setCamera(settings) {
    const { mode = "orbit", target = [0, 0, 0], distance = 10, yaw = -2.35, pitch = 0.8, scale = 50 } = settings;
    if (this.controls) this.controls.dispose();
    if (mode === "top") {
      // Looking down z: x to the right, y up, `scale` pixels per metre.
      const w = this.width / 2 / scale, h = this.height / 2 / scale;
      this.camera = new THREE.OrthographicCamera(-w, w, h, -h, 0.01, 1000);
      this.camera.position.set(target[0], target[1], target[2] + 100);
      this.camera.up.set(0, 1, 0);
      this.pixelsPerMetre = scale;
    } else {
      this.camera = new THREE.PerspectiveCamera(50, this.width / this.height, 0.01, 1000);
      this.camera.up.set(0, 0, 1);
      this.camera.position.set(target[0] + distance * Math.cos(pitch) * Math.cos(yaw),
        target[1] + distance * Math.cos(pitch) * Math.sin(yaw), target[2] + distance * Math.sin(pitch));
      this.pixelsPerMetre = null;
    }
    this.camera.lookAt(...target);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.target.set(...target);
    this.controls.enableRotate = mode !== "top";
    this.controls.addEventListener("change", () => this.pointSizes());
    this.controls.update();
    this.pointSizes();
  }

  // Perspective: point sizes in metres; top-down: metres times the pixels per metre (at least 2 px).
  pointSizes() {
    for (const group of this.layers.values())
      for (const object of group.children)
        if (object.isPoints) {
          const metres = object.userData.size;
          object.material.sizeAttenuation = !this.pixelsPerMetre;
          object.material.size = this.pixelsPerMetre
            ? Math.max(2, metres * this.pixelsPerMetre * this.camera.zoom) : metres;
          object.material.needsUpdate = true;
        }
    this.dirty = true;
  }

  itemObjects(item, buffers) {
    const colors = item.colors ? typedArray(item.colors, buffers) : null;
    const transparent = colors ? colors.some((value, index) => index % 4 === 3 && value < 255) : false;
    if (item.type === "points" || item.type === "lines") {
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute("position", new THREE.BufferAttribute(typedArray(item.positions, buffers), 3));
      geometry.setAttribute("color", new THREE.BufferAttribute(colors, 4, true));
      if (item.type === "lines")
        return [new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ vertexColors: true, transparent }))];
      const points = new THREE.Points(geometry, new THREE.PointsMaterial({ vertexColors: true, transparent }));
      points.userData.size = item.size;
      return [points];
    }
    if (item.type === "shapes") {
      const matrices = typedArray(item.matrices, buffers);
      const count = matrices.length / 16;
      const opacity = colors.filter((_, index) => index % 4 === 3).reduce((a, b) => a + b, 0) / count / 255;
      const material = new THREE.MeshLambertMaterial({ transparent: opacity < 1, opacity });
      const mesh = new THREE.InstancedMesh(this.shapes[item.shape], material, count);
      const matrix = new THREE.Matrix4(), color = new THREE.Color();
      for (let i = 0; i < count; i++) {
        // The kernel sends row-major 4x4 matrices (numpy's order); three's fromArray is column-major.
        mesh.setMatrixAt(i, matrix.fromArray(matrices, i * 16).transpose());
        mesh.setColorAt(i, color.setRGB(colors[4 * i] / 255, colors[4 * i + 1] / 255, colors[4 * i + 2] / 255));
      }
      return [mesh];
    }
    if (item.type === "texts") {
      const positions = typedArray(item.positions, buffers);
      return item.texts.map((text, i) => {
        const sprite = textSprite(text, colors.slice(4 * i, 4 * i + 4), item.heights[i]);
        sprite.position.set(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
        return sprite;
      });
    }
    return [];
  }

  setLayer(name, items, buffers) {
    const old = this.layers.get(name);
    if (old) {
      this.scene.remove(old);
      old.traverse((object) => {
        if (object.material) {
          if (object.material.map) object.material.map.dispose();
          object.material.dispose();
        }
        if (object.geometry && !Object.values(this.shapes).includes(object.geometry)) object.geometry.dispose();
      });
    }
    const group = new THREE.Group();
    for (const item of items) for (const object of this.itemObjects(item, buffers)) group.add(object);
    this.scene.add(group);
    this.layers.set(name, group);
  }

  render() {
    const started = performance.now();
    this.renderer.render(this.scene, this.camera);
    this.renderMs = performance.now() - started;
    this.frames += 1;
    this.dirty = false;
  }

  dispose() {
    for (const name of [...this.layers.keys()]) this.setLayer(name, [], []);
    this.controls.dispose();
    this.renderer.dispose();
  }
}

function statusList(displays) {
  const list = document.createElement("div");
  list.className = "rviz-displays";
  list.style.cssText = "font: 12px sans-serif; padding: 4px 0;";
  for (const display of displays) {
    const line = document.createElement("div");
    line.className = "rviz-display";
    line.dataset.name = display.name;
    line.style.color = LEVEL_COLORS[display.level] || "inherit";
    line.textContent = `${display.name}${display.topic ? " (" + display.topic + ")" : ""}: ${display.status}`;
    list.appendChild(line);
  }
  return list;
}

function render({ model, el }) {
  const size = model.get("size");
  const scene = new Scene(el, size[0], size[1]);
  let statusEl = statusList(model.get("displays"));
  el.appendChild(statusEl);
  scene.setCamera(model.get("camera"));
  let pending = null; // the newest message not on screen yet; an older one is replaced, not queued
  let running = true;

  model.on("msg:custom", (content, buffers) => {
    if (content.kind !== "layers") return;
    pending = { content, buffers };
  });
  model.on("change:camera", () => scene.setCamera(model.get("camera")));
  model.on("change:displays", () => {
    const fresh = statusList(model.get("displays"));
    statusEl.replaceWith(fresh);
    statusEl = fresh;
  });

  function frame() {
    if (!running) return;
    if (pending) {
      const { content, buffers } = pending;
      pending = null;
      for (const [name, items] of Object.entries(content.layers)) scene.setLayer(name, items, buffers);
      scene.pointSizes();
      scene.render();
      el.dataset.seq = String(content.seq);
      el.dataset.frames = String(scene.frames);
      el.dataset.renderMs = scene.renderMs.toFixed(2);
      model.send({ kind: "drawn", seq: content.seq, frames: scene.frames, render_ms: scene.renderMs });
    } else if (scene.dirty) {
      scene.render();
      el.dataset.frames = String(scene.frames);
    }
    requestAnimationFrame(frame);
  }
  requestAnimationFrame(frame);
  model.send({ kind: "ready" });
  return () => {
    running = false;
    scene.dispose();
  };
}

export default { render };
