// The viewer of spiral_cad's continuity reports (spiral_cad/app/html_report.py writes the page around it).
// One self-contained page: the data in <script id="spiral-data">, this script, no network.
// WebGL 2: the part's triangles with zebra stripes (reflection lines of light tubes fixed to the view),
// mean curvature or plain shading; the edges (or a curve's pieces) coloured by their verdict, clickable.
// The hash sets the state: #mode=zebra|curvature|shaded&edge=N (or item=K)&stripes=N&view=x,y,z
(function () {
  "use strict";
  const data = JSON.parse(document.getElementById("spiral-data").textContent);
  const canvas = document.getElementById("view");
  const panel = document.getElementById("item");
  const status = document.getElementById("status");

  function decode(text, Type) {
    if (!text) return new Type(0);
    const bytes = Uint8Array.from(atob(text), (c) => c.charCodeAt(0));
    return new Type(bytes.buffer);
  }

  function decoded(text) {
    try { return decodeURIComponent(text); } catch (error) { return ""; }  // a malformed %-code: as if not given
  }
  function hashState() {
    const state = {};
    for (const part of location.hash.replace(/^#/, "").split("&")) {
      const [key, value] = part.split("=");
      if (key) state[decoded(key)] = decoded(value || "");
    }
    return state;
  }
  // #edge=N: the item of the checker's edge N (a part's page); #item=K: the page's K-th item, worst first
  function chosenItem(hash) {
    if (hash.edge !== undefined && hash.edge !== "") return data.items.findIndex((item) => item.label === `edge ${hash.edge}`);
    return hash.item !== undefined && hash.item !== "" ? parseInt(hash.item, 10) : -1;
  }

  // ------------------------------------------------------------------ small matrix algebra (column-major)
  function perspective(fovy, aspect, near, far) {
    const f = 1 / Math.tan(fovy / 2), nf = 1 / (near - far);
    return [f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0];
  }
  function lookAt(eye, target, up) {
    const z = normalize(sub(eye, target)), x = normalize(cross(up, z)), y = cross(z, x);
    return [x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0,
      -dot(x, eye), -dot(y, eye), -dot(z, eye), 1];
  }
  function multiply(a, b) {
    const out = new Array(16).fill(0);
    for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) for (let k = 0; k < 4; k++) out[c * 4 + r] += a[k * 4 + r] * b[c * 4 + k];
    return out;
  }
  function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function normalize(a) { const n = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / n, a[1] / n, a[2] / n]; }

  // ------------------------------------------------------------------ state
  const start = hashState();
  const modes = ["zebra", "curvature", "shaded"];
  const state = {
    mode: modes.includes(start.mode) ? start.mode : (data.mesh ? "zebra" : "shaded"),
    stripes: Math.min(Math.max(parseInt(start.stripes || data.stripes, 10) || data.stripes, 2), 200),
    selected: chosenItem(start),
    showLines: true,
  };
  const given = (start.view || "").split(",").map(Number);
  let direction = normalize(given.length === 3 && given.every(Number.isFinite) && Math.hypot(...given) > 0 ? given : data.view);
  let distance = 2.0 * data.size;  // the bounding sphere (half the diagonal) inside a 30° field
  const target = [0, 0, 0];

  // ------------------------------------------------------------------ WebGL
  const gl = canvas.getContext("webgl2", { antialias: true, preserveDrawingBuffer: true });
  if (!gl) {
    status.textContent = "This browser offers no WebGL 2: the tables below still hold every number.";
    document.body.dataset.ready = "no-webgl";
    return;
  }

  function program(vertex, fragment) {
    const made = gl.createProgram();
    for (const [type, source] of [[gl.VERTEX_SHADER, vertex], [gl.FRAGMENT_SHADER, fragment]]) {
      const shader = gl.createShader(type);
      gl.shaderSource(shader, source);
      gl.compileShader(shader);
      if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(shader));
      gl.attachShader(made, shader);
    }
    gl.linkProgram(made);
    if (!gl.getProgramParameter(made, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(made));
    return made;
  }

  const surfaceProgram = program(`#version 300 es
    in vec3 position; in vec3 normal; in float curvature;
    uniform mat4 view, projection;
    out vec3 vNormal, vPosition; out float vCurvature;
    void main() {
      vec4 p = view * vec4(position, 1.0);
      vPosition = p.xyz; vNormal = mat3(view) * normal; vCurvature = curvature;
      gl_Position = projection * p;
    }`, `#version 300 es
    precision highp float;
    in vec3 vNormal, vPosition; in float vCurvature;
    uniform int mode; uniform float stripes, scale; uniform vec3 zebraEye;
    out vec4 colour;
    vec3 diverging(float t) {
      t = clamp(t, -1.0, 1.0);
      vec3 white = vec3(0.92), red = vec3(0.70, 0.02, 0.15), blue = vec3(0.13, 0.30, 0.75);
      return t < 0.0 ? mix(white, blue, -t) : mix(white, red, t);
    }
    void main() {
      vec3 n = normalize(vNormal), d = normalize(vPosition);
      if (dot(n, d) > 0.0) n = -n;  // a face seen from behind (an open shell): turned to the viewer
      float light = 0.35 + 0.65 * max(dot(n, -d), 0.0);
      if (mode == 0) {
        // horizontal tubes of light fixed to the view, seen from an eye at a set distance from the part
        // (as spiral_cad.app.zebra): the stripes are bands of the reflected ray's elevation above them
        vec3 r = reflect(normalize(vPosition - zebraEye), n);
        float phase = (asin(clamp(r.y, -1.0, 1.0)) / 3.14159265 + 0.5) * stripes;
        float t = abs(fract(phase) - 0.5) * 2.0;
        float blur = 2.0 * fwidth(phase) + 1e-4;
        float dark = smoothstep(0.5 - blur, 0.5 + blur, t);
        colour = vec4(vec3(mix(0.97, 0.05, dark)), 1.0);
      } else if (mode == 1) {
        colour = vec4(diverging(vCurvature / scale) * (0.55 + 0.45 * light), 1.0);
      } else {
        colour = vec4(vec3(0.78) * light, 1.0);
      }
    }`);

  const lineProgram = program(`#version 300 es
    in vec3 position; in vec3 colour;
    uniform mat4 view, projection; uniform float pointSize;
    out vec3 vColour;
    void main() { vColour = colour; gl_Position = projection * view * vec4(position, 1.0); gl_PointSize = pointSize; }`,
  `#version 300 es
    precision mediump float;
    in vec3 vColour; out vec4 colour;
    void main() { colour = vec4(vColour, 1.0); }`);

  function buffer(array, target) {
    const made = gl.createBuffer();
    gl.bindBuffer(target || gl.ARRAY_BUFFER, made);
    gl.bufferData(target || gl.ARRAY_BUFFER, array, gl.STATIC_DRAW);
    return made;
  }
  function attribute(prog, name, made, size) {
    const at = gl.getAttribLocation(prog, name);
    if (at < 0) return;
    gl.bindBuffer(gl.ARRAY_BUFFER, made);
    gl.enableVertexAttribArray(at);
    gl.vertexAttribPointer(at, size, gl.FLOAT, false, 0, 0);
  }

  // the surfaces
  let surface = null;
  if (data.mesh) {
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    attribute(surfaceProgram, "position", buffer(decode(data.mesh.positions, Float32Array)), 3);
    attribute(surfaceProgram, "normal", buffer(decode(data.mesh.normals, Float32Array)), 3);
    attribute(surfaceProgram, "curvature", buffer(decode(data.mesh.curvature, Float32Array)), 1);
    const triangles = decode(data.mesh.triangles, Uint32Array);
    buffer(triangles, gl.ELEMENT_ARRAY_BUFFER);
    gl.bindVertexArray(null);
    surface = { vao, count: triangles.length };
  }

  // the lines: one polyline per line, drawn as segments in its level's colour
  const linePoints = decode(data.lines.points, Float32Array);
  const starts = data.lines.starts;
  const lineItem = data.lines.items;
  const palette = data.palette;
  function rgb(hex) { return [1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16) / 255); }
  function lineColour(k) {
    const item = lineItem[k];
    return rgb(item >= 0 ? palette[data.items[item].level] || "#000000" : palette[data.lines.kinds[k]] || "#888888");
  }
  function segments(which) {
    const positions = [], colours = [];
    for (const k of which) {
      const colour = k === "selected" ? null : lineColour(k);
      const line = k === "selected" ? state.selectedLine : k;
      for (let i = starts[line]; i + 1 < starts[line + 1]; i++) {
        for (const j of [i, i + 1]) {
          positions.push(linePoints[3 * j], linePoints[3 * j + 1], linePoints[3 * j + 2]);
          colours.push(...(colour || [0.0, 0.9, 1.0]));
        }
      }
    }
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    attribute(lineProgram, "position", buffer(new Float32Array(positions)), 3);
    attribute(lineProgram, "colour", buffer(new Float32Array(colours)), 3);
    gl.bindVertexArray(null);
    return { vao, count: positions.length / 3 };
  }
  const allLines = segments([...Array(starts.length - 1).keys()]);
  const markerPoints = decode(data.markers.points, Float32Array);
  const markers = (() => {
    const colours = [];
    data.markers.items.forEach((item) => colours.push(...rgb(palette[data.items[item].level] || "#000000")));
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    attribute(lineProgram, "position", buffer(markerPoints), 3);
    attribute(lineProgram, "colour", buffer(new Float32Array(colours)), 3);
    gl.bindVertexArray(null);
    return { vao, count: markerPoints.length / 3 };
  })();
  let highlight = null;

  // ------------------------------------------------------------------ drawing
  let matrices = null;
  function draw() {
    const ratio = window.devicePixelRatio || 1;
    const width = Math.max(1, Math.round(canvas.clientWidth * ratio)), height = Math.max(1, Math.round(canvas.clientHeight * ratio));
    if (canvas.width !== width || canvas.height !== height) { canvas.width = width; canvas.height = height; }
    gl.viewport(0, 0, width, height);
    gl.clearColor(1, 1, 1, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    const up = Math.abs(direction[2]) < 0.99 ? [0, 0, 1] : [0, 1, 0];
    const eye = [target[0] + distance * direction[0], target[1] + distance * direction[1], target[2] + distance * direction[2]];
    const view = lookAt(eye, target, up);
    const projection = perspective(Math.PI / 6, width / height, distance / 50, distance + 2 * data.size);
    matrices = { view, projection, both: multiply(projection, view), width, height };
    if (surface) {
      gl.useProgram(surfaceProgram);
      gl.uniformMatrix4fv(gl.getUniformLocation(surfaceProgram, "view"), false, view);
      gl.uniformMatrix4fv(gl.getUniformLocation(surfaceProgram, "projection"), false, projection);
      gl.uniform1i(gl.getUniformLocation(surfaceProgram, "mode"), modes.indexOf(state.mode));
      gl.uniform1f(gl.getUniformLocation(surfaceProgram, "stripes"), state.stripes);
      gl.uniform1f(gl.getUniformLocation(surfaceProgram, "scale"), data.mesh.scale);
      gl.uniform3f(gl.getUniformLocation(surfaceProgram, "zebraEye"), 0, 0, data.distance * data.size - distance);
      gl.enable(gl.POLYGON_OFFSET_FILL);
      gl.polygonOffset(1, 1);  // the edges drawn on the faces stay in front of them
      gl.bindVertexArray(surface.vao);
      gl.drawElements(gl.TRIANGLES, surface.count, gl.UNSIGNED_INT, 0);
      gl.disable(gl.POLYGON_OFFSET_FILL);
    }
    gl.useProgram(lineProgram);
    gl.uniformMatrix4fv(gl.getUniformLocation(lineProgram, "view"), false, view);
    gl.uniformMatrix4fv(gl.getUniformLocation(lineProgram, "projection"), false, projection);
    gl.uniform1f(gl.getUniformLocation(lineProgram, "pointSize"), 7 * (window.devicePixelRatio || 1));
    if (state.showLines) {
      gl.bindVertexArray(allLines.vao);
      gl.drawArrays(gl.LINES, 0, allLines.count);
      gl.bindVertexArray(markers.vao);
      gl.drawArrays(gl.POINTS, 0, markers.count);
    }
    if (highlight) {
      gl.disable(gl.DEPTH_TEST);  // the chosen edge shows even behind the part, as a line of dots (lines are one pixel)
      gl.uniform1f(gl.getUniformLocation(lineProgram, "pointSize"), 5 * (window.devicePixelRatio || 1));
      gl.bindVertexArray(highlight.vao);
      if (!highlight.points) gl.drawArrays(gl.LINES, 0, highlight.count);
      gl.drawArrays(gl.POINTS, 0, highlight.count);
    }
    gl.bindVertexArray(null);
    document.body.dataset.ready = "yes";
  }
  let pending = false;
  function redraw() {
    if (!pending) { pending = true; requestAnimationFrame(() => { pending = false; draw(); }); }
  }

  // ------------------------------------------------------------------ choosing an item
  function show(index) {
    state.selected = index;
    highlight = null;
    panel.textContent = "";
    if (!(index >= 0 && index < data.items.length)) {
      panel.textContent = "Click an edge (or a joint) for its numbers.";
      redraw();
      return;
    }
    const item = data.items[index];
    const heading = document.createElement("h2");
    heading.textContent = `${item.label}: ${item.level}`;
    heading.style.color = palette[item.level] || "#000";
    panel.appendChild(heading);
    const table = document.createElement("table");
    for (const [key, value] of item.rows) {
      const row = table.insertRow();
      row.insertCell().textContent = key;
      row.insertCell().textContent = value;
    }
    panel.appendChild(table);
    if (item.line >= 0) {
      state.selectedLine = item.line;
      highlight = segments(["selected"]);
    } else if (item.point) {
      const vao = gl.createVertexArray();
      gl.bindVertexArray(vao);
      attribute(lineProgram, "position", buffer(new Float32Array(item.point)), 3);
      attribute(lineProgram, "colour", buffer(new Float32Array([0, 0.9, 1])), 3);
      gl.bindVertexArray(null);
      highlight = { vao, count: 1, points: true };
    }
    const hash = hashState();
    hash.item = String(index);
    history.replaceState(null, "", "#" + Object.entries(hash).map(([k, v]) => `${k}=${v}`).join("&"));
    redraw();
  }

  function screen(x, y, z) {
    const m = matrices.both;
    const w = m[3] * x + m[7] * y + m[11] * z + m[15];
    return [((m[0] * x + m[4] * y + m[8] * z + m[12]) / w + 1) / 2 * matrices.width,
      (1 - (m[1] * x + m[5] * y + m[9] * z + m[13]) / w) / 2 * matrices.height, w];
  }
  function nearest(px, py) {
    let best = -1, bestDistance = 8 * (window.devicePixelRatio || 1);
    for (let k = 0; k + 1 < starts.length; k++) {
      if (lineItem[k] < 0) continue;
      let previous = null;
      for (let i = starts[k]; i < starts[k + 1]; i++) {
        const p = screen(linePoints[3 * i], linePoints[3 * i + 1], linePoints[3 * i + 2]);
        if (previous && p[2] > 0 && previous[2] > 0) {
          const dx = p[0] - previous[0], dy = p[1] - previous[1], length = dx * dx + dy * dy;
          const t = length > 0 ? Math.min(Math.max(((px - previous[0]) * dx + (py - previous[1]) * dy) / length, 0), 1) : 0;
          const d = Math.hypot(previous[0] + t * dx - px, previous[1] + t * dy - py);
          if (d < bestDistance) { bestDistance = d; best = lineItem[k]; }
        }
        previous = p;
      }
    }
    data.markers.items.forEach((item, k) => {
      const p = screen(markerPoints[3 * k], markerPoints[3 * k + 1], markerPoints[3 * k + 2]);
      const d = Math.hypot(p[0] - px, p[1] - py);
      if (p[2] > 0 && d < bestDistance) { bestDistance = d; best = item; }
    });
    return best;
  }

  // ------------------------------------------------------------------ controls
  let drag = null;
  canvas.addEventListener("pointerdown", (event) => { drag = { x: event.clientX, y: event.clientY, moved: false }; canvas.setPointerCapture(event.pointerId); });
  canvas.addEventListener("pointermove", (event) => {
    if (!drag) return;
    const dx = event.clientX - drag.x, dy = event.clientY - drag.y;
    if (Math.abs(dx) + Math.abs(dy) > 2) drag.moved = true;
    if (!drag.moved) return;
    drag.x = event.clientX; drag.y = event.clientY;
    // turn about the vertical (z) and about the screen's horizontal axis
    const yaw = -dx * 0.008, pitch = dy * 0.008;
    let [x, y, z] = direction;
    [x, y] = [x * Math.cos(yaw) - y * Math.sin(yaw), x * Math.sin(yaw) + y * Math.cos(yaw)];
    const elevation = Math.min(Math.max(Math.asin(Math.max(-1, Math.min(1, z))) + pitch, -1.55), 1.55);
    const around = Math.hypot(x, y) || 1;
    direction = [x / around * Math.cos(elevation), y / around * Math.cos(elevation), Math.sin(elevation)];
    redraw();
  });
  canvas.addEventListener("pointerup", (event) => {
    if (drag && !drag.moved) {
      const box = canvas.getBoundingClientRect(), ratio = window.devicePixelRatio || 1;
      const picked = nearest((event.clientX - box.left) * ratio, (event.clientY - box.top) * ratio);
      if (picked >= 0) show(picked);
    }
    drag = null;
  });
  canvas.addEventListener("wheel", (event) => {
    event.preventDefault();
    distance = Math.min(Math.max(distance * Math.exp(event.deltaY * 0.001), data.size * 0.05), data.size * 20);
    redraw();
  }, { passive: false });

  for (const mode of modes) {
    const button = document.getElementById(`mode-${mode}`);
    if (!button) continue;
    button.disabled = !data.mesh && mode !== "shaded";
    button.checked = state.mode === mode;
    button.addEventListener("change", () => { state.mode = mode; redraw(); });
  }
  const stripes = document.getElementById("stripes");
  if (stripes) {
    stripes.value = state.stripes;
    stripes.addEventListener("input", () => { state.stripes = Number(stripes.value); redraw(); });
  }
  const lines = document.getElementById("lines");
  lines.addEventListener("change", () => { state.showLines = lines.checked; redraw(); });
  for (const row of document.querySelectorAll("[data-item]")) {
    row.addEventListener("click", () => show(Number(row.dataset.item)));
  }
  window.addEventListener("resize", redraw);
  window.addEventListener("hashchange", () => {
    const hash = hashState();
    if (modes.includes(hash.mode) && (data.mesh || hash.mode === "shaded")) {
      state.mode = hash.mode;
      const button = document.getElementById(`mode-${hash.mode}`);
      if (button) button.checked = true;
    }
    const chosen = chosenItem(hash);
    if (chosen !== state.selected) show(chosen);
    redraw();
  });
  show(state.selected);
  draw();
})();
