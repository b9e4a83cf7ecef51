"""Execution backends: one class per file, one YAML per backend under conf/backend/."""
