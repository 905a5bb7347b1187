// LeaS plan and motion viewer: a small WebGL2 renderer for the pages that
// leas_jax/contacts/viewer.py writes. The page inlines this file and a JSON
// element "plan-data" (see viewer.py `html_payload` for its keys); nothing is
// fetched. Drag: orbit, right- or shift-drag: pan, wheel: zoom. The URL
// fragment can set the view: #cam=azimuth,elevation,distance,tx,ty,tz
// (rad, rad, m, m, m, m) &frame=N &panel=0 (hide the panel).
"use strict";
const DATA = JSON.parse(document.getElementById("plan-data").textContent);

function decode(b64, Type) {
  const bin = atob(b64), bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  return new Type(bytes.buffer);
}

// ---- 4x4 column-major matrices (WebGL layout)
function perspective(fovy, aspect, near, far) {
  const f = 1 / Math.tan(fovy / 2), nf = 1 / (near - far);
  return new Float32Array([f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0]);
}
function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
function normalize(a) { const n = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / n, a[1] / n, a[2] / n]; }
function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
function lookAt(eye, target, up) {
  const z = normalize(sub(eye, target)), x = normalize(cross(up, z)), y = cross(z, x);
  return new Float32Array([x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0,
                           -dot(x, eye), -dot(y, eye), -dot(z, eye), 1]);
}
// Row-major 3x4 [R | p] (Python side) to column-major 4x4.
function fromRows34(m, o) {
  return new Float32Array([m[o], m[o + 4], m[o + 8], 0, m[o + 1], m[o + 5], m[o + 9], 0,
                           m[o + 2], m[o + 6], m[o + 10], 0, m[o + 3], m[o + 7], m[o + 11], 1]);
}
// a * b for column-major 4x4 rigid transforms (last row 0 0 0 1).
function mul(a, b) {
  const out = new Float32Array(16);
  for (let c = 0; c < 4; c++) {
    for (let r = 0; r < 3; r++) {
      out[4 * c + r] = a[r] * b[4 * c] + a[4 + r] * b[4 * c + 1] + a[8 + r] * b[4 * c + 2] + (c === 3 ? a[12 + r] : 0);
    }
  }
  out[15] = 1;
  return out;
}
// Rotation about a unit axis (0: x, 1: y, 2: z) by angle, as a 4x4.
function axisRotation(axis, angle) {
  const c = Math.cos(angle), s = Math.sin(angle), m = new Float32Array([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);
  const i = (axis + 1) % 3, j = (axis + 2) % 3;  // the plane rotated: (y, z), (z, x) or (x, y)
  m[4 * i + i] = c; m[4 * i + j] = s; m[4 * j + i] = -s; m[4 * j + j] = c;
  return m;
}
// Free-flyer configuration (x, y, z, quaternion x, y, z, w) as a 4x4.
function freeFlyer(q, o) {
  let x = q[o + 3], y = q[o + 4], z = q[o + 5], w = q[o + 6];
  const n = Math.hypot(x, y, z, w) || 1;
  x /= n; y /= n; z /= n; w /= n;
  return new Float32Array([
    1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w), 0,
    2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w), 0,
    2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y), 0,
    q[o], q[o + 1], q[o + 2], 1]);
}
const IDENTITY = new Float32Array([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);

// ---- robot kinematics: the Pinocchio tree (free flyer + revolute joints about x, y or z)
const robot = DATA.robot;
let kinematics = null;
if (robot) {
  const m = robot.model, jp = decode(m.joint_placements, Float32Array), gp = decode(m.geom_placements, Float32Array);
  kinematics = {
    parent: m.parent, kind: m.kind, qIndex: m.q_index, nq: m.nq,
    joint: m.parent.map((_, j) => fromRows34(jp, 12 * j)),
    geomJoint: m.geom_joint, geom: m.geom_joint.map((_, g) => fromRows34(gp, 12 * g)),
  };
  robot.tracks.forEach(t => {
    t.qs = decode(t.q, Float32Array);
    t.frames = t.qs.length / kinematics.nq;
    t.cache = new Map();
  });
  robot.times = decode(robot.times, Float32Array);
}
// World placement of every drawn geometry (mesh scale folded in) at a configuration.
// Joint j's parent comes before it (Pinocchio order); joint 0 is the universe.
function geomPlacements(q, o) {
  const K = kinematics, world = [IDENTITY];
  for (let j = 1; j < K.parent.length; j++) {
    const kind = K.kind[j], at = o + K.qIndex[j];
    const motion = kind === "free" ? freeFlyer(q, at) : axisRotation("xyz".indexOf(kind[1]), q[at]);
    world.push(mul(mul(world[K.parent[j]], K.joint[j]), motion));
  }
  return K.geom.map((placement, g) => mul(world[K.geomJoint[g]], placement));
}
// Placements of a track at a frame (frames past the track's end hold its last one).
function trackPlacements(track, frame) {
  const f = Math.max(0, Math.min(frame, track.frames - 1));
  if (!track.cache.has(f)) track.cache.set(f, geomPlacements(track.qs, f * kinematics.nq));
  return track.cache.get(f);
}

// ---- WebGL
const canvas = document.getElementById("view");
const gl = canvas.getContext("webgl2", {antialias: true});
if (!gl) {
  document.getElementById("error").textContent = "WebGL2 is not available in this browser.";
  throw new Error("no WebGL2");
}

// Normals come from screen-space derivatives of the world position (flat per
// triangle, no normal arrays in the file), turned towards the eye: both sides
// of a face are lit alike, whatever the winding or a mirroring scale.
const VS = `#version 300 es
in vec3 aPos;
uniform mat4 uProj, uView, uModel;
out vec3 vWorld;
void main() {
  vec4 w = uModel * vec4(aPos, 1.0);
  vWorld = w.xyz;
  gl_Position = uProj * uView * w;
}`;
const FS = `#version 300 es
precision highp float;
in vec3 vWorld;
uniform vec4 uColor;
uniform vec3 uEye;
uniform vec2 uHeights;  // terrain: heights of the lowest and highest upward faces
uniform int uMode;  // 0: shaded, 1: flat colour (lines), 2: terrain (height colours, 0.5 m grid on level faces)
out vec4 outColor;
vec3 heightColor(float z) {
  float t = clamp((z - uHeights.x) / max(uHeights.y - uHeights.x, 1e-3), 0.0, 1.0);
  vec3 low = vec3(0.66, 0.62, 0.54), mid = vec3(0.52, 0.70, 0.52), high = vec3(0.45, 0.62, 0.85);
  return t < 0.5 ? mix(low, mid, 2.0 * t) : mix(mid, high, 2.0 * t - 1.0);
}
void main() {
  if (uMode == 1) { outColor = uColor; return; }
  vec3 c = cross(dFdx(vWorld), dFdy(vWorld));
  vec3 n = dot(c, c) > 1e-24 ? normalize(c) : vec3(0.0, 0.0, 1.0);
  if (dot(n, uEye - vWorld) < 0.0) n = -n;
  float light = 0.38 + 0.52 * max(dot(n, normalize(vec3(0.35, 0.25, 1.0))), 0.0)
              + 0.22 * max(dot(n, normalize(vec3(-0.7, -0.5, 0.25))), 0.0);
  vec3 base = uColor.rgb;
  if (uMode == 2) {
    base = heightColor(vWorld.z);
    if (abs(n.z) > 0.7) {  // grid lines on level faces only: fwidth of x or y vanishes on a wall
      vec2 w = max(fwidth(vWorld.xy * 2.0), vec2(1e-4));
      vec2 g = abs(fract(vWorld.xy * 2.0 + 0.5) - 0.5) / w;
      base *= 1.0 - 0.3 * (1.0 - min(min(g.x, g.y), 1.0));
    }
  }
  outColor = vec4(min(base * light, vec3(1.0)), uColor.a);
}`;
function compile(type, src) {
  const s = gl.createShader(type);
  gl.shaderSource(s, src);
  gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
  return s;
}
const prog = gl.createProgram();
gl.attachShader(prog, compile(gl.VERTEX_SHADER, VS));
gl.attachShader(prog, compile(gl.FRAGMENT_SHADER, FS));
gl.linkProgram(prog);
if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
gl.useProgram(prog);
const loc = {};
for (const name of ["uProj", "uView", "uModel", "uColor", "uMode", "uEye", "uHeights"]) loc[name] = gl.getUniformLocation(prog, name);
const aPos = gl.getAttribLocation(prog, "aPos");

function makeDrawable(positions, indices, indexType) {
  const vao = gl.createVertexArray();
  gl.bindVertexArray(vao);
  const vbo = gl.createBuffer();
  gl.bindBuffer(gl.ARRAY_BUFFER, vbo);
  gl.bufferData(gl.ARRAY_BUFFER, positions, gl.STATIC_DRAW);
  gl.enableVertexAttribArray(aPos);
  gl.vertexAttribPointer(aPos, 3, gl.FLOAT, false, 0, 0);
  let count = positions.length / 3, type = null;
  if (indices) {
    const ibo = gl.createBuffer();
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ibo);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, indices, gl.STATIC_DRAW);
    count = indices.length;
    type = indexType === "u16" ? gl.UNSIGNED_SHORT : gl.UNSIGNED_INT;
  }
  gl.bindVertexArray(null);
  return {vao, count, type};
}
function draw(d, mode, primitive, color, model) {
  if (d.count === 0) return;
  gl.uniformMatrix4fv(loc.uModel, false, model || IDENTITY);
  gl.uniform4fv(loc.uColor, color);
  gl.uniform1i(loc.uMode, mode);
  gl.bindVertexArray(d.vao);
  if (d.type !== null) gl.drawElements(primitive, d.count, d.type, 0);
  else gl.drawArrays(primitive, 0, d.count);
}

