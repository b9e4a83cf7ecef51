// Pose Studio: author a library motion, see the trajectory the robot would run and its checks,
// preview it in MuJoCo, perform the draft on the robot, and save it into the live library.
import { api, el, fillBadges } from "./common.js";
import { DraftHistory, wireUndo } from "./studio_history.js";
import { keyframeTimes, renderTiming, round, wireKeyframes, wireTimeDrag } from "./studio_keyframes.js";
import { wireLibraryActions } from "./studio_library.js";
import { preview } from "./studio_preview.js";

const $ = (id) => document.getElementById(id);
const NAME_RE = /^[a-z][a-z0-9_]{1,63}$/;
const S = { library: null, keyframes: [], stroke: null, times: null, clipboard: null, selected: 0, report: null,
  frames: null, t: 0, playing: false };
let checkTimer = null, checkSeq = 0;
const edits = new DraftHistory();
const DRAFT = "__draft__"; // the Motion menu's entry for the draft on screen
const { renderChecks, drawAll, play, showPreviewFrames, renderPreview } = preview(S, draft, () => updateSaveButton());

const neutral = () => [...S.library.neutral_pose];

async function loadLibrary(keep) {
  S.library = await api("/api/library");
  const open = $("open-name");
  open.replaceChildren(el("option", { value: DRAFT, id: "draft-option" }),
    ...S.library.classes.map((cls) => el("optgroup", { label: cls },
      S.library.entries.filter((e) => e.class === cls).map((e) => el("option", { value: e.name, text: `${e.name} (${e.keyframes})` })))));
  if (keep) S.opened = keep;
  showDraftInMenu();
  document.querySelector("#library-badge b")?.replaceChildren(String(S.library.version));
}

// What the page edits: everything a save writes. Undo/redo and "unsaved changes" compare these.
function snapshot() {
  return { name: $("name").value, class: $("class").value, description: $("description").value,
    motion_type: $("motion-type").value, explicit: $("explicit").checked, duration: $("duration").value,
    keyframes: S.keyframes, stroke: S.stroke, times: S.times };
}

function restore(state) {
  $("name").value = state.name; $("class").value = state.class; $("description").value = state.description;
  $("motion-type").value = state.motion_type; $("explicit").checked = state.explicit;
  $("duration").value = state.duration;
  S.keyframes = state.keyframes; S.stroke = state.stroke; S.times = state.times;
  S.selected = Math.min(S.selected, S.keyframes.length - 1);
  refresh();
}

const unsaved = () => edits.dirty(snapshot());

// The Motion menu shows what is on screen: the opened motion while unchanged, else the draft entry.
function showDraftInMenu() {
  const option = $("draft-option"), open = $("open-name");
  if (!option) return;
  const name = $("name").value || "new motion";
  option.textContent = `✎ editing: ${name}${unsaved() ? " (unsaved changes)" : ""}`;
  open.value = S.opened && !unsaved() && S.library.entries.some((e) => e.name === S.opened) ? S.opened : DRAFT;
  $("undo").disabled = !edits.canUndo; $("redo").disabled = !edits.canRedo;
  $("rename").disabled = $("delete").disabled = !S.opened;
}

// After each committed edit: a step for undo, and the menu's "unsaved" mark.
function committed() { edits.commit(snapshot()); showDraftInMenu(); }

function leaveDraft() { return !unsaved() || confirm("The draft on screen has unsaved changes. Discard them?"); }

function setMotion(entry, opened = null) {
  for (const id of ["save-result", "perform-result", "library-result", "joint-note"]) $(id).replaceChildren();
  S.opened = opened;
  $("name").value = entry.name; $("class").value = entry.class; $("description").value = entry.description;
  $("motion-type").value = entry.motion_type;
  $("explicit").checked = entry.duration !== null && entry.duration !== undefined;
  $("duration").value = entry.duration ?? entry.times?.at(-1) ?? 2.0;
  S.keyframes = entry.keyframes.map((k) => [...k]);
  S.times = entry.times ? [...entry.times] : null;
  S.stroke = entry.stroke ? [...entry.stroke] : null;
  S.selected = Math.min(1, S.keyframes.length - 1);
  S.frames = null; showPreviewFrames();
  refresh();
  edits.reset(snapshot()); showDraftInMenu();
  setTimeout(renderPreview, 200); // one MuJoCo preview per opened motion; edits re-render on request
}

function newMotion() {
  const up = neutral(); up[7] = -0.9; up[8] = -0.5; up[10] = 0.2; // right arm raised forward-out: clean at every intensity
  setMotion({ name: "", class: "welcoming", description: "", motion_type: "sequence", duration: null,
              keyframes: [neutral(), up, neutral()], stroke: [1, 1] });
}

