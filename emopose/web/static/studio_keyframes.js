// Pose Studio's keyframe edits: add, remove, reorder, neutral, mirror, copy/paste, and each keyframe's time.
// S.times: when each keyframe is reached (s from the start; K0 at 0, the last is the duration), or null
// for evenly spaced keyframes. A time belongs to its slot: moving a keyframe up or down swaps the poses,
// not the times. Copy/paste copies a whole keyframe (both arms); "paste mirrored" puts the copied left arm
// on the right and the right arm on the left with the mirror signs (the same gesture with the other hand).
import { el } from "./common.js";
import { timeAtX } from "./studio_plot.js";

const $ = (id) => document.getElementById(id);
const MIRROR = [1, -1, -1, 1, -1, 1, -1]; // q_right = MIRROR * q_left (emopose/robot/kinematics.py)
const MIN_GAP = 0.02; // one control tick: the closest two keyframe times may be (the library's rule)
const MAX_DURATION = 20; // s, the longest motion the library accepts
export const round = (v) => Math.round(v * 1000) / 1000;

const evenTimes = (count, span) =>
  Array.from({ length: count }, (_, k) => round(count > 1 ? (span * k) / (count - 1) : span));

// The duration the keyframes are spread over: the last keyframe's time, the explicit one, else the rule.
function duration(S) {
  if (S.times) return S.times.at(-1);
  return $("explicit").checked ? Number($("duration").value) : S.report?.default_duration ?? 1;
}

export const keyframeTimes = (S) => S.times ?? evenTimes(S.keyframes.length, duration(S));

// The whole keyframe mirrored: each arm takes the other's values with the mirror signs.
const mirrored = (q) => q.map((_, j) => round(MIRROR[j % 7] * q[(j + 7) % 14]));

// Where keyframe k's time may go: after its predecessor, before its successor (the last: the longest motion).
function timeRange(times, k) {
  const last = k === times.length - 1;
  return [round(times[k - 1] + MIN_GAP), last ? MAX_DURATION : round(times[k + 1] - MIN_GAP)];
}

// `page`: S (the studio's state), edit(fn) (apply, re-check, one undo step) and neutral() (the rest pose).
export function wireKeyframes(page) {
  const { S, edit } = page;
  const kf = () => S.keyframes[S.selected];
  const note = (bad, text) => {
    $("time-note").className = bad ? "bad" : ""; $("time-note").textContent = text;
  };
  $("kf-add").onclick = () => edit(() => {
    const k = S.selected;
    const t = S.times; // the new keyframe: halfway to the next, or one more step after the last
    if (t) t.splice(k + 1, 0, round(k + 1 < t.length ? (t[k] + t[k + 1]) / 2 : 2 * t[k] - t[k - 1]));
    S.keyframes.splice(k + 1, 0, [...kf()]); S.selected = k + 1;
  });
  $("kf-remove").onclick = () => edit(() => {
    S.keyframes.splice(S.selected, 1);
    if (S.times) { // removing K0 makes K1 the start, at 0 s
      S.times.splice(S.selected, 1);
      const t0 = S.times[0];
      S.times = S.times.map((t) => round(t - t0));
    }
    S.selected = Math.max(0, S.selected - 1);
  });
  const swap = (d) => edit(() => {
    const k = S.selected;
    [S.keyframes[k], S.keyframes[k + d]] = [S.keyframes[k + d], S.keyframes[k]]; S.selected = k + d;
  });
  $("kf-up").onclick = () => swap(-1); $("kf-down").onclick = () => swap(1);
  $("kf-neutral").onclick = () => edit(() => { S.keyframes[S.selected] = page.neutral(); });
  const copyArm = (from, to) => edit(() => {
    const q = kf();
    for (let j = 0; j < 7; j++) q[to + j] = round(MIRROR[j] * q[from + j]);
  });
  $("mirror-lr").onclick = () => copyArm(0, 7);
  $("mirror-rl").onclick = () => copyArm(7, 0);
  wireClipboard(page);
  // A typed time outside its neighbours is refused and said so, never clamped.
  $("kf-time").addEventListener("change", () => {
    const k = S.selected, v = Number($("kf-time").value);
    const times = [...keyframeTimes(S)], [low, high] = timeRange(times, k);
    if ($("kf-time").value === "" || !(v >= low && v <= high)) {
      note(true, `K${k} at ${$("kf-time").value} s: it must be ${low}..${high} s (after K${k - 1}`
        + `${k + 1 < times.length ? `, before K${k + 1}` : ""}); not applied`);
      $("kf-time").value = times[k];
      return;
    }
    note(false, "");
    edit(() => { times[k] = round(v); S.times = times; });
  });
  $("duration").addEventListener("change", () => { // with keyframe times, a new duration scales them all
    const d = Number($("duration").value), t = S.times;
    if (t && d >= MIN_GAP * (t.length - 1) && d <= MAX_DURATION) {
      S.times = t.map((x) => round((x * d) / t.at(-1)));
    }
  });
  $("times-even").onclick = () => edit(() => {
    $("explicit").checked = true; $("duration").value = duration(S); S.times = null;
  });
}

