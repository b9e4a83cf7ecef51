"""Semantic planners: one file per family, one YAML per option under conf/planner/."""
