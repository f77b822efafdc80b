"""The fins of a model (`uvms_pin.model.uvms.Fin`, gz-sim's LiftDrag) as the core's
(src/uvms_core/fins.hpp: the same force, wet fraction and wrench as `uvms_pin.hydro.lift_drag`
and `uvms_pin.physics.fins`)."""

from __future__ import annotations

from types import ModuleType
from typing import Any

import numpy as np

from uvms_pin.hydro.lift_drag import LiftDragParams

__all__ = ["fins_to_core", "lift_drag_to_core"]

_NUMBERS = (
    "area_m2", "fluid_density_kg_m3", "cla", "cda", "cma", "alpha_stall_rad", "cla_stall",
    "cda_stall", "cma_stall", "alpha0_rad", "control_joint_rad_to_cl", "cm_delta",
)  # fmt: skip


def lift_drag_to_core(params: LiftDragParams, core: ModuleType) -> Any:
    """The core's LiftDrag of ``params``."""
    out = core.LiftDrag()
    for name in _NUMBERS:
        setattr(out, name, float(getattr(params, name)))
    out.cp_m = np.asarray(params.cp_m, dtype=float)
    out.forward = np.asarray(params.forward, dtype=float)
    out.upward = np.asarray(params.upward, dtype=float)
    out.radial_symmetry = bool(params.radial_symmetry)
    out.reversible = bool(params.reversible)
    return out


def fins_to_core(fins, core: ModuleType) -> Any:
    """The core's Fins of a model's ``fins`` (empty: none)."""
    out = []
    for fin in fins:
        own = core.Fin()
        own.joint_id = int(fin.joint_id)
        own.rotation_in_joint = np.asarray(fin.placement_in_joint.rotation, dtype=float)
        own.translation_in_joint = np.asarray(fin.placement_in_joint.translation, dtype=float)
        own.params = lift_drag_to_core(fin.params, core)
        own.control_q_index = -1 if fin.control_q_index is None else int(fin.control_q_index)
        out.append(own)
    held = core.Fins()
    held.fins = out
    return held
