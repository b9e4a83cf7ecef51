"""One utterance's path: the Turn model, the stages' pipeline, the timeline, the turn runner and
the session."""