// ---- scene
const terrain = makeDrawable(decode(DATA.terrain.positions, Float32Array), decode(DATA.terrain.indices, Uint32Array), "u32");
const guideAll = decode(DATA.guide, Float32Array);
const nGuide = guideAll.length / 3, lastValid = DATA.last_valid_index;
const okEnd = Math.max(0, Math.min(lastValid, nGuide - 1));
const guideOk = makeDrawable(lastValid >= 0 ? guideAll.slice(0, 3 * (okEnd + 1)) : new Float32Array(0));
const guideBad = makeDrawable(lastValid < nGuide - 1 ? guideAll.slice(lastValid >= 0 ? 3 * okEnd : 0) : new Float32Array(0));
// Footprints: each rectangle (4 corners) as 2 triangles and a closed outline,
// lifted 3 mm over the support surface (and drawn in front of the terrain by
// its polygon offset).
function footDrawables(b64) {
  const c = decode(b64, Float32Array), n = c.length / 12;
  const tri = new Float32Array(n * 18), lines = new Float32Array(n * 24);
  for (let r = 0; r < n; r++) {
    const v = i => [c[12 * r + 3 * i], c[12 * r + 3 * i + 1], c[12 * r + 3 * i + 2] + 0.003];
    [0, 1, 2, 0, 2, 3].forEach((i, k) => tri.set(v(i), 18 * r + 3 * k));
    [0, 1, 1, 2, 2, 3, 3, 0].forEach((i, k) => lines.set(v(i), 24 * r + 3 * k));
  }
  return {fill: makeDrawable(tri), outline: makeDrawable(lines)};
}
const feet = [footDrawables(DATA.footprints.left), footDrawables(DATA.footprints.right)];
const meshes = DATA.meshes.map(m => makeDrawable(decode(m.positions, Float32Array),
    decode(m.indices, m.index_type === "u16" ? Uint16Array : Uint32Array), m.index_type));

