// The gradmesh editor's page, what keeps work and what serves habits: the document's file and
// state, saving (asking before a file the editor did not write is replaced), the warning
// before leaving with unsaved edits, the recovery copy, layers imported from files, the
// preview and each layer's mesh shown, picking across layers, the keys that work everywhere
// but in text fields, exports, copy and paste of faces. Loaded after app.js, whose globals
// (editor, send, $, showMessage, the pick functions) it uses.
"use strict";

const files = {
  lastSave: null,       // the last save command sent, to send again with overwrite on "yes"
};
window.gradmeshFiles = files;

// ---- saving -------------------------------------------------------------------------------

function save() {
  if (editor.state && editor.state.file) sendSave({ type: "save" });
  else saveAs();
}

function saveAs() {
  const name = prompt("Save as (a .json name in the starting folder):",
    (editor.state && editor.state.file) || "untitled.json");
  if (name) sendSave({ type: "save_as", name });
}

function sendSave(command) {
  files.lastSave = command;
  send(command);
}

// An error the page answers by asking the user; true if `message` was one.
function answerRefusal(message) {
  files.selectFrom = null;
  if (message.code !== "file_exists" || !files.lastSave) return false;
  const command = files.lastSave;
  files.lastSave = null;
  if (confirm(`${message.message}.\n\nReplace it?`)) {
    sendSave({ ...command, overwrite: true });
  } else {
    showMessage("Not saved: the file was left as it was.");
  }
  refocusCanvas();
  return true;
}

// ---- what the page shows of the file ------------------------------------------------------

function showFileState(state) {
  const name = state.file || "new document (not saved)";
  $("file-name").textContent = name;
  $("file-name").classList.toggle("modified", state.modified);
  $("file-modified").textContent = state.modified ? "modified" : "";
  const saved = state.saved;
  $("file-saved").textContent = saved
    ? `Saved to ${saved.file} at ${new Date(saved.at).toLocaleTimeString()}` : "";
}

// Shortcuts go to the canvas again after a dialog or a menu.
function refocusCanvas() {
  overlay.focus({ preventScroll: true });
}

window.addEventListener("beforeunload", (event) => {
  if (editor.state && editor.state.modified) {
    event.preventDefault();
    event.returnValue = "";
  }
});

$("save").onclick = () => { save(); refocusCanvas(); };
$("save-as").onclick = () => { saveAs(); refocusCanvas(); };

// ---- the recovery copy ----------------------------------------------------------------------

function showRecovery(state) {
  const found = state.recovery;
  $("recovery").hidden = !found;
  if (!found) return;
  const when = new Date(found.at).toLocaleString();
  $("recovery-text").textContent =
    `Unsaved edits of this document were kept in ${found.file} (${when}). ` +
    "Restore them, or discard them? Editing waits for your choice.";
}

$("recovery-restore").onclick = () => { send({ type: "recovery", restore: true }); refocusCanvas(); };
$("recovery-discard").onclick = () => {
  if (confirm("Discard the kept edits? They cannot be brought back.")) send({ type: "recovery", restore: false });
  refocusCanvas();
};

// ---- layers from files ----------------------------------------------------------------------

async function listImportable() {
  const response = await fetch(`/api/files?token=${encodeURIComponent(token)}`);
  if (!response.ok) return;
  const names = await response.json();
  $("import-layer").replaceChildren(new Option("import as layer…", ""), ...names.map((n) => new Option(n, n)));
}

$("import-layer").addEventListener("focus", listImportable);
$("import-layer").addEventListener("pointerdown", listImportable);
$("import-layer").addEventListener("change", (event) => {
  const name = event.target.value;
  event.target.value = "";
  refocusCanvas();
  if (!name || !editor.state) return;
  files.activateFrom = editor.state.layers.length;
  send({ type: "import_layers", name });
});

