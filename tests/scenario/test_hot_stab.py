"""scenarios/hot_stab.toml: the BlueROV2 Heavy + Alpha 5 inserts a stab held in its jaw into
a hot-stab receptacle (a 25 mm stab, 1.5 mm radial clearance, 150 mm deep, a 45 degree
chamfer) to full depth, aiming 4 mm off the bore's axis; its own metrics
(scenarios/hot_stab_metrics.py) say whether it did. The metrics on made-up rollouts, then the
shipped run and the runs made impossible (a grip too weak to carry the stab, a push budget
too small to make the chamfer centre it)."""

from __future__ import annotations

import math
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pinocchio as pin
import pytest

import uvms_pin as up

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
SCENARIO = SCENARIOS / "hot_stab.toml"
JAWS = SCENARIOS.parent / "models" / "uvms_bluerov2_alpha5_jaws.urdf"
LENGTH_M = 0.38
MOUTH = np.array([0.75, -0.1, -2.25])


@pytest.fixture(scope="module")
def metrics_module():
    sys.path.insert(0, str(SCENARIOS))
    try:
        import hot_stab_metrics
    finally:
        sys.path.remove(str(SCENARIOS))
    return hot_stab_metrics


def _rollout(tips_world_m: np.ndarray, centre_shift_m: np.ndarray | None = None, force_N=0.0):
    """A made-up rollout: the stab along world +x with its tip at each of ``tips_world_m``,
    the vehicle (level, its arm at its neutral configuration) moving with it, the
    receptacle's bore along +x from MOUTH; ``centre_shift_m`` (n, 3) moves the stab's centre
    (not the vehicle) by as much."""
    n = len(tips_world_m)
    states = np.zeros((n, 13))
    along_x = pin.Quaternion(pin.rpy.rpyToMatrix(0.0, np.pi / 2, 0.0)).coeffs()  # z -> +x
    states[:, :3] = tips_world_m - [LENGTH_M / 2, 0.0, 0.0]
    states[:, 3:7] = along_x
    if centre_shift_m is not None:
        states[:, :3] += centre_shift_m
    contact = np.zeros((n, 2, 9))
    contact[:, 1, 2] = force_N  # the stab on the receptacle's second piece
    contact[:, 0, 1] = 100.0  # a pair that is not the stab's with the receptacle
    world = {
        "free_objects": [{"name": "stab", "length_m": LENGTH_M}],
        "fixtures": [{"name": "receptacle", "position_world_m": MOUTH.tolist(),
                      "rpy_rad": [0.0, 0.0, math.pi]}],
        "object_pairs": ["stab|seabed", "stab|receptacle.receptacle#1"],
    }  # fmt: skip
    components = [f"stab_{c}" for c in ("x y z qx qy qz qw u v w p q r".split())]
    q = np.tile(up.load_uvms(JAWS).neutral_configuration(), (n, 1))
    q[:, :3] += tips_world_m - tips_world_m[0]
    return SimpleNamespace(
        time_s=np.linspace(0.0, 10.0, n),
        q=q,
        signals={"free_objects": states, "free_object_contact": contact.reshape(n, -1)},
        metadata={
            "world": {"world": world},
            "signal_units": {"free_objects": {"components": components}},
            "model_source": str(JAWS),
        },
    )


def _path(depths_m, lateral_m):
    return np.array(
        [MOUTH + np.array([d, y, 0.0]) for d, y in zip(depths_m, lateral_m, strict=True)]
    )


def test_a_stab_at_full_depth_is_inserted_and_its_offsets_are_read_at_the_mouth(metrics_module):
    depths = [-0.1, -0.012, -0.008, -0.004, 0.001, 0.05, 0.148]
    lateral = [0.004, 0.004, 0.0035, 0.002, 0.001, 0.0005, 0.0002]
    m = metrics_module.insertion(_rollout(_path(depths, lateral), force_N=7.5))
    assert m["inserted"] == 1.0
    assert m["insertion_depth_m"] == pytest.approx(0.148)
    assert m["insertion_depth_max_m"] == pytest.approx(0.148)
    assert m["mouth_offset_m"] == pytest.approx(0.0035)  # first at the chamfer's edge
    assert m["bore_offset_m"] == pytest.approx(0.001)  # first past the chamfer
    assert m["contact_force_peak_N"] == pytest.approx(7.5)  # the other pair left out
    assert m["stab_slipped"] == 0.0 and m["stab_slip_m"] == pytest.approx(0.0, abs=1e-9)


