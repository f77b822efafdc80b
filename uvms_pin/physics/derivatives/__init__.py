"""Derivatives of the underwater dynamics along the tangent of the configuration manifold.

`motion` (each body's velocity and acceleration Jacobians), `fluid` (each hydrodynamic term's
wrench Jacobians, one function per term), `surface` (the wet-fraction terms of a hull the
free surface cuts), `joint_limits` (the joint stops and the drives' friction), `reference`
(the forward-dynamics derivatives in Python: the oracle of the compiled core) and `step`
(one control period of a fixed-step integrator). docs/derivatives.md derives them.
"""
