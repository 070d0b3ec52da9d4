// The gradmesh editor's page: draws the server's frames and the control mesh over them, and
// sends edits over a WebSocket. The server renders; this page only shows and asks.
"use strict";

const token = document.body.dataset.token;
const picture = document.getElementById("picture");
const overlay = document.getElementById("overlay");
const pictureContext = picture.getContext("2d");
const overlayContext = overlay.getContext("2d");
const $ = (id) => document.getElementById(id);

// What the page knows. `state` is the server's last state message.
const editor = {
  state: null,
  activeLayer: 0,
  selection: [],        // point indices of the active layer, in the order chosen
  edge: null,           // [a, b]
  face: null,           // face index
  view: null,           // {x0, y0, x1, y1}: the plane rectangle shown
  framesReceived: 0,
  busy: false,          // a batch is out and its answer has not come
  pending: [],          // commands waiting for the answer to the batch out
  drag: null,           // the gesture under way
  refined: null,        // {layer, face, level, vertices, chosen}: refined vertices shown
  nextGesture: 1,
  error: "",
  // Drag latency, in milliseconds of the page's clock: a drag's move waits in `moves` until
  // the batch that carries it goes out, then in `inFlight` until that batch's answer (its
  // frame drawn) comes; `samples` keeps each move's time to its frame, the newest 4,000.
  // Its parts: `waits`, each move's time until its batch went out; per batch of moves,
  // `roundTrips` from sending to the answer's end, `server` the server's time on the batch
  // within it, and `work` the time the page spent handling the answer's messages (frame,
  // state).
  latency: { moves: [], inFlight: [], samples: [], waits: [], roundTrips: [], server: [],
    work: [], sentAt: 0, handling: 0 },
  overlayQueued: false, // the overlay is to be drawn at the next animation frame
  foldsToCome: false,   // the last state left out the folds, which come in the next
};
window.gradmesh = editor;

// ---- connection -------------------------------------------------------------------------

let socket = null;

function connect() {
  const url = `ws://${location.host}/ws?token=${encodeURIComponent(token)}`;
  socket = new WebSocket(url);
  socket.binaryType = "arraybuffer";
  socket.onopen = () => { editor.busy = false; send({ type: "state" }); };
  socket.onmessage = (event) => {
    const start = performance.now();
    if (typeof event.data === "string") {
      receiveText(JSON.parse(event.data));
    } else {
      drawFrame(event.data);
    }
    editor.latency.handling += performance.now() - start;
  };
  socket.onclose = () => {
    showMessage("The connection to the server is closed: reload the page once it runs again.");
  };
}

// Queues a command; a command of the same gesture already waiting is replaced (only the
// latest position of a drag matters).
function send(command) {
  const gesture = command.gesture;
  if (gesture !== undefined) {
    const i = editor.pending.findIndex((c) => c.gesture === gesture && c.type === command.type);
    if (i >= 0) { editor.pending[i] = command; flush(); return; }
  }
  if (command.type === "view") {
    editor.pending = editor.pending.filter((c) => c.type !== "view");
  }
  editor.pending.push(command);
  flush();
}

// Sends what waits, unless the answer to the last batch has not come yet.
function flush() {
  if (editor.busy || !socket || socket.readyState !== WebSocket.OPEN || editor.pending.length === 0) {
    return;
  }
  for (const command of editor.pending) {
    socket.send(JSON.stringify(command));
  }
  editor.pending = [];
  editor.busy = true;
  const latency = editor.latency;
  latency.sentAt = performance.now();
  latency.handling = 0;
  for (const moved of latency.moves) latency.waits.push(latency.sentAt - moved);
  latency.inFlight.push(...latency.moves);
  latency.moves = [];
}

// The batch out is answered (the server took `serverMs` on it): its frame is on the canvas.
function noteFrameReady(serverMs) {
  const latency = editor.latency;
  const now = performance.now();
  if (latency.inFlight.length > 0) {
    latency.roundTrips.push(now - latency.sentAt);
    latency.server.push(serverMs);
    latency.work.push(latency.handling);
  }
  for (const moved of latency.inFlight) latency.samples.push(now - moved);
  latency.inFlight = [];
  for (const list of [latency.samples, latency.waits, latency.roundTrips, latency.server, latency.work]) {
    if (list.length > 4000) list.splice(0, list.length - 4000);
  }
}

function edit(op, gesture) {
  const command = { type: "edit", op };
  if (gesture !== undefined) command.gesture = gesture;
  send(command);
}

function receiveText(message) {
  if (message.type === "done") {
    editor.busy = false;
    noteFrameReady(message.ms);
    flush();
  } else if (message.type === "error" && answerRefusal(message)) {
    // files.js asked the user.
  } else if (message.type === "error" || message.type === "notice") {
    showMessage(message.message);
  } else if (message.type === "select") {
    editor.chosen = message; // what a mesh tool made: selected once the state has it
  } else if (message.type === "state") {
    const first = editor.state === null;
    const folds = editor.state ? editor.state.layers.map((l) => l.folds) : [];
    editor.state = message;
    // The server sends the folds in a state of their own once the frame is out.
    editor.foldsToCome = !!message.folds_to_come;
    if (!message.folds_checked) {
      message.layers.forEach((layer, i) => { layer.folds = folds[i] || []; });
    }
    if (editor.activeLayer >= message.layers.length) editor.activeLayer = Math.max(0, message.layers.length - 1);
    if (editor.chosen) {
      const chosen = editor.chosen;
      editor.chosen = null;
      editor.activeLayer = chosen.layer;
      editor.selection = chosen.points;
      editor.face = chosen.face;
      editor.edge = null;
    }
    const layer = activeLayer();
    if (layer) editor.selection = editor.selection.filter((p) => p < layer.points.length);
    if (first) fitView();
    if (editor.refined) loadRefined(editor.refined.layer, editor.refined.face, editor.refined.level);
    updatePanels();
    requestOverlay();
  }
}

