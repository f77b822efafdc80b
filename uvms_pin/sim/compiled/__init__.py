"""The compiled seam of a run: the core objects of the plant, the integrator, the actuation,
the control laws, the sampled loop and the batch are built here, and only here, from the
public attributes of their Python counterparts (the physics' parts are built in
`uvms_pin.physics.compiled`). Whether a run is compiled is decided before it starts, in
`uvms_pin.sim.pipeline`."""
