"""objects.png: the free objects' positions, the contact forces on them and the jaw's fingers,
for runs with free objects; contacts.png: the contact force on the UVMS per object of the
world; metrics.json: each free object's displacement."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT
from matplotlib.figure import Figure

import uvms_pin as up
from uvms_pin.results.figures.objects import objects_figures, plot_contacts, plot_objects
from uvms_pin.results.free_objects import force_on_object_N, free_object_summary


@pytest.fixture(scope="module")
def pushed():
    """push_object until the box has slid a little (the arm meets it near 5.5 s)."""
    scenario = up.load_scenario(
        ROOT / "scenarios" / "push_object.toml", {"scenario.duration_s": 7.0}
    )
    return up.simulate(scenario, progress=False)


def test_a_run_with_a_jaw_and_a_rod_gets_positions_forces_and_fingers(tmp_path):
    scenario = up.load_scenario(
        ROOT / "scenarios" / "gripper_close.toml", {"scenario.duration_s": 0.05}
    )
    rollout = up.simulate(scenario, progress=False)
    fig = plot_objects(rollout)
    assert isinstance(fig, Figure) and len(fig.axes) == 3
    positions, forces, fingers = fig.axes
    assert [line.get_label().split(" (")[0] for line in positions.get_lines()] == [
        "rod x",
        "rod y",
        "rod z",
    ]
    assert len(forces.get_lines()) == 2
    assert len(fingers.get_lines()) == 2  # one per finger, not their grip forces
    paths = objects_figures(rollout, tmp_path)
    assert [p.name for p in paths] == ["objects.png", "contacts.png"]
    assert all(p.stat().st_size > 1000 for p in paths)


def test_the_box_positions_and_forces_drawn_are_the_logged_ones(pushed):
    fig = plot_objects(pushed)
    positions, forces = fig.axes
    x = positions.get_lines()[0].get_ydata()
    box = pushed.signals["free_objects"]
    np.testing.assert_array_equal(x, box[:, 0] - box[0, 0])
    assert x[-1] > 0.02  # pushed forward
    push = np.linalg.norm(
        force_on_object_N(pushed, "world_contact", "world_contact_pairs", "box"), axis=1
    )
    np.testing.assert_array_equal(forces.get_lines()[0].get_ydata(), push)
    assert push[pushed.time_s < 5.0].max() == 0.0 and push.max() > 10.0
    # the seabed carries the box's net weight (34.375 kg less its displaced water) before the push
    seabed = forces.get_lines()[1].get_ydata()
    rho, volume = 1025.0, 0.25 * 0.5 * 0.25
    net = (34.375 - rho * volume) * 9.81
    assert seabed[(pushed.time_s > 1.0) & (pushed.time_s < 5.0)] == pytest.approx(net, rel=0.01)


def test_the_contact_figure_sums_the_uvms_pieces_per_object(pushed):
    fig = plot_contacts(pushed)
    labels = [line.get_label() for line in fig.axes[0].get_lines()]
    assert labels == ["from seabed", "from box", "total"]
    from_box = fig.axes[0].get_lines()[1].get_ydata()
    np.testing.assert_allclose(
        from_box,
        np.linalg.norm(
            force_on_object_N(pushed, "world_contact", "world_contact_pairs", "box"), axis=1
        ),
        rtol=1e-12,
        atol=1e-12,
    )


def test_metrics_hold_each_free_objects_displacement(pushed):
    metrics = pushed.metrics()
    box = pushed.signals["free_objects"]
    assert metrics["object_box_displacement_m"] == pytest.approx(
        np.linalg.norm(box[-1, :3] - box[0, :3]), rel=1e-15
    )
    assert metrics["object_box_displacement_m"] > 0.02
    assert metrics["object_box_max_speed_m_s"] == pytest.approx(
        np.linalg.norm(box[:, 7:10], axis=1).max(), rel=1e-15
    )
    summary = free_object_summary(pushed)["box"]  # where it ended: its last sample's x y z
    assert [summary[f"final_{a}_m"] for a in "xyz"] == box[-1, :3].tolist()
    assert len({round(v, 6) for v in box[-1, :3]}) == 3  # three different numbers: no mix-up


def test_a_run_without_a_world_gets_none(tmp_path):
    scenario = up.load_scenario(
        ROOT / "scenarios" / "passive_still_water.toml", {"scenario.duration_s": 0.1}
    )
    rollout = up.simulate(scenario, progress=False)
    assert objects_figures(rollout, tmp_path) == []
    assert not any(key.startswith("object_") for key in rollout.metrics())
