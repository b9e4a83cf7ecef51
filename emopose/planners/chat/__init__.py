"""Planners that ask a chat model through litellm: the JSON planner, direct labels and annotate."""
