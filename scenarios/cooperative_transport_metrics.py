"""Whether the cooperative transport worked (scenarios/cooperative_transport.toml), from the
rollouts: ``[metrics] extra = ["cooperative_transport_metrics:transport"]`` gives each
robot's block; `team` the metrics that need both robots (the internal force).

Each robot's rollout (its controller's role read from its metadata):

- ``load_share``: the upward force the robot's jaws put on the bar (the true contact force,
  ``wrench_contact_world``), over the bar's net weight, averaged while the team holds the
  bar at rest before the path starts (1 s to ``path_start_s``) [1].
- ``load_share_end``: the same over the last ``REST_S`` seconds (the bar at its end).

The leader's (the first robot's rollout logs the bar, ``free_objects``):

- ``bar_final_distance_m``: the bar centre's distance to the path's end at the last sample.
- ``bar_tracking_error_max_m``, ``bar_tracking_error_rms_m``: |bar centre - x_d(t)| from the
  path's start on, x_d the desired path (the leader's logged target moved by its grasp
  offset); left out of a run that ends before the path starts (a shortened run, a short sweep's).
- ``bar_delivered``: 1 when ``bar_final_distance_m`` < 5 cm.

The follower's:

- ``funnel_kept``: 1 when every estimation error stayed inside its funnel, |z_hat_j -
  z_meas_j| < rho(t) on every axis at every control tick (the controller's largest |xi| so
  far, ``estimate.xi_max_*``, below 1 at the end); ``estimate_xi_max``: that largest |xi|.
- ``estimate_error_final_m``: |z_hat - z_meas| at the last sample [m].
"""

from __future__ import annotations

import numpy as np

DELIVERED_WITHIN_M = 0.05
REST_S = 3.0
WARM_UP_S = 1.0


def _parameters(rollout) -> dict:
    return (rollout.metadata.get("controller") or {}).get("params") or {}


def upward_force_N(rollout) -> np.ndarray:
    """The force the robot's end-effector contacts push on what it holds, z (n,) [N]."""
    return np.asarray(rollout.wrench_contact_world)[:, 2]


def _load_shares(rollout, params: dict) -> dict[str, float]:
    t = np.asarray(rollout.time_s)
    weight = float(params["object_net_weight_N"])
    up = upward_force_N(rollout)
    start = float(params.get("path_start_s", 2.0))
    before = (t >= WARM_UP_S) & (t <= start)
    end = t >= t[-1] - REST_S
    out = {"load_share_end": float(up[end].mean() / weight)}
    if np.any(before):
        out["load_share"] = float(up[before].mean() / weight)
    return out


def desired_path_m(rollout, bar: np.ndarray) -> np.ndarray:
    """x_d(t) (n, 3) [m]: the leader's logged target for its grasp point, moved by its
    grasp offset (the bar starts at the path's start)."""
    target = np.asarray(rollout.signals["estimate"])[:, :3]
    return target - target[0] + bar[0]


def _leader(rollout, params: dict) -> dict[str, float]:
    t = np.asarray(rollout.time_s)
    bar = np.asarray(rollout.signals["free_objects"])[:, :3]
    path = desired_path_m(rollout, bar)
    end = np.asarray(params["waypoints_world_m"], dtype=float)[-1]
    moving = t >= float(params.get("path_start_s", 2.0))
    error = np.linalg.norm(bar - path, axis=1)[moving]
    final = float(np.linalg.norm(bar[-1] - end))
    out = {"bar_final_distance_m": final, "bar_delivered": float(final < DELIVERED_WITHIN_M)}
    if error.size:  # a run that ends before the path starts has no tracking error
        out["bar_tracking_error_max_m"] = float(error.max())
        out["bar_tracking_error_rms_m"] = float(np.sqrt(np.mean(error**2)))
    return out


def _follower(rollout) -> dict[str, float]:
    estimate = np.asarray(rollout.signals["estimate"])
    xi_max = float(estimate[-1, 7:10].max())
    error = np.linalg.norm(estimate[-1, :3] - estimate[-1, 3:6])
    return {
        "funnel_kept": float(xi_max < 1.0),
        "estimate_xi_max": xi_max,
        "estimate_error_final_m": float(error),
    }


def transport(rollout) -> dict[str, float]:
    """The metrics of the module docstring, for one robot's rollout."""
    params = _parameters(rollout)
    out = _load_shares(rollout, params)
    if params.get("role") == "leader":
        out.update(_leader(rollout, params))
    else:
        out.update(_follower(rollout))
    return out


def internal_force_N(first, second, first_share: float) -> np.ndarray:
    """The internal force on the bar (n,) [N]: how far the first robot's push departs from
    its share of the pair's total, |f_1 - c_1 (f_1 + f_2)| = |c_2 f_1 - c_1 f_2| (the
    true contact forces, world axes): what squeezes or stretches the bar between the jaws."""
    f_1 = np.asarray(first.wrench_contact_world)[:, :3]
    f_2 = np.asarray(second.wrench_contact_world)[:, :3]
    return np.linalg.norm(f_1 - first_share * (f_1 + f_2), axis=1)


def team(rollouts) -> dict[str, float]:
    """The metrics of both robots: ``internal_force_max_N`` and ``internal_force_rms_N``
    (`internal_force_N`, the leader first) after the first second (the grip settling); none
    for a run shorter than that."""
    leader, follower = (rollouts.robot(n) for n in rollouts.names)
    share = float(_parameters(leader)["load_share"])
    force = internal_force_N(leader, follower, share)
    settled = np.asarray(leader.time_s) >= WARM_UP_S
    if not np.any(settled):  # a run shorter than the grip's settling
        return {}
    return {
        "internal_force_max_N": float(force[settled].max()),
        "internal_force_rms_N": float(np.sqrt(np.mean(force[settled] ** 2))),
    }
