"""Motion execution: trajectories, the gesture sequencer and the 50 Hz control loop that feeds a backend."""
