// The chat page: dialogue history with timed cues, the composer, and the live robot panel.
import { api, connect, el, fillBadges } from "./common.js";
import { markOutcome, markStroke, ReplyPlayer, setSourceWords, showFailure, showPlayed, turnBubble } from "./cues.js";
import { cancelledNote, PlanningBubble } from "./planning.js";
import { ReportPanel } from "./report.js";
import { Microphone } from "./mic.js";
import { RobotPanel } from "./robot.js";

const $ = (id) => document.getElementById(id);
const history = $("history");
const robot = new RobotPanel();
let players = [];
let replyOpen = false; // a streamed reply arrives sentence by sentence: its turns play one after another
let libraryVersion = null;
let plannerName = "";

// Narration planners (keyword, local, llm mode=narrate) speak the user's text as the robot's line. The
// server says which kind it runs (hello.narrates); a server that does not say is not guessed for: the
// first turn shows it.
// A failed call narrates whatever the planner: only a said turn the planner answered tells its kind.
const tellsMode = (m) => m.type === "turn" && m.kind === "say" && m.source !== "call_failed";

function showMode(narrates) {
  $("mode-hint").textContent = narrates === true ? `narration: the robot says your text (planner ${plannerName})`
    : narrates === false ? `planner ${plannerName} writes the robot's reply to you`
    : `planner ${plannerName}: the first reply shows whether the robot answers or says your text`;
}

// The longest line the server takes (hello.limits.utterance_chars), enforced at the input with a count.
function setInputLimit(limit) {
  if (Number.isInteger(limit) && limit > 0) $("say-text").maxLength = limit;
  showCount();
}

function showCount() {
  const input = $("say-text"), used = Array.from(input.value).length;
  $("say-count").textContent = `${used} / ${input.maxLength}`;
  $("say-count").classList.toggle("late", used >= input.maxLength);
}

function clearPlanning() { planning.clear(); }

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
  clearPlanning();
  if (turn.kind !== "say") history.append(userBubble(`▶ perform ${turn.cues[0]?.resolved ?? ""} (i${turn.cues[0]?.requested_intensity ?? 3})`, true));
  else if (!history.lastElementChild?.matches(`.bubble.user[data-utterance]`)) history.append(userBubble(turn.utterance));
  history.querySelectorAll(".bubble.user[data-utterance]").forEach((n) => n.removeAttribute("data-utterance"));
  const bubble = turnBubble(turn);
  history.append(bubble);
  if (live) {
    if (!replyOpen) { players.forEach((p) => p.cancel("cut off by the next reply")); players = []; }
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
      setSourceWords(msg.sources);
      msg.log.forEach((m) => { // outcomes are in the turns
        if (m.type === "turn") addTurn(m, false);
        else if (m.type === "turn_cancelled") showCancelled(m);
      });
      msg.log.filter((m) => m.type === "planner_failed").forEach(onFailure);
      plannerName = msg.planner;
      showMode(msg.narrates ?? msg.log.filter(tellsMode).map((t) => t.narrated).pop());
      setInputLimit(msg.limits?.utterance_chars);
      loadMotions();
      break;
    case "turn_started":
      replyOpen = false;
      history.append(userBubble(msg.utterance));
      history.lastElementChild.setAttribute("data-utterance", ""); // addTurn will not repeat it
      microphone.heard();
      planning.show(msg);
      scrollDown();
      break;
    case "turn": addTurn(msg, true); if (tellsMode(msg)) showMode(msg.narrated); break;
    case "interrupted":
      players.forEach((p) => p.cancel("interrupted"));
      $("interrupt-note").textContent = "interrupted: the queue is cleared";
      break;
    case "planner_failed": onFailure(msg); break;
    case "turn_cancelled": clearPlanning(); showCancelled(msg); scrollDown(); break;
    case "cancel_refused": planning.refused(msg.message); break;
    case "reply_stopped":
      clearPlanning();
      if (msg.error) showError(`the reply stopped: ${msg.error}`);
      break;
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
      planning.update(msg.planning);
      microphone.serverVoice(msg.voice);
      if (msg.library_version !== libraryVersion) { libraryVersion = msg.library_version; loadMotions(); }
      break;
    case "error": showError(msg.message); clearPlanning(); microphone.serverError(msg.message); break;
  }
}

// the cancelled line's own bubble (sent just now, or replayed) stays; the note says nothing came of it
function showCancelled(msg) {
  const last = history.lastElementChild;
  if (!last?.matches(".bubble.user[data-utterance]")) history.append(userBubble(msg.utterance));
  history.querySelectorAll(".bubble.user[data-utterance]").forEach((n) => n.removeAttribute("data-utterance"));
  history.append(cancelledNote(msg));
}

function onFailure(msg) {
  const bubble = history.querySelector(`.bubble.robot[data-turn="${msg.turn_id}"]`);
  if (bubble) showFailure(bubble, msg.banner);
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
  status: showConnection,
});
const planning = new PlanningBubble(history, (msg) => socket.send(msg));
new ReportPanel($("report"));

// Disconnected: said at the top of the conversation, on the view, and on every action that cannot go out.
function showConnection(up) {
  $("connection").textContent = up ? "live" : "disconnected: reconnecting…";
  $("connection").classList.toggle("late", !up);
  $("offline").classList.toggle("hidden", up);
  robot.live(up);
  microphone.connection(up);
  if (up) $("interrupt-note").textContent = "";
}

const notSent = (what) => showError(`${what} not sent: the page is disconnected (reconnecting…)`);

$("say-form").addEventListener("submit", (event) => {
  event.preventDefault();
  const text = $("say-text").value.trim();
  if (!text) return;
  if (!socket.send({ type: "say", text, attach_camera: $("attach").checked })) { notSent("your line was"); return; }
  $("say-text").value = "";
  typing = false;  // the line is sent: the server plans it (the thinking posture)
  showCount();
});
$("say-text").addEventListener("input", showCount);
// While the visitor types the robot takes its listening posture; emptying the line gives it up.
let typing = false;
$("say-text").addEventListener("input", () => {
  const started = $("say-text").value.trim() !== "";
  if (started !== typing && socket.send({ type: "listening", active: started })) typing = started;
});
$("gesture-go").addEventListener("click", () => {
  const sent = socket.send({ type: "gesture", name: $("gesture-name").value,
    intensity: Number($("gesture-intensity").value) });
  if (!sent) notSent("the gesture was");
});
$("interrupt").addEventListener("click", () => {
  const sent = socket.send({ type: "interrupt" });
  $("interrupt-note").textContent = sent ? "interrupt sent…" : "not connected: the interrupt was not sent";
});

// The microphone (shown when the server has an ASR): streamed over this socket, mic.js.
const microphone = new Microphone($("mic"), $("mic-state"), (bytes) => socket.sendBytes(bytes));