// The top layer imported becomes the active one when the state shows it.
function activateImported(state) {
  if (files.activateFrom === undefined || state.layers.length <= files.activateFrom) return;
  editor.activeLayer = state.layers.length - 1;
  editor.selection = []; editor.edge = null; editor.face = null;
  files.activateFrom = undefined;
}

// ---- seeing: the preview and each layer's mesh ----------------------------------------------

editor.preview = false;          // the picture alone: no mesh, no warnings drawn
editor.meshHidden = new Set();   // layers whose mesh is not drawn (their picture still is)

function togglePreview() {
  editor.preview = !editor.preview;
  $("preview").classList.toggle("on", editor.preview);
  $("preview").textContent = editor.preview ? "Show mesh (Tab)" : "Preview (Tab)";
  drawOverlay();
}

// Whether the mesh of layer `i` is drawn and takes clicks.
function meshShown(i) {
  const layer = editor.state && editor.state.layers[i];
  return !!layer && !layer.hidden && !editor.preview && !editor.meshHidden.has(i);
}

// The check box "mesh shown" of layer `i` in the layer list.
function meshToggle(i) {
  const box = document.createElement("input");
  box.type = "checkbox";
  box.className = "mesh-shown";
  box.checked = !editor.meshHidden.has(i);
  box.title = "mesh shown";
  box.onclick = (event) => {
    event.stopPropagation();
    if (box.checked) editor.meshHidden.delete(i); else editor.meshHidden.add(i);
    drawOverlay();
  };
  return box;
}

$("preview").onclick = () => { togglePreview(); refocusCanvas(); };

// ---- picking ------------------------------------------------------------------------------

// A handle shorter than this (in CSS pixels) is taken only when nothing else is under the
// pointer.
const SHORT_HANDLE_PX = 5;

// What a press at (sx, sy) takes in `layer`: {point}, {handle: [from, to]} or null. Points
// win over the handles of other points; a point's own handle wins when the pointer is nearer
// its end; a short handle is taken only when no point or other handle is under the pointer.
function pickPress(layer, sx, sy) {
  const point = pickPoint(layer, sx, sy);
  let long = null, short = null;
  for (const p of editor.selection) {
    for (const [from, to] of layer.handles) {
      if (from !== p) continue;
      const [ex, ey] = handleEnd(layer, from, to);
      const [px, py] = toScreen(...layer.points[from]);
      const distance = Math.hypot(ex - sx, ey - sy);
      if (distance >= 7) continue;
      const found = { handle: [from, to], distance };
      if (Math.hypot(ex - px, ey - py) < SHORT_HANDLE_PX) {
        if (!short || distance < short.distance) short = found;
      } else if (!long || distance < long.distance) {
        long = found;
      }
    }
  }
  if (point !== null) {
    const [px, py] = toScreen(...layer.points[point]);
    const own = long && long.handle[0] === point && long.distance < Math.hypot(px - sx, py - sy);
    return own ? { handle: long.handle } : { point };
  }
  if (long) return { handle: long.handle };
  if (short) return { handle: short.handle };
  return null;
}

// A press on a point of another layer whose mesh is shown makes that layer the active one
// (the topmost, if several), unless a point or handle of the active layer is under the
// pointer.
function activateLayerWithPointUnder(sx, sy) {
  const active = activeLayer();
  if (active && meshShown(editor.activeLayer) && pickPress(active, sx, sy)) return;
  activateTopmost((layer) => pickPoint(layer, sx, sy) !== null);
}

// A click (not a drag) on nothing of the active layer makes the topmost layer whose mesh is
// shown and whose faces hold the pointer the active one.
function activateLayerWithFaceUnder(sx, sy) {
  if (activeHas(sx, sy)) return;
  activateTopmost((layer) => pickFace(layer, sx, sy) !== null);
}

function activeHas(sx, sy) {
  const active = activeLayer();
  return !!active && meshShown(editor.activeLayer)
    && !!(pickPress(active, sx, sy) || pickEdge(active, sx, sy));
}

