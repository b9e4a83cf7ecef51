// Pose Studio's right column: the checks before saving, the trajectory curves, the stick figure and the
// MuJoCo preview frames, played or scrubbed in time. `S` is the studio's state, `draft()` the request.
import { api, drawStick, el } from "./common.js";
import { drawCurves } from "./studio_plot.js";

const $ = (id) => document.getElementById(id);

export function preview(S, draft, updateSaveButton) {
  function renderChecks(r) {
    const K = S.keyframes.length;
    $("duration-rule").textContent = `default rule d = clip(0.3·(K−1), 1, 5) = clip(0.3·${K - 1}, 1, 5) = ${r.default_duration.toFixed(2)} s`
      + (r.times_declared ? ` · not used: the last keyframe's time is the duration, ${r.duration.toFixed(2)} s`
        : r.explicit_duration ? ` · overridden: ${r.duration.toFixed(2)} s` : " · used");
    $("traj-meta").textContent = `${r.samples.length} samples · ${((r.samples.length - 1) * r.dt).toFixed(2)} s · intensity ${r.intensity}`;
    $("check-limits").replaceChildren(r.keyframe_violations.length
      ? el("span", { class: "pill bad", text: `outside: ${r.keyframe_violations.join(", ")}` }) : el("span", { class: "pill ok", text: "within limits" }));
    $("check-levels").replaceChildren(...r.levels.map((c) => el("span", { class: `pill ${c.ok ? "ok" : "bad"}`,
      title: c.reason || "", text: `i${c.intensity} ${c.ok ? "✓" : "✗"} ${(c.min_clearance_m * 100).toFixed(1)} cm` })));
    const [speed, said] = r.timing_faults.length ? ["bad", "keyframe times too fast for the speed bound (below)"]
      : r.stretch > 1.001 ? ["warn", `slowed ×${r.stretch.toFixed(2)} to respect joint speed limits`]
      : ["ok", "within speed limits"];
    $("check-speed").replaceChildren(el("span", { class: `pill ${speed}`, text: said }));
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

  return { renderChecks, drawAll, play, showPreviewFrames, renderPreview };
}
