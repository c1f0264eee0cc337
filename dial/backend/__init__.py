"""MuJoCo backend: the robot model and its named indices."""
