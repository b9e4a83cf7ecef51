// The page's microphone, hands-free: a click starts it, another stops it. getUserMedia -> an AudioWorklet
// (mic_worklet.js: 16 kHz mono PCM16 in 32 ms frames) -> binary messages on the page's WebSocket. The
// server's VAD ends each utterance, which is transcribed and answered (emopose/web/voice_io.py); its state
// pushes say when it hears speech (state.voice), and the transcript arrives as the turn's line.
import { pcm16, TARGET_RATE } from "./mic_pcm.js";

// Sent when the visitor stops the microphone: longer than the server's hang time (asr.listening.hang_ms,
// 600 ms by default), so words said just before the click still end an utterance and are answered.
const SILENCE_ON_STOP_S = 1.0;
const TRANSCRIBING_SHOWN_S = 15; // an utterance that was only noise gives no line: stop saying "transcribing"
const STATES = {
  off: "", starting: "microphone: asking for permission…", listening: "microphone: listening…",
  speech: "microphone: heard speech…", transcribing: "microphone: heard speech, transcribing…",
};

export class Microphone {
  constructor(button, label, sendBytes) {
    Object.assign(this, { button, label, sendBytes });
    this.state = "off";
    this.capture = null;   // { stream, context } while the microphone is open
    this.wanted = false;   // a click while the permission prompt is open cancels the start
    this.utterances = null; // the server's count of ended utterances (state.voice), to see a new one
    button.addEventListener("click", () => (this.wanted ? this.stop() : this.start()));
  }

  async start() {
    this.wanted = true;
    if (!navigator.mediaDevices?.getUserMedia) {
      this.fail("the browser gives the microphone only to https or localhost pages");
      return;
    }
    this.show("starting");
    try {
      const stream = await navigator.mediaDevices.getUserMedia({
        audio: { channelCount: 1, echoCancellation: true, noiseSuppression: true, autoGainControl: true },
      });
      this.capture = { stream, context: new AudioContext() };
      if (!this.wanted) { this.release(); return; }
      await this.connectWorklet();
      const unplugged = () => this.fail("the microphone was disconnected");
      stream.getAudioTracks()[0].addEventListener("ended", unplugged);
      if (this.wanted) this.show("listening");
    } catch (error) {
      if (!this.wanted) return; // switched off while it started: its closed context is no failure
      this.fail(error.name === "NotAllowedError" ? "permission denied: allow the microphone for this page"
        : `no microphone: ${error.message}`);
    }
  }

  async connectWorklet() {
    const { stream, context } = this.capture;
    await context.audioWorklet.addModule("/static/mic_worklet.js");
    const node = new AudioWorkletNode(context, "mic-capture", { numberOfOutputs: 0 });
    node.port.onmessage = (event) => {
      if (this.capture && !this.sendBytes(event.data)) this.fail("disconnected from the robot");
    };
    context.createMediaStreamSource(stream).connect(node);
  }

  stop() {
    if (this.capture && this.state !== "starting") {
      this.sendBytes(pcm16(new Float32Array(SILENCE_ON_STOP_S * TARGET_RATE)));
    }
    this.release();
    this.show("off");
  }

  release() {
    this.wanted = false;
    if (this.capture === null) return;
    this.capture.stream.getTracks().forEach((track) => track.stop());
    this.capture.context.close();
    this.capture = null;
  }

  fail(message) {
    this.release();
    this.show("error", `microphone off: ${message}`);
  }

  show(state, text = STATES[state]) {
    this.state = state;
    clearTimeout(this.timer);
    if (state === "transcribing") {
      this.timer = setTimeout(() => this.show("listening"), TRANSCRIBING_SHOWN_S * 1000);
    }
    this.label.textContent = text;
    this.label.classList.toggle("late", state === "error");
    this.button.classList.toggle("recording", this.wanted);
    this.button.setAttribute("aria-pressed", String(this.wanted));
    this.button.title = this.wanted ? "Stop the microphone"
      : "Talk to the robot (the microphone stays on until clicked again)";
  }

  // The server's voice state (each state push): its VAD hears speech, or has ended an utterance.
  serverVoice(voice) {
    if (!voice) return;
    const ended = this.utterances !== null && voice.utterances > this.utterances;
    this.utterances = voice.utterances;
    if (this.capture === null || this.state === "starting") return;
    if (voice.speaking) { if (this.state !== "speech") this.show("speech"); }
    else if (ended) this.show("transcribing");
    else if (this.state === "speech") this.show("listening");
  }

  heard() { // a line's turn started: what was transcribed is in the conversation now
    if (this.state === "transcribing") this.show("listening");
  }

  serverError(message) {
    if (this.capture !== null && message.includes("does not listen")) {
      this.fail("no speech recognition on this server (run serve with asr=whisper)");
    }
  }

  connection(up) {
    if (!up && this.wanted) this.fail("disconnected from the robot (click again once the page is live)");
  }
}