function showMessage(text) {
  editor.error = text;
  const box = $("message");
  box.textContent = text;
  box.classList.toggle("shown", text !== "");
  clearTimeout(showMessage.timer);
  if (text) showMessage.timer = setTimeout(() => showMessage(""), 8000);
}

// ---- frames -------------------------------------------------------------------------------

// A frame: "GMF2", then u32 frame number, width, height, run count; each run: first row,
// row count, first column, column count, then the RGBA8 pixels of that rectangle.
function drawFrame(buffer) {
  const words = new DataView(buffer);
  const width = words.getUint32(8, true);
  const height = words.getUint32(12, true);
  const runs = words.getUint32(16, true);
  if (picture.width !== width || picture.height !== height) {
    picture.width = width;
    picture.height = height;
  }
  let at = 20;
  for (let r = 0; r < runs; r++) {
    const first = words.getUint32(at, true);
    const count = words.getUint32(at + 4, true);
    const x = words.getUint32(at + 8, true);
    const columns = words.getUint32(at + 12, true);
    at += 16;
    const bytes = new Uint8ClampedArray(buffer, at, columns * count * 4);
    pictureContext.putImageData(new ImageData(bytes, columns, count), x, first);
    at += bytes.length;
  }
  editor.framesReceived++;
}

// ---- view ---------------------------------------------------------------------------------

// The canvas's size, read from the layout once per task (the overlay converts thousands of
// points with it, and the layout does not change while a script runs): forgotten when the
// running script ends.
let measuredSize = null;
function canvasSize() {
  if (measuredSize) return measuredSize;
  const rect = overlay.getBoundingClientRect();
  const ratio = window.devicePixelRatio || 1;
  measuredSize = {
    cssWidth: rect.width, cssHeight: rect.height, ratio,
    width: Math.max(1, Math.round(rect.width * ratio)),
    height: Math.max(1, Math.round(rect.height * ratio)),
  };
  queueMicrotask(() => { measuredSize = null; });
  return measuredSize;
}

function scale() {
  return canvasSize().cssWidth / (editor.view.x1 - editor.view.x0);
}

// Plane to CSS pixels of the canvas, and back.
function toScreen(x, y) {
  const s = scale();
  return [(x - editor.view.x0) * s, (y - editor.view.y0) * s];
}
function toPlane(sx, sy) {
  const s = scale();
  return [editor.view.x0 + sx / s, editor.view.y0 + sy / s];
}
editor.toScreen = toScreen;

function setView(x0, y0, width) {
  const size = canvasSize();
  const height = width * size.cssHeight / size.cssWidth;
  editor.view = { x0, y0, x1: x0 + width, y1: y0 + height };
  sendView();
  drawOverlay();
}

function fitView() {
  let [minX, minY, maxX, maxY] = [Infinity, Infinity, -Infinity, -Infinity];
  // The document's own view (a vectorised picture's rectangle) when it has one, else its points.
  if (editor.state && editor.state.view) [minX, minY, maxX, maxY] = editor.state.view;
  else for (const layer of editor.state ? editor.state.layers : []) {
    for (const [x, y] of layer.points) {
      minX = Math.min(minX, x); minY = Math.min(minY, y);
      maxX = Math.max(maxX, x); maxY = Math.max(maxY, y);
    }
  }
  if (!isFinite(minX)) { minX = 0; minY = 0; maxX = 400; maxY = 300; }
  const size = canvasSize();
  const margin = 0.08 * Math.max(maxX - minX, maxY - minY, 1);
  const w = maxX - minX + 2 * margin;
  const h = maxY - minY + 2 * margin;
  const width = Math.max(w, h * size.cssWidth / size.cssHeight);
  const height = width * size.cssHeight / size.cssWidth;
  setView((minX + maxX) / 2 - width / 2, (minY + maxY) / 2 - height / 2, width);
}

function sendView() {
  if (!editor.view) return;
  const size = canvasSize();
  overlay.width = size.width;
  overlay.height = size.height;
  const v = editor.view;
  send({ type: "view", width: size.width, height: size.height, view: [v.x0, v.y0, v.x1, v.y1] });
  updateBackdrop();
}

function zoomAt(sx, sy, factor) {
  const [px, py] = toPlane(sx, sy);
  const width = (editor.view.x1 - editor.view.x0) / factor;
  const s = canvasSize().cssWidth / width;
  setView(px - sx / s, py - sy / s, width);
}

window.addEventListener("resize", () => {
  if (editor.view) setView(editor.view.x0, editor.view.y0, editor.view.x1 - editor.view.x0);
});

// ---- the control mesh ---------------------------------------------------------------------

function activeLayer() {
  return editor.state ? editor.state.layers[editor.activeLayer] : null;
}

function handleOf(layer, from, to) {
  for (const [f, t, hx, hy] of layer.handles) {
    if (f === from && t === to) return [hx, hy];
  }
  const [ax, ay] = layer.points[from];
  const [bx, by] = layer.points[to];
  return [(bx - ax) / 3, (by - ay) / 3];
}

