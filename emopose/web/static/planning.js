// The line being planned: "planning… 3.4 s", the model call's retries while it retries, and Cancel.
import { el } from "./common.js";

export class PlanningBubble {
  // send(message) -> true when it went out (the WebSocket is open)
  constructor(history, send) {
    this.history = history;
    this.send = send;
    this.node = null;
    this.turn = null; // the turn_started message's id: the Cancel names it
    this.timer = null;
  }

  get shown() { return this.node !== null; }

  // counts from when the server started the turn (msg.now: the server's clock when it was sent)
  show(msg) {
    this.clear();
    const started = performance.now() - Math.max(0, (msg.now ?? msg.server_now) - msg.server_now) * 1000;
    const text = el("span", { class: "planning-text", text: "planning…" });
    this.retries = el("span", { class: "planning-retries" });
    this.note = el("span", { class: "planning-note small" });
    this.button = el("button", { type: "button", class: "cancel-planning", text: "Cancel",
      title: "stop waiting for this reply: nothing is said or done", onclick: () => this.cancel() });
    this.node = el("div", { class: "bubble robot pending" }, text, this.retries, this.button, this.note);
    this.turn = msg.id;
    const tick = () => { text.textContent = `planning… ${((performance.now() - started) / 1000).toFixed(1)} s`; };
    tick();
    this.timer = setInterval(tick, 100);
    this.history.append(this.node);
  }

  // the live state's `planning` ({turn, since, retries}): retries are shown once there are any
  update(planning) {
    if (!this.node || !planning || planning.turn !== this.turn) return;
    const n = planning.retries ?? 0;
    this.retries.textContent = n > 0 ? `the model call failed: retrying (${n} ${n === 1 ? "retry" : "retries"})` : "";
  }

  cancel() {
    if (!this.send({ type: "cancel", turn: this.turn })) {
      this.note.textContent = "not connected: the cancel was not sent";
      return;
    }
    this.button.disabled = true;
    this.note.textContent = "cancelling…";
  }

  refused(message) {
    if (!this.node) return;
    this.button.disabled = false;
    this.note.textContent = message;
  }

  clear() {
    clearInterval(this.timer);
    if (this.node) this.node.remove();
    this.node = null;
    this.turn = null;
  }
}

// A line cancelled while it was planned: said in the conversation where its reply would have been.
export function cancelledNote(msg) {
  return el("div", { class: "bubble note cancelled-line", "data-cancelled": msg.turn_id,
    text: `cancelled after ${msg.planning_s.toFixed(1)} s of planning: nothing was said or done` });
}
