"""One arm's run: a joint past its limits is named, with when and where."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pinocchio as pin

from uvms_pin.apps.arms.outcome import joint_limit_violation


class _Rollout(SimpleNamespace):
    """What `joint_limit_violation` reads of a rollout: q, time_s and its length."""

    def __len__(self) -> int:
        return len(self.time_s)


def _rollout(uvms, joint: int, excess_rad: float) -> _Rollout:
    """Three samples at the neutral pose; at t = 0.2 s ``joint`` is ``excess_rad`` past
    its upper limit."""
    q = np.tile(pin.neutral(uvms.model), (3, 1))
    q[2, 7 + joint] = uvms.model.upperPositionLimit[7 + joint] + excess_rad
    return _Rollout(q=q, time_s=np.array([0.0, 0.1, 0.2]))


def test_joint_limit_violation(reference_uvms):
    uvms = reference_uvms
    limited = int(np.flatnonzero(np.isfinite(uvms.model.upperPositionLimit[7:]))[0])
    inside = _rollout(uvms, limited, -1e-3)
    assert joint_limit_violation(inside, uvms) == ""
    assert joint_limit_violation(_Rollout(q=inside.q[:0], time_s=inside.time_s[:0]), uvms) == ""
    text = joint_limit_violation(_rollout(uvms, limited, 0.01), uvms)
    assert text.startswith(f"joint '{uvms.arm_joint_names[limited]}' left its limits [")
    assert "at t = 0.200 s" in text