function activateTopmost(under) {
  const layers = editor.state ? editor.state.layers : [];
  const hit = layers.map((_, i) => i).reverse().find((i) => meshShown(i) && under(layers[i]));
  if (hit === undefined || hit === editor.activeLayer) return;
  editor.activeLayer = hit;
  editor.selection = []; editor.edge = null; editor.face = null;
  updatePanels();
}

// ---- keys ---------------------------------------------------------------------------------

// Whether `element` takes typed text (shortcuts leave it alone).
function isTextField(element) {
  if (!element) return false;
  if (element.tagName === "TEXTAREA" || element.isContentEditable) return true;
  if (element.tagName === "SELECT") return true;
  return element.tagName === "INPUT"
    && ["text", "number", "search", "email", "url", "password", ""].includes(element.type);
}

// The keys handled before the editor's own: Ctrl+S everywhere (never the browser's dialog);
// elsewhere than in a text field, Tab (preview), Ctrl+A (all points), Ctrl+C, Ctrl+V and
// Ctrl+D (copy, paste, duplicate faces), the arrows (nudge 1 pixel, Shift 10). Returns true
// if the key was taken.
function takeKey(event) {
  const ctrl = event.ctrlKey || event.metaKey;
  const key = event.key.toLowerCase();
  if (ctrl && key === "s") {
    event.preventDefault();
    if (event.shiftKey) saveAs(); else save();
    return true;
  }
  if (isTextField(event.target)) return false;
  if (event.key === "Tab" && !ctrl && !event.altKey) {
    togglePreview();
  } else if (ctrl && key === "a") {
    const layer = activeLayer();
    editor.selection = layer ? layer.points.map((_, i) => i) : [];
    editor.edge = null; editor.face = null;
  } else if (ctrl && key === "c") {
    copyFaces();
  } else if (ctrl && key === "v") {
    pasteFaces();
  } else if (ctrl && key === "d") {
    if (copyFaces()) pasteFaces();
  } else if (!ctrl && event.key.startsWith("Arrow")) {
    nudge(event.key, event.shiftKey ? 10 : 1);
  } else {
    return false;
  }
  event.preventDefault();
  updatePanels();
  drawOverlay();
  return true;
}

// Moves the selected points by `pixels` screen pixels in the arrow's direction.
function nudge(arrow, pixels) {
  if (editor.selection.length === 0 || !editor.view) return;
  const step = pixels / scale();
  const [dx, dy] = { ArrowLeft: [-step, 0], ArrowRight: [step, 0], ArrowUp: [0, -step], ArrowDown: [0, step] }[arrow];
  edit({ op: "move_points", layer: editor.activeLayer, points: editor.selection, dx, dy });
}

// After a button, a check box or a menu, keys go to the canvas again.
document.addEventListener("click", (event) => {
  const t = event.target;
  if (t.tagName === "BUTTON" || (t.tagName === "INPUT" && t.type === "checkbox")) refocusCanvas();
});
document.addEventListener("change", (event) => {
  if (event.target.tagName === "SELECT") refocusCanvas();
});

// ---- exports ------------------------------------------------------------------------------

// Downloads the visible layers in `format` (png, pdf, svg), named after the document.
async function exportPicture(format) {
  const size = Math.round(Number($("export-size").value)) || 2048;
  const query = `token=${encodeURIComponent(token)}&format=${format}&size=${size}`;
  showMessage(`Exporting ${format.toUpperCase()}…`);
  const response = await fetch(`/api/export?${query}`);
  if (!response.ok) { showMessage(`Not exported: ${await response.text()}`); return; }
  const disposition = response.headers.get("Content-Disposition") || "";
  const match = /filename="([^"]*)"/.exec(disposition);
  const link = document.createElement("a");
  link.href = URL.createObjectURL(await response.blob());
  link.download = match ? match[1] : `picture.${format}`;
  document.body.append(link);
  link.click();
  link.remove();
  setTimeout(() => URL.revokeObjectURL(link.href), 60000);
  files.exported = link.download;
  showMessage(`Exported ${link.download}`);
}

