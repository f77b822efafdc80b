"""The scenario's controller adapted to another arm's joint count.

Every controller array with one entry per generalized velocity (nv of the reference
UVMS) is re-sized for the new arm: the vehicle's six entries are kept; for the arm part,
``k_zeta`` is alpha M_jj(q0) per joint (the diagonal of the mass matrix at the initial
configuration, alpha the median of the reference arm's k_zeta / M_jj: the same loop rate
per joint, which is what the sampled controller's stability depends on), and the other
arrays take the median of the reference arm's entries.
"""

from __future__ import annotations

import numpy as np

from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.dynamics import mass_matrix


def _median_arm(values: list, n_ref: int) -> float:
    """The median of the arm part (after the vehicle's six) of a per-velocity array."""
    return float(np.median(np.asarray(values[6 : 6 + n_ref], dtype=float)))


def controller_overrides(
    raw_controller: dict, reference: UVMS, q_ref: np.ndarray, uvms: UVMS, q0: np.ndarray
) -> dict:
    """``controller.KEY`` overrides re-sizing every per-velocity array for ``uvms``.

    ``raw_controller``: the scenario's [controller] table, tuned for ``reference`` at
    ``q_ref``; ``q0``: the new arm's initial configuration (nq of ``uvms``).
    """
    nv_ref, n_ref, n = reference.nv, reference.n_arm_joints, uvms.n_arm_joints
    m_ref = np.diag(mass_matrix(reference, q_ref))[6:]
    m_new = np.diag(mass_matrix(uvms, q0))[6:]
    out = {}
    for key, value in raw_controller.items():
        if not (isinstance(value, list) and len(value) == nv_ref):
            continue
        vehicle = [float(x) for x in value[:6]]
        if key == "k_zeta":
            alpha = float(np.median(np.asarray(value[6:], dtype=float) / m_ref))
            arm = (alpha * m_new).tolist()
        else:
            arm = [_median_arm(value, n_ref)] * n
        out[f"controller.{key}"] = vehicle + arm
    if "null_space_target" in raw_controller:
        # the reference design pulls the arm back to its working pose: each arm's own
        out["controller.null_space_target"] = uvms.arm_joints.positions(q0).tolist()
    return out
