"""Whether a valve was turned (scenarios/valve_turn.toml), from the rollout:
``[metrics] extra = ["valve_turn_metrics:valve"]``.

The valve is the fixture joint logged as ``panel.valve_rad`` (the fixture named ``panel``,
its joint ``valve``).

- ``valve_turned_rad``: the valve's angle at the end less its angle at the start [rad].
- ``valve_turned_max_rad``: the largest such angle over the run [rad].
- ``turned``: 1 when ``valve_turned_rad`` >= 0.95 pi/2 (a quarter turn), 0 otherwise.
- ``contact_force_peak_N``: the largest total contact force on the UVMS [N]
  (`uvms_pin.results.metrics.world_contact_metrics`).
"""

from __future__ import annotations

import math

import numpy as np

from uvms_pin.results.metrics import world_contact_metrics

FIXTURE = "panel"
JOINT = "valve"
QUARTER_TURN_RAD = math.pi / 2
TURNED_FRACTION = 0.95


def _valve_rad(rollout) -> np.ndarray:
    components = (rollout.metadata.get("signal_units", {}).get(FIXTURE) or {}).get("components")
    if not components or JOINT not in components:  # the world's objects changed
        raise ValueError(f"no fixture {FIXTURE!r} with a joint {JOINT!r} in the rollout's world")
    return np.asarray(rollout.signals[FIXTURE])[:, components.index(JOINT)]


def valve(rollout) -> dict[str, float]:
    """The metrics of the module docstring."""
    angle = _valve_rad(rollout)
    turned = float(angle[-1] - angle[0])
    contacts = world_contact_metrics(rollout)
    return {
        "valve_turned_rad": turned,
        "valve_turned_max_rad": float(np.max(angle - angle[0])),
        "turned": float(turned >= TURNED_FRACTION * QUARTER_TURN_RAD),
        "contact_force_peak_N": contacts.get("world_contact_force_peak_N", 0.0),
    }
