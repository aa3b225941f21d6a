"""IK solvers: closed form for the yaw-pitch-pitch-pitch-roll family, numerical otherwise."""
