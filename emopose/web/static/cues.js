// One robot reply in the history: the text with each gesture's trigger marked, the cue list, and the
// live highlighting that lights a trigger up when its stroke lands (or at its release time in the
// paper's modes), relative to speech start. A cue the
// sequencer did not perform (rejected, dropped) is marked with the reason and never lights up.
import { CLASS_COLORS, el } from "./common.js";

function replyNode(reply, cues) {
  const spans = cues.filter((c) => c.char_start !== null).sort((a, b) => a.char_start - b.char_start);
  const node = el("div", { class: "reply" });
  let at = 0;
  for (const cue of spans) {
    if (cue.char_start < at) continue; // overlapping triggers: the first one keeps the mark
    node.append(reply.slice(at, cue.char_start));
    node.append(el("mark", { "data-k": cue.k, style: `--cue:${CLASS_COLORS[cue.class]}`, text: reply.slice(cue.char_start, cue.char_end) }));
    at = cue.char_end;
  }
  node.append(reply.slice(at));
  return node;
}

function cueNode(cue) {
  const rule = cue.rule === "exact" ? "exact" : cue.rule.replace("_", " ");
  const asked = cue.requested && cue.requested !== cue.resolved ? ` (asked ${cue.requested})` : "";
  return el("div", { class: "cue", "data-k": cue.k, style: `--cue:${CLASS_COLORS[cue.resolved_class] || "#888"}` },
    el("span", { class: "muted", text: cue.class }), "→",
    el("span", { class: "name", text: cue.resolved }),
    el("span", { class: "muted", text: `${rule}${asked} · i${cue.intensity}` }),
    cue.trigger ? el("span", { text: `“${cue.trigger}”` }) : null,
    el("span", { class: "time", text: cueTime(cue) }));
}

// Timeline cues show where the stroke lands (planned, then executed once the robot reports it); the
// paper's modes show the release time.
function cueTime(cue) {
  if (cue.stroke_s === null || cue.stroke_s === undefined) return cue.release_s === null ? "" : `${cue.release_s.toFixed(2)} s`;
  const executed = cue.stroke_executed_s === null || cue.stroke_executed_s === undefined ? ""
    : ` · executed ${cue.stroke_executed_s.toFixed(2)} s`;
  return `stroke ${cue.stroke_s.toFixed(2)} s${executed}`;
}

// The executed stroke time arrived after the turn was shown.
export function markStroke(bubble, k, executed) {
  const cue = bubble.querySelector(`.cue[data-k="${k}"]`);
  const data = cue && bubble.cueData && bubble.cueData[k];
  if (data) { data.stroke_executed_s = executed; cue.querySelector(".time").textContent = cueTime(data); }
}

// Mark cue k of a reply bubble as not performed: "rejected: <reason>" on the cue, its trigger struck out.
export function markOutcome(bubble, k, outcome) {
  bubble.querySelectorAll(`[data-k="${k}"]`).forEach((n) => { n.classList.remove("fired"); n.classList.add("refused"); });
  const cue = bubble.querySelector(`.cue[data-k="${k}"]`);
  if (cue && !cue.dataset.outcome) {
    cue.dataset.outcome = outcome.kind;
    cue.after(el("div", { class: "outcome", text: `${outcome.kind}: ${outcome.reason}` }));
  }
}

const ORIGIN = { gesture: "named gesture", draft: "Pose Studio draft" };

export function turnBubble(turn) {
  const bar = el("div", { class: "speechbar" }, el("div"));
  const meta = `${ORIGIN[turn.kind] ?? `plan: ${turn.source}`} · speech ${turn.speech.duration_s.toFixed(1)} s`
    + ` · planner ${(turn.planner_latency_s * 1000).toFixed(0)} ms · library v${turn.library_version}`;
  const bubble = el("div", { class: "bubble robot", "data-turn": turn.turn_id },
    turn.narrated ? el("div", { class: "narrated", text: "narration: the robot says your text" }) : null,
    turn.reply ? replyNode(turn.reply, turn.cues) : null,
    el("div", { class: "cues" }, turn.cues.map(cueNode)), bar, el("div", { class: "meta", text: meta }));
  turn.cues.forEach((cue) => cue.outcome && markOutcome(bubble, cue.k, cue.outcome));
  bubble.cueData = turn.cues;
  return bubble;
}

// A trigger lights up when its stroke lands (timeline mode), else at the gesture's release.
const lightAt = (cue) => cue.stroke_s ?? cue.release_s ?? 0;

// Plays one reply: its audio when the server has a WAV, and the highlighting on that clock
// (or on a timer started at the server's speech start when there is no audio or it cannot play).
export class ReplyPlayer {
  constructor(bubble, turn) {
    this.bubble = bubble; this.turn = turn; this.done = false;
    // Negative: the speech starts later (the next sentence of a streamed reply, queued behind this one).
    const ago = (turn.now ?? turn.server_now) - (turn.speech_start ?? turn.server_now);
    this.t0 = performance.now() - ago * 1000;
    this.audio = null;
    if (turn.speech.audio) {
      this.audio = new Audio(turn.speech.audio);
      const start = () => this.audio?.play().catch(() => { this.audio = null; }); // autoplay refused: keep the timer
      if (ago < 0) this.timer = setTimeout(start, -ago * 1000);
      else start();
    }
    this.end = Math.max(turn.speech.duration_s, ...turn.cues.map(lightAt)) + 0.3;
    requestAnimationFrame(() => this.tick());
  }

  time() {
    if (this.audio && !this.audio.paused && this.audio.currentTime > 0) return this.audio.currentTime;
    return (performance.now() - this.t0) / 1000;
  }

  tick() {
    if (this.done) return;
    const t = this.time();
    for (const cue of this.turn.cues) {
      if (cue.release_s !== null && lightAt(cue) <= t) {
        this.bubble.querySelectorAll(`[data-k="${cue.k}"]:not(.refused)`).forEach((n) => n.classList.add("fired"));
      }
    }
    const bar = this.bubble.querySelector(".speechbar > div");
    bar.style.width = `${Math.max(0, Math.min(100, (100 * t) / Math.max(this.end, 0.01)))}%`;
    if (t >= this.end) { this.done = true; return; }
    requestAnimationFrame(() => this.tick());
  }

  cancel() {
    if (this.done) return;
    this.done = true;
    clearTimeout(this.timer);
    if (this.audio) this.audio.pause();
    this.bubble.querySelectorAll(".cue:not(.fired):not(.refused)").forEach((n) => n.classList.add("cancelled"));
  }
}

// History turns (sent when the page connects) are shown already played.
export function showPlayed(bubble) {
  bubble.querySelectorAll("[data-k]:not(.refused)").forEach((n) => n.classList.add("fired"));
  bubble.querySelector(".speechbar > div").style.width = "100%";
}