// The edge from a to b as four points of a cubic, in CSS pixels.
function edgeCurve(layer, a, b) {
  const [ax, ay] = layer.points[a];
  const [bx, by] = layer.points[b];
  const [hax, hay] = handleOf(layer, a, b);
  const [hbx, hby] = handleOf(layer, b, a);
  return [toScreen(ax, ay), toScreen(ax + hax, ay + hay), toScreen(bx + hbx, by + hby), toScreen(bx, by)];
}

function edgeStyle(kind, sharpness) {
  if (kind === "crease") return { colour: "#ffb340", width: 2.5, dash: sharpness === null ? [] : [6, 3] };
  if (kind === "discontinuous") return { colour: "#ff4d6d", width: 2.5, dash: [3, 3] };
  return { colour: "#ffffff", width: 1, dash: [] };
}

// Draws the overlay at the next animation frame, once however often it is asked for in
// between (a drag asks on every move and every answer).
function requestOverlay() {
  if (editor.overlayQueued) return;
  editor.overlayQueued = true;
  requestAnimationFrame(() => {
    editor.overlayQueued = false;
    drawOverlay();
  });
}

function drawOverlay() {
  const size = canvasSize();
  const c = overlayContext;
  c.setTransform(size.ratio, 0, 0, size.ratio, 0, 0);
  c.clearRect(0, 0, size.cssWidth, size.cssHeight);
  const layer = activeLayer();
  if (!layer || !editor.view || !meshShown(editor.activeLayer)) { drawBox(c); return; }
  if (editor.face !== null && layer.faces[editor.face]) {
    const corners = layer.faces[editor.face];
    c.beginPath();
    corners.forEach((p, i) => {
      const [x, y] = toScreen(...layer.points[p]);
      if (i === 0) c.moveTo(x, y); else c.lineTo(x, y);
    });
    c.closePath();
    c.fillStyle = "#4a90e255";
    c.fill();
  }
  drawEdges(c, layer);
  const selected = new Set(editor.selection);
  drawHandles(c, layer, selected);
  drawPoints(c, layer, selected);
  drawSides(c, layer);
  drawRefined(c);
  for (const [x, y] of layer.folds) {
    const [sx, sy] = toScreen(x, y);
    c.strokeStyle = "#f33"; c.lineWidth = 2;
    c.beginPath(); c.arc(sx, sy, 12, 0, 2 * Math.PI); c.stroke();
    c.fillStyle = "#f33"; c.font = "bold 12px sans-serif"; c.fillText("fold", sx + 14, sy + 4);
  }
  drawBox(c);
}

// The mesh lines, one path per look (plain, crease, discontinuous, the selected edge), each
// stroked twice: a dark line under a light one.
function drawEdges(c, layer) {
  const paths = new Map();
  for (const [a, b, kind, sharpness] of layer.edges) {
    const selected = editor.edge && editor.edge[0] === a && editor.edge[1] === b;
    const key = selected ? `selected ${kind} ${sharpness === null}` : `${kind} ${sharpness === null}`;
    if (!paths.has(key)) paths.set(key, { path: new Path2D(), style: edgeStyle(kind, sharpness), selected });
    const [p0, p1, p2, p3] = edgeCurve(layer, a, b);
    const path = paths.get(key).path;
    path.moveTo(...p0);
    path.bezierCurveTo(...p1, ...p2, ...p3);
  }
  // Plain lines first, the selected edge last, so tagged and chosen edges show above.
  const order = [...paths.values()].sort((x, y) => rank(x) - rank(y));
  function rank(entry) { return entry.selected ? 2 : entry.style.width > 1 ? 1 : 0; }
  for (const { path, style, selected } of order) {
    c.setLineDash([]);
    c.strokeStyle = "#000a";
    c.lineWidth = style.width + 2;
    c.stroke(path);
    c.setLineDash(style.dash);
    c.strokeStyle = selected ? "#4af" : style.colour;
    c.lineWidth = selected ? style.width + 1.5 : style.width;
    c.stroke(path);
  }
  c.setLineDash([]);
}

function drawHandles(c, layer, selected) {
  if (selected.size === 0) return;
  const lines = new Path2D();
  const ends = new Path2D();
  for (const [from, to] of layer.handles) {
    if (!selected.has(from)) continue;
    const end = handleEnd(layer, from, to);
    lines.moveTo(...toScreen(...layer.points[from]));
    lines.lineTo(...end);
    ends.moveTo(end[0] + 3.5, end[1]);
    ends.arc(...end, 3.5, 0, 2 * Math.PI);
  }
  c.strokeStyle = "#4af"; c.lineWidth = 1;
  c.stroke(lines);
  c.fillStyle = "#fff";
  c.fill(ends);
  c.stroke(ends);
}

// Each point a square of its colour; outlines and out-of-gamut rings one path each.
function drawPoints(c, layer, selected) {
  const outlines = new Path2D();
  const chosen = new Path2D();
  const rings = new Path2D();
  const outOfGamut = new Set(layer.out_of_gamut);
  layer.points.forEach(([x, y], i) => {
    const [sx, sy] = toScreen(x, y);
    const isSelected = selected.has(i);
    const r = isSelected ? 6 : 4.5;
    c.fillStyle = layer.hex[i];
    c.fillRect(sx - r, sy - r, 2 * r, 2 * r);
    (isSelected ? chosen : outlines).rect(sx - r, sy - r, 2 * r, 2 * r);
    if (outOfGamut.has(i)) {
      rings.moveTo(sx + r + 4, sy);
      rings.arc(sx, sy, r + 4, 0, 2 * Math.PI);
    }
  });
  c.strokeStyle = "#000"; c.lineWidth = 1.5;
  c.stroke(outlines);
  c.strokeStyle = "#4af"; c.lineWidth = 2.5;
  c.stroke(chosen);
  c.strokeStyle = "#fa0"; c.lineWidth = 1.5;
  c.stroke(rings);
}

