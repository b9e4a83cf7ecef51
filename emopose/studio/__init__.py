"""Pose Studio: authoring library motions (the draft model, its checks, and saving into the library)."""
