"""Scalar summaries of a rollout (what `metrics.json` holds)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.results.estimate_metrics import estimate_metrics
from uvms_pin.results.extra_metrics import extra_metrics
from uvms_pin.results.free_objects import free_object_metrics
from uvms_pin.results.joint_positions import KINDS, REVOLUTE, arm_positions, configuration_width
from uvms_pin.results.task_metrics import task_metrics

if TYPE_CHECKING:
    from uvms_pin.results.rollout_data import RolloutData


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x)))) if x.size else math.nan


def compute_metrics(rollout: RolloutData, *, extra: bool = True) -> dict[str, float]:
    """Metrics of any run: timing, energy (`energy_metrics`: a balance when driven), motion
    and effort; a tracking task's (`uvms_pin.results.task_metrics`); then, with ``extra``,
    your own, the functions the rollout's metadata names (`uvms_pin.results.extra_metrics`,
    a scenario's ``[metrics] extra``). Efforts: vehicle force = |tau[0:3]|,
    vehicle torque = |tau[3:6]|, joint torques = max over joints of |tau_j|.
    """
    meta = rollout.metadata
    out: dict[str, float] = {
        "simulated_time_s": float(meta.get("simulated_time_s", math.nan)),
        "wall_time_s": float(meta.get("wall_time_s", math.nan)),
        "real_time_factor": float(meta.get("real_time_factor", math.nan)),
        "n_samples": float(len(rollout)),
    }
    if len(rollout) == 0:
        return out
    kinetic = rollout.kinetic_energy_J
    total = rollout.total_energy_J
    out.update(
        kinetic_energy_initial_J=float(kinetic[0]),
        kinetic_energy_final_J=float(kinetic[-1]),
        **energy_metrics(rollout),
        energy_max_increase_J=float(np.max(np.diff(total))) if len(total) > 1 else 0.0,
        vehicle_displacement_m=float(np.linalg.norm(rollout.q[-1, :3] - rollout.q[0, :3])),
        vehicle_speed_final_m_s=float(np.linalg.norm(rollout.v[-1, :3])),
        vehicle_angular_speed_final_rad_s=float(np.linalg.norm(rollout.v[-1, 3:6])),
    )
    force = np.linalg.norm(rollout.tau[:, :3], axis=1)
    torque = np.linalg.norm(rollout.tau[:, 3:6], axis=1)
    # Fix: the RMS was taken over every joint and sample, so idle joints diluted it (a
    # 4-joint arm with one joint working reported half its torque); it is now the RMS of
    # max_j |tau_j|, the quantity the docstring names (the peak was already its maximum)
    arm = np.abs(rollout.tau[:, 6:])
    out.update(
        vehicle_force_peak_N=float(force.max()),
        vehicle_force_rms_N=_rms(force),
        vehicle_torque_peak_Nm=float(torque.max()),
        vehicle_torque_rms_Nm=_rms(torque),
    )
    if arm.shape[1]:  # a vehicle without an arm has no joint torque metrics (not NaN, not 0)
        joints = arm.max(axis=1)
        out.update(joint_torque_peak_Nm=float(joints.max()), joint_torque_rms_Nm=_rms(joints))
    out.update(force_tracking_metrics(rollout))
    out.update(joint_limit_metrics(rollout))
    out.update(surface_metrics(rollout))
    out.update(world_contact_metrics(rollout))
    out.update(free_object_metrics(rollout))
    out.update(task_metrics(rollout))
    out.update(estimate_metrics(rollout))
    if extra:
        out.update(extra_metrics(rollout, out))
    return out


def checked_metrics(rollout: RolloutData) -> tuple[dict[str, float], ParameterError | None]:
    """(the rollout's metrics, the failure of a metric of your own or None): when one of
    yours raises or returns what is no metric, the built-in metrics alone and its error
    (naming it, with its traceback), so that what a run simulated is saved whatever the
    function does; `compute_metrics` of the saved rollout computes them again once fixed."""
    built_in = compute_metrics(rollout, extra=False)
    try:
        return {**built_in, **extra_metrics(rollout, built_in)}, None
    except ParameterError as exc:
        return built_in, exc


def driven(rollout: RolloutData) -> bool:
    """Whether anything did work on the system: a generalized force, a contact, a
    disturbance (the water's own forces aside)."""
    return bool(
        np.any(rollout.tau)
        or np.any(rollout.wrench_contact_world)
        or np.any(rollout.wrench_disturbance_body)
    )


def work_of_tau_J(rollout: RolloutData) -> np.ndarray:
    """W(t) = int_0^t tau . zeta dt [J]: the work of the applied generalized force, by the
    trapezoid rule over the logged samples (tau is held between control ticks, so this is
    exact only as the log period goes to the control period)."""
    power = np.einsum("ij,ij->i", rollout.tau, rollout.v)  # tau is conjugate to zeta [W]
    steps = 0.5 * (power[1:] + power[:-1]) * np.diff(rollout.time_s)
    return np.concatenate([[0.0], np.cumsum(steps)])


def energy_metrics(rollout: RolloutData) -> dict[str, float]:
    """The energy of a run. Driven (a force, contact or disturbance did work): its balance,
    E(T) - E(0) = W_tau + W_rest, with W_tau the work of the applied generalized force
    (`work_of_tau_J`) and W_rest the work of the water (damping, currents: dissipation),
    the contact (the end-effector's, the world's) and the joint stops (their springs hold
    energy while pressed), and the disturbance, what the energy change leaves. Not driven: the largest
    relative change of E = T + U, max |E(t) - E(0)| / max(|E(0)|, T(0)) (the water's
    damping dissipates; without it, the integration's error)."""
    total = rollout.total_energy_J
    change = float(total[-1] - total[0])
    if not driven(rollout):
        scale = max(abs(total[0]), rollout.kinetic_energy_J[0], 1e-12)
        return {
            "energy_change_J": change,
            "energy_relative_drift_max": float(np.max(np.abs(total - total[0])) / scale),
        }
    work = float(work_of_tau_J(rollout)[-1])
    return {
        "energy_change_J": change,
        "work_of_tau_J": work,
        "work_of_water_contact_disturbance_J": change - work,
    }


#: How close to a limit a joint counts as held at it [rad or m] (the constraint solve ends a
#: joint within h times its 1e-8 tolerance of its limit, far below this)
AT_LIMIT_RAD = 1e-6
#: How far past a limit a joint must be to count in the time past it [rad or m]: a joint a
#: constraint holds at its limit ends there to rounding (3.7e-15 rad measured on a finger of
#: gripper_close with rigid moving contacts), which is at its stop, not past it
PAST_LIMIT_RAD = 1e-9

#: A wet fraction this far below 1 counts as partly out of the water (rounding aside).
_WET = 1.0 - 1e-9


def surface_metrics(rollout: RolloutData) -> dict[str, float]:
    """How long some body was out of the water, in part or whole [s], from the logged wet
    fractions (a run under a free surface): each sample counts until the next one.

    ``time_partly_out_of_water_s``: some body had 0 <= f < 1 (part of it, or all, above
    the surface); ``time_wholly_out_of_water_s``: some body had f = 0; and the smallest
    wet fraction of any body over the run.
    """
    fractions = rollout.signals.get("wet_fraction")
    if fractions is None or len(rollout) == 0 or fractions.shape[1] == 0:
        return {}
    held = np.diff(rollout.time_s, append=rollout.time_s[-1])
    return {
        "time_partly_out_of_water_s": float(held @ np.any(fractions < _WET, axis=1)),
        "time_wholly_out_of_water_s": float(held @ np.any(fractions <= 0.0, axis=1)),
        "wet_fraction_min": float(fractions.min()),
    }


def joint_limit_metrics(rollout: RolloutData) -> dict[str, float]:
    """How far the arm went past its position limits [rad] (0: never), the time share, and
    the time at a stop [s] (some joint past a limit; each sample counts until the next),
    over the joints that have limits (a continuous joint has none; {} if no joint has).

    With compliant stops a joint past its limit is pressing on its stop, by tau / k_s; with
    the limits as constraints (the default with a control period) it rests at its limit (to
    rounding: the time share counts a joint more than ``PAST_LIMIT_RAD`` past it), and
    ``time_at_joint_stop_s`` counts the time some joint is within ``AT_LIMIT_RAD`` of a limit
    or past it. Without either nothing stops a joint, and a controller that drives one past
    its limit shows up here, not as a crash.
    """
    meta = rollout.metadata
    if "arm_position_lower_rad" not in meta or len(rollout) == 0 or rollout.q.shape[1] <= 7:
        return {}
    lower = np.array([-math.inf if x is None else x for x in meta["arm_position_lower_rad"]])
    upper = np.array([math.inf if x is None else x for x in meta["arm_position_upper_rad"]])
    kinds = meta.get("arm_joint_kinds") or [REVOLUTE] * lower.size
    limited = np.isfinite(lower) & np.isfinite(upper)
    if (  # metadata that does not describe these columns (written by hand, or damaged)
        not np.any(limited)
        or not lower.size == upper.size == len(kinds)
        or not set(kinds) <= set(KINDS)
        or configuration_width(kinds) != rollout.q.shape[1] - 7
    ):
        return {}
    q = arm_positions(rollout.q[:, 7:], kinds)[:, limited]
    excess = np.maximum(lower[limited] - q, 0.0) + np.maximum(q - upper[limited], 0.0)
    held = np.diff(rollout.time_s, append=rollout.time_s[-1])
    past = np.any(excess > PAST_LIMIT_RAD, axis=1)
    # a limit solved as a constraint holds its joint AT the limit (to the solver's tolerance)
    gap = np.minimum(q - lower[limited], upper[limited] - q)
    at_stop = np.any(gap <= AT_LIMIT_RAD, axis=1)
    return {
        "joint_limit_excess_max_rad": float(excess.max()),
        "joint_limit_excess_time_fraction": float(np.mean(past)),
        "time_at_joint_stop_s": float(held @ at_stop),
    }


def world_contact_metrics(rollout: RolloutData) -> dict[str, float]:
    """From the logged world contacts (signal ``world_contact``, 9 numbers per pair: force
    [N], point [m], moment [N m]): the time some body touched an object [s] and the
    largest total contact force on the UVMS [N]."""
    wrenches = rollout.signals.get("world_contact")
    if wrenches is None or len(rollout) == 0 or wrenches.shape[1] == 0:
        return {}
    per_pair = wrenches.reshape(len(rollout), -1, 9)
    touching = np.any(np.linalg.norm(per_pair[:, :, :3], axis=2) > 0.0, axis=1)
    held = np.diff(rollout.time_s, append=rollout.time_s[-1])
    total = np.linalg.norm(per_pair[:, :, :3].sum(axis=1), axis=1)
    return {
        "time_in_world_contact_s": float(held @ touching),
        "world_contact_force_peak_N": float(total.max()),
    }


def transient_end_s(rollout: RolloutData, fraction: float = 0.05) -> float:
    """First time the force funnels have decayed to within ``fraction`` of their final width:
    rho(t) - rho_inf <= fraction (rho0 - rho_inf). NaN without a force funnel."""
    rho = rollout.signals.get("rho_x")
    if rho is None or len(rho) < 2:
        return math.nan
    rho_force = rho[:, 0]
    span = rho_force[0] - rho_force[-1]
    if span <= 0.0:
        return float(rollout.time_s[0])
    settled = np.flatnonzero(rho_force - rho_force[-1] <= fraction * span)
    return float(rollout.time_s[settled[0]])


def force_overshoot_N(error_N: np.ndarray) -> float:
    """The largest force error past the desired force [N], over every component.

    ``error_N`` (n, k): e = f_e - f_d per sample. A component whose initial error is nonzero
    overshoots when its error takes the opposite sign (by how much); a component starting at
    zero error overshoots by any error it takes later, of either sign. 0 when nothing overshoots
    or with fewer than two samples.
    """
    if len(error_N) < 2:
        return 0.0
    initial_sign = np.sign(error_N[0])
    past = np.where(initial_sign != 0.0, -initial_sign * error_N, np.abs(error_N))
    return float(max(0.0, np.max(past[1:])))


def force_tracking_metrics(rollout: RolloutData) -> dict[str, float]:
    """Force-control metrics from a run that logged the controller's signals.

    Force error is the TRUE one, f_e - f_d (the sensor's noise excluded), per component;
    "after transient" starts at `transient_end_s`, the time the force funnel has closed: a
    run without a force funnel (the MPC, the baselines) has no such time, and its
    ``transient_end_s`` and after-transient errors are left out rather than given as NaN
    (the whole run's ``force_error_rms_N`` and ``force_error_max_N`` are there; `uvms-pin
    compare-controllers` judges every controller after one window, ``--after``). Overshoot: the largest error of the
    opposite sign to the initial error, over every force component [N]. Funnel margin:
    min over time and components of 1 - |xi| per level (> 0 means the funnel held).
    """
    signals = rollout.signals
    if "force_desired_world_N" not in signals or len(rollout) == 0:
        return {}
    desired = signals["force_desired_world_N"]
    error = rollout.wrench_contact_world[:, :3] - desired
    norm = np.linalg.norm(error, axis=1)
    out = {
        "force_error_rms_N": _rms(norm),
        "force_error_max_N": float(norm.max()),
        "force_overshoot_N": force_overshoot_N(error),
    }
    t_transient = transient_end_s(rollout)
    if math.isfinite(t_transient):  # a funnel's last sample is always within it: never empty
        after = rollout.time_s >= t_transient
        out.update(
            transient_end_s=t_transient,
            force_error_rms_after_transient_N=_rms(norm[after]),
            force_error_max_after_transient_N=float(norm[after].max()),
        )
    for level, key in (("first", "xi_x"), ("second", "xi_zeta")):
        if key in signals:
            out[f"funnel_margin_min_{level}"] = float(np.min(1.0 - np.abs(signals[key])))
    if "e_x" in signals:
        out["orientation_error_final_rad"] = float(np.linalg.norm(signals["e_x"][-1, 3:6]))
    commanded = signals.get("tau_commanded")
    if commanded is not None:
        out["commanded_vehicle_force_peak_N"] = float(
            np.linalg.norm(commanded[:, :3], axis=1).max()
        )
        out["commanded_vehicle_torque_peak_Nm"] = float(
            np.linalg.norm(commanded[:, 3:6], axis=1).max()
        )
        out["commanded_joint_torque_peak_Nm"] = (
            float(np.abs(commanded[:, 6:]).max()) if commanded.shape[1] > 6 else 0.0
        )
    return out
