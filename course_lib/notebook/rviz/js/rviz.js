// The notebook's RViz in the browser: an anywidget module that draws what the kernel sends.
//
// The kernel (course_lib/notebook/rviz/view.py) does the ROS and the geometry; this draws its
// items with three.js, in the fixed frame (ROS axes: z up). Messages from the kernel:
//   {kind: "layers", seq, layers: {name: [item, ...]}}, arrays as binary buffers
//     ({buffer: i, dtype, shape}), or {same: true}: the array this place (layer, item, key) had in
//     the message before; a layer not named keeps what it shows. A points item's optional `pose`
//     (4x4, row-major) places its positions in the fixed frame.
// Each time a message's layers are on screen the browser answers {kind: "drawn", seq, frames,
// render_ms}: the kernel sends more only while few are unanswered (newest wins; nothing queues).
// The tools answer {kind: "tool", tool, point, yaw}. Traits: `camera`, `displays` (status lines),
// `tool`, `frames` and `fixed_frame` (the tool bar's list).
import * as THREE from "three";
import { OrbitControls } from "three/addons/controls/OrbitControls.js";
import { mergeGeometries } from "three/addons/utils/BufferGeometryUtils.js";

// Colours are used as the messages give them (0-255 per channel on screen), as RViz shows them.
THREE.ColorManagement.enabled = false;

const MAX_WAITING = 2; // drawings received and not yet on screen, at most (see render's `waiting`)
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

const ARRAYS = ["positions", "colors", "matrices", "jpeg"];

// A view of the message's bytes (copied only when a float's start is not 4-byte aligned).
function typedArray(ref, buffers) {
  const view = buffers[ref.buffer];
  const Type = ref.dtype === "uint8" ? Uint8Array : Float32Array;
  if (view.byteOffset % Type.BYTES_PER_ELEMENT === 0)
    return new Type(view.buffer, view.byteOffset, view.byteLength / Type.BYTES_PER_ELEMENT);
  return new Type(view.buffer.slice(view.byteOffset, view.byteOffset + view.byteLength));
}

// An item with its arrays as typed arrays, a `same` one taken from the item before it at its
// place; null when that is unknown (a view opened after the message before: the kernel sends all
// again when this view says it is ready).
function decodeItem(item, buffers, before) {
  const out = { ...item };
  for (const key of ARRAYS) {
    if (!item[key]) continue;
    if (item[key].same && !(before && before[key])) return null;
    out[key] = item[key].same ? before[key] : typedArray(item[key], buffers);
  }
  if (out.colors) // see-through when an alpha is under 255; checked again only for new colours
    out.transparent = item.colors.same ? before.transparent : hasAlpha(out.colors);
  return out;
}

function hasAlpha(colors) {
  for (let i = 3; i < colors.length; i += 4) if (colors[i] < 255) return true;
  return false;
}

// Points and segments keep one geometry, its attributes allocated with room to grow: a new
// drawing is copied into them and only its range uploaded; an array the object drew last time
// (a `same` one) is not uploaded again. The object is never culled (its bounds change with each
// drawing) and is placed by the item's pose.
function setVertices(object, item) {
  const geometry = object.geometry, count = item.positions.length / 3;
  const position = geometry.getAttribute("position");
  if (!position || position.count < count) {
    const room = Math.max(64, Math.ceil(count * 1.25));
    geometry.dispose(); // the old GPU buffers go; the geometry is used again
    geometry.setAttribute("position", new THREE.BufferAttribute(new Float32Array(room * 3), 3).setUsage(THREE.DynamicDrawUsage));
    geometry.setAttribute("color", new THREE.BufferAttribute(new Uint8Array(room * 4), 4, true).setUsage(THREE.DynamicDrawUsage));
    object.userData.drawn = {};
  }
  upload(geometry.getAttribute("position"), item.positions, object.userData.drawn, "positions");
  upload(geometry.getAttribute("color"), item.colors, object.userData.drawn, "colors");
  geometry.setDrawRange(0, count);
  object.frustumCulled = false;
  object.matrixAutoUpdate = false;
  if (item.pose) object.matrix.fromArray(item.pose.flat()).transpose(); // row-major, as numpy's
  else object.matrix.identity();
  object.matrixWorldNeedsUpdate = true;
}

