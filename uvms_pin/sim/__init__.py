"""Simulation: the plant, integrators, sensors, actuation and the one closed-loop engine."""
