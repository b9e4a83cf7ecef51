"""The six pipeline stages: parse, resolve, modulate, schedule, sequence, dispatch (conf/pipeline/)."""
