"""The record of one environment episode, exported as a `Rollout` (replay.html, plots)."""

from __future__ import annotations

from typing import Any

import numpy as np

from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.dynamics import kinetic_energy, potential_energy
from uvms_pin.results.rollout import Rollout


class EpisodeRecord:
    """Per control tick: time, state, applied and commanded tau, wrenches."""

    def __init__(self) -> None:
        self.rows: list[tuple[np.ndarray, ...]] = []

    def add(self, time_s, q, v, tau_applied, tau_commanded, contact, measured, disturbance):
        self.rows.append(
            (time_s, q.copy(), v.copy(), tau_applied, tau_commanded, contact, measured, disturbance)
        )

    def __len__(self) -> int:
        return len(self.rows)

    def to_rollout(self, uvms: UVMS, metadata: dict[str, Any]) -> Rollout:
        """A Rollout with one sample per recorded tick (tau[k]: held from time_s[k] on;
        the last sample, where no action was given yet, repeats the previous input)."""
        n = len(self.rows)
        rollout = Rollout.allocate(n, uvms.nq, uvms.nv, metadata)
        commanded = rollout.signal("tau_commanded", uvms.nv)
        for k, (t, q, v, tau, tau_cmd, contact, measured, disturbance) in enumerate(self.rows):
            rollout.time_s[k] = t
            rollout.q[k] = q
            rollout.v[k] = v
            rollout.tau[k] = tau
            commanded[k] = tau_cmd
            rollout.wrench_contact_world[k] = contact
            rollout.wrench_measured_world[k] = measured
            rollout.wrench_disturbance_body[k] = disturbance
            rollout.kinetic_energy_J[k] = kinetic_energy(uvms, q, v)
            rollout.potential_energy_J[k] = potential_energy(uvms, q)
        return rollout