function draft() {
  return { keyframes: S.keyframes, motion_type: $("motion-type").value, intensity: Number($("intensity").value),
           duration: $("explicit").checked && !S.times ? Number($("duration").value) : null, stroke: S.stroke,
           times: S.times };
}

// Sync points: the stroke is a span of interior keyframes; an edit that breaks it falls back to auto.
function fixStroke() {
  const K = S.keyframes.length, pose = $("motion-type").value === "pose";
  if (pose) S.stroke = null;
  else if (S.stroke && !(1 <= S.stroke[0] && S.stroke[0] <= S.stroke[1] && S.stroke[1] <= K - 2)) S.stroke = null;
}

function refresh() {
  fixStroke();
  renderKeyframes(); renderSliders(); renderNameHint(); renderTiming(S);
  clearTimeout(checkTimer);
  checkTimer = setTimeout(check, 150); // debounce slider drags
}

function renderKeyframes() {
  const list = $("keyframes");
  const arm = (kf, side) => `${side} ${kf.slice(side === "L" ? 0 : 7, side === "L" ? 7 : 14).map((v) => v.toFixed(2)).join(" ")}`;
  list.replaceChildren(...S.keyframes.map((kf, k) => el("li", { class: k === S.selected ? "selected" : "", onclick: () => { S.selected = k; refresh(); } },
    el("span", { class: "k", style: "width:auto;min-width:40px" }, el("div", { text: `K${k}` }),
      el("div", { class: "small muted", text: `${keyframeTimes(S)[k].toFixed(2)} s` })),
    el("span", { class: "sum" }, el("span", { text: arm(kf, "L") }), el("span", { text: arm(kf, "R") })),
    el("span", { class: "stroke-mark", text: strokeMark(k) }))));
  const pose = $("motion-type").value === "pose";
  $("kf-add").disabled = pose || S.keyframes.length >= 14;
  $("kf-remove").disabled = S.keyframes.length <= (pose ? 1 : 3);
  $("kf-up").disabled = S.selected === 0; $("kf-down").disabled = S.selected === S.keyframes.length - 1;
  $("kf-label").textContent = `keyframe K${S.selected}`;
}

function renderSliders() {
  const { names, lower, upper } = S.library.limits, q = S.keyframes[S.selected], box = $("sliders");
  box.replaceChildren();
  names.forEach((name, j) => {
    if (j % 7 === 0) box.append(el("div", { class: "group", text: j ? "Right arm" : "Left arm" }));
    const label = name.replace(/^(left|right)_/, "").replace(/_joint$/, "").replace("_", " ");
    const attrs = { min: lower[j], max: upper[j], step: 0.01, value: q[j], "aria-label": name };
    const range = el("input", { type: "range", ...attrs }), number = el("input", { type: "number", ...attrs });
    const set = (v) => { q[j] = round(Number(v)); range.value = q[j]; number.value = q[j]; refreshLight(); };
    range.addEventListener("input", () => set(range.value));
    range.addEventListener("change", committed);
    // A typed value outside the joint's limits is refused, and said so; never clamped silently.
    number.addEventListener("change", () => {
      const v = Number(number.value), ok = number.value !== "" && v >= lower[j] && v <= upper[j];
      number.classList.toggle("invalid", !ok);
      $("joint-note").className = ok ? "" : "bad";
      $("joint-note").textContent = ok ? "" : `${name}: ${number.value} rad is outside its limits `
        + `${lower[j]} .. ${upper[j]} rad; not applied (K${S.selected} keeps ${q[j]})`;
      if (ok) { set(v); committed(); } else number.value = q[j];
    });
    box.append(el("span", { title: `${name}: ${lower[j]} .. ${upper[j]} rad`, text: label }), range, number);
  });
}

function refreshLight() { // a slider moved: keep the DOM of the sliders, redo the rest
  renderKeyframes(); clearTimeout(checkTimer); checkTimer = setTimeout(check, 120);
}

const nameExists = () => S.library.entries.some((e) => e.name === $("name").value);

function updateSaveButton() {
  $("save").disabled = !(S.report && S.report.can_save && NAME_RE.test($("name").value) && $("description").value.trim().length >= 3
    && (!nameExists() || $("overwrite").checked));
}

function renderNameHint() {
  updateSaveButton();
  const name = $("name").value, exists = nameExists();
  $("overwrite-wrap").classList.toggle("hidden", !exists);
  $("name-hint").textContent = !name ? "name it to save: lower case letters, digits and _"
    : !NAME_RE.test(name) ? "⚠ names must match ^[a-z][a-z0-9_]{1,63}$"
    : exists ? "this name exists: tick “replace the existing motion” to save over it" : "new motion";
}

