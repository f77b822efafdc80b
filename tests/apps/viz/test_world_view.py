"""The world as drawn: its objects in the static scene, one arrow per (body, object) pair
from the pair's contact point along the force, as long as the stated scale."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from viz_support import ROOT

from uvms_pin.apps.viz.meshcat_scene import Frame, SceneStyle, UvmsScene, recording_visualizer
from uvms_pin.apps.viz.world_view import WorldView
from uvms_pin.physics.world.free_object import free_object
from uvms_pin.physics.world.objects import plane, solid
from uvms_pin.physics.world.world import World

ROCK = ROOT / "scenarios" / "meshes" / "rock.obj"


@pytest.fixture(scope="module")
def world(reference_uvms):
    objects = [
        plane("seabed", [0, 0, -3], [0.1, 0, 1], 0.6, 0.5),
        solid("crate", "box", {"size_m": [1, 1, 1]}, [2, 0, -2.5], [0, 0, 0], 0.6, 0.5),
        solid(
            "pipe", "cylinder", {"radius_m": 0.2, "length_m": 3}, [0, 2, -2.8], [0, 0, 0], 0.6, 0.5
        ),
        solid("rock", "mesh", {"path": ROCK}, [-2, 0, -2.8], [0, 0, 0.3], 0.6, 0.5),
    ]
    return World(reference_uvms, objects)


def test_the_scene_draws_every_object_and_no_floor_of_its_own(reference_uvms, world):
    view = WorldView.from_record(world.record(), [0, 0, -2])
    scene = UvmsScene(reference_uvms, world=view)
    vis, window = recording_visualizer()
    scene.build(vis)
    blob = b"".join(window.commands)
    for name in (b"seabed", b"crate", b"pipe", b"rock"):
        assert b"uvms_pin/world/objects/" + name in blob
    assert b"uvms_pin/world/contacts/pair0" in blob
    assert b"uvms_pin/floor" not in blob  # the seabed is the floor
    assert "world contact forces (orange)" in scene.legend()


def test_a_pair_arrow_starts_at_its_point_and_is_scale_times_force_long(reference_uvms, world):
    view = WorldView.from_record(world.record(), [0, 0, -2])
    style = SceneStyle(world_force_scale_m_per_N=0.02)
    scene = UvmsScene(reference_uvms, world=view, style=style)
    contacts = np.zeros((len(world.pair_names), 9))
    k = 3
    contacts[k, :3] = [0.0, 30.0, 40.0]  # 50 N
    contacts[k, 3:6] = [0.5, -0.2, -2.9]
    poses = scene.poses(Frame(0.0, reference_uvms.neutral_configuration(), None, None, contacts))
    position, quat, _ = poses[f"world/contacts/pair{k}"]
    assert np.allclose(position, contacts[k, 3:6])
    along = pin.Quaternion(np.asarray(quat, dtype=float)).matrix() @ np.array([0.0, 1.0, 0.0])
    assert np.allclose(along, [0.0, 0.6, 0.8])  # the arrow points along the force
    shaft = poses[f"world/contacts/pair{k}/shaft"][2][1]
    head = 4.0 * style.arrow_radius_m
    assert shaft + head == pytest.approx(0.02 * 50.0)
    # the other pairs carry no force: their arrows are hidden
    assert np.all(poses["world/contacts/pair0"][2] < 1e-5)


def test_a_free_object_is_drawn_where_its_logged_pose_puts_it(reference_uvms, world):
    box = free_object(
        "crate2", "box", {"size_m": [0.4, 0.4, 0.4]}, ([1.0, 1.0, -2.8], [0, 0, 0]),
        mass_kg=50.0, water_density_kg_m3=1025.0,
    )  # fmt: skip
    free_world = World(reference_uvms, world.objects, world.law, [box])
    record = {**free_world.record(), "object_pairs": ["crate2|seabed"]}
    view = WorldView.from_record(record, [0, 0, -2])
    scene = UvmsScene(reference_uvms, world=view)
    vis, window = recording_visualizer()
    scene.build(vis)
    blob = b"".join(window.commands)
    assert b"uvms_pin/world/free/crate2/shape" in blob
    assert b"uvms_pin/world/contacts/object0" in blob
    q = reference_uvms.neutral_configuration()
    at_start = scene.poses(Frame(0.0, q))["world/free/crate2"]
    assert np.allclose(at_start[0], [1.0, 1.0, -2.8]) and np.allclose(at_start[1], [0, 0, 0, 1])
    turned = pin.Quaternion(pin.rpy.rpyToMatrix(0.0, 0.0, 0.5)).coeffs()
    state = np.concatenate([[2.0, 1.5, -2.75], turned, np.zeros(6)])
    pushed = np.zeros(9)
    pushed[:3], pushed[3:6] = [0.0, 0.0, 80.0], [2.0, 1.5, -2.95]
    poses = scene.poses(Frame(1.0, q, free_objects=state, object_contact=pushed))
    position, quat, _ = poses["world/free/crate2"]
    assert np.allclose(position, [2.0, 1.5, -2.75]) and np.allclose(quat, turned)
    assert np.allclose(poses["world/contacts/object0"][0], [2.0, 1.5, -2.95])


VALVE = ROOT / "models" / "fixtures" / "subsea_panel_valve.urdf"


def _valve_view(reference_uvms, rpy=(0.0, 0.0, 0.0)):
    from uvms_pin.physics.world.fixture import fixture

    panel = fixture(
        "panel", VALVE, ([0.5, -0.2, -2.0], rpy), joint_positions={"valve": 0.2},
        water_density_kg_m3=1025.0,
    )  # fmt: skip
    view = WorldView.from_record(World(reference_uvms, (), fixtures=[panel]).record(), [0, 0, -2])
    return panel, view


def test_a_fixture_is_drawn_with_its_links_at_its_logged_joint_positions(reference_uvms):
    panel, view = _valve_view(reference_uvms, (0.0, 0.0, np.pi))
    scene = UvmsScene(reference_uvms, world=view)
    vis, window = recording_visualizer()
    scene.build(vis)
    blob = b"".join(window.commands)
    assert b"uvms_pin/world/fixtures/panel/universe" in blob  # the panel, fixed in the world
    assert b"uvms_pin/world/fixtures/panel/valve" in blob  # the handle, on its joint
    q = reference_uvms.neutral_configuration()
    model, data = panel.uvms.model, panel.uvms.model.createData()
    handle = model.getJointId("valve")
    for angle in (0.0, 0.7, np.pi / 2):
        position, quat, _ = scene.poses(Frame(0.0, q, fixtures={"panel": np.array([angle])}))[
            "world/fixtures/panel/valve"
        ]
        pin.forwardKinematics(model, data, np.array([angle]))
        assert np.allclose(position, data.oMi[handle].translation)
        turned = pin.Quaternion(np.asarray(quat, dtype=float)).matrix()
        assert np.allclose(turned, data.oMi[handle].rotation)
        # the handle turns about the panel's x (world -x here): by the logged angle
        assert np.allclose(
            turned, pin.rpy.rpyToMatrix(0.0, 0.0, np.pi) @ pin.rpy.rpyToMatrix(angle, 0, 0)
        )
    # without a logged row: its initial position
    initial = scene.poses(Frame(0.0, q))["world/fixtures/panel/valve"][1]
    expected = pin.rpy.rpyToMatrix(0.0, 0.0, np.pi) @ pin.rpy.rpyToMatrix(0.2, 0, 0)
    assert np.allclose(pin.Quaternion(np.asarray(initial, dtype=float)).matrix(), expected)


def test_the_live_feed_hands_the_fixtures_joint_rows_to_the_scene(reference_uvms):
    from types import SimpleNamespace

    from uvms_pin.apps.viz.live import LiveFeed
    from uvms_pin.results.signal import Signal

    pushed = []
    feed = LiveFeed(SimpleNamespace(push=pushed.append))
    q = reference_uvms.neutral_configuration()
    sample = SimpleNamespace(
        time_s=1.0, q=q, measurement=SimpleNamespace(wrench_world=np.zeros(6)),
        signals={"panel": Signal([0.9], ["valve"], "rad")},
    )  # fmt: skip
    feed.on_sample(sample)
    _, view = _valve_view(reference_uvms)
    poses = UvmsScene(reference_uvms, world=view).poses(pushed[0])
    rotation = pin.Quaternion(np.asarray(poses["world/fixtures/panel/valve"][1])).matrix()
    assert np.allclose(rotation, pin.rpy.rpyToMatrix(0.9, 0.0, 0.0))


@pytest.mark.parametrize("stem", ["seabed_landing", "valve_panel"])
def test_a_run_from_a_relative_scenario_path_replays_from_any_folder(tmp_path, monkeypatch, stem):
    """A scenario loaded as ``scenarios/x.toml`` from the repository's folder: its mesh and
    fixture files are recorded by absolute path (they were recorded relative to that folder,
    and a replay from any other crashed in trimesh), so the replay is written from another
    working directory; a mesh gone since is named, not a traceback."""
    import json

    from uvms_pin.apps.viz.replay import write_replay
    from uvms_pin.errors import ParameterError
    from uvms_pin.results.rollout import Rollout
    from uvms_pin.scenario.load import load_scenario
    from uvms_pin.sim.run import simulate

    monkeypatch.chdir(ROOT)
    scenario = load_scenario(f"scenarios/{stem}.toml", {"scenario.duration_s": 0.1})
    simulate(scenario, progress=False).save(tmp_path / "run")
    monkeypatch.chdir(tmp_path)
    record = json.loads((tmp_path / "run" / "rollout.json").read_text())["world"]["world"]
    listed = [*record.get("objects", ()), *record.get("fixtures", ())]
    paths = [o["path"] for o in listed if "path" in o]
    assert paths and all(Path(p).is_absolute() and Path(p).is_file() for p in paths)
    write_replay(Rollout.load(tmp_path / "run"), tmp_path / "replay.html")
    assert (tmp_path / "replay.html").stat().st_size > 10_000
    if stem == "seabed_landing":
        meta = tmp_path / "run" / "rollout.json"
        meta.write_text(meta.read_text().replace(str(ROCK.resolve()), "/gone/rock.obj"))
        with pytest.raises(ParameterError, match="world object 'rock': mesh file '/gone/rock"):
            write_replay(Rollout.load(tmp_path / "run"), tmp_path / "replay2.html")
        assert not (tmp_path / "replay2.html").exists()
