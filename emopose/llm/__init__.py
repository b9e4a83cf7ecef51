"""The LLM client shared by chat planners, hosted ASR and TTS: litellm calls, errors, cache, counters,
checks, streams."""
