// Pose Studio: author a library motion, see the trajectory the robot would run and its checks,
// preview it in MuJoCo, perform the draft on the robot, and save it into the live library.
import { api, drawStick, el, fillBadges } from "./common.js";
import { drawCurves } from "./studio_plot.js";

const $ = (id) => document.getElementById(id);
const MIRROR = [1, -1, -1, 1, -1, 1, -1]; // q_right = MIRROR * q_left (emopose/robot/kinematics.py)
const NAME_RE = /^[a-z][a-z0-9_]{1,63}$/;
const S = { library: null, keyframes: [], stroke: null, selected: 0, report: null, frames: null, t: 0, playing: false };
let checkTimer = null, checkSeq = 0;

const round = (v) => Math.round(v * 1000) / 1000;
const neutral = () => [...S.library.neutral_pose];

async function loadLibrary(keep) {
  S.library = await api("/api/library");
  const open = $("open-name");
  open.replaceChildren(...S.library.classes.map((cls) => el("optgroup", { label: cls },
    S.library.entries.filter((e) => e.class === cls).map((e) => el("option", { value: e.name, text: `${e.name} (${e.keyframes})` })))));
  if (keep) open.value = keep;
  document.querySelector("#library-badge b")?.replaceChildren(String(S.library.version));
}

function setMotion(entry) {
  $("name").value = entry.name; $("class").value = entry.class; $("description").value = entry.description;
  $("motion-type").value = entry.motion_type;
  $("explicit").checked = entry.duration !== null && entry.duration !== undefined;
  $("duration").value = entry.duration ?? 2.0;
  S.keyframes = entry.keyframes.map((k) => [...k]);
  S.stroke = entry.stroke ? [...entry.stroke] : null;
  S.selected = Math.min(1, S.keyframes.length - 1);
  S.frames = null; showPreviewFrames();
  refresh();
  setTimeout(renderPreview, 200); // one MuJoCo preview per opened motion; edits re-render on request
}

function newMotion() {
  const up = neutral(); up[7] = -0.9; up[8] = -0.5; up[10] = 0.2; // right arm raised forward-out: clean at every intensity
  setMotion({ name: "", class: "welcoming", description: "", motion_type: "sequence", duration: null,
              keyframes: [neutral(), up, neutral()], stroke: [1, 1] });
}

function draft() {
  return { keyframes: S.keyframes, motion_type: $("motion-type").value, intensity: Number($("intensity").value),
           duration: $("explicit").checked ? Number($("duration").value) : null, stroke: S.stroke };
}

// Sync points: the stroke is a span of interior keyframes; an edit that breaks it falls back to auto.
function fixStroke() {
  const K = S.keyframes.length, pose = $("motion-type").value === "pose";
  if (pose) S.stroke = null;
  else if (S.stroke && !(1 <= S.stroke[0] && S.stroke[0] <= S.stroke[1] && S.stroke[1] <= K - 2)) S.stroke = null;
}

function refresh() {
  fixStroke();
  renderKeyframes(); renderSliders(); renderNameHint();
  $("duration").disabled = !$("explicit").checked;
  clearTimeout(checkTimer);
  checkTimer = setTimeout(check, 150); // debounce slider drags
}