// ---- URL fragment: #cam=az,el,dist,tx,ty,tz&frame=N&panel=0
const hash = {};
const fragment = (typeof location !== "undefined" && location.hash) ? location.hash.slice(1) : "";
for (const part of fragment.split("&")) {
  const eq = part.indexOf("=");
  if (eq > 0) hash[part.slice(0, eq)] = decodeURIComponent(part.slice(eq + 1));
}
if (hash.panel === "0") document.getElementById("panel").style.display = "none";

// ---- UI
const nFrames = robot ? robot.times.length : 0;
const slider = document.getElementById("posture"), label = document.getElementById("posture-label");
const showAll = document.getElementById("show-all"), showRobot = document.getElementById("show-robot");
const playButton = document.getElementById("play"), speed = document.getElementById("speed");
// data goes into the page as text nodes only (textContent), never parsed as HTML
const info = document.getElementById("info"), nameNode = document.createElement("b");
nameNode.textContent = String(DATA.name);
info.appendChild(nameNode);
info.appendChild(document.createTextNode(": " + String(DATA.subtitle)));
const trackBoxes = [];
if (robot) {
  slider.max = nFrames - 1;
  const frame = Math.max(0, Math.min(nFrames - 1, Math.round(Number(hash.frame) || 0)));
  slider.value = String(frame);
  // "all frames at once" only where few are stored (the key postures of a plan)
  if (!robot.overlay) document.getElementById("show-all-label").style.display = "none";
  // one checkbox per track where there are several (the "robot" box shows or hides them all)
  const tracksNode = document.getElementById("tracks");
  robot.tracks.forEach(t => {
    const box = document.createElement("input"), labelNode = document.createElement("label");
    box.type = "checkbox";
    box.checked = true;
    box.onchange = () => render();
    labelNode.appendChild(box);
    labelNode.appendChild(document.createTextNode(" " + String(t.name) + " "));
    if (robot.tracks.length > 1) tracksNode.appendChild(labelNode);
    trackBoxes.push(box);
  });
} else {
  document.getElementById("robot-controls").style.display = "none";
}
function frameLabel(f) {
  if (robot.postures) return `#${robot.postures[f]} (guide index ${robot.guide_index[f]})`;
  return `t = ${robot.times[f].toFixed(2)} s / ${robot.times[nFrames - 1].toFixed(2)} s`;
}
function updateLabel() {
  if (robot) label.textContent = frameLabel(+slider.value);
}
// Playback follows the frames' times (s) at the chosen speed; it loops.
let playing = false, clock = 0, lastTick = 0;
function tick(now) {
  if (!playing) return;
  const start = robot.times[0], end = robot.times[nFrames - 1];
  clock += (now - lastTick) / 1000 * Number(speed.value || 1);
  lastTick = now;
  if (clock > end) clock = start;
  let f = +slider.value;
  if (robot.times[f] > clock) f = 0;
  while (f + 1 < nFrames && robot.times[f + 1] <= clock) f++;
  slider.value = String(f);
  updateLabel();
  render();
  requestAnimationFrame(tick);
}
playButton.onclick = () => {
  playing = !playing && nFrames > 1;
  playButton.textContent = playing ? "pause" : "play";
  if (!playing) return;
  clock = robot.times[+slider.value];
  if (+slider.value === nFrames - 1) { clock = robot.times[0]; slider.value = "0"; }
  lastTick = performance.now();
  requestAnimationFrame(tick);
};
slider.oninput = () => { updateLabel(); render(); };
showAll.onchange = showRobot.onchange = () => render();
updateLabel();

