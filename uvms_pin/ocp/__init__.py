"""Optimal control of a UVMS in water with crocoddyl (the ``ocp`` extra:
``pip install 'uvms-pin[ocp]'``).

`model` (the differential action model: the underwater forward dynamics and their analytical
derivatives, `uvms_pin.physics.dynamics.forward_dynamics_derivatives`), `costs` (end-effector
pose, vehicle pose and attitude, effort, state regularisation) and `problems` (a shooting
problem over a horizon on Euler or RK4 nodes, solved by crocoddyl's box-constrained FDDP or
by mim_solvers' CSQP with the input bounds as constraints). crocoddyl and mim_solvers are
imported by these modules only: the rest of uvms-pin runs without them.
docs/derivatives.md.
"""
