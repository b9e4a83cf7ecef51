"""The web UI (python -m emopose +experiment=serve): chat, live simulation view and Pose Studio."""