// ---- orbit camera (z up) around the centre of the terrain bounds
const b = DATA.bounds, heights = DATA.terrain.heights;
const cam = {
  target: [(b[0][0] + b[1][0]) / 2, (b[0][1] + b[1][1]) / 2, heights[0]],
  dist: 1.2 * Math.hypot(b[1][0] - b[0][0], b[1][1] - b[0][1]),
  az: -Math.PI / 2 - 0.5, el: 0.6,
};
if (hash.cam) {
  const v = hash.cam.split(",").map(Number);
  if (v.length === 6 && v.every(Number.isFinite)) {
    [cam.az, cam.el, cam.dist] = v;
    cam.target = v.slice(3);
  }
}
// Radius of a sphere round the terrain centre holding the scene: sets the far plane.
const sceneRadius = 0.5 * Math.hypot(b[1][0] - b[0][0], b[1][1] - b[0][1], heights[1] - heights[0] + 2);
function eye() {
  return [cam.target[0] + cam.dist * Math.cos(cam.el) * Math.cos(cam.az),
          cam.target[1] + cam.dist * Math.cos(cam.el) * Math.sin(cam.az),
          cam.target[2] + cam.dist * Math.sin(cam.el)];
}
let drag = null;
canvas.addEventListener("contextmenu", e => e.preventDefault());
canvas.addEventListener("mousedown", e => { drag = {x: e.clientX, y: e.clientY, pan: e.button === 2 || e.shiftKey}; });
window.addEventListener("mouseup", () => { drag = null; });
window.addEventListener("mousemove", e => {
  if (!drag) return;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  drag.x = e.clientX; drag.y = e.clientY;
  if (drag.pan) {
    const s = cam.dist * 0.0015, ca = Math.cos(cam.az), sa = Math.sin(cam.az);
    // Grab-the-ground panning: screen right is (-sin az, cos az), the view
    // direction on the ground is -(cos az, sin az).
    cam.target[0] += s * (dx * sa - dy * ca);
    cam.target[1] += s * (-dx * ca - dy * sa);
  } else {
    cam.az -= dx * 0.005;
    cam.el = Math.max(-1.5, Math.min(1.5, cam.el + dy * 0.005));
  }
  render();
});
canvas.addEventListener("wheel", e => {
  e.preventDefault();
  cam.dist = Math.max(0.2, cam.dist * Math.exp(e.deltaY * 0.001));
  render();
}, {passive: false});

