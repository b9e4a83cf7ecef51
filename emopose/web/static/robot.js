// The live robot panel: simulation view (MuJoCo frames, or the stick figure of the command stream),
// sequencer state, queue and events, and the camera feed.
import { drawStick, el } from "./common.js";

const $ = (id) => document.getElementById(id);

export class RobotPanel {
  constructor() {
    this.hasSim = false;
    this.frameTimes = [];
    this.urls = {};
  }

  configure(info) {
    this.hasSim = Boolean(info.channels.sim);
    $("sim").classList.toggle("hidden", !this.hasSim);
    $("stick").classList.toggle("hidden", this.hasSim);
    $("sim-caption").textContent = this.hasSim ? info.channels.sim : "stick figure of the command stream";
    $("camera-card").classList.toggle("hidden", !info.channels.camera);
    $("camera-caption").textContent = info.channels.camera || "";
  }

  frame(tag, blob) {
    const image = tag === "s" ? $("sim") : $("camera");
    const url = URL.createObjectURL(blob);
    image.onload = () => URL.revokeObjectURL(url);
    image.src = url;
    image.dataset.frames = String(Number(image.dataset.frames || 0) + 1);
    if (tag === "s") {
      const now = performance.now();
      this.frameTimes = [...this.frameTimes.filter((t) => now - t < 2000), now];
      $("fps").textContent = `${(this.frameTimes.length / 2).toFixed(1)} fps`;
    }
  }

  update(state) {
    if (!this.hasSim) drawStick($("stick"), state.stick);
    const pill = $("seq-state");
    pill.textContent = state.state;
    pill.className = `pill ${state.state}`;
    $("seq-active").textContent = state.active ? `${state.active.name} (${state.active.label})` : "—";
    const queue = $("seq-queue");
    queue.replaceChildren(...(state.pending.length ? state.pending.map((c) => el("li", {},
      el("span", { text: c.name }), el("span", { class: "muted small", text: c.release_in_s > 0 ? `in ${c.release_in_s.toFixed(1)} s` : "released" })))
      : [el("li", { class: "muted", text: "empty" })]));
    if (state.loop) {  // deadlines the 50 Hz loop missed: a stalled loop delays every gesture after it
      const share = state.loop.ticks ? (100 * state.loop.missed) / state.loop.ticks : 0;
      $("loop-missed").textContent = `${state.loop.missed} missed of ${state.loop.ticks} ticks (${share.toFixed(2)} %)`;
      $("loop-missed").className = share > 1 ? "late" : "";
    }
    const events = $("events");
    for (const e of state.events) {
      if (e.kind === "state") continue;
      events.prepend(el("li", { class: e.kind }, el("span", { class: "muted", text: e.kind }),
        el("span", { text: e.name }), el("span", { class: "muted", text: e.detail })));
    }
    while (events.children.length > 6) events.lastElementChild.remove();
  }
}