// A dot inside the face, near the point: the colour of that side.
function drawSides(c, layer) {
  for (const [p, f, hex] of layer.sides) {
    const corners = layer.faces[f];
    if (!corners) continue;
    const centre = corners.reduce((acc, q) => [acc[0] + layer.points[q][0] / corners.length,
      acc[1] + layer.points[q][1] / corners.length], [0, 0]);
    const [x, y] = layer.points[p];
    const [sx, sy] = toScreen(x + 0.2 * (centre[0] - x), y + 0.2 * (centre[1] - y));
    c.fillStyle = hex; c.strokeStyle = "#000"; c.lineWidth = 1.5;
    c.beginPath(); c.arc(sx, sy, 4, 0, 2 * Math.PI); c.fill(); c.stroke();
  }
}

function drawRefined(c) {
  const r = editor.refined;
  if (!r || r.layer !== editor.activeLayer) return;
  for (const v of r.vertices) {
    const [sx, sy] = toScreen(...v.position);
    const chosen = r.chosen === v;
    c.fillStyle = chosen ? "#ff0" : "#0ff";
    c.strokeStyle = "#000"; c.lineWidth = 1;
    c.beginPath(); c.arc(sx, sy, chosen ? 4.5 : 2.5, 0, 2 * Math.PI); c.fill(); c.stroke();
  }
}

// Fetches the refined vertices of a face at a level, with their addresses. Only the answer to
// the latest request is shown (answers to earlier ones may come after it).
let refinedRequests = 0;
async function loadRefined(layer, face, level) {
  const request = ++refinedRequests;
  const query = `token=${encodeURIComponent(token)}&layer=${layer}&face=${face}&level=${level}`;
  const response = await fetch(`/api/refined?${query}`);
  const text = await response.text();
  if (request !== refinedRequests) return;
  if (!response.ok) { showMessage(text); editor.refined = null; drawOverlay(); return; }
  const chosen = editor.refined && editor.refined.chosen;
  const vertices = JSON.parse(text);
  editor.refined = { layer, face, level, vertices, chosen: null };
  if (chosen) {
    editor.refined.chosen = vertices.find((v) => v.point === chosen.point && v.at[0] === chosen.at[0] && v.at[1] === chosen.at[1]) || null;
  }
  drawOverlay();
}

function pickRefined(sx, sy) {
  const r = editor.refined;
  if (!r || r.layer !== editor.activeLayer) return null;
  let best = null, bestDistance = 6;
  for (const v of r.vertices) {
    const [x, y] = toScreen(...v.position);
    const d = Math.hypot(x - sx, y - sy);
    if (d < bestDistance) { best = v; bestDistance = d; }
  }
  return best;
}

function handleEnd(layer, from, to) {
  const [x, y] = layer.points[from];
  const [hx, hy] = handleOf(layer, from, to);
  return toScreen(x + hx, y + hy);
}

function drawBox(c) {
  if (editor.tools) editor.tools.draw(c);
  const d = editor.drag;
  if (!d || d.kind !== "box") return;
  c.strokeStyle = "#4af"; c.setLineDash([4, 3]); c.lineWidth = 1;
  c.strokeRect(d.start[0], d.start[1], d.at[0] - d.start[0], d.at[1] - d.start[1]);
  c.setLineDash([]);
}

// ---- picking ------------------------------------------------------------------------------

function pickPoint(layer, sx, sy) {
  let best = null, bestDistance = 8;
  layer.points.forEach(([x, y], i) => {
    const [px, py] = toScreen(x, y);
    const d = Math.hypot(px - sx, py - sy);
    if (d < bestDistance) { best = i; bestDistance = d; }
  });
  return best;
}

function pickEdge(layer, sx, sy) {
  let best = null, bestDistance = 6;
  for (const [a, b] of layer.edges) {
    const [p0, p1, p2, p3] = edgeCurve(layer, a, b);
    for (let k = 0; k <= 24; k++) {
      const t = k / 24, u = 1 - t;
      const w = [u * u * u, 3 * u * u * t, 3 * u * t * t, t * t * t];
      const x = w[0] * p0[0] + w[1] * p1[0] + w[2] * p2[0] + w[3] * p3[0];
      const y = w[0] * p0[1] + w[1] * p1[1] + w[2] * p2[1] + w[3] * p3[1];
      const d = Math.hypot(x - sx, y - sy);
      if (d < bestDistance) { best = [a, b]; bestDistance = d; }
    }
  }
  return best;
}

function pickFace(layer, sx, sy) {
  const [x, y] = toPlane(sx, sy);
  for (let f = layer.faces.length - 1; f >= 0; f--) {
    const corners = layer.faces[f].map((p) => layer.points[p]);
    let inside = false;
    for (let i = 0, j = corners.length - 1; i < corners.length; j = i++) {
      const [xi, yi] = corners[i], [xj, yj] = corners[j];
      if ((yi > y) !== (yj > y) && x < (xj - xi) * (y - yi) / (yj - yi) + xi) inside = !inside;
    }
    if (inside) return f;
  }
  return null;
}