function drawRobot(placements, color) {
  robot.geoms.forEach((g, i) => draw(meshes[g.mesh], 0, gl.TRIANGLES,
      color || [g.color[0], g.color[1], g.color[2], 1], placements[i]));
}

function render() {
  const w = canvas.clientWidth, h = canvas.clientHeight, dpr = window.devicePixelRatio || 1;
  if (canvas.width !== Math.round(w * dpr) || canvas.height !== Math.round(h * dpr)) {
    canvas.width = Math.round(w * dpr); canvas.height = Math.round(h * dpr);
  }
  gl.viewport(0, 0, canvas.width, canvas.height);
  gl.clearColor(0.13, 0.14, 0.16, 1);
  gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
  gl.enable(gl.DEPTH_TEST);
  gl.depthFunc(gl.LEQUAL);
  gl.disable(gl.BLEND);
  gl.depthMask(true);
  // Near and far planes follow the camera: depth precision where the scene is.
  const e = eye(), toCentre = Math.hypot(...sub(e, cam.target));
  const near = Math.max(0.01, 0.02 * cam.dist), far = toCentre + 2 * sceneRadius + 5;
  gl.uniformMatrix4fv(loc.uProj, false, perspective(0.8, canvas.width / Math.max(1, canvas.height), near, far));
  gl.uniformMatrix4fv(loc.uView, false, lookAt(e, cam.target, [0, 0, 1]));
  gl.uniform3fv(loc.uEye, e);
  gl.uniform2fv(loc.uHeights, heights);
  // The terrain is pushed back in depth so that footprints, lines and feet on it never fight it.
  gl.enable(gl.POLYGON_OFFSET_FILL);
  gl.polygonOffset(1, 2);
  draw(terrain, 2, gl.TRIANGLES, [1, 1, 1, 1]);
  gl.disable(gl.POLYGON_OFFSET_FILL);
  draw(guideOk, 1, gl.LINE_STRIP, [0.3, 0.85, 0.3, 1]);
  draw(guideBad, 1, gl.LINE_STRIP, [0.95, 0.2, 0.2, 1]);
  feet.forEach((f, i) => {
    const c = DATA.foot_colors[i];
    draw(f.fill, 0, gl.TRIANGLES, [c[0], c[1], c[2], 1]);
    draw(f.outline, 1, gl.LINES, [0.05, 0.05, 0.05, 1]);
  });
  if (robot && showRobot.checked) {
    const frames = showAll.checked && robot.overlay ? robot.times.map((_, f) => f) : [+slider.value];
    const ghosts = [];
    robot.tracks.forEach((t, k) => {
      if (!trackBoxes[k].checked) return;
      for (const f of frames) {
        if (t.style === "ghost") ghosts.push([t, f]);
        else drawRobot(trackPlacements(t, f), null);
      }
    });
    // Translucent tracks last, without depth writes, pulled slightly forward
    // so that where they coincide with a solid robot they show consistently.
    if (ghosts.length) {
      gl.enable(gl.BLEND);
      gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
      gl.depthMask(false);
      gl.enable(gl.POLYGON_OFFSET_FILL);
      gl.polygonOffset(-1, -2);
      for (const [t, f] of ghosts) drawRobot(trackPlacements(t, f), t.color);
      gl.disable(gl.POLYGON_OFFSET_FILL);
      gl.depthMask(true);
      gl.disable(gl.BLEND);
    }
  }
  document.body.dataset.rendered = String((+document.body.dataset.rendered || 0) + 1);
}
window.addEventListener("resize", () => render());
render();
// What a caller (a test, the console) can read back: the camera and the robot's placements.
window.leasViewer = {cam, eye, geomPlacements, trackPlacements, render};
