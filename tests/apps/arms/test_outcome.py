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


def test_a_joint_within_the_tolerance_of_a_limit_is_not_past_it(reference_uvms):
    """On a limit, or past it by less than the 1e-6 rad tolerance (the constraint solve's
    rounding), is inside; 1.3e-6 rad past either limit is named."""
    uvms = reference_uvms
    limited = int(np.flatnonzero(np.isfinite(uvms.model.upperPositionLimit[7:]))[0])
    for excess in (0.0, 5e-7):
        assert joint_limit_violation(_rollout(uvms, limited, excess), uvms) == ""
    assert "left its limits" in joint_limit_violation(_rollout(uvms, limited, 1.3e-6), uvms)
    below = _rollout(uvms, limited, 0.0)
    low = uvms.model.lowerPositionLimit[7 + limited]
    for excess, named in ((0.0, False), (5e-7, False), (1.3e-6, True)):
        below.q[2, 7 + limited] = low - excess
        assert bool(joint_limit_violation(below, uvms)) is named, excess