def test_a_stab_short_of_full_depth_or_slipping_in_the_jaw_is_said_so(metrics_module):
    depths = [-0.1, -0.02, 0.0, 0.1, 0.14]  # 10 mm short
    m = metrics_module.insertion(_rollout(_path(depths, [0.0] * 5)))
    assert m["inserted"] == 0.0 and m["insertion_depth_m"] == pytest.approx(0.14)
    assert m["contact_force_peak_N"] == 0.0
    # never at the mouth: the offsets at its deepest
    m = metrics_module.insertion(_rollout(_path([-0.2, -0.1, -0.15], [0.06, 0.05, 0.04])))
    assert m["inserted"] == 0.0 and m["mouth_offset_m"] == pytest.approx(0.05)
    # the centre moves 8 mm in the jaw after the jaw has settled: slipped
    shift = np.zeros((5, 3))
    shift[3:, 0] = -0.008
    m = metrics_module.insertion(_rollout(_path(depths, [0.0] * 5), centre_shift_m=shift))
    assert m["stab_slipped"] == 1.0 and m["stab_slip_m"] == pytest.approx(0.008)
    assert m["stab_shift_m"] == pytest.approx(0.0, abs=1e-9)
    # 6 mm sideways between the fingers: a shift, not a slip; 30 mm: out of the jaw
    for across, slipped in ((0.006, 0.0), (0.03, 1.0)):
        shift = np.zeros((5, 3))
        shift[3:, 1] = across
        m = metrics_module.insertion(_rollout(_path(depths, [0.0] * 5), centre_shift_m=shift))
        assert m["stab_shift_m"] == pytest.approx(across)
        assert m["stab_slip_m"] == pytest.approx(0.0, abs=1e-9)
        assert m["stab_slipped"] == slipped


def _metrics(**overrides) -> dict[str, float]:
    rollout = up.simulate(up.load_scenario(SCENARIO, overrides=overrides))
    assert rollout.metadata["status"] == "ok"
    return rollout.metrics()


def test_the_stab_is_inserted_to_full_depth_the_chamfer_taking_the_aim_error():
    m = _metrics()
    assert m["inserted"] == 1.0
    assert m["insertion_depth_m"] == pytest.approx(0.15, abs=0.002)
    # it met the chamfer 4-7 mm off the bore's axis and went in within the 1.5 mm clearance
    assert 0.004 < m["mouth_offset_m"] < 0.008
    assert m["bore_offset_m"] < 0.0015
    assert m["stab_slipped"] == 0.0 and m["stab_slip_m"] < 0.005
    assert 1.0 < m["contact_force_peak_N"] < 20.0  # within the push budget
    assert m["energy_max_increase_J"] < 0.05


def test_a_grip_too_weak_for_the_stab_drops_it_and_nothing_is_inserted():
    # 0.2 N per finger: 2 mu F = 0.2 N at most, the stab's net weight
    # (1400 - 1025) kg/m^3 x pi 0.0125^2 x 0.38 m^3 x g = 0.69 N; it falls in the approach
    net_weight_N = (1400 - 1025) * math.pi * 0.0125**2 * 0.38 * 9.81
    assert 2 * 0.5 * 0.2 < net_weight_N
    m = _metrics(**{"gripper.max_force_N": 0.2, "scenario.duration_s": 6.0})
    assert m["inserted"] == 0.0 and m["stab_slipped"] == 1.0
    assert m["insertion_depth_max_m"] < -0.05  # never near the mouth
    assert m["contact_force_peak_N"] == 0.0


def test_a_push_budget_too_small_leaves_the_stab_short_of_full_depth():
    m = _metrics(**{"controller.max_push_N": 0.3})
    assert m["inserted"] == 0.0
    assert m["insertion_depth_m"] < 0.1
    assert m["stab_slipped"] == 0.0  # held, only pushed too softly