// ---- mouse --------------------------------------------------------------------------------

let spaceDown = false;

function eventPosition(event) {
  const rect = overlay.getBoundingClientRect();
  return [event.clientX - rect.left, event.clientY - rect.top];
}

overlay.addEventListener("contextmenu", (event) => event.preventDefault());

overlay.addEventListener("pointerdown", (event) => {
  overlay.focus();
  overlay.setPointerCapture(event.pointerId);
  const at = eventPosition(event);
  if (event.button === 1 || event.button === 2 || spaceDown) {
    editor.drag = { kind: "pan", start: at, view: { ...editor.view } };
    return;
  }
  if (editor.preview) return;
  if (editor.tools && editor.tools.pointerDown(event, at)) return;
  activateLayerWithPointUnder(...at);
  const layer = activeLayer();
  if (!layer || !meshShown(editor.activeLayer)) return;
  const refined = pickRefined(...at);
  if (refined) {
    editor.refined.chosen = refined;
    $("mr-level").value = editor.refined.level;
    $("mr-face").value = editor.refined.face;
    $("mr-point").value = refined.point;
    $("mr-i").value = refined.at[0];
    $("mr-j").value = refined.at[1];
    editor.drag = { kind: "refined", start: at, gesture: editor.nextGesture++, vertex: refined,
      origin: [...refined.position], layer: editor.refined.layer, face: editor.refined.face, level: editor.refined.level };
    drawOverlay();
    return;
  }
  const picked = pickPress(layer, ...at);
  if (picked && picked.handle) {
    const handle = picked.handle;
    editor.drag = { kind: "handle", handle, start: at, gesture: editor.nextGesture++,
      origin: handleOf(layer, ...handle) };
    return;
  }
  const point = picked ? picked.point : null;
  if (point !== null) {
    if (event.shiftKey) {
      editor.selection = editor.selection.includes(point)
        ? editor.selection.filter((p) => p !== point) : [...editor.selection, point];
    } else if (!editor.selection.includes(point)) {
      editor.selection = [point];
    }
    editor.edge = null;
    editor.face = null;
    editor.drag = { kind: "points", start: at, gesture: editor.nextGesture++,
      points: [...editor.selection], origins: editor.selection.map((p) => [...layer.points[p]]) };
  } else {
    editor.drag = { kind: "box", start: at, at, shift: event.shiftKey };
  }
  updatePanels();
  drawOverlay();
});

// Moves as they arrive: Chromium holds `pointermove` back to the next animation frame (up to
// 16 ms), `pointerrawupdate` (where there is one) is dispatched at once.
const moveEvent = "onpointerrawupdate" in window ? "pointerrawupdate" : "pointermove";
overlay.addEventListener(moveEvent, (event) => {
  if (editor.tools && editor.tools.pointerMove(event, eventPosition(event))) return;
  if (!editor.drag) return;
  // The event's time is when the input arrived, so the wait for the page's turn counts too.
  if (editor.drag.gesture !== undefined) editor.latency.moves.push(event.timeStamp);
  dragTo(editor.drag, eventPosition(event));
});

// Follows a drag to `at` (screen pixels of the overlay).
function dragTo(d, at) {
  const s = scale();
  const [dx, dy] = [(at[0] - d.start[0]) / s, (at[1] - d.start[1]) / s];
  const layer = activeLayer();
  if (d.kind === "pan") {
    const width = d.view.x1 - d.view.x0;
    editor.view = { ...d.view };
    setView(d.view.x0 - dx, d.view.y0 - dy, width);
  } else if (d.kind === "points") {
    d.moved = true;
    d.points.forEach((p, i) => { layer.points[p] = [d.origins[i][0] + dx, d.origins[i][1] + dy]; });
    edit({ op: "move_points", layer: editor.activeLayer, points: d.points, dx, dy }, d.gesture);
    requestOverlay();
  } else if (d.kind === "handle") {
    d.moved = true;
    const [from, to] = d.handle;
    const [x, y] = [d.origin[0] + dx, d.origin[1] + dy];
    layer.handles = layer.handles.map((h) => (h[0] === from && h[1] === to ? [from, to, x, y] : h));
    edit({ op: "set_handle", layer: editor.activeLayer, from, to, x, y }, d.gesture);
    requestOverlay();
  } else if (d.kind === "refined") {
    // The server sets the vertex's position offset so that its limit position moves by this.
    d.moved = true;
    d.vertex.position = [d.origin[0] + dx, d.origin[1] + dy];
    edit({ op: "move_refined_vertex", layer: d.layer, level: d.level, face: d.face,
      point: d.vertex.point, at: d.vertex.at, dx, dy }, d.gesture);
    requestOverlay();
  } else if (d.kind === "box") {
    d.at = at;
    requestOverlay();
  }
}

overlay.addEventListener("pointerup", (event) => {
  if (editor.tools && editor.tools.pointerUp(event, eventPosition(event))) return;
  const d = editor.drag;
  editor.drag = null;
  if (!d) return;
  const at = eventPosition(event);
  if (d.kind === "points" || d.kind === "handle" || d.kind === "refined") {
    // The last move event may not be where the button went up.
    if (d.moved) { dragTo(d, at); send({ type: "end_gesture" }); }
  } else if (d.kind === "box") {
    finishBox(d, at);
  }
  drawOverlay();
});

