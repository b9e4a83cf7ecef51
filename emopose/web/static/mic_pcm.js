// The microphone's sample path, pure so a test can run it in a page (tests/web/test_browser_microphone.py):
// the input's channels -> mono -> 16 kHz -> 32 ms frames of little-endian int16, what the server's
// Listener takes (emopose/web/voice_io.py) and the VAD's own chunk length (512 samples).

export const TARGET_RATE = 16000;
export const FRAME_SAMPLES = 512; // 32 ms at 16 kHz

export function mono(channels) {
  if (channels.length === 1) return channels[0];
  const out = new Float32Array(channels[0].length);
  for (const channel of channels) channel.forEach((x, i) => { out[i] += x / channels.length; });
  return out;
}

// Each output sample is the mean of the input over its own interval (fromRate / toRate input samples,
// fractional edges weighted): a box low-pass that keeps most of the aliasing out of the 8 kHz band, for any
// ratio (48 kHz, 44.1 kHz; below 16 kHz it repeats samples) and the same result whatever the chunking.
export class Resampler {
  constructor(fromRate, toRate = TARGET_RATE) {
    this.step = fromRate / toRate; // input samples per output sample
    this.sum = 0;     // weighted input of the output sample being built
    this.filled = 0;  // how much of its interval is covered, in input samples
  }

  push(input) {
    const out = [];
    for (const x of input) {
      let left = 1; // the part of this input sample not yet given to an output sample
      while (this.filled + left >= this.step) {
        const part = this.step - this.filled;
        out.push((this.sum + x * part) / this.step);
        left -= part;
        this.sum = 0;
        this.filled = 0;
      }
      this.sum += x * left;
      this.filled += left;
    }
    return Float32Array.from(out);
  }
}

// Float samples in [-1, 1] (beyond: clipped) -> little-endian int16 bytes.
export function pcm16(samples) {
  const view = new DataView(new ArrayBuffer(2 * samples.length));
  samples.forEach((x, i) => {
    const clipped = Math.max(-1, Math.min(1, x));
    view.setInt16(2 * i, Math.round(clipped < 0 ? clipped * 0x8000 : clipped * 0x7fff), true);
  });
  return view.buffer;
}

// Samples in any lengths -> PCM16 frames of exactly `size` samples (the rest waits for more).
export class Framer {
  constructor(size = FRAME_SAMPLES) {
    this.size = size;
    this.pending = new Float32Array(size);
    this.count = 0;
  }

  push(samples) {
    const frames = [];
    for (const x of samples) {
      this.pending[this.count++] = x;
      if (this.count === this.size) {
        frames.push(pcm16(this.pending));
        this.count = 0;
      }
    }
    return frames;
  }
}
