"""The seam between the Python reference and the compiled core (``uvms_pin._core``).

One module per concept the core knows, each saying once how the Python object becomes its
compiled counterpart (a struct with named fields, the C++ names) or why it cannot (a
`Fallback` with the reason): `dynamics` (the hydrodynamic bodies and the dynamics of a
UVMS, src/uvms_core/hydro_bodies.hpp and dynamics.hpp), `flow` (flow.hpp), `contact`
(contact.hpp), `disturbance` (disturbance.hpp), `ray_caster` (the perception's caster,
ray_caster.hpp). The integrators' counterparts are in
`uvms_pin.sim.integrators`, the plant's in `uvms_pin.sim.plant`, the controller's in
`uvms_pin.control.ppc_kernel`. `Backend` is the one object that chooses between the two
implementations; `extension` loads the compiled module and checks that it is current.
"""