// A drag the browser takes away (a touch turned into a scroll, the window losing the pointer)
// ends where it was: the server draws the picture exactly again once the gesture ends.
overlay.addEventListener("pointercancel", () => {
  const d = editor.drag;
  editor.drag = null;
  if (d && d.moved && d.gesture !== undefined) send({ type: "end_gesture" });
  requestOverlay();
});

// A box drag selects the points inside; a click on nothing selects the edge or face under it.
function finishBox(d, at) {
  if (Math.abs(at[0] - d.start[0]) < 3 && Math.abs(at[1] - d.start[1]) < 3) activateLayerWithFaceUnder(...at);
  const layer = activeLayer();
  const [x0, x1] = [Math.min(d.start[0], at[0]), Math.max(d.start[0], at[0])];
  const [y0, y1] = [Math.min(d.start[1], at[1]), Math.max(d.start[1], at[1])];
  if (x1 - x0 < 3 && y1 - y0 < 3) {
    editor.edge = pickEdge(layer, ...at);
    editor.face = editor.edge ? null : pickFace(layer, ...at);
    if (!d.shift) editor.selection = [];
  } else {
    const inside = [];
    layer.points.forEach(([x, y], i) => {
      const [sx, sy] = toScreen(x, y);
      if (sx >= x0 && sx <= x1 && sy >= y0 && sy <= y1) inside.push(i);
    });
    editor.selection = d.shift ? [...new Set([...editor.selection, ...inside])] : inside;
  }
  updatePanels();
}

overlay.addEventListener("wheel", (event) => {
  event.preventDefault();
  zoomAt(...eventPosition(event), Math.exp(-event.deltaY * 0.0015));
}, { passive: false });

// ---- keyboard -----------------------------------------------------------------------------

window.addEventListener("keyup", (event) => { if (event.key === " ") spaceDown = false; });
window.addEventListener("keydown", (event) => {
  if (takeKey(event)) return;
  if (isTextField(event.target)) return;
  const ctrl = event.ctrlKey || event.metaKey;
  const key = event.key.toLowerCase();
  if (ctrl && key === "z") { send({ type: event.shiftKey ? "redo" : "undo" }); }
  else if (ctrl && key === "y") { send({ type: "redo" }); }
  else if (ctrl) { return; }
  else if (editor.tools && editor.tools.key(event, key)) { /* a tool's key (tools.js) */ }
  else if (event.key === " ") { spaceDown = true; }
  else if (event.key === "Delete" || event.key === "Backspace") { deleteSelection(); }
  else if (event.key === "Escape") { editor.selection = []; editor.edge = null; editor.face = null; }
  else if (key === "a") { const l = activeLayer(); editor.selection = l ? l.points.map((_, i) => i) : []; }
  else if (key === "c") { setEdgeKind("crease"); }
  else if (key === "s") { setEdgeKind("smooth"); }
  else if (key === "d") { setEdgeKind("discontinuous"); }
  else if (key === "e") { splitEdge(); }
  else if (key === "f") { addFace(); }
  else if (key === "r") { addRectangle(); }
  else if (key === "0") { fitView(); }
  else if (key === "+" || key === "=") { const s = canvasSize(); zoomAt(s.cssWidth / 2, s.cssHeight / 2, 1.25); }
  else if (key === "-") { const s = canvasSize(); zoomAt(s.cssWidth / 2, s.cssHeight / 2, 0.8); }
  else { return; }
  event.preventDefault();
  updatePanels();
  drawOverlay();
});

// ---- actions ------------------------------------------------------------------------------

function deleteSelection() {
  if (editor.selection.length > 0) {
    edit({ op: "delete_points", layer: editor.activeLayer, points: editor.selection });
    editor.selection = [];
  } else if (editor.face !== null) {
    edit({ op: "delete_faces", layer: editor.activeLayer, faces: [editor.face] });
    editor.face = null;
  }
}

function setEdgeKind(kind) {
  if (!editor.edge) { showMessage("Select an edge first (click on it)."); return; }
  const value = $("sharpness").value;
  const sharpness = kind === "crease" && value !== "" ? Number(value) : null;
  edit({ op: "set_edge", layer: editor.activeLayer, a: editor.edge[0], b: editor.edge[1], kind, sharpness });
}

function splitEdge() {
  if (!editor.edge) { showMessage("Select an edge first (click on it)."); return; }
  edit({ op: "split_edge", layer: editor.activeLayer, a: editor.edge[0], b: editor.edge[1] });
  editor.edge = null;
}

function addFace() {
  if (editor.selection.length < 3) { showMessage("Select three or more points, in order around the new face."); return; }
  edit({ op: "add_face", layer: editor.activeLayer, points: editor.selection });
}

function splitFace() {
  const layer = activeLayer();
  let face = editor.face;
  const [a, b] = editor.selection;
  if (editor.selection.length !== 2) { showMessage("Select two corners of a face (Shift+click), then Split face."); return; }
  if (face === null) face = layer.faces.findIndex((f) => f.includes(a) && f.includes(b));
  if (face < 0) { showMessage("The two points are not corners of one face."); return; }
  edit({ op: "split_face", layer: editor.activeLayer, face, a, b });
}

function addRectangle() {
  if (!editor.state) return;
  if (editor.state.layers.length === 0) edit({ op: "add_layer", name: "Layer 1" });
  const v = editor.view;
  const [w, h] = [v.x1 - v.x0, v.y1 - v.y0];
  const side = 0.3 * Math.min(w, h);
  const [cx, cy] = [(v.x0 + v.x1) / 2, (v.y0 + v.y1) / 2];
  edit({ op: "add_rectangle", layer: editor.activeLayer, rect: [cx - side, cy - side / 1.5, cx + side, cy + side / 1.5] });
}

