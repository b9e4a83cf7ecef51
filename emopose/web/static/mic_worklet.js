// The microphone's AudioWorklet (loaded by mic.js): each render quantum of the input, mixed to mono and
// resampled to 16 kHz, leaves as 32 ms PCM16 frames on the node's port (buffers transferred, not copied).
import { Framer, mono, Resampler } from "./mic_pcm.js";

class MicCapture extends AudioWorkletProcessor {
  constructor() {
    super();
    this.resampler = new Resampler(sampleRate); // the context's rate: the worklet scope's global
    this.framer = new Framer();
  }

  process(inputs) {
    const channels = inputs[0];
    if (channels && channels.length > 0) {
      for (const frame of this.framer.push(this.resampler.push(mono(channels)))) {
        this.port.postMessage(frame, [frame]);
      }
    }
    return true;
  }
}

registerProcessor("mic-capture", MicCapture);
