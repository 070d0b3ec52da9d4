// The gradmesh editor's page, its files: the document's file and state, saving (asking before
// a file the editor did not write is replaced), the warning before leaving with unsaved edits.
// Loaded after app.js, whose globals (editor, send, $, showMessage) it uses.
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
