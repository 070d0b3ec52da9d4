// The mesh tools of one click (grid, ellipse, outline, loop cut, point in face, dissolve) and
// tracing (a reference image under the mesh, and an eyedropper setting the selected points'
// colours from it). Loaded after app.js, whose functions and `editor` it uses; app.js calls
// `editor.tools` from its mouse, keyboard, drawing and message handlers.
"use strict";

(() => {
  const tools = {
    mode: null,        // "grid", "ellipse", "outline", "loop_cut", "point" or null
    drag: null,        // {start, at}: a grid's or ellipse's box being dragged, CSS pixels
    outline: [],       // the outline's corners so far, plane coordinates
    hover: null,       // the pointer, CSS pixels
    reference: null,   // {image, x, y, width, pixels}: the reference image and its place
    referenceDrag: null,
  };
  editor.tools = tools;

  const hints = {
    grid: "Drag a rectangle: a grid of the size set in Tools. Esc cancels.",
    ellipse: "Drag the ellipse's box. Esc cancels.",
    outline: "Click the outline's corners; click the first again (or Enter) to close it. Esc cancels.",
    loop_cut: "Click an edge: a line of points across its strip of quads. Esc cancels.",
    point: "Click inside a face: a point there, joined to the face's corners. Esc cancels.",
    trace: "Drag a box over the part of the reference image to trace, or click for all of it. Esc cancels.",
  };
  const buttons = {
    grid: "tool-grid", ellipse: "tool-ellipse", outline: "tool-outline",
    loop_cut: "tool-loop-cut", point: "tool-point", trace: "tool-trace",
  };

  function setMode(mode) {
    tools.mode = mode;
    tools.drag = null;
    tools.outline = [];
    for (const [name, id] of Object.entries(buttons)) $(id).classList.toggle("active", name === mode);
    $("tool-hint").textContent = mode ? hints[mode] : "";
    overlay.style.cursor = mode ? "cell" : "";
    drawOverlay();
  }

  // The layer a new mesh goes into: the active one, made if the document has none.
  function targetLayer() {
    if (editor.state && editor.state.layers.length === 0) {
      edit({ op: "add_layer", name: "Layer 1" });
      editor.activeLayer = 0;
    }
    return editor.activeLayer;
  }

  // The box dragged, in plane coordinates, or null if it is too small to mean one.
  function draggedRect(d) {
    if (Math.abs(d.at[0] - d.start[0]) < 4 || Math.abs(d.at[1] - d.start[1]) < 4) return null;
    return [...toPlane(...d.start), ...toPlane(...d.at)];
  }

  function gridSize(id) {
    const n = Math.round(Number($(id).value));
    return Number.isFinite(n) ? Math.min(64, Math.max(1, n)) : 2;
  }

  function finishBox() {
    const d = tools.drag;
    tools.drag = null;
    const rect = draggedRect(d);
    if (tools.mode === "trace") { setMode(null); traceImage(rect); return; }
    if (!rect) { showMessage("Drag over the place the new mesh should fill."); drawOverlay(); return; }
    const layer = targetLayer();
    if (tools.mode === "grid") {
      edit({ op: "add_grid", layer, rect, columns: gridSize("grid-columns"), rows: gridSize("grid-rows") });
    } else {
      edit({ op: "add_ellipse", layer, rect });
    }
    setMode(null);
  }

  function finishOutline() {
    if (tools.outline.length < 3) { showMessage("An outline needs three or more corners."); return; }
    edit({ op: "add_outline", layer: targetLayer(), outline: tools.outline });
    setMode(null);
  }

  // Where along the edge from a to b (0 to 1) the point of the curve nearest (sx, sy) lies.
  function edgeParameter(layer, a, b, sx, sy) {
    const [p0, p1, p2, p3] = edgeCurve(layer, a, b);
    let best = 0.5, bestDistance = Infinity;
    for (let k = 1; k < 64; k++) {
      const t = k / 64, u = 1 - t;
      const w = [u * u * u, 3 * u * u * t, 3 * u * t * t, t * t * t];
      const x = w[0] * p0[0] + w[1] * p1[0] + w[2] * p2[0] + w[3] * p3[0];
      const y = w[0] * p0[1] + w[1] * p1[1] + w[2] * p2[1] + w[3] * p3[1];
      const d = Math.hypot(x - sx, y - sy);
      if (d < bestDistance) { best = t; bestDistance = d; }
    }
    return best;
  }

  function clickTool(at) {
    const layer = activeLayer();
    if (tools.mode === "outline") {
      const first = tools.outline[0];
      if (tools.outline.length >= 3 && Math.hypot(...toScreen(...first).map((v, i) => v - at[i])) < 8) {
        finishOutline();
      } else {
        tools.outline.push(toPlane(...at));
        drawOverlay();
      }
      return;
    }
    if (!layer || layer.hidden) { showMessage("Choose a shown layer first."); return; }
    if (tools.mode === "loop_cut") {
      const e = pickEdge(layer, ...at);
      if (!e) { showMessage("Click on an edge (a line of the mesh)."); return; }
      edit({ op: "loop_cut", layer: editor.activeLayer, a: e[0], b: e[1], at: edgeParameter(layer, e[0], e[1], ...at) });
      setMode(null);
    } else if (tools.mode === "point") {
      const face = pickFace(layer, ...at);
      if (face === null) { showMessage("Click inside a face of the active layer."); return; }
      const [x, y] = toPlane(...at);
      edit({ op: "add_point_in_face", layer: editor.activeLayer, face, x, y });
      setMode(null);
    }
  }

  // Dissolves the selected points, else the selected edge.
  function dissolve() {
    if (editor.selection.length > 0) {
      edit({ op: "dissolve_points", layer: editor.activeLayer, points: editor.selection });
      editor.selection = [];
    } else if (editor.edge) {
      edit({ op: "dissolve_edge", layer: editor.activeLayer, a: editor.edge[0], b: editor.edge[1] });
      editor.edge = null;
    } else {
      showMessage("Select points or an edge to dissolve.");
    }
  }

  // ---- the hooks app.js calls --------------------------------------------------------------

  tools.pointerDown = (event, at) => {
    if (event.button !== 0) return false;
    const ref = tools.reference;
    if (event.altKey && ref && !$("reference-lock").checked) {
      tools.referenceDrag = { start: at, x: ref.x, y: ref.y };
      return true;
    }
    if (!tools.mode) return false;
    if (tools.mode === "grid" || tools.mode === "ellipse" || tools.mode === "trace") {
      tools.drag = { start: at, at };
    } else {
      clickTool(at);
    }
    return true;
  };

  tools.pointerMove = (event, at) => {
    tools.hover = at;
    if (tools.referenceDrag) {
      const d = tools.referenceDrag, s = scale();
      tools.reference.x = d.x + (at[0] - d.start[0]) / s;
      tools.reference.y = d.y + (at[1] - d.start[1]) / s;
      showReferencePlace();
      drawOverlay();
      return true;
    }
    if (tools.drag) tools.drag.at = at;
    if (tools.mode) drawOverlay();
    return tools.drag !== null;
  };

  tools.pointerUp = (event, at) => {
    if (tools.referenceDrag) { tools.referenceDrag = null; return true; }
    if (!tools.drag) return false;
    tools.drag.at = at;
    finishBox();
    return true;
  };

  // A key of the tools; true if it was one.
  tools.key = (event, key) => {
    if (event.key === "Escape" && tools.mode) { setMode(null); return true; }
    if (event.key === "Enter" && tools.mode === "outline") { finishOutline(); return true; }
    const mode = { g: "grid", o: "ellipse", p: "outline", l: "loop_cut", i: "point", t: "trace" }[key];
    if (mode) { setMode(tools.mode === mode ? null : mode); return true; }
    if (key === "x") { dissolve(); return true; }
    if (key === "k") { eyedropper(); return true; }
    return false;
  };

  // Draws what a tool is making, and places the reference image.
  tools.draw = (c) => {
    placeReference();
    c.save();
    c.strokeStyle = "#4af"; c.lineWidth = 1.5; c.setLineDash([5, 3]);
    const d = tools.drag;
    if (d) {
      const [x0, y0] = d.start, [x1, y1] = d.at;
      if (tools.mode === "trace") {
        c.strokeRect(Math.min(x0, x1), Math.min(y0, y1), Math.abs(x1 - x0), Math.abs(y1 - y0));
      } else if (tools.mode === "grid") {
        const [n, m] = [gridSize("grid-columns"), gridSize("grid-rows")];
        c.beginPath();
        for (let i = 0; i <= n; i++) { const x = x0 + (x1 - x0) * i / n; c.moveTo(x, y0); c.lineTo(x, y1); }
        for (let j = 0; j <= m; j++) { const y = y0 + (y1 - y0) * j / m; c.moveTo(x0, y); c.lineTo(x1, y); }
        c.stroke();
      } else {
        c.beginPath();
        c.ellipse((x0 + x1) / 2, (y0 + y1) / 2, Math.abs(x1 - x0) / 2, Math.abs(y1 - y0) / 2, 0, 0, 2 * Math.PI);
        c.stroke();
      }
    }
    if (tools.mode === "outline" && tools.outline.length > 0) {
      c.beginPath();
      tools.outline.forEach((p, i) => { const [x, y] = toScreen(...p); if (i === 0) c.moveTo(x, y); else c.lineTo(x, y); });
      if (tools.hover) c.lineTo(...tools.hover);
      c.stroke();
      c.setLineDash([]);
      c.fillStyle = "#4af";
      for (const p of tools.outline) { const [x, y] = toScreen(...p); c.fillRect(x - 3, y - 3, 6, 6); }
    }
    c.restore();
  };

  // ---- the reference image ---------------------------------------------------------------

  const image = $("reference");

  function loadReference(file) {
    if (!file) return;
    if (!/^image\/(png|jpeg)$/.test(file.type)) { showMessage(`${file.name} is not a PNG or JPEG image.`); return; }
    const url = URL.createObjectURL(file);
    const img = new Image();
    img.onload = () => {
      const canvas = document.createElement("canvas");
      canvas.width = img.naturalWidth;
      canvas.height = img.naturalHeight;
      const context = canvas.getContext("2d", { willReadFrequently: true });
      context.drawImage(img, 0, 0);
      const pixels = context.getImageData(0, 0, canvas.width, canvas.height);
      const old = tools.reference;
      if (old) URL.revokeObjectURL(old.url);
      tools.reference = { url, x: 0, y: 0, width: 1, pixels };
      image.src = url;
      fitReference();
    };
    img.onerror = () => { URL.revokeObjectURL(url); showMessage(`${file.name} could not be read as an image.`); };
    img.src = url;
  }

  // Places the image over the document's points (or the view if there are none).
  function fitReference() {
    const ref = tools.reference;
    if (!ref) return;
    const v = editor.view;
    let [x0, y0, x1, y1] = [v.x0, v.y0, v.x1, v.y1];
    const points = editor.state ? editor.state.layers.flatMap((l) => l.points) : [];
    if (points.length > 0) {
      x0 = Math.min(...points.map((p) => p[0])); x1 = Math.max(...points.map((p) => p[0]));
      y0 = Math.min(...points.map((p) => p[1])); y1 = Math.max(...points.map((p) => p[1]));
    }
    const aspect = ref.pixels.height / ref.pixels.width;
    ref.width = Math.max(x1 - x0, (y1 - y0) / aspect);
    ref.x = (x0 + x1) / 2 - ref.width / 2;
    ref.y = (y0 + y1) / 2 - ref.width * aspect / 2;
    showReferencePlace();
    drawOverlay();
  }

  function showReferencePlace() {
    const ref = tools.reference;
    $("reference-x").value = +ref.x.toFixed(3);
    $("reference-y").value = +ref.y.toFixed(3);
    $("reference-width").value = +ref.width.toFixed(3);
  }

  function placeReference() {
    const ref = tools.reference;
    image.style.display = ref && editor.view ? "block" : "none";
    if (!ref || !editor.view) return;
    const [left, top] = toScreen(ref.x, ref.y);
    image.style.left = `${left}px`;
    image.style.top = `${top}px`;
    image.style.width = `${ref.width * scale()}px`;
    image.style.opacity = $("reference-opacity").value;
    const stage = $("stage");
    if ($("reference-behind").checked) stage.insertBefore(image, picture);
    else stage.insertBefore(image, overlay);
  }

  // The image's colour at plane point (x, y), averaged over 3 x 3 pixels, or null outside it.
  function referenceColour(x, y) {
    const ref = tools.reference;
    const { width, height, data } = ref.pixels;
    const u = Math.floor((x - ref.x) / ref.width * width);
    const v = Math.floor((y - ref.y) / (ref.width * height / width) * height);
    if (u < 0 || v < 0 || u >= width || v >= height) return null;
    const sum = [0, 0, 0];
    let n = 0;
    for (let j = Math.max(0, v - 1); j <= Math.min(height - 1, v + 1); j++) {
      for (let i = Math.max(0, u - 1); i <= Math.min(width - 1, u + 1); i++) {
        for (let k = 0; k < 3; k++) sum[k] += data[4 * (j * width + i) + k];
        n++;
      }
    }
    return "#" + sum.map((s) => Math.round(s / n).toString(16).padStart(2, "0")).join("");
  }

  // Sets each selected point's colour to the image's colour under it.
  function eyedropper() {
    const layer = activeLayer();
    if (!tools.reference) { showMessage("Place a reference image first (Tools: Reference image)."); return; }
    if (!layer || editor.selection.length === 0) { showMessage("Select the points to colour from the image."); return; }
    const points = [], css = [];
    for (const p of editor.selection) {
      const colour = referenceColour(...layer.points[p]);
      if (colour) { points.push(p); css.push(colour); }
    }
    if (points.length === 0) { showMessage("The selected points are outside the reference image."); return; }
    edit({ op: "set_colours", layer: editor.activeLayer, points, css });
    if (points.length < editor.selection.length) {
      showMessage(`${editor.selection.length - points.length} selected points are outside the image and kept their colours.`);
    }
  }

  // ---- trace -------------------------------------------------------------------------------

  // The largest side, in pixels, of the picture sent to be traced: larger parts are scaled
  // down (the server's fit takes longer with more pixels, and a request is at most 1 MiB).
  const TRACE_SIDE = 320;

  // The part of the reference image under `rect` (plane coordinates; null: all of it), in
  // whole image pixels, and the plane rectangle those pixels cover; null if none.
  function traceRegion(rect) {
    const ref = tools.reference;
    const { width, height } = ref.pixels;
    const perUnit = width / ref.width;
    const box = rect
      ? [Math.min(rect[0], rect[2]), Math.min(rect[1], rect[3]), Math.max(rect[0], rect[2]), Math.max(rect[1], rect[3])]
      : [ref.x, ref.y, ref.x + ref.width, ref.y + height / perUnit];
    const px0 = Math.max(0, Math.round((box[0] - ref.x) * perUnit));
    const py0 = Math.max(0, Math.round((box[1] - ref.y) * perUnit));
    const px1 = Math.min(width, Math.round((box[2] - ref.x) * perUnit));
    const py1 = Math.min(height, Math.round((box[3] - ref.y) * perUnit));
    if (px1 - px0 < 4 || py1 - py0 < 4) return null;
    const plane = [ref.x + px0 / perUnit, ref.y + py0 / perUnit, ref.x + px1 / perUnit, ref.y + py1 / perUnit];
    return { pixels: [px0, py0, px1 - px0, py1 - py0], plane };
  }

  // Sends the part of the reference image under `rect` to be traced; the mesh comes back as a
  // new layer (one undo step), made active.
  async function traceImage(rect) {
    if (!tools.reference) { showMessage("Place a reference image first (Tools: Reference image)."); return; }
    const region = traceRegion(rect);
    if (!region) { showMessage("Drag the box over the reference image."); return; }
    const [sx, sy, sw, sh] = region.pixels;
    const shrink = Math.min(1, TRACE_SIDE / Math.max(sw, sh));
    const canvas = document.createElement("canvas");
    canvas.width = Math.max(1, Math.round(sw * shrink));
    canvas.height = Math.max(1, Math.round(sh * shrink));
    canvas.getContext("2d").drawImage(image, sx, sy, sw, sh, 0, 0, canvas.width, canvas.height);
    const png = await new Promise((resolve) => canvas.toBlob(resolve, "image/png"));
    const points = Math.round(Number($("trace-points").value));
    const [x0, y0, x1, y1] = region.plane;
    const query = new URLSearchParams({ token, x0, y0, x1, y1, points: Number.isFinite(points) ? points : 100 });
    $("tool-trace").disabled = true;
    $("tool-hint").textContent = "Tracing…";
    tools.tracing = true;
    try {
      const response = await fetch(`/api/trace?${query}`, { method: "POST", body: png, headers: { "Content-Type": "image/png" } });
      const answer = await response.json().catch(() => ({ message: `the trace failed (${response.status})` }));
      if (!response.ok) { showMessage(answer.message); return; }
      editor.chosen = { layer: answer.layer, points: [], face: null };
      send({ type: "state" });
      showMessage(`Traced: ${answer.points} points, ${answer.psnr.toFixed(1)} dB against the picture.`);
    } catch (error) {
      showMessage(`The trace failed: ${error}`);
    } finally {
      tools.tracing = false;
      $("tool-trace").disabled = false;
      $("tool-hint").textContent = tools.mode ? hints[tools.mode] : "";
    }
  }

  $("reference-file").addEventListener("change", (event) => loadReference(event.target.files[0]));
  $("reference-fit").onclick = fitReference;
  $("reference-remove").onclick = () => {
    if (tools.reference) URL.revokeObjectURL(tools.reference.url);
    tools.reference = null;
    image.removeAttribute("src");
    $("reference-file").value = "";
    drawOverlay();
  };
  for (const [id, field] of [["reference-x", "x"], ["reference-y", "y"], ["reference-width", "width"]]) {
    $(id).addEventListener("change", (event) => {
      const value = Number(event.target.value);
      const valid = Number.isFinite(value) && (field !== "width" || value > 0);
      if (!tools.reference || !valid || $("reference-lock").checked) return;
      tools.reference[field] = value;
      drawOverlay();
    });
  }
  $("reference-lock").addEventListener("change", (event) => {
    for (const id of ["reference-x", "reference-y", "reference-width", "reference-fit"]) $(id).disabled = event.target.checked;
  });
  for (const id of ["reference-opacity", "reference-behind"]) $(id).addEventListener("input", drawOverlay);
  $("eyedropper").onclick = eyedropper;
  $("tool-dissolve").onclick = dissolve;
  for (const [mode, id] of Object.entries(buttons)) $(id).onclick = () => setMode(tools.mode === mode ? null : mode);
})();