$("export").addEventListener("change", (event) => {
  const format = event.target.value;
  event.target.value = "";
  refocusCanvas();
  if (format) exportPicture(format);
});

// ---- copy, paste, duplicate ---------------------------------------------------------------

// The faces chosen: the selected face, or the faces all of whose corners are selected.
function selectedFaces() {
  const layer = activeLayer();
  if (!layer) return [];
  if (editor.face !== null) return [editor.face];
  const chosen = new Set(editor.selection);
  return layer.faces.map((corners, i) => [corners, i])
    .filter(([corners]) => corners.every((p) => chosen.has(p))).map(([, i]) => i);
}

function copyFaces() {
  const faces = selectedFaces();
  if (faces.length === 0) {
    showMessage("Select a face (click inside it), or the points of whole faces, to copy.");
    return false;
  }
  files.copied = { layer: editor.activeLayer, faces };
  showMessage(`Copied ${faces.length} face${faces.length > 1 ? "s" : ""}.`);
  return true;
}

// Pastes the faces copied into the active layer, 10 pixels down and right of where they were
// when pasted; the new points become the selection.
function pasteFaces() {
  const layer = activeLayer();
  if (!files.copied) { showMessage("Nothing copied yet (Ctrl+C)."); return; }
  if (!layer || !editor.view) return;
  const step = 10 / scale();
  files.selectFrom = { layer: editor.activeLayer, first: layer.points.length };
  send({ type: "paste", from_layer: files.copied.layer, faces: files.copied.faces,
    layer: editor.activeLayer, dx: step, dy: step });
}

function selectPasted(state) {
  const from = files.selectFrom;
  const layer = from && state.layers[from.layer];
  if (!layer || layer.points.length <= from.first) return;
  editor.activeLayer = from.layer;
  editor.selection = layer.points.map((_, i) => i).slice(from.first);
  editor.face = null; editor.edge = null;
  files.selectFrom = null;
}

// ---- the backdrop of SVG and PDF files ------------------------------------------------------------
// What an SVG file draws besides its mesh fills: drawn by the server at the canvas's view, under
// the picture, locked (it takes no clicks); the panel says what is not editable. A PDF file's
// other content is not drawn: the panel only says what was left out.

function showBackdrops(state) {
  const backdrops = state.backdrops || [];
  $("backdrop-info").hidden = backdrops.length === 0;
  $("backdrop-shown").parentElement.hidden = !backdrops.some((b) => b.drawn);
  $("backdrop-text").textContent = backdrops.map((b) => b.message).join("; ");
  const key = backdrops.map((b) => b.file).join("\n");
  if (key !== showBackdrops.key) {
    showBackdrops.key = key;
    updateBackdrop();
  }
}

// Asks for the backdrop at the current view, a moment after the view stops changing.
function updateBackdrop() {
  clearTimeout(updateBackdrop.timer);
  updateBackdrop.timer = setTimeout(loadBackdrop, 120);
}

function loadBackdrop() {
  const image = $("backdrop");
  const backdrops = editor.state ? editor.state.backdrops || [] : [];
  if (!backdrops.some((b) => b.drawn) || !$("backdrop-shown").checked || !editor.view) {
    image.style.display = "none";
    return;
  }
  const size = canvasSize();
  const v = editor.view;
  const query = new URLSearchParams({
    token, width: size.width, height: size.height, x0: v.x0, y0: v.y0, x1: v.x1, y1: v.y1,
  });
  const url = `/api/backdrop.png?${query}`;
  const shown = () => { image.style.display = "block"; image.dataset.view = query.toString(); };
  image.onload = shown;
  image.onerror = () => { image.style.display = "none"; };
  image.src = url;
}

$("backdrop-shown").addEventListener("change", () => { loadBackdrop(); refocusCanvas(); });
