"""Physics of a UVMS in water: the dynamics (M, h, forward dynamics), environment contact
and disturbances, kinematics, and the seam to the compiled core."""
