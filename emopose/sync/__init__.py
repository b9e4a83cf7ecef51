"""Speech-gesture sync measurement: where executed strokes land on their words, live or from a recording."""