function upload(attribute, values, drawn, key) {
  if (drawn[key] === values) return;
  attribute.array.set(values);
  attribute.clearUpdateRanges();
  attribute.addUpdateRange(0, values.length);
  attribute.needsUpdate = true;
  drawn[key] = values;
}

// Materials are shared and kept, never disposed with a layer: three.js deletes a shader program
// when its last material is disposed, and compiling it again for the next drawing (SwiftShader,
// headless Chromium) blocked the page for 50-120 ms about 8 times a second, while the kernel's
// messages queued behind it and reached the view in bursts. Keys are few: a kind, a point size,
// an opacity in 1/255 steps, a text.
const materials = new Map();

function sharedMaterial(key, make) {
  let material = materials.get(key);
  if (!material) {
    material = make();
    materials.set(key, material);
  }
  return material;
}

// A frame's name is drawn again with every transform: its texture is made once and kept.
const textTextures = new Map();

function textSprite(text, color, height) {
  const key = `${text}|${color.join(",")}`;
  let texture = textTextures.get(key);
  if (!texture) {
    texture = textTexture(text, color);
    textTextures.set(key, texture);
  }
  const sprite = new THREE.Sprite(sharedMaterial(`sprite|${key}`, () => new THREE.SpriteMaterial({ map: texture, depthTest: false })));
  sprite.scale.set((height * texture.image.width) / texture.image.height, height, 1);
  return sprite;
}

