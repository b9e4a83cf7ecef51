// The chat page: dialogue history with timed cues, the composer, and the live robot panel.
import { api, connect, el, fillBadges } from "./common.js";
import { markOutcome, markStroke, ReplyPlayer, showPlayed, turnBubble } from "./cues.js";
import { RobotPanel } from "./robot.js";

const $ = (id) => document.getElementById(id);
const history = $("history");
const robot = new RobotPanel();
let players = [];
let pending = null;
let replyOpen = false; // a streamed reply arrives sentence by sentence: its turns play one after another
let libraryVersion = null;
let plannerName = "";

// Narration planners (keyword, local, llm mode=narrate) speak the user's text as the robot's line; the page
// says so once a turn shows it, and until then says who writes the reply.
function showMode(narrated) {
  $("mode-hint").textContent = narrated ? `narration: the robot says your text (planner ${plannerName})`
    : `planner ${plannerName} writes the reply; a narration planner says your text as it is`;
}

function showError(message) {
  const banner = $("error");
  banner.textContent = message;
  banner.classList.toggle("hidden", !message);
  if (message) setTimeout(() => banner.classList.add("hidden"), 6000);
}

function scrollDown() { history.scrollTop = history.scrollHeight; }

function userBubble(text, gesture = false) {
  return el("div", { class: `bubble user${gesture ? " gesture" : ""}`, text });
}

function addTurn(turn, live) {
  if (pending) { pending.remove(); pending = null; }
  if (turn.kind !== "say") history.append(userBubble(`▶ perform ${turn.cues[0]?.resolved ?? ""} (i${turn.cues[0]?.intensity ?? 3})`, true));
  else if (!history.lastElementChild?.matches(`.bubble.user[data-utterance]`)) history.append(userBubble(turn.utterance));
  history.querySelectorAll(".bubble.user[data-utterance]").forEach((n) => n.removeAttribute("data-utterance"));
  const bubble = turnBubble(turn);
  history.append(bubble);
  if (live) {
    if (!replyOpen) { players.forEach((p) => p.cancel()); players = []; } // a new reply cut the previous one
    players.push(new ReplyPlayer(bubble, turn)); // a later sentence starts at its own speech start
    replyOpen = turn.kind === "say";
  } else showPlayed(bubble);
  scrollDown();
}

function onMessage(msg) {
  switch (msg.type) {
    case "hello":
      fillBadges($("badges"), msg);
      libraryVersion = msg.library_version;
      robot.configure(msg);
      $("mic").classList.toggle("hidden", !msg.asr);
      $("attach-wrap").classList.toggle("hidden", !msg.channels.camera);
      history.replaceChildren();
      msg.log.filter((m) => m.type === "turn").forEach((t) => addTurn(t, false)); // outcomes are in the turns
      plannerName = msg.planner;
      showMode(msg.log.some((m) => m.type === "turn" && m.narrated));
      loadMotions();
      break;
    case "turn_started":
      replyOpen = false;
      history.append(userBubble(msg.utterance));
      history.lastElementChild.setAttribute("data-utterance", ""); // addTurn will not repeat it
      pending = el("div", { class: "bubble robot pending", text: "planning…" });
      history.append(pending);
      scrollDown();
      break;
    case "turn": addTurn(msg, true); if (msg.narrated) showMode(true); break;
    case "interrupted": players.forEach((p) => p.cancel()); break;
    case "cue_outcome": {
      const bubble = history.querySelector(`.bubble.robot[data-turn="${msg.turn_id}"]`);
      if (bubble) markOutcome(bubble, msg.k, msg.outcome);
      break;
    }
    case "cue_stroke": {
      const bubble = history.querySelector(`.bubble.robot[data-turn="${msg.turn_id}"]`);
      if (bubble) markStroke(bubble, msg.k, msg.executed_s);
      break;
    }
    case "library_saved": loadMotions(msg.name); break;
    case "state":
      robot.update(msg);
      if (msg.library_version !== libraryVersion) { libraryVersion = msg.library_version; loadMotions(); }
      break;
    case "error": showError(msg.message); if (pending) { pending.remove(); pending = null; } break;
  }
}

async function loadMotions(select) {
  const library = await api("/api/library");
  const picker = $("gesture-name");
  const current = select || picker.value;
  picker.replaceChildren(...library.classes.map((cls) => el("optgroup", { label: cls },
    library.entries.filter((e) => e.class === cls).map((e) => el("option", { value: e.name, text: e.name })))));
  if (current && library.entries.some((e) => e.name === current)) picker.value = current;
  document.querySelector("#library-badge b")?.replaceChildren(String(library.version));
}

const socket = connect({
  message: onMessage,
  frame: (tag, blob) => robot.frame(tag, blob),
  status: (up) => { $("connection").textContent = up ? "live" : "reconnecting…"; },
});

$("say-form").addEventListener("submit", (event) => {
  event.preventDefault();
  const text = $("say-text").value.trim();
  if (!text) return;
  socket.send({ type: "say", text, attach_camera: $("attach").checked });
  $("say-text").value = "";
});
$("gesture-go").addEventListener("click", () => {
  socket.send({ type: "gesture", name: $("gesture-name").value, intensity: Number($("gesture-intensity").value) });
});
$("interrupt").addEventListener("click", () => socket.send({ type: "interrupt" }));

// Microphone (only shown when the server has an ASR): record while held, send on release. getUserMedia
// resolves only after the permission prompt, so a release that comes first stops the take as it starts
// (otherwise a quick tap would leave the microphone recording).
let recorder = null;
let held = false;

async function startRecording() {
  held = true;
  try {
    const stream = await navigator.mediaDevices.getUserMedia({ audio: true });
    const chunks = [];
    const take = new MediaRecorder(stream);
    take.ondataavailable = (e) => chunks.push(e.data);
    take.onstop = () => {
      stream.getTracks().forEach((t) => t.stop());
      sendRecording(new Blob(chunks, { type: take.mimeType.split(";")[0] }));
    };
    take.start();
    recorder = take;
    $("mic").classList.add("recording");
    if (!held) stopRecording();
  } catch (error) { showError(`microphone: ${error.message}`); }
}

function stopRecording() {
  held = false;
  if (recorder && recorder.state === "recording") recorder.stop();
  recorder = null;
  $("mic").classList.remove("recording");
}

// The transcript comes back as an ordinary turn through the WebSocket; only a failure is answered here.
async function sendRecording(blob) {
  const response = await fetch("/api/utterance/audio",
    { method: "POST", body: blob, headers: { "Content-Type": blob.type } });
  if (!response.ok) {
    const answer = await response.json().catch(() => ({}));
    showError(answer.error || `microphone: HTTP ${response.status}`);
  }
}

$("mic").addEventListener("pointerdown", startRecording);
$("mic").addEventListener("pointerup", stopRecording);
$("mic").addEventListener("pointercancel", stopRecording);
