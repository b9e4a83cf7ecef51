// Pose Studio's curve plot: the 50 Hz trajectory of each joint (left arm | right arm, 7 rows),
// keyframe times as dashed lines (the selected one solid), the stroke span shaded, hard limits in red
// when in view.

const SHORT = ["shoulder pitch", "shoulder roll", "shoulder yaw", "elbow", "wrist roll", "wrist pitch", "wrist yaw"];
const PAD_LEFT = 8, GAP = 10; // px: left margin, and between the left- and right-arm columns

const cellWidth = (width) => (width - PAD_LEFT - GAP) / 2;
const span = (report) => Math.max((report.samples.length - 1) * report.dt, 1e-6);

// The time (s on the plotted run) under a pointer `x` px from the canvas' left edge, in either column;
// `slop`: how many seconds a few px are, to find a keyframe line under the pointer.
export function timeAtX(canvas, report, x) {
  const w = cellWidth(canvas.clientWidth), col = x < PAD_LEFT + w + GAP / 2 ? 0 : 1;
  const perPx = span(report) / w;
  return { t: (x - PAD_LEFT - col * (w + GAP)) * perPx, slop: 6 * perPx };
}

export function drawCurves(canvas, report, limits, selected, cursor = null) {
  const ratio = window.devicePixelRatio || 1;
  const width = canvas.clientWidth, height = canvas.clientHeight;
  canvas.width = Math.round(width * ratio); canvas.height = Math.round(height * ratio);
  const g = canvas.getContext("2d");
  g.setTransform(ratio, 0, 0, ratio, 0, 0);
  g.clearRect(0, 0, width, height);
  if (!report) return;
  const samples = report.samples, n = samples.length, seconds = span(report);
  const rows = 7, titleH = 14, cellW = cellWidth(width), cellH = height / rows;
  g.font = "11px system-ui, sans-serif";
  for (let j = 0; j < 14; j++) {
    const col = j < 7 ? 0 : 1, row = j % 7;
    const x0 = PAD_LEFT + col * (cellW + GAP), y0 = row * cellH + titleH, w = cellW, h = cellH - titleH - 6;
    const values = samples.map((s) => s[j]);
    let lo = Math.min(...values), hi = Math.max(...values);
    const mid = (lo + hi) / 2, half = Math.max((hi - lo) / 2 + 0.05, 0.15);
    lo = mid - half; hi = mid + half;
    const X = (t) => x0 + (t / seconds) * w, Y = (v) => y0 + h - ((v - lo) / (hi - lo)) * h;
    g.fillStyle = "#f7f9fc"; g.fillRect(x0, y0, w, h);
    g.fillStyle = "#6b7385";
    g.fillText(`${col ? "R" : "L"} ${SHORT[row]}  [${values[0].toFixed(2)} → ${values[n - 1].toFixed(2)}]`, x0, y0 - 3);
    g.strokeStyle = "#d64545"; g.setLineDash([2, 2]); g.lineWidth = 1;
    for (const limit of [limits.lower[j], limits.upper[j]]) {
      if (limit > lo && limit < hi) { g.beginPath(); g.moveTo(x0, Y(limit)); g.lineTo(x0 + w, Y(limit)); g.stroke(); }
    }
    if (report.stroke && report.keyframes.length > 1) { // the stroke span: what the timeline puts on the word
      const [a, b] = report.stroke.map((k) => X(report.keyframe_times[k]));
      g.fillStyle = "rgba(47, 111, 237, 0.12)"; g.fillRect(a - 2, y0, Math.max(b - a, 0) + 4, h);
    }
    report.keyframe_times.forEach((t, k) => {
      g.strokeStyle = k === selected ? "#2f6fed" : "#c5cddb";
      g.setLineDash(k === selected ? [] : [3, 3]);
      g.beginPath(); g.moveTo(X(t), y0); g.lineTo(X(t), y0 + h); g.stroke();
    });
    g.setLineDash([]);
    g.strokeStyle = col ? "#e08a1e" : "#2f6fed"; g.lineWidth = 1.6;
    g.beginPath();
    values.forEach((v, i) => (i ? g.lineTo(X(i * report.dt), Y(v)) : g.moveTo(X(0), Y(v))));
    g.stroke();
    g.fillStyle = "#1d2330";
    report.keyframes.forEach((kf, k) => {
      if (k === 0 && report.keyframes.length > 1) return; // the run starts from the current pose instead
      g.beginPath(); g.arc(X(report.keyframe_times[k]), Y(kf[j]), 2.5, 0, 2 * Math.PI); g.fill();
    });
    if (cursor !== null) {
      g.strokeStyle = "#1d2330"; g.lineWidth = 1;
      g.beginPath(); g.moveTo(X(cursor), y0); g.lineTo(X(cursor), y0 + h); g.stroke();
    }
  }
}
