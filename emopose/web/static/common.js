// Shared by the chat page and Pose Studio: HTTP calls, the WebSocket, badges, the stick figure.

export const CLASS_COLORS = {
  pointing: "#2f6fed", emphasizing: "#c2410c", rejecting: "#d64545", agreeing: "#1f9d55",
  doubting: "#7c3aed", welcoming: "#0891b2", comforting: "#db2777", neutral: "#64748b",
};

// The server turned a ?token= into an HttpOnly cookie; drop it from the address bar.
if (new URLSearchParams(location.search).has("token")) history.replaceState(null, "", location.pathname);

export async function api(path, body) {
  const options = body === undefined ? {} : {
    method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body),
  };
  const response = await fetch(path, { credentials: "same-origin", ...options });
  let data;
  try { data = await response.json(); } catch { data = { error: `HTTP ${response.status}` }; }
  if (!response.ok) {
    const error = new Error(data.error || `HTTP ${response.status}`);
    error.status = response.status;
    throw error;
  }
  return data;
}

export function el(tag, props = {}, ...children) {
  const node = document.createElement(tag);
  for (const [key, value] of Object.entries(props)) {
    if (key === "class") node.className = value;
    else if (key === "style") node.style.cssText = value;
    else if (key.startsWith("on")) node.addEventListener(key.slice(2), value);
    else if (key === "text") node.textContent = value;
    else node.setAttribute(key, value);
  }
  for (const child of children.flat()) {
    if (child !== null && child !== undefined) node.append(child instanceof Node ? child : String(child));
  }
  return node;
}

// Server clock (session seconds) -> this page's wall clock; the offset is learnt from the live state, and
// times shown before it is known are filled in then.
let clockOffset = null;

function fillTime(node) {
  if (clockOffset === null) return;
  const at = new Date((Number(node.dataset.t) + clockOffset) * 1000);
  node.textContent = at.toLocaleTimeString([], { hour12: false });
}

export function syncClock(serverNow) {
  clockOffset = Date.now() / 1000 - serverNow;
  document.querySelectorAll("time[data-t]:empty").forEach(fillTime);
}

export function clockTime(serverTime) {
  const node = el("time", { "data-t": serverTime });
  fillTime(node);
  return node;
}

// One WebSocket with automatic reconnection; binary messages are frames: 1 tag byte + JPEG.
export function connect({ message, frame, status }) {
  let socket = null;
  const open = () => {
    const scheme = location.protocol === "https:" ? "wss" : "ws";
    socket = new WebSocket(`${scheme}://${location.host}/ws`);
    socket.binaryType = "arraybuffer";
    socket.onopen = () => status && status(true);
    socket.onclose = () => { status && status(false); setTimeout(open, 1000); };
    socket.onmessage = (event) => {
      if (typeof event.data === "string") { message(JSON.parse(event.data)); return; }
      const bytes = new Uint8Array(event.data);
      frame && frame(String.fromCharCode(bytes[0]), new Blob([bytes.subarray(1)], { type: "image/jpeg" }));
    };
  };
  open();
  // true when the message went out: a closed socket sends nothing, and the caller says so
  return {
    send: (msg) => {
      if (!socket || socket.readyState !== WebSocket.OPEN) return false;
      socket.send(JSON.stringify(msg));
      return true;
    },
    sendBytes: (buffer) => { // the microphone's PCM frames (mic.js)
      if (!socket || socket.readyState !== WebSocket.OPEN) return false;
      socket.send(buffer);
      return true;
    },
  };
}

export function fillBadges(container, info) {
  container.replaceChildren(
    el("span", { class: "badge" }, "backend ", el("b", { text: info.backend })),
    el("span", { class: "badge" }, "planner ", el("b", { text: info.planner })),
    el("span", { class: "badge" }, "tts ", el("b", { text: info.tts })),
    el("span", { class: "badge", id: "library-badge" }, "library v", el("b", { text: String(info.library_version) })),
  );
}

// Two views of the arms in metres (torso frame): front (viewer faces the robot) and side.
export function drawStick(canvas, stick, { background = "#0f1420" } = {}) {
  const ratio = window.devicePixelRatio || 1;
  const width = canvas.clientWidth || 400, height = canvas.clientHeight || 300;
  if (canvas.width !== Math.round(width * ratio)) { canvas.width = Math.round(width * ratio); canvas.height = Math.round(height * ratio); }
  const g = canvas.getContext("2d");
  g.setTransform(ratio, 0, 0, ratio, 0, 0);
  g.fillStyle = background; g.fillRect(0, 0, width, height);
  if (!stick) return;
  const half = width / 2, scale = Math.min(half / 1.25, height / 1.25);
  ["front", "side"].forEach((view, i) => {
    const cx = half * i + half / 2, cy = height * 0.42;
    const P = ([h, v]) => [cx + h * scale, cy - (v - 0.2) * scale];
    const figure = stick[view];
    g.lineCap = "round"; g.lineJoin = "round";
    g.strokeStyle = "#3a4560"; g.lineWidth = 2 * figure.torso_r * scale;
    g.beginPath(); g.moveTo(...P(figure.torso[0])); g.lineTo(...P(figure.torso[1])); g.stroke();
    const [hh, hv, hr] = figure.head;
    g.fillStyle = "#3a4560"; g.beginPath(); g.arc(...P([hh, hv]), hr * scale, 0, 2 * Math.PI); g.fill();
    figure.arms.forEach((arm, side) => {
      g.strokeStyle = side === 0 ? "#5aa9ff" : "#ffb347"; g.lineWidth = Math.max(3, 0.035 * scale);
      g.beginPath(); arm.forEach((p, k) => (k ? g.lineTo(...P(p)) : g.moveTo(...P(p)))); g.stroke();
      g.fillStyle = "#e8eefc";
      arm.slice(1, 4).forEach((p) => { g.beginPath(); g.arc(...P(p), 3, 0, 2 * Math.PI); g.fill(); });
    });
    g.fillStyle = "#8c98b3"; g.font = "11px system-ui, sans-serif";
    g.fillText(view === "front" ? "front (robot's left in blue)" : "side (facing right)", half * i + 8, 16);
  });
}

// A cue's intensity as played; a softened gesture (it did not fit at the one asked) says so.
export function intensityWords(cue) {
  const asked = cue.requested_intensity;
  return asked !== cue.intensity ? `i${cue.intensity}, softened from i${asked}` : `i${cue.intensity}`;
}
