"""Semantic planners, one folder per family (local/, chat/, baselines/); one YAML per option
under conf/planner/."""
