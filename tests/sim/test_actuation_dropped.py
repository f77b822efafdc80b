"""Wrench components no thruster can produce: the least-squares allocation drops them without
a word, so a run says so once, naming them with the largest value dropped and the
``allocated_components`` that would state it; a scenario that states it hears nothing."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from conftest import ROOT

from uvms_pin.errors import ActuationWarning
from uvms_pin.model.thruster import Thruster
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.actuation import ThrustersAndJointLimits
from uvms_pin.sim.run import simulate

REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"


def _box_rov() -> list[Thruster]:
    """Six thrusters through the centre: surge, sway, heave and yaw only (no roll, pitch)."""

    def t(name, r, d):
        return Thruster(name, np.array(r, float), np.array(d, float), 50.0, 40.0)

    return [
        t("aft_port", [-0.2, 0.1, 0.0], [1, 0, 0]),
        t("aft_starboard", [-0.2, -0.1, 0.0], [1, 0, 0]),
        t("lateral", [0.0, 0.0, 0.0], [0, 1, 0]),
        t("vertical", [0.0, 0.0, 0.0], [0, 0, 1]),
        t("lateral_2", [0.1, 0.0, 0.0], [0, 1, 0]),
        t("vertical_2", [0.0, 0.0, 0.0], [0, 0, -1]),
    ]


def test_the_largest_dropped_pitch_is_reported_with_the_components_to_state():
    actuation = ThrustersAndJointLimits(_box_rov(), None)
    actuation.start()
    for pitch in (1.0, -5.7, 3.0):
        applied = actuation.apply(np.array([1.0, 0.0, 0.0, 0.0, pitch, 0.5]))
        assert abs(applied[4]) < 1e-12  # no thrust makes pitch: it vanished
    message = actuation.dropped()
    assert message is not None
    assert "dropped up to 5.7 N m of pitch moment my" in message
    assert "allocated_components = [0, 1, 2, 5]" in message
    actuation.start()  # a new run forgets the old one
    assert actuation.dropped() is None


def test_a_stated_allocation_is_silent():
    actuation = ThrustersAndJointLimits(_box_rov(), None, allocated_components=[0, 1, 2, 5])
    actuation.apply(np.array([1.0, 0.0, 0.0, 2.0, 5.7, 0.5]))
    assert actuation.dropped() is None


def test_a_run_warns_once(tmp_path):
    text = REALISTIC.read_text().replace("allocated_components = [0, 1, 2, 5]\n", "")
    path = tmp_path / "default_allocation.toml"
    path.write_text(text.replace('"uvms_lbv150"', f'"{ROOT / "models" / "uvms_lbv150.urdf"}"'))
    for scenario, expected in ((path, 1), (REALISTIC, 0)):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            simulate(load_scenario(scenario, {"scenario.duration_s": 0.1}), progress=False)
        found = [str(w.message) for w in caught if issubclass(w.category, ActuationWarning)]
        assert len(found) == expected, found
        assert all("of pitch moment my" in text for text in found)


@pytest.mark.parametrize("components", [[0, 1, 2, 3, 4, 5]])
def test_thrusters_that_produce_everything_track_nothing(components):
    from uvms_pin.model.vehicles.bluerov2_heavy import thrusters

    actuation = ThrustersAndJointLimits(thrusters(), None, components)
    actuation.apply(np.array([1.0, 2.0, 3.0, 0.4, 0.5, 0.6]))
    assert actuation.dropped() is None
