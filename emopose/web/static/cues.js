// One robot reply in the history: the text with each gesture's trigger marked, the cue list, and the
// live highlighting that lights a trigger up when its stroke lands (or at its release time in the
// paper's modes), relative to speech start. A cue the
// sequencer did not perform (rejected, dropped) is marked with the reason and never lights up.
import { CLASS_COLORS, clockTime, el, intensityWords } from "./common.js";

// The server's character offsets count code points (Python strings); JavaScript strings index UTF-16
// units, in which an emoji counts twice. Slicing the code-point array keeps the marks on their words.
function replyNode(reply, cues) {
  const chars = Array.from(reply), text = (a, b) => chars.slice(a, b).join("");
  const spans = cues.filter((c) => c.char_start !== null).sort((a, b) => a.char_start - b.char_start);
  const node = el("div", { class: "reply" });
  let at = 0;
  for (const cue of spans) {
    if (cue.char_start < at) continue; // overlapping triggers: the first one keeps the mark
    node.append(text(at, cue.char_start));
    node.append(el("mark", { "data-k": cue.k, style: `--cue:${CLASS_COLORS[cue.class]}`,
      text: text(cue.char_start, cue.char_end) }));
    at = cue.char_end;
  }
  node.append(text(at));
  return node;
}

function cueNode(cue) {
  const rule = cue.rule === "exact" ? "exact" : cue.rule.replace("_", " ");
  const asked = cue.requested && cue.requested !== cue.resolved ? ` (asked ${cue.requested})` : "";
  return el("div", { class: "cue", "data-k": cue.k, style: `--cue:${CLASS_COLORS[cue.resolved_class] || "#888"}` },
    el("span", { class: "muted", text: cue.class }), "→",
    el("span", { class: "name", text: cue.resolved }),
    el("span", { class: "muted", text: `${rule}${asked} · ${intensityWords(cue)}` }),
    cue.trigger ? el("span", { class: "trigger", text: `“${cue.trigger}”` }) : null,
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

// Where a turn's gestures came from, in the server's words (hello.sources: each plan source for a visitor).
const ORIGIN = { gesture: "named gesture", draft: "Pose Studio draft" };
let sourceWords = {};
export function setSourceWords(words) { sourceWords = words || {}; }
const origin = (turn) => ORIGIN[turn.kind] ?? sourceWords[turn.source] ?? turn.source;

// Whether the dialogue so far reached the planner (history_messages) and, when it says, whether it read it.
function contextWords(turn) {
  const n = turn.history_messages;
  if (turn.kind !== "say" || n === undefined) return null;
  if (!n) return "no earlier messages";
  const messages = `${n} earlier message${n > 1 ? "s" : ""}`;
  if (turn.history_used === false) return `${messages} set aside (unrelated)`;
  return turn.history_used ? `read with ${messages}` : `${messages} given to the planner`;
}

// The planner call failed for good: a banner with the cause (the server's planner_failed message, when it
// comes, puts its own words there: showFailure).
function failureBanner(turn) {
  return el("div", { class: "call-failed", role: "alert" }, el("b", { text: "Planner call failed: " }),
    el("span", { text: turn.planner_error || "no cause given" }));
}

export function showFailure(bubble, banner) {
  bubble.querySelector(".call-failed")?.replaceChildren(el("b", { text: "Planner call failed. " }), banner);
}

export function turnBubble(turn) {
  const bar = el("div", { class: "speechbar" }, el("div"));
  const failed = turn.source === "call_failed";
  const meta = [origin(turn), contextWords(turn), `speech ${turn.speech.duration_s.toFixed(1)} s`,
    `planner ${(turn.planner_latency_s * 1000).toFixed(0)} ms`, `library v${turn.library_version}`, ""]
    .filter((part) => part !== null).join(" · ");
  const bubble = el("div", { class: `bubble robot${failed ? " failed" : ""}`, "data-turn": turn.turn_id },
    failed ? failureBanner(turn) : null,
    turn.narrated && !failed ? el("div", { class: "narrated", text: "narration: the robot says your text" }) : null,
    turn.reply ? replyNode(turn.reply, turn.cues) : null,
    el("div", { class: "cues" }, turn.cues.map(cueNode)), bar, el("div", { class: "meta" }, meta, clockTime(turn.server_now)));
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

  // Stopped before its end: `why` is shown on the bubble ("cut off by the next reply", "interrupted").
  cancel(why) {
    if (this.done) return;
    this.done = true;
    clearTimeout(this.timer);
    if (this.audio) this.audio.pause();
    this.bubble.querySelectorAll(".cue:not(.fired):not(.refused)").forEach((n) => n.classList.add("cancelled"));
    this.bubble.querySelector(".meta").before(el("div", { class: "cut-off", text: why }));
  }
}

// History turns (sent when the page connects) are shown already played.
export function showPlayed(bubble) {
  bubble.querySelectorAll("[data-k]:not(.refused)").forEach((n) => n.classList.add("fired"));
  bubble.querySelector(".speechbar > div").style.width = "100%";
}