function setColour(colour, gesture) {
  if (editor.selection.length === 0) return;
  edit({ op: "set_colour", layer: editor.activeLayer, points: editor.selection, ...colour }, gesture);
}

let colourGesture = null;
$("colour-picker").addEventListener("input", (event) => {
  if (colourGesture === null) colourGesture = editor.nextGesture++;
  setColour({ css: event.target.value }, colourGesture);
});
$("colour-picker").addEventListener("change", () => {
  if (colourGesture !== null) send({ type: "end_gesture" });
  colourGesture = null;
});
$("colour-hex").addEventListener("change", (event) => {
  const text = event.target.value.trim();
  if (text) setColour({ css: text });
});
for (const id of ["c0", "c1", "c2"]) {
  $(id).addEventListener("change", () => setColour({ colour: ["c0", "c1", "c2"].map((c) => Number($(c).value)) }));
}
let opacityGesture = null;
$("opacity").addEventListener("input", (event) => {
  if (editor.selection.length === 0) return;
  if (opacityGesture === null) opacityGesture = editor.nextGesture++;
  edit({ op: "set_opacity", layer: editor.activeLayer, points: editor.selection, opacity: Number(event.target.value) }, opacityGesture);
});
$("opacity").addEventListener("change", () => {
  if (opacityGesture !== null) send({ type: "end_gesture" });
  opacityGesture = null;
});
$("edge-kind").addEventListener("change", (event) => setEdgeKind(event.target.value));
$("sharpness").addEventListener("change", () => setEdgeKind("crease"));
$("split-edge").onclick = splitEdge;
$("add-rect").onclick = addRectangle;
$("add-face").onclick = addFace;
$("split-face").onclick = splitFace;
$("delete").onclick = deleteSelection;
$("undo").onclick = () => send({ type: "undo" });
$("redo").onclick = () => send({ type: "redo" });
$("fit").onclick = fitView;
$("new").onclick = () => {
  if (editor.state && editor.state.modified && !confirm("Discard the changes not saved?")) return;
  editor.state = null; editor.selection = []; send({ type: "new" });
};
$("files").addEventListener("focus", refreshFiles);
$("files").addEventListener("change", (event) => {
  const name = event.target.value;
  event.target.value = "";
  if (!name) return;
  if (editor.state && editor.state.modified && !confirm("Discard the changes not saved?")) return;
  editor.state = null; editor.selection = []; editor.activeLayer = 0;
  send({ type: "open", name });
});
$("layer-add").onclick = () => {
  const n = editor.state ? editor.state.layers.length : 0;
  edit({ op: "add_layer", name: `Layer ${n + 1}` });
  editor.activeLayer = n;
};
$("layer-up").onclick = () => moveLayer(1);
$("layer-down").onclick = () => moveLayer(-1);
$("layer-rename").onclick = () => {
  const layer = activeLayer();
  if (!layer) return;
  const name = prompt("Layer name:", layer.name || "");
  if (name !== null) edit({ op: "rename_layer", layer: editor.activeLayer, name });
};
$("layer-delete").onclick = () => {
  if (activeLayer()) edit({ op: "delete_layer", layer: editor.activeLayer });
};
$("side-colour").onclick = () => sideColour($("colour-picker").value);
$("side-clear").onclick = () => sideColour(null);
$("side-opacity-set").onclick = sideOpacity;
$("mr-show").onclick = () => {
  if (editor.face === null) { showMessage("Select a face first (click inside it)."); return; }
  loadRefined(editor.activeLayer, editor.face, Number($("mr-level").value));
};
$("mr-hide").onclick = () => { refinedRequests++; editor.refined = null; drawOverlay(); };
$("mr-set").onclick = () => refinedEdit(true);
$("mr-clear").onclick = () => refinedEdit(false);

// The selected point and the selected face around it: a side of a discontinuity, or null.
function selectedSide() {
  if (editor.selection.length !== 1 || editor.face === null) {
    showMessage("Select one point, then Shift+click inside a face around it.");
    return null;
  }
  return { layer: editor.activeLayer, point: editor.selection[0], face: editor.face };
}

// The colour of the selected point on the side of the selected face (at a discontinuity).
function sideColour(css) {
  const side = selectedSide();
  if (!side) return;
  const op = { op: "set_side_colour", ...side };
  if (css) op.css = css;
  edit(op);
}

// The opacity of that side; an empty field gives it the point's opacity again.
function sideOpacity() {
  const side = selectedSide();
  if (!side) return;
  const op = { op: "set_side_opacity", ...side };
  const text = $("side-opacity").value.trim();
  if (text !== "") op.opacity = Number(text);
  edit(op);
}

function refinedEdit(set) {
  const number = (id) => Number($(id).value);
  const op = {
    op: "set_refined_edit", layer: editor.activeLayer, level: number("mr-level"), face: number("mr-face"),
    point: number("mr-point"), at: [number("mr-i"), number("mr-j")],
  };
  if (set) {
    op.colour = cssToLayerColour($("mr-colour").value);
    if ($("mr-opacity").value !== "") op.opacity = number("mr-opacity");
  }
  edit(op);
}