function textTexture(text, color) {
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
  return new THREE.CanvasTexture(canvas);
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
    this.panelBox = document.createElement("div"); // the canvas and the Image displays' panels over it
    this.panelBox.style.cssText = `position: relative; width: ${width}px; height: ${height}px;`;
    this.panelBox.appendChild(this.renderer.domElement);
    el.appendChild(this.panelBox);
    this.panels = new Map();
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
    this.controls.autoRotate = Boolean(settings.spin) && mode !== "top"; // spin 2: a turn in 30 s
    this.controls.autoRotateSpeed = Number(settings.spin) || 0;
    this.controls.addEventListener("change", () => this.pointSizes());
    this.controls.update();
    this.pointSizes();
  }

  // Perspective: point sizes in metres; top-down: metres times the pixels per metre (at least 2 px).
  pointSizes() {
    for (const { group } of this.layers.values())
      for (const object of group.children)
        if (object.isPoints) {
          const metres = object.userData.size;
          const attenuation = !this.pixelsPerMetre;
          if (object.material.sizeAttenuation !== attenuation) { // a define of its program: compiled again
            object.material.sizeAttenuation = attenuation;
            object.material.needsUpdate = true;
          }
          object.material.size = this.pixelsPerMetre
            ? Math.max(2, metres * this.pixelsPerMetre * this.camera.zoom) : metres;
        }
    this.dirty = true;
  }

  // An item's three.js objects: those of `old` (the item before it at its place) updated when
  // it is points or segments as this one is, else new ones.
  itemSlot(item, old) {
    if (item.type !== "points" && item.type !== "lines") return { type: item.type, objects: this.itemObjects(item) };
    const transparent = item.transparent;
    const object = old && old.type === item.type ? old.objects[0]
      : new (item.type === "points" ? THREE.Points : THREE.LineSegments)(new THREE.BufferGeometry());
    object.material = item.type === "lines"
      ? sharedMaterial(`lines|${transparent}`, () => new THREE.LineBasicMaterial({ vertexColors: true, transparent }))
      : sharedMaterial(`points|${item.size}|${transparent}`, () => new THREE.PointsMaterial({ vertexColors: true, transparent }));
    object.userData.size = item.size;
    setVertices(object, item);
    return old && old.objects[0] === object ? old : { type: item.type, objects: [object] };
  }

  itemObjects(item) {
    const colors = item.colors;
    if (item.type === "shapes") {
      const matrices = item.matrices;
      const count = matrices.length / 16;
      const opacity = Math.round(colors.filter((_, index) => index % 4 === 3).reduce((a, b) => a + b, 0) / count) / 255;
      const material = sharedMaterial(`shapes|${opacity}`, () => new THREE.MeshLambertMaterial({ transparent: opacity < 1, opacity }));
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
      const positions = item.positions;
      return item.texts.map((text, i) => {
        const sprite = textSprite(text, colors.slice(4 * i, 4 * i + 4), item.heights[i]);
        sprite.position.set(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
        return sprite;
      });
    }
    return [];
  }

  setLayer(name, items) {
    const old = this.layers.get(name) || { group: new THREE.Group(), slots: [] };
    if (!this.layers.has(name)) this.scene.add(old.group);
    const slots = items.map((item, index) => this.itemSlot(item, old.slots[index]));
    for (const slot of old.slots) {
      if (slots.includes(slot)) continue;
      for (const object of slot.objects) { // materials (and text textures) are shared and stay
        old.group.remove(object);
        if (object.geometry && !Object.values(this.shapes).includes(object.geometry)) object.geometry.dispose();
      }
    }
    for (const slot of slots) for (const object of slot.objects) if (object.parent !== old.group) old.group.add(object);
    this.setPanel(name, items.find((item) => item.type === "image"));
    this.layers.set(name, { group: old.group, slots });
  }

  // The point of the fixed frame's ground (z = 0) under a pixel of the canvas, or null (the sky).
  groundPoint(event) {
    const box = this.renderer.domElement.getBoundingClientRect();
    const ndc = new THREE.Vector2(((event.clientX - box.left) / box.width) * 2 - 1,
      -((event.clientY - box.top) / box.height) * 2 + 1);
    const ray = new THREE.Raycaster();
    ray.setFromCamera(ndc, this.camera);
    const hit = new THREE.Vector3();
    return ray.ray.intersectPlane(new THREE.Plane(new THREE.Vector3(0, 0, 1), 0), hit) ? hit : null;
  }

  render() {
    const started = performance.now();
    this.renderer.render(this.scene, this.camera);
    this.renderMs = performance.now() - started;
    this.frames += 1;
    this.dirty = false;
  }

  // An Image display's picture: a 2D panel over the canvas's top left corner, as RViz docks it.
  setPanel(name, item) {
    let panel = this.panels.get(name);
    if (!item) {
      if (panel) {
        URL.revokeObjectURL(panel.src);
        panel.remove();
        this.panels.delete(name);
      }
      return;
    }
    if (!panel) {
      panel = document.createElement("img");
      panel.className = "rviz-image";
      panel.dataset.name = name;
      panel.style.cssText = "position: absolute; border: 1px solid #888; left: 4px;";
      this.panelBox.appendChild(panel);
      this.panels.set(name, panel);
    }
    const old = panel.src;
    panel.src = URL.createObjectURL(new Blob([item.jpeg], { type: "image/jpeg" }));
    if (old) URL.revokeObjectURL(old);
    panel.style.width = `${item.width}px`;
    panel.style.height = `${Math.round(item.width * item.aspect)}px`;
    let top = 4;
    for (const other of this.panels.values()) {
      other.style.top = `${top}px`;
      top += parseInt(other.style.height, 10) + 4;
    }
  }

  dispose() {
    for (const name of [...this.layers.keys()]) this.setLayer(name, []);
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

// RViz's tool bar: the tools (one use each, then back to Move Camera, as RViz's are), the views
// and the Global Options' fixed frame (a list of the frames the kernel knows).
const TOOLS = ["Move Camera", "2D Goal Pose", "Publish Point"];

function toolBar(model, scene) {
  const bar = document.createElement("div");
  bar.className = "rviz-toolbar";
  bar.style.cssText = "font: 12px sans-serif; padding: 2px 0; display: flex; gap: 4px; align-items: center;";
  const buttons = TOOLS.map((tool) => {
    const button = document.createElement("button");
    button.textContent = tool;
    button.dataset.tool = tool;
    button.onclick = () => { model.set("tool", tool); model.save_changes(); };
    bar.appendChild(button);
    return button;
  });
  for (const [label, mode] of [["Orbit", "orbit"], ["TopDownOrtho", "top"]]) {
    const button = document.createElement("button");
    button.textContent = label;
    button.onclick = () => { model.set("camera", { ...model.get("camera"), mode }); model.save_changes(); };
    bar.appendChild(button);
  }
  const label = document.createElement("label");
  label.textContent = "Fixed Frame ";
  const select = document.createElement("select");
  select.className = "rviz-fixed-frame";
  select.onchange = () => { model.set("fixed_frame", select.value); model.save_changes(); };
  label.appendChild(select);
  bar.appendChild(label);
  const show = () => {
    const tool = model.get("tool");
    for (const button of buttons) button.style.fontWeight = button.dataset.tool === tool ? "bold" : "normal";
    scene.controls.enabled = tool === "Move Camera";
    const frames = [...new Set([model.get("fixed_frame"), ...model.get("frames")])];
    select.replaceChildren(...frames.map((frame) => new Option(frame, frame, false, frame === model.get("fixed_frame"))));
  };
  for (const name of ["tool", "frames", "fixed_frame", "camera"]) model.on(`change:${name}`, show);
  show();
  return bar;
}

// 2D Goal Pose: press where the robot should be, drag the way it should face, release; Publish
// Point: click. Both on the fixed frame's ground (z = 0); the kernel publishes them.
function useTools(model, scene) {
  const canvas = scene.renderer.domElement;
  let start = null;
  canvas.addEventListener("pointerdown", (event) => {
    if (model.get("tool") === "Move Camera" || event.button !== 0) return;
    start = scene.groundPoint(event);
  });
  canvas.addEventListener("pointerup", (event) => {
    const tool = model.get("tool");
    if (tool === "Move Camera" || !start) return;
    const end = scene.groundPoint(event) || start;
    if (tool === "Publish Point") model.send({ kind: "tool", tool, point: [end.x, end.y, end.z] });
    else {
      const moved = end.distanceTo(start) > 1e-6;
      const yaw = moved ? Math.atan2(end.y - start.y, end.x - start.x) : 0;
      model.send({ kind: "tool", tool, point: [start.x, start.y, 0], yaw });
    }
    start = null;
    model.set("tool", "Move Camera");
    model.save_changes();
  });
}

function render({ model, el }) {
  const size = model.get("size");
  el.classList.add("rviz-view"); // its data-received, -seq (shown), -frames, -render-ms: for tests, benchmarks
  const scene = new Scene(el, size[0], size[1]);
  let statusEl = statusList(model.get("displays"));
  el.appendChild(statusEl);
  scene.setCamera(model.get("camera"));
  el.insertBefore(toolBar(model, scene), el.firstChild);
  useTools(model, scene);
  // The drawings not on screen yet, decoded as they came (views of the messages' bytes), oldest
  // first, one shown per animation frame: the kernel sends them evenly, but a busy page or server
  // hands them over in bunches, and a bunch merged into one frame showed 12-17 frames/s of a 20 Hz
  // scan. Beyond MAX_WAITING the oldest two merge (per layer the newer drawing wins; a layer only
  // the older had stays): a lagging page skips, never queues.
  const waiting = [];
  const received = new Map(); // each layer's items as last received, for their `same` arrays
  let running = true;

  model.on("msg:custom", (content, buffers) => {
    if (content.kind !== "layers") return;
    const layers = new Map();
    for (const [name, items] of Object.entries(content.layers)) {
      const before = received.get(name) || [];
      const decoded = items.map((item, index) => decodeItem(item, buffers, before[index]));
      if (decoded.includes(null)) continue;
      received.set(name, decoded);
      layers.set(name, decoded);
    }
    waiting.push({ seq: content.seq, layers });
    while (waiting.length > MAX_WAITING) {
      const [older, newer] = waiting.splice(0, 2);
      for (const [name, layer] of newer.layers) older.layers.set(name, layer);
      waiting.unshift({ seq: newer.seq, layers: older.layers });
    }
    el.dataset.received = String(content.seq);
  });
  model.on("change:camera", () => {
    scene.setCamera(model.get("camera"));
    scene.controls.enabled = model.get("tool") === "Move Camera";
  });
  model.on("change:displays", () => {
    const fresh = statusList(model.get("displays"));
    statusEl.replaceWith(fresh);
    statusEl = fresh;
  });

  function frame() {
    if (!running) return;
    if (scene.controls.autoRotate) scene.controls.update(); // a spinning orbit: a frame each time
    if (waiting.length) {
      const { seq, layers } = waiting.shift();
      for (const [name, items] of layers) scene.setLayer(name, items);
      scene.pointSizes();
      scene.render();
      el.dataset.seq = String(seq);
      el.dataset.frames = String(scene.frames);
      el.dataset.renderMs = scene.renderMs.toFixed(2);
      model.send({ kind: "drawn", seq, frames: scene.frames, render_ms: scene.renderMs });
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
