"""A free object held by a link from the scenario file (``attached_to``, ``release_at_s``):
the BlueROV2 Heavy + Alpha 5 of push_object carries a 1 kg ball held by its jaw, so the
passive vehicle sinks faster than without it (it feels the payload's net weight through
the attachment); the ball keeps its place at the jaw until it is released; the run says
why it is stepped in Python; a bad link is refused naming the file, the key and the links."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from uvms_pin.errors import ScenarioError
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
#: 0.5 m from the robot: held by an invisible rigid arm, clear of every other body
BALL = {
    "type": "sphere", "name": "ball", "radius_m": 0.05, "density_kg_m3": 2000.0,
    "position_world_m": [1.4, 0.0, -9.2],
}  # fmt: skip
PASSIVE = {"controller": {"type": "none"}, "scenario.duration_s": 1.0, "world.objects": []}


def _run(ball: dict | None):
    objects = [] if ball is None else [ball]
    scenario = load_scenario(SCENARIOS / "push_object.toml", {**PASSIVE, "world.objects": objects})
    return scenario, simulate(scenario, progress=False)


def _jaw_offsets(scenario, rollout) -> np.ndarray:
    """The ball's centre in the jaw link's frame at each logged sample (T, 3) [m]."""
    model = scenario.uvms.model
    data = model.createData()
    jaw = model.frames[model.getBodyId("alpha_jaw_link")].parentJoint
    ball = rollout.signals["free_objects"][:, :3]
    out = []
    for q, centre in zip(rollout.q, ball, strict=True):
        pin.forwardKinematics(model, data, q)
        out.append(data.oMi[jaw].actInv(centre))
    return np.array(out)


def test_the_vehicle_carries_the_ball_its_jaw_holds():
    scenario, held = _run({**BALL, "attached_to": "alpha_jaw_link"})
    _, alone = _run(None)
    assert held.status.kind == "ok" and alone.status.kind == "ok"
    offsets = _jaw_offsets(scenario, held)
    assert np.max(np.abs(offsets - offsets[0])) < 1e-4
    # the ball's net weight, about 5 N, pulls the passive vehicle down
    assert held.q[-1, 2] < alone.q[-1, 2] - 1e-3
    world = held.metadata["world"]["world"]
    assert world["attachments"] == [
        {"object_name": "ball", "link": "alpha_jaw_link", "release_at_s": None, "attach_at_s": 0.0}
    ]
    assert "one compiled call" in world["integration"]  # the attachment in the core's step


def test_a_released_ball_leaves_the_jaw():
    scenario, rollout = _run({**BALL, "attached_to": "alpha_jaw_link", "release_at_s": 0.3})
    offsets = _jaw_offsets(scenario, rollout)
    before = rollout.time_s <= 0.3
    assert np.max(np.abs(offsets[before] - offsets[0])) < 1e-4
    assert np.linalg.norm(offsets[-1] - offsets[0]) > 0.05


def test_an_unknown_link_is_refused_naming_the_key_and_the_links():
    with pytest.raises(
        ScenarioError, match=r"push_object.toml: \[world\]: attached_to: 'claw'.*alpha_jaw_link"
    ):
        load_scenario(
            SCENARIOS / "push_object.toml",
            {**PASSIVE, "world.objects": [{**BALL, "attached_to": "claw"}]},
        )
