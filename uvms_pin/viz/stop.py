"""Why and when a stopped run stopped, as figures and the replay header show it."""

from __future__ import annotations

from uvms_pin.rollout import Rollout


def stop_summary(rollout: Rollout) -> str | None:
    """One line saying when and why a run stopped early; None for a finished run.

    A funnel violation names the level, component, time, error and bound (the state it
    happened in is not a logged sample: the figures end before it).
    """
    meta = rollout.metadata
    status = meta.get("status", "ok")
    if status in ("ok", ""):
        return None
    v = meta.get("violation")
    if v:
        return (
            f"{status} at t = {v['time_s']:.6g} s: {v['level']}-level error "
            f"'{v['component']}' = {v['error']:.4g} reached its bound rho = {v['bound']:.4g}"
        )
    error = str(meta.get("error", ""))
    return f"{status}: {error[:120] + '...' if len(error) > 120 else error}"


def stop_time_s(rollout: Rollout) -> float | None:
    """When the run stopped [s] (the violation time, else the last logged sample)."""
    if stop_summary(rollout) is None:
        return None
    v = rollout.metadata.get("violation")
    if v:
        return float(v["time_s"])
    return float(rollout.time_s[-1]) if len(rollout) else 0.0