function strokeSpan() { return S.stroke || (S.report ? S.report.stroke : null); }

function strokeMark(k) {
  const span = strokeSpan();
  if (!span || $("motion-type").value === "pose") return "";
  return k === span[0] && k === span[1] ? "stroke" : k === span[0] ? "stroke ▸" : k === span[1] ? "◂ stroke" : "";
}

function renderStroke() {
  const pose = $("motion-type").value === "pose", span = strokeSpan();
  for (const id of ["stroke-start", "stroke-end", "stroke-auto"]) $(id).disabled = pose;
  $("stroke-label").textContent = pose ? "a pose is its own stroke"
    : span ? `K${span[0]}–K${span[1]}${S.stroke ? "" : " (auto: largest excursion)"}` : "";
}

async function check() {
  const seq = ++checkSeq;
  try {
    const report = await api("/api/studio/check", draft());
    if (seq !== checkSeq) return; // a newer edit is on its way
    S.report = report; S.t = 0;
    renderChecks(report); renderKeyframes(); renderStroke(); drawAll();
    if (S.frames && S.frames.key !== JSON.stringify(draft())) $("preview-caption").textContent = "edited since the render: Render in MuJoCo again";
    if (!S.playing) play();
  } catch (error) {
    $("verdict").replaceChildren(el("span", { class: "pill bad", text: "invalid" }));
    $("check-notes").replaceChildren(el("li", { text: error.message }));
  }
}

function edit(fn) { fn(); refresh(); committed(); }
const kf = () => S.keyframes[S.selected];
wireKeyframes({ S, edit, neutral });
wireTimeDrag({ S, refresh, committed, moved: () => { refreshLight(); renderTiming(S); drawAll(); } });
$("motion-type").onchange = () => edit(() => {
  S.times = null; // a pose has no keyframe times; a new sequence starts evenly spaced
  if ($("motion-type").value === "pose") { S.keyframes = [kf()]; S.selected = 0; }
  else if (S.keyframes.length < 3) { S.keyframes = [neutral(), kf(), neutral()]; S.selected = 1; }
});
for (const id of ["explicit", "duration", "motion-type", "class"]) $(id).addEventListener("change", committed);
for (const id of ["explicit", "duration", "intensity"]) $(id).addEventListener("change", refresh);
const interior = () => Math.min(Math.max(S.selected, 1), S.keyframes.length - 2);
$("stroke-start").onclick = () => edit(() => { const k = interior(); S.stroke = [k, Math.max(k, strokeSpan()?.[1] ?? k)]; });
$("stroke-end").onclick = () => edit(() => { const k = interior(); S.stroke = [Math.min(k, strokeSpan()?.[0] ?? k), k]; });
$("stroke-auto").onclick = () => edit(() => { S.stroke = null; });
$("name").oninput = () => { renderNameHint(); showDraftInMenu(); };
$("overwrite").onchange = updateSaveButton;
$("description").oninput = updateSaveButton;
for (const id of ["name", "description"]) $(id).addEventListener("change", committed);
$("open").onclick = async () => {
  const name = $("open-name").value;
  if (name === DRAFT || !leaveDraft()) return;
  setMotion(await api(`/api/library/${encodeURIComponent(name)}`), name);
};
$("new").onclick = () => leaveDraft() && newMotion();
wireUndo(edits, (state) => { if (state) restore(state); showDraftInMenu(); });
// Leaving (a link, reload, closing the tab) with unsaved changes: the browser asks first.
window.addEventListener("beforeunload", (e) => { if (unsaved()) e.preventDefault(); });
$("render").onclick = renderPreview;
$("play").onclick = () => { S.t = 0; S.playing = false; requestAnimationFrame(play); };
$("scrub").oninput = () => { S.playing = false; const r = S.report; if (r) { S.t = (Number($("scrub").value) / 1000) * (r.samples.length - 1) * r.dt; drawAll(); } };
wireLibraryActions({
  draft,
  motion: () => ({ name: $("name").value, class: $("class").value, description: $("description").value,
    motion_type: $("motion-type").value, duration: draft().duration, stroke: S.stroke, times: S.times, keyframes: S.keyframes }),
  opened: () => S.opened,
  after: async (name, saved) => {
    S.opened = name;
    if (saved) edits.saved(snapshot());
    await loadLibrary(name); renderNameHint();
  },
});
window.addEventListener("resize", drawAll);

(async () => {
  fillBadges($("badges"), await api("/api/info"));
  await loadLibrary();
  $("class").replaceChildren(...S.library.classes.map((c) => el("option", { value: c, text: c })));
  newMotion();
})();
