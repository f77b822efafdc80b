"""Names of the components of logged quantities, shared by the controllers that log them and
the figures and messages that read them."""

#: The first-level (task-space) error components of the force/orientation task: force [N]
#: along world x, y, z, then the end-effector's roll, pitch, yaw [rad].
FIRST_LEVEL_NAMES: tuple[str, ...] = ("f_x", "f_y", "f_z", "roll", "pitch", "yaw")
#: The vehicle's six generalized-velocity components (SNAME: surge, sway, heave, roll rate,
#: pitch rate, yaw rate), all in the vehicle body frame.
VEHICLE_VELOCITY_NAMES: tuple[str, ...] = ("u", "v", "w", "p", "q", "r")