function wireClipboard(page) {
  const { S, edit } = page;
  const paste = (transform) => {
    if (!S.clipboard) return;
    const q = transform(S.clipboard.q), { limits } = S.library;
    const outside = q.flatMap((v, j) => (v < limits.lower[j] || v > limits.upper[j]
      ? [`${limits.names[j]} ${v} (limits ${limits.lower[j]} .. ${limits.upper[j]})`] : []));
    $("joint-note").className = outside.length ? "bad" : "";
    $("joint-note").textContent = outside.length
      ? `not pasted, outside the limits: ${outside.join("; ")}` : "";
    if (!outside.length) edit(() => { S.keyframes[S.selected] = q; });
  };
  const copy = () => {
    const from = `K${S.selected} of ${$("name").value || "the draft"}`;
    S.clipboard = { q: [...S.keyframes[S.selected]], from };
    $("kf-paste").disabled = $("kf-paste-mirrored").disabled = false;
    $("clipboard").replaceChildren(el("span", { text: `copied ${S.clipboard.from}` }));
  };
  $("kf-copy").onclick = copy;
  $("kf-paste").onclick = () => paste((q) => [...q]);
  $("kf-paste-mirrored").onclick = () => paste(mirrored);
  // Ctrl+C / Ctrl+V on the page (not inside a field, which keeps its own copy and paste).
  window.addEventListener("keydown", (e) => {
    if (!(e.ctrlKey || e.metaKey) || e.target.matches("input, textarea, select")) return;
    const key = e.key.toLowerCase();
    if (key === "c" && !String(window.getSelection())) { copy(); e.preventDefault(); }
    if (key === "v") { paste(e.shiftKey ? mirrored : (q) => [...q]); e.preventDefault(); }
  });
}

// The Timing card: the selected keyframe's time, and the duration (with keyframe times: the last one's).
export function renderTiming(S) {
  const times = keyframeTimes(S), pose = $("motion-type").value === "pose", k = S.selected;
  $("explicit").disabled = Boolean(S.times);
  if (S.times) { $("explicit").checked = true; $("duration").value = S.times.at(-1); }
  $("duration").disabled = !$("explicit").checked;
  $("kf-time").disabled = pose || k === 0;
  $("kf-time").value = pose ? "" : times[k];
  $("time-label").textContent = pose ? "a pose has no keyframe times" : `K${k} reached at`;
  $("times-even").disabled = !S.times;
  const byHand = "keyframe times set by hand (saved as times:); the checks, the curves and the preview "
    + "follow them, a reply's timeline still spaces them evenly over this duration";
  $("times-mode").textContent = pose ? "" : S.times ? byHand
    : "keyframes evenly spaced over the duration: type a time or drag a keyframe's line on the curves";
}

// Dragging a keyframe's line on the curves retimes it (K0 stays at 0); one undo step per drag.
// `page`: S, refresh(), committed() and moved() (redraw while dragging; the check follows).
export function wireTimeDrag(page) {
  const { S } = page, canvas = $("curves");
  let dragging = null; // { k, times } while the pointer is down on keyframe k's line
  const under = (e) => {
    const r = S.report;
    if (!r || $("motion-type").value === "pose") return null;
    const { t, slop } = timeAtX(canvas, r, e.offsetX);
    const near = r.keyframe_times.map((kt, k) => [Math.abs(kt - t), k])
      .filter(([d, k]) => k > 0 && k < S.keyframes.length && d <= slop); // (the report may lag an edit)
    return near.length ? near.sort((a, b) => a[0] - b[0])[0][1] : null;
  };
  canvas.addEventListener("pointerdown", (e) => {
    const k = under(e);
    if (k === null) return;
    dragging = { k, times: [...keyframeTimes(S)] };
    canvas.setPointerCapture(e.pointerId);
    S.selected = k; page.refresh();
  });
  canvas.addEventListener("pointermove", (e) => {
    if (!dragging) { canvas.style.cursor = under(e) === null ? "" : "ew-resize"; return; }
    const r = S.report, { k, times } = dragging, [low, high] = timeRange(times, k);
    times[k] = round(Math.min(high, Math.max(low, timeAtX(canvas, r, e.offsetX).t / r.stretch)));
    S.times = [...times];
    r.keyframe_times = S.times.map((t) => t * r.stretch); // the line follows the pointer before the check
    page.moved();
  });
  const drop = () => { if (dragging) { dragging = null; page.committed(); } };
  canvas.addEventListener("pointerup", drop);
  canvas.addEventListener("pointercancel", drop);
}
