"""What the robot knows of its surroundings: planar geometry, scene objects and the view it plans in."""
