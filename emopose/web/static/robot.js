// The live robot panel: simulation view (MuJoCo frames, or the stick figure of the command stream),
// sequencer state, queue, events and loop health, and the camera feed. Everything is said in plain
// words: the sequencer's internal states (blending, holding) mean nothing to a visitor.
import { clockTime, drawStick, el, syncClock } from "./common.js";

const $ = (id) => document.getElementById(id);

// Sequencer event kinds (emopose/contract.py EventKind) as a visitor reads them.
const EVENT_WORDS = {
  started: "started", stroke: "stroke", completed: "done", cut: "blended on", stopped: "cut short",
  rejected: "refused", dropped: "dropped",
};

// Red only for what went wrong: a refusal, a drop, a stall. Cut short by the next gesture or by an
// interrupt is the normal way one gesture gives way to another.
const isBad = (e) => e.kind === "rejected" || e.kind === "dropped"
  || (e.kind === "stopped" && (e.detail || "").startsWith("stall"));

function stateWords(state) {
  if (state.active) return state.state === "executing" ? ["gesturing", "executing"] : ["moving into it", "blending"];
  if (state.state === "blending") return ["returning to rest", "blending"];
  return ["idle", "idle"]; // holding: the arm keeps its last pose a moment, with nothing to do
}

function queueRow(command, active) {
  const when = command.release_in_s > 0 ? `in ${command.release_in_s.toFixed(1)} s`
    : active ? "next, after the current one" : "starting";
  return el("li", {}, el("span", { text: command.name }), el("span", { class: "muted small", text: when }));
}

// The control loop's health: deadlines missed and stalls (a stalled loop delays every gesture after it).
function loopHealth(loop) {
  if (!loop) return { text: "not running", bad: false };
  const share = loop.ticks ? (100 * loop.missed_deadlines) / loop.ticks : 0;
  const stalls = loop.stalls ?? 0;
  const late = loop.lateness_ms_p99 === undefined ? "" : ` · p99 late ${loop.lateness_ms_p99.toFixed(1)} ms`;
  return { text: `${loop.running === false ? "stopped · " : ""}${loop.missed_deadlines} missed of ${loop.ticks} ticks`
    + ` (${share.toFixed(2)} %) · ${stalls} stall${stalls === 1 ? "" : "s"}${late}`,
  bad: share > 1 || stalls > 0 || loop.running === false };
}

export class RobotPanel {
  constructor() {
    this.hasSim = false;
    this.frameTimes = [];
  }

  configure(info) {
    this.hasSim = Boolean(info.channels.sim);
    $("sim").classList.toggle("hidden", !this.hasSim);
    $("stick").classList.toggle("hidden", this.hasSim);
    $("sim-caption").textContent = this.hasSim ? info.channels.sim : "stick figure of the command stream";
    $("camera-card").classList.toggle("hidden", !info.channels.camera);
    $("camera-caption").textContent = info.channels.camera || "";
  }

  // Disconnected: the view keeps its last picture, marked as not live.
  live(up) {
    document.querySelectorAll(".view.live").forEach((v) => v.classList.toggle("stale", !up));
    if (!up) $("fps").textContent = "not live";
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
    syncClock(state.server_now);
    if (!this.hasSim) drawStick($("stick"), state.stick);
    const [words, kind] = stateWords(state), pill = $("seq-state");
    pill.textContent = words;
    pill.className = `pill ${kind}`;
    pill.title = `sequencer state: ${state.state}`;
    $("seq-active").textContent = state.active ? `${state.active.name} (${state.active.label})` : "—";
    $("seq-queue").replaceChildren(...(state.pending.length ? state.pending.map((c) => queueRow(c, state.active))
      : [el("li", { class: "muted", text: "empty" })]));
    const health = loopHealth(state.loop);
    $("loop-health").textContent = health.text;
    $("loop-health").className = health.bad ? "late" : "";
    const events = $("events");
    for (const e of state.events) {
      if (e.kind === "state") continue;
      events.prepend(el("li", { class: isBad(e) ? "bad" : "" }, clockTime(e.t),
        el("span", { class: "muted", text: EVENT_WORDS[e.kind] ?? e.kind }),
        el("span", { text: e.name }), el("span", { class: "muted detail", text: e.detail || "" })));
    }
    while (events.children.length > 6) events.lastElementChild.remove();
  }
}