// Only sRGB-family layers take the picker's colour as numbers; Lab layers get it converted.
function cssToLayerColour(hex) {
  const layer = activeLayer();
  const rgb = [1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16) / 255);
  const linear = rgb.map((c) => (c <= 0.04045 ? c / 12.92 : Math.pow((c + 0.055) / 1.055, 2.4)));
  if (layer.space === "srgb") return rgb;
  if (layer.space === "srgb-linear") return linear;
  const [r, g, b] = linear;
  const xyz = [
    (0.4124564 * r + 0.3575761 * g + 0.1804375 * b) / 0.95047,
    0.2126729 * r + 0.7151522 * g + 0.072175 * b,
    (0.0193339 * r + 0.119192 * g + 0.9503041 * b) / 1.08883,
  ];
  const f = xyz.map((t) => (t > 216 / 24389 ? Math.cbrt(t) : (24389 / 27 * t + 16) / 116));
  return [116 * f[1] - 16, 500 * (f[0] - f[1]), 200 * (f[1] - f[2])];
}

function moveLayer(delta) {
  const n = editor.state ? editor.state.layers.length : 0;
  const to = editor.activeLayer + delta;
  if (to < 0 || to >= n) return;
  edit({ op: "move_layer", layer: editor.activeLayer, to });
  editor.activeLayer = to;
}

async function refreshFiles() {
  const response = await fetch(`/api/files?token=${encodeURIComponent(token)}`);
  if (!response.ok) return;
  const names = await response.json();
  const select = $("files");
  select.replaceChildren(new Option("open a file…", ""), ...names.map((n) => new Option(n, n)));
}

// ---- panels -------------------------------------------------------------------------------

function updatePanels() {
  const state = editor.state;
  if (!state) return;
  activateImported(state);
  selectPasted(state);
  showFileState(state);
  showRecovery(state);
  showBackdrops(state);
  $("undo").disabled = !state.can_undo;
  $("redo").disabled = !state.can_redo;
  updateLayerList(state);
  const layer = activeLayer();
  updatePointPanel(layer);
  $("edge-panel").style.opacity = editor.edge ? 1 : 0.5;
  $("edge-name").textContent = editor.edge ? `${editor.edge[0]}–${editor.edge[1]}` : "(click one)";
  if (layer && editor.edge) {
    const tag = layer.edges.find(([a, b]) => a === editor.edge[0] && b === editor.edge[1]);
    if (tag) {
      $("edge-kind").value = tag[2];
      $("sharpness").value = tag[3] === null ? "" : tag[3];
    }
  }
  $("mr-list").replaceChildren(...(layer ? layer.edits : []).map(([level, face, point, at, offset]) => {
    const item = document.createElement("li");
    const moved = offset ? `, moved ${offset.map((o) => o.toFixed(3)).join(",")}` : "";
    item.textContent = `level ${level}, face ${face}, corner ${point}, at ${at.join(",")}${moved}`;
    return item;
  }));
  updateWarnings(state);
}

function updateLayerList(state) {
  const list = $("layers");
  list.replaceChildren();
  state.layers.map((layer, i) => [layer, i]).reverse().forEach(([layer, i]) => {
    const item = document.createElement("li");
    item.classList.toggle("active", i === editor.activeLayer);
    item.classList.toggle("hidden-layer", layer.hidden);
    const shown = document.createElement("input");
    shown.type = "checkbox";
    shown.checked = !layer.hidden;
    shown.title = "shown";
    shown.onclick = (event) => {
      event.stopPropagation();
      edit({ op: "set_layer_hidden", layer: i, hidden: !shown.checked });
    };
    const name = document.createElement("span");
    name.textContent = `${layer.name || "unnamed"} (${layer.points.length} points, ${layer.space})`;
    item.append(shown, meshToggle(i), name);
    item.onclick = () => { editor.activeLayer = i; editor.selection = []; editor.edge = null; editor.face = null; updatePanels(); drawOverlay(); };
    list.append(item);
  });
}

function updatePointPanel(layer) {
  const selection = editor.selection;
  $("point-count").textContent = selection.length ? `(${selection.length} selected)` : "(none selected)";
  $("point-panel").style.opacity = selection.length ? 1 : 0.5;
  if (!layer) return;
  $("space-name").textContent = layer.space;
  if (selection.length === 0) return;
  const p = selection[0];
  const active = document.activeElement;
  if (active !== $("colour-picker")) $("colour-picker").value = layer.hex[p];
  if (active !== $("colour-hex")) $("colour-hex").value = layer.hex[p];
  ["c0", "c1", "c2"].forEach((id, k) => { if (active !== $(id)) $(id).value = +layer.colours[p][k].toFixed(4); });
  if (active !== $("opacity")) $("opacity").value = layer.opacity[p];
  $("opacity-value").textContent = layer.opacity[p].toFixed(2);
  const side = layer.sides.find(([q, f]) => q === p && f === editor.face);
  if (active !== $("side-opacity")) $("side-opacity").value = side && side[3] !== null ? side[3] : "";
}

function updateWarnings(state) {
  const items = [];
  state.layers.forEach((layer, i) => {
    const name = layer.name || `layer ${i}`;
    for (const [x, y, area] of layer.folds) {
      items.push(`${name}: the surface folds over itself near (${x.toFixed(1)}, ${y.toFixed(1)}), area ${area.toFixed(2)}`);
    }
    if (layer.out_of_gamut.length > 0) {
      items.push(`${name}: ${layer.out_of_gamut.length} point colours outside sRGB (ringed in orange)`);
    }
  });
  $("warnings").replaceChildren(...items.map((text) => {
    const item = document.createElement("li");
    item.textContent = text;
    return item;
  }));
}

connect();
