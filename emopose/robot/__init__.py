"""The project's own G1 upper-body model: MJCF asset plus a small builder (mujoco imported lazily)."""
