"""The PPC law's compiled counterpart (src/uvms_core/ppc.hpp): its settings, by name, and
named views of the signals of its last call.

`PrescribedPerformanceController` builds one through its backend (`PpcKernel.build`) and
calls `compute` on every control call; a status other than ok (a funnel left or the clamp of
the funnel extension passed, the solver declining, the Euler singularity, bad input) means
the Python reference evaluates that call.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.control.pseudo_inverse import REFINE_ABOVE_CONDITION_BOUND
from uvms_pin.physics.compiled.backend import Backend, Fallback
from uvms_pin.physics.compiled.ppc import ppc_to_core
from uvms_pin.physics.kinematics import EULER_SINGULARITY_MIN_ABS_COS_PITCH

#: The signals of a call, in the order the Python law keeps them (`PPCSignals`).
SIGNALS = ("rpy_ee", "e_x", "rho_x", "xi_x", "xdot_r", "zeta_r", "e_zeta", "rho_zeta",
           "xi_zeta", "tau")  # fmt: skip


class PpcKernel:
    """One compiled law with its constants, and read-only views of its last ok call's
    signals by name (``views["tau"]``, ..., ``views["margin"]``: 1 - max |xi|)."""

    def __init__(self, kernel):
        self.kernel = kernel  # the core's law (`uvms_pin.physics.compiled.ppc`)
        #: every signal of the last ok call in one read-only buffer (the views are slices)
        self.packed = packed = self.kernel.signals()
        self.views = {
            name: packed[start:stop] for name, (start, stop) in self.kernel.signal_layout().items()
        }
        self.compute = self.kernel.compute  # the C++ method itself: nothing in between
        #: tau (nv,) of the last ok call (a view: copy it to keep it)
        self.tau = self.views["tau"]

    @classmethod
    def build(
        cls, backend: Backend, model: pin.Model, settings: dict[str, object]
    ) -> PpcKernel | Fallback:
        """The kernel of ``model`` with ``settings`` (the fields of the core's PpcSettings,
        by name), or the backend's Fallback (the Python reference was asked for)."""
        constants = {
            "refine_above_condition_bound": REFINE_ABOVE_CONDITION_BOUND,
            "min_abs_cos_pitch": EULER_SINGULARITY_MIN_ABS_COS_PITCH,
        }
        return backend.counterpart(
            lambda core: cls(ppc_to_core(core, model, {**settings, **constants}))
        )

    def copies(self) -> tuple[np.ndarray, ...]:
        """Copies of the last ok call's signals, in the order of `SIGNALS`."""
        return tuple(self.views[name].copy() for name in SIGNALS)

    @property
    def margin(self) -> float:
        """min(1 - |xi|) over both levels at the last ok call."""
        return float(self.views["margin"][0])
