"""Navigation sensors of the vehicle: IMU, depth (pressure), DVL, USBL; seeded, sampled at
the control ticks, logged as rollout signals (`uvms_pin.sim.navigation.suite`)."""
