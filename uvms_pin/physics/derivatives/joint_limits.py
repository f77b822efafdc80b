"""The derivatives of the arm joints' own generalized forces: the compliant joint stops
(`uvms_pin.physics.joint_stops`) and the drives' friction (`uvms_pin.physics.joint_friction`).

Both act on one joint coordinate each (revolute or prismatic: its q-tangent is its q), so
their Jacobians are diagonal on the joints' rows. A generalized force tau_j(q, v) added to
the dynamics moves the acceleration by

    da/dq += M^-1 d tau_j/dq,   da/dv += M^-1 d tau_j/dv.

Stops. Past the upper limit by e = q - q_max > 0, tau = -max(0, k e + c e_dot):

    d tau/dq = -k,  d tau/dv = -c      while k e + c e_dot > 0 (the stop pushes)

and 0 otherwise (mirrored at q_min: tau = max(0, k e - c qdot), e = q_min - q, the same
-k and -c). The law has kinks where the joint reaches its limit (e = 0) and where the
stop lets go (k e + c e_dot = 0): there the derivative of the side the state is on is
returned, the stop counted as pushing only when e > 0 and its force is > 0 (strictly).

Friction. tau_f = -(b v + c tanh(v / s)) is smooth: d tau_f / dv = -(b + (c / s) sech^2(v / s)),
and it does not depend on q.
"""

from __future__ import annotations

import numpy as np

from uvms_pin.physics.joint_friction import JointFriction
from uvms_pin.physics.joint_stops import JointStops


def joint_stop_jacobians(
    stops: JointStops, q: np.ndarray, v: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(d tau_stop/dq, d tau_stop/dv) (nv, nv), q along the tangent (see the module)."""
    nv = v.shape[0]
    joints, rates = q[stops.q_index], v[stops.v_index]
    k, c = stops.stiffness_Nm_rad, stops.damping_Nm_s_rad
    over = joints - stops.upper_rad
    under = stops.lower_rad - joints
    pushing = ((over > 0.0) & (k * over + c * rates > 0.0)) | (
        (under > 0.0) & (k * under - c * rates > 0.0)
    )
    by_q, by_v = np.zeros((nv, nv)), np.zeros((nv, nv))
    rows = stops.v_index[pushing]
    by_q[rows, rows] = -k
    by_v[rows, rows] = -c
    return by_q, by_v


def joint_friction_jacobian(friction: JointFriction, v: np.ndarray) -> np.ndarray:
    """d tau_f / dv (nv, nv) of the drives' friction on the arm joints v[6:] (see the module)."""
    nv = v.shape[0]
    scale = friction.velocity_scale_rad_s
    slope = friction.viscous_Nms + friction.coulomb_Nm / scale / np.cosh(v[6:] / scale) ** 2
    out = np.zeros((nv, nv))
    out[6:, 6:] = -np.diag(slope)
    return out