function renderKeyframes() {
  const list = $("keyframes");
  list.replaceChildren(...S.keyframes.map((kf, k) => el("li", { class: k === S.selected ? "selected" : "", onclick: () => { S.selected = k; refresh(); } },
    el("span", { class: "k", text: `K${k}` }),
    el("span", { class: "sum", text: kf.map((v) => v.toFixed(2)).join(" ") }),
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
    const set = (v) => { q[j] = round(Math.min(upper[j], Math.max(lower[j], Number(v)))); range.value = q[j]; number.value = q[j]; refreshLight(); };
    range.addEventListener("input", () => set(range.value));
    number.addEventListener("change", () => set(number.value));
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

function renderChecks(r) {
  const K = S.keyframes.length;
  $("duration-rule").textContent = `default rule d = clip(0.3·(K−1), 1, 5) = clip(0.3·${K - 1}, 1, 5) = ${r.default_duration.toFixed(2)} s`
    + (r.explicit_duration ? ` · overridden: ${r.duration.toFixed(2)} s` : " · used");
  $("traj-meta").textContent = `${r.samples.length} samples · ${((r.samples.length - 1) * r.dt).toFixed(2)} s · intensity ${r.intensity}`;
  $("check-limits").replaceChildren(r.keyframe_violations.length
    ? el("span", { class: "pill bad", text: `outside: ${r.keyframe_violations.join(", ")}` }) : el("span", { class: "pill ok", text: "within limits" }));
  $("check-levels").replaceChildren(...r.levels.map((c) => el("span", { class: `pill ${c.ok ? "ok" : "bad"}`,
    title: c.reason || "", text: `i${c.intensity} ${c.ok ? "✓" : "✗"} ${(c.min_clearance_m * 100).toFixed(1)} cm` })));
  $("check-speed").replaceChildren(r.stretch > 1.001
    ? el("span", { class: "pill warn", text: `slowed ×${r.stretch.toFixed(2)} to respect joint speed limits` }) : el("span", { class: "pill ok", text: "within speed limits" }));
  $("check-notes").replaceChildren(...r.problems.map((p) => el("li", { class: "bad", style: "color:var(--bad)", text: p })),
    ...r.warnings.map((w) => el("li", { class: "warn", text: `warning: ${w}` })),
    el("li", { class: "muted small", text: `checked: ${r.checked} (${r.check_ms.toFixed(0)} ms)` }));
  $("verdict").replaceChildren(el("span", { class: `pill ${r.can_save ? "ok" : "bad"}`, text: r.can_save ? "ready to save" : "cannot save" }));
  updateSaveButton();
}

function drawAll() {
  const r = S.report;
  if (!r) return;
  drawCurves($("curves"), r, S.library.limits, S.selected, S.t);
  const stick = r.stick[Math.min(r.stick.length - 1, Math.round(S.t / r.stick_dt))];
  drawStick($("preview-stick"), stick);
  const span = (r.samples.length - 1) * r.dt;
  $("scrub").value = String(Math.round((1000 * S.t) / Math.max(span, 1e-6)));
  if (S.frames && S.frames.frames.length) {
    let best = 0;
    S.frames.times.forEach((t, i) => { if (Math.abs(t - S.t) < Math.abs(S.frames.times[best] - S.t)) best = i; });
    $("preview-img").src = S.frames.frames[best];
  }
}

function play() {
  const r = S.report;
  if (!r) return;
  const span = (r.samples.length - 1) * r.dt, start = performance.now() - S.t * 1000;
  S.playing = true;
  const step = () => {
    if (!S.playing || S.report !== r) { S.playing = false; return; }
    S.t = Math.min(span, (performance.now() - start) / 1000);
    drawAll();
    if (S.t < span) requestAnimationFrame(step); else S.playing = false;
  };
  requestAnimationFrame(step);
}

function showPreviewFrames() {
  const has = S.frames && S.frames.frames.length;
  $("preview-img").classList.toggle("hidden", !has);
  $("preview-caption").textContent = !S.frames ? "not rendered yet"
    : has ? `MuJoCo '${S.frames.camera}' · ${S.frames.frames.length} frames` : `stick figure only: ${S.frames.reason}`;
}

async function renderPreview() {
  $("render").disabled = true; $("preview-caption").textContent = "rendering…";
  try {
    const request = { ...draft(), camera: $("camera").value };
    S.frames = { ...(await api("/api/studio/preview", request)), key: JSON.stringify(draft()) };
    showPreviewFrames(); S.t = 0; play();
  } catch (error) { $("preview-caption").textContent = error.message; }
  $("render").disabled = false;
}

async function save() {
  const out = $("save-result");
  try {
    const saved = await api("/api/library", { name: $("name").value, class: $("class").value, description: $("description").value,
      motion_type: $("motion-type").value, duration: draft().duration, stroke: S.stroke, keyframes: S.keyframes, overwrite: $("overwrite").checked });
    out.className = "ok";
    out.textContent = `saved ${saved.name} → ${saved.file}` + (saved.backup ? ` (backup ${saved.backup})` : "") + ` · library v${saved.version}: the planner and resolver see it now`;
    await loadLibrary(saved.name); renderNameHint();
  } catch (error) { out.className = "bad"; out.textContent = error.message; }
}

// Runs the keyframes on screen (saved or not) through the same checks as any gesture; the library is unchanged.
async function perform() {
  const out = $("perform-result");
  try {
    const turn = await api("/api/studio/perform", { ...draft(), class: $("class").value });
    out.className = "ok";
    out.textContent = `performing the draft on screen at intensity ${turn.cues[0].intensity}`
      + ` (as ${turn.cues[0].resolved}; the library is unchanged)`;
  } catch (error) { out.className = "bad"; out.textContent = error.message; }
}

function edit(fn) { fn(); refresh(); }
const kf = () => S.keyframes[S.selected];
$("kf-add").onclick = () => edit(() => { S.keyframes.splice(S.selected + 1, 0, [...kf()]); S.selected += 1; });
$("kf-remove").onclick = () => edit(() => { S.keyframes.splice(S.selected, 1); S.selected = Math.max(0, S.selected - 1); });
const swap = (d) => edit(() => { const k = S.selected; [S.keyframes[k], S.keyframes[k + d]] = [S.keyframes[k + d], S.keyframes[k]]; S.selected = k + d; });
$("kf-up").onclick = () => swap(-1); $("kf-down").onclick = () => swap(1);
$("kf-neutral").onclick = () => edit(() => { S.keyframes[S.selected] = neutral(); });
$("mirror-lr").onclick = () => edit(() => { const q = kf(); for (let j = 0; j < 7; j++) q[7 + j] = round(MIRROR[j] * q[j]); });
$("mirror-rl").onclick = () => edit(() => { const q = kf(); for (let j = 0; j < 7; j++) q[j] = round(MIRROR[j] * q[7 + j]); });
$("motion-type").onchange = () => edit(() => {
  if ($("motion-type").value === "pose") { S.keyframes = [kf()]; S.selected = 0; }
  else if (S.keyframes.length < 3) { S.keyframes = [neutral(), kf(), neutral()]; S.selected = 1; }
});
for (const id of ["explicit", "duration", "intensity"]) $(id).onchange = refresh;
const interior = () => Math.min(Math.max(S.selected, 1), S.keyframes.length - 2);
$("stroke-start").onclick = () => edit(() => { const k = interior(); S.stroke = [k, Math.max(k, strokeSpan()?.[1] ?? k)]; });
$("stroke-end").onclick = () => edit(() => { const k = interior(); S.stroke = [Math.min(k, strokeSpan()?.[0] ?? k), k]; });
$("stroke-auto").onclick = () => edit(() => { S.stroke = null; });
$("name").oninput = renderNameHint;
$("overwrite").onchange = updateSaveButton;
$("description").oninput = updateSaveButton;
$("open").onclick = async () => setMotion(await api(`/api/library/${encodeURIComponent($("open-name").value)}`));
$("new").onclick = newMotion;
$("render").onclick = renderPreview;
$("play").onclick = () => { S.t = 0; S.playing = false; requestAnimationFrame(play); };
$("scrub").oninput = () => { S.playing = false; const r = S.report; if (r) { S.t = (Number($("scrub").value) / 1000) * (r.samples.length - 1) * r.dt; drawAll(); } };
$("save").onclick = save;
$("perform").onclick = perform;
window.addEventListener("resize", drawAll);

(async () => {
  fillBadges($("badges"), await api("/api/info"));
  await loadLibrary();
  $("class").replaceChildren(...S.library.classes.map((c) => el("option", { value: c, text: c })));
  newMotion();
})();
