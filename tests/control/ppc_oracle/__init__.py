"""A frozen copy of the prescribed-performance controller as it was before it was optimized.

``ppc.py``, ``performance.py`` and ``kinematics.py`` are uvms_pin's files of commit 1c81485,
verbatim except for their imports of each other. They are the oracle of
``test_ppc_oracle.py``: the fast controller must give the same outputs (tau, signals, funnel
margin, exceptions) to 1e-12. Do not edit them; do not import them from the package.
"""


def in_place_of_the_package_ppc(*args, backend: str = "core", **kwargs):
    """The oracle, built with the arguments a scenario gives the package's controller
    (``mock.patch("uvms_pin.scenario.ppc.PrescribedPerformanceController", ...)``): the
    ``backend`` keyword, newer than the oracle, is dropped (the oracle has one backend)."""
    from ppc_oracle.ppc import PrescribedPerformanceController

    return PrescribedPerformanceController(*args, **kwargs)
