"""``RolloutData.plot``: every figure of a rollout by name, as matplotlib Figures."""

from __future__ import annotations

from collections.abc import Callable

from matplotlib.figure import Figure

from uvms_pin.errors import ParameterError
from uvms_pin.results.figures.estimate import ESTIMATE_SIGNALS, plot_estimate
from uvms_pin.results.figures.paper import (
    PPC_SIGNALS,
    plot_first_level,
    plot_force,
    plot_second_level,
)
from uvms_pin.results.figures.standard import plot_energy, plot_pose, plot_velocities
from uvms_pin.results.figures.tracking import TRACKING_SIGNALS, plot_tracking
from uvms_pin.results.rollout_data import RolloutData

#: kind -> (figure function, signals it needs)
KINDS: dict[str, tuple[Callable[..., Figure], tuple[str, ...]]] = {
    "pose": (plot_pose, ()),
    "velocities": (plot_velocities, ()),
    "energy": (plot_energy, ()),
    "force": (plot_force, ("force_desired_world_N",)),
    "first_level": (plot_first_level, PPC_SIGNALS),
    "second_level": (plot_second_level, PPC_SIGNALS),
    "tracking": (plot_tracking, TRACKING_SIGNALS),
    "estimate": (plot_estimate, ESTIMATE_SIGNALS),
}


def _available(rollout: RolloutData, needs: tuple[str, ...]) -> bool:
    return len(rollout) >= 2 and all(name in rollout.signals for name in needs)


def plot_rollout(rollout: RolloutData, kind: str | None = None) -> Figure | dict[str, Figure]:
    """One figure by ``kind``, or (``kind=None``) every figure the rollout has data for."""
    if kind is None:
        return {
            name: fn(rollout) for name, (fn, needs) in KINDS.items() if _available(rollout, needs)
        }
    if kind not in KINDS:
        raise ParameterError(f"unknown plot kind '{kind}'; choose from {', '.join(KINDS)}")
    fn, needs = KINDS[kind]
    if not _available(rollout, needs):
        missing = [name for name in needs if name not in rollout.signals]
        why = f"signals {', '.join(missing)} not logged" if missing else "fewer than 2 samples"
        raise ParameterError(f"cannot plot '{kind}' for this rollout: {why}")
    return fn(rollout)
