// Pose Studio's undo/redo and unsaved-changes tracking: the draft's snapshots after each committed edit,
// and the snapshot last opened or saved (leaving the page, or opening another motion, asks first when
// the draft differs from it).
const LIMIT = 200; // snapshots kept

export class DraftHistory {
  constructor() {
    this.states = [];
    this.index = -1;
    this.baseline = null;
  }

  reset(state) {
    this.states = [JSON.stringify(state)];
    this.index = 0;
    this.baseline = this.states[0];
  }

  commit(state) {
    const text = JSON.stringify(state);
    if (text === this.states[this.index]) return;
    this.states = [...this.states.slice(Math.max(0, this.index + 1 - LIMIT)), text];
    this.index = this.states.length - 1;
  }

  undo() { return this.index > 0 ? JSON.parse(this.states[--this.index]) : null; }

  redo() { return this.index < this.states.length - 1 ? JSON.parse(this.states[++this.index]) : null; }

  get canUndo() { return this.index > 0; }

  get canRedo() { return this.index < this.states.length - 1; }

  saved(state) { this.baseline = JSON.stringify(state); }

  dirty(state) { return JSON.stringify(state) !== this.baseline; }
}

// The undo/redo buttons and Ctrl+Z / Ctrl+Y (Ctrl+Shift+Z); text fields keep their own undo.
export function wireUndo(edits, apply) {
  document.getElementById("undo").onclick = () => apply(edits.undo());
  document.getElementById("redo").onclick = () => apply(edits.redo());
  window.addEventListener("keydown", (e) => {
    if (!(e.ctrlKey || e.metaKey) || e.target.matches("input[type=text], textarea")) return;
    const key = e.key.toLowerCase();
    if (key !== "z" && key !== "y") return;
    e.preventDefault();
    apply(key === "y" || e.shiftKey ? edits.redo() : edits.undo());
  });
}
