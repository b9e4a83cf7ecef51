"""Speech: synthesis with word timings (espeak-ng), optional hosted TTS/ASR, playback."""
