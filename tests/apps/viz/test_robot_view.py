"""The robot as drawn: every URDF <visual> element (primitives with their colours, meshes) in
its body's node, the collision shapes on request, one animation track per moving body, and
the BlueROV2 Heavy + Alpha 5 replay within its size bound."""

from __future__ import annotations

import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import umsgpack
from PIL import Image
from viz_support import ROOT, SCENARIOS

import uvms_pin as up
from uvms_pin.apps.viz.meshcat_scene import Frame, UvmsScene, recording_visualizer
from uvms_pin.apps.viz.replay import write_replay
from uvms_pin.apps.viz.robot_view import moving_bodies, piece_placement
from uvms_pin.errors import ModelWarning, VizError
from uvms_pin.model.vehicles.bluerov2_heavy import thrusters
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

BLUEROV_ALPHA5 = ROOT / "models" / "uvms_bluerov2_alpha5.urdf"
T200_RGBA = (0.18, 0.18, 0.20, 1.0)  # models/derive_bluerov_alpha5.py
# the 10 s force-tracking replay (scenarios/bluerov_alpha5_force_tracking.toml) was 1.84 MB
# when the vehicle was one translucent box and the arm five balls; at most 1.5x that now
BOX_AND_BALLS_REPLAY_BYTES = 1_836_170


@pytest.fixture(scope="module")
def bluerov():
    return up.load_uvms(BLUEROV_ALPHA5)


def _urdf_elements(path, tag: str) -> dict[str, int]:
    """Number of ``tag`` elements (visual, collision) per link of a URDF file."""
    return {
        link.get("name"): len(link.findall(tag))
        for link in ET.parse(path).getroot().iter("link")
        if link.findall(tag)
    }


def _objects(scene: UvmsScene) -> dict[str, dict]:
    """The objects the scene's build sends, by path: {path: set_object command}."""
    vis, window = recording_visualizer()
    scene.build(vis)
    commands = [umsgpack.unpackb(c) for c in window.commands]
    return {c["path"]: c for c in commands if c["type"] == "set_object"}


def test_every_visual_element_of_the_urdf_is_drawn_in_its_body(bluerov):
    scene = UvmsScene(bluerov)
    objects = _objects(scene)
    drawn = [p for p in objects if "/robot/visuals/" in p]
    assert len(drawn) == sum(_urdf_elements(BLUEROV_ALPHA5, "visual").values()) >= 30
    assert not any("/robot/collisions/" in p for p in objects)  # not asked for
    visuals = scene.geometry["visuals"]
    model = bluerov.model
    for obj in visuals.geometryObjects:
        assert f"/meshcat/uvms_pin/robot/visuals/{model.names[obj.parentJoint]}/{obj.name}" in drawn
    # the vehicle is no box: 21 pieces, among them a T200 along each thruster's axis
    hull = [o for o in visuals.geometryObjects if o.name.startswith("base_link_")]
    assert len(hull) == 21
    t200 = [o for o in hull if np.allclose(o.meshColor, T200_RGBA)]
    assert len(t200) == 8
    for thruster in thrusters():
        matches = [
            o
            for o in t200
            if np.allclose(o.placement.translation, thruster.position_body_m)
            and abs(o.placement.rotation[:, 2] @ thruster.direction_body) > 1 - 1e-9
        ]
        assert len(matches) == 1, thruster.name
    # each link of the arm has its housings, drawn in the URDF's colour (not the default)
    for joint in ("alpha_axis_e", "alpha_axis_d", "alpha_axis_c", "alpha_axis_b"):
        pieces = [
            o
            for o in visuals.geometryObjects
            if model.names[o.parentJoint] == joint and o.name.startswith("alpha_")
        ]
        assert pieces and all(np.allclose(o.meshColor[:3], 0.1, atol=0.02) for o in pieces)


def test_collision_shapes_are_a_toggle(bluerov):
    collisions = sum(_urdf_elements(BLUEROV_ALPHA5, "collision").values())
    only = UvmsScene(bluerov, show="collision")
    objects = _objects(only)
    assert sum("/robot/collisions/" in p for p in objects) == collisions >= 2
    assert not any("/robot/visuals/" in p for p in objects)
    assert "collision shapes" in only.legend()
    both = _objects(UvmsScene(bluerov, show="both"))
    assert sum("/robot/collisions/" in p for p in both) == collisions
    assert sum("/robot/visuals/" in p for p in both) == sum(
        _urdf_elements(BLUEROV_ALPHA5, "visual").values()
    )
    with pytest.raises(VizError, match="show='meshes'"):
        UvmsScene(bluerov, show="meshes")


def test_one_animation_track_per_moving_body_not_per_piece(bluerov):
    scene = UvmsScene(bluerov, show="both")
    q = bluerov.neutral_configuration()
    q[7:11] = [-0.2, 0.8, 2.2, 0.2]
    poses = scene.poses(Frame(0.0, q))
    robot = sorted(p for p in poses if p.startswith("robot/"))
    bodies = [
        bluerov.model.names[j] for j in moving_bodies(bluerov.model, scene.geometry["visuals"])
    ]
    assert bodies == ["root_joint", "alpha_axis_e", "alpha_axis_d", "alpha_axis_c", "alpha_axis_b"]
    assert robot == sorted(
        [f"robot/visuals/{b}" for b in bodies]
        + ["robot/collisions/root_joint"]
        + ["robot/collisions/alpha_axis_b"]  # the probe (tool) merged into the wrist
    )
    assert len(scene.geometry["visuals"].geometryObjects) > 6 * len(bodies)


def test_a_mesh_visual_is_drawn_from_its_file_at_its_scale(tmp_path):
    """A URDF <mesh> (here the rock the project ships, scaled) is sent as the file's mesh,
    placed and scaled in its body's node."""
    rock = SCENARIOS / "meshes" / "rock.obj"
    text = (ROOT / "models" / "bluerov2_heavy.urdf").read_text()
    mesh = (
        '<visual><origin xyz="0.1 0 0.2" rpy="0 0 0.5"/><geometry>'
        f'<mesh filename="{rock}" scale="0.5 0.25 0.2"/></geometry></visual>\n  </link>'
    )
    urdf = tmp_path / "rov_with_mesh.urdf"
    urdf.write_text(text.replace("</link>", mesh, 1))
    uvms = up.load_uvms(urdf, ee_frame="base_link", sensor_frame="base_link")
    scene = UvmsScene(uvms)
    (obj,) = [
        o for o in scene.geometry["visuals"].geometryObjects if o.meshPath.endswith("rock.obj")
    ]
    vis, window = recording_visualizer()
    scene.build(vis)
    commands = [umsgpack.unpackb(c) for c in window.commands]
    path = f"/meshcat/uvms_pin/robot/visuals/root_joint/{obj.name}"
    (drawn,) = [c for c in commands if c["type"] == "set_object" and c["path"] == path]
    assert drawn["object"]["geometries"][0]["format"] == "obj"  # the file itself, inlined
    assert rock.read_bytes()[:200] in drawn["object"]["geometries"][0]["data"].encode()
    (placed,) = [c for c in commands if c["type"] == "set_transform" and c["path"] == path]
    matrix = np.array(placed["matrix"], dtype=float).reshape(4, 4).T  # column-major
    np.testing.assert_allclose(matrix, piece_placement(obj), atol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(matrix[:3, :3], axis=0), [0.5, 0.25, 0.2])


def test_a_relative_mesh_visual_is_found_from_the_urdfs_folder_as_the_loader_finds_it(
    tmp_path, monkeypatch
):
    """pinocchio looks a relative mesh up in its package directories only: the URDF's folder
    is one, so a model whose visuals sit beside it draws from any working directory; a
    visual mesh it cannot find is left out, named in a warning (the rest is drawn), one it
    cannot read is a VizError naming the URDF, not a ValueError."""
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "rock.obj").write_bytes((SCENARIOS / "meshes" / "rock.obj").read_bytes())
    text = (ROOT / "models" / "bluerov2_heavy.urdf").read_text()
    mesh = '<visual><geometry><mesh filename="{}"/></geometry></visual>\n  </link>'
    urdf = tmp_path / "rov.urdf"
    urdf.write_text(text.replace("</link>", mesh.format("meshes/rock.obj"), 1))
    monkeypatch.chdir(ROOT)
    uvms = up.load_uvms(urdf, ee_frame="base_link", sensor_frame="base_link")
    paths = [o.meshPath for o in UvmsScene(uvms).geometry["visuals"].geometryObjects]
    assert str(tmp_path / "meshes" / "rock.obj") in [str(Path(p).resolve()) for p in paths]
    drawn = len(paths)
    urdf.write_text(text.replace("</link>", mesh.format("meshes/none.obj"), 1))
    uvms = up.load_uvms(urdf, ee_frame="base_link", sensor_frame="base_link")
    with pytest.warns(ModelWarning, match=r"1 visual mesh file\(s\) not found.*meshes/none\.obj"):
        scene = UvmsScene(uvms)
    assert len(scene.geometry["visuals"].geometryObjects) == drawn - 1
    (tmp_path / "meshes" / "broken.obj").write_text("not a mesh")
    urdf.write_text(text.replace("</link>", mesh.format("meshes/broken.obj"), 1))
    uvms = up.load_uvms(urdf, ee_frame="base_link", sensor_frame="base_link")
    with pytest.raises(VizError, match=r"(?s)rov\.urdf: cannot draw its visuals: .*broken\.obj"):
        UvmsScene(uvms)


def test_a_link_whose_visual_meshes_are_all_missing_is_drawn_by_its_collision_shapes(tmp_path):
    """An imported model whose meshes stayed behind (uuv_simulator's RexROV: one mesh per
    link) is drawn by its collision boxes, not as nothing."""
    urdf = tmp_path / "v.urdf"
    urdf.write_text(
        '<robot name="v"><link name="base_link">'
        '<inertial><mass value="10"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>'
        "</inertial>"
        '<visual><geometry><mesh filename="file:///nowhere/hull.dae"/></geometry></visual>'
        '<collision><origin xyz="0 0 0.1" rpy="0 0 0"/><geometry><box size="1 0.5 0.4"/>'
        "</geometry></collision>"
        '<hydrodynamics><volume value="0.01"/></hydrodynamics>'
        "</link></robot>"
    )
    uvms = up.load_uvms(urdf)
    with pytest.warns(ModelWarning, match=r"hull\.dae.*1 collision shape\(s\) drawn"):
        scene = UvmsScene(uvms)
    (piece,) = scene.geometry["visuals"].geometryObjects
    np.testing.assert_allclose(piece.placement.translation, [0.0, 0.0, 0.1])
    assert piece.geometry.halfSide.tolist() == [0.5, 0.25, 0.2]


@pytest.fixture(scope="module")
def bluerov_replay(tmp_path_factory):
    """The replay page of scenarios/bluerov_alpha5_force_tracking.toml (10 s)."""
    rollout = simulate(load_scenario(SCENARIOS / "bluerov_alpha5_force_tracking.toml"))
    path = tmp_path_factory.mktemp("bluerov") / "replay.html"
    return write_replay(rollout, path)


def test_the_bluerov_alpha5_replay_stays_within_its_size_bound(bluerov_replay):
    assert bluerov_replay.stat().st_size <= 1.5 * BOX_AND_BALLS_REPLAY_BYTES


def test_the_replay_shows_a_bluerov2_with_an_arm_in_a_browser(bluerov_replay, tmp_path):
    """At a close camera (behind the vehicle's left, as docs/replay_bluerov_alpha5.png): the
    black frame and thrusters and the blue foam cover the screen as they do not for a box."""
    from viz_support import HeadlessPage

    page = HeadlessPage(1000, 640)  # skips without chromium
    try:
        page.open(bluerov_replay.as_uri(), "viewer.animator.actions.length > 0")
        page.evaluate("animator.pause(); seek(5.0); true")
        page.evaluate(
            "viewer.set_transform(['meshcat', 'uvms_pin'], "
            "[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -0.25, 0.05, 2.0, 1]); "
            "viewer.camera.position.set(0.75, 0.35, -0.85); viewer.controls.update(); true"
        )
        page.next_frames(8)
        image = np.asarray(Image.open(page.screenshot(tmp_path / "rov.png")).convert("RGB"))
    finally:
        page.close()
    r, g, b = (image[..., k].astype(float) for k in range(3))
    foam = (b > 140) & (b > 1.8 * g) & (r < 80)
    black = (r < 30) & (g < 30) & (b < 35)
    # measured 4062 and 13908 here; the box and balls gave 2302 and 4641
    assert foam.sum() > 3000
    assert black.sum() > 9000


def test_show_is_a_run_and_replay_option(tmp_path):
    from viz_support import short_scenario

    from uvms_pin.apps.cli.main import main

    scenario = short_scenario(tmp_path, 0.2)
    out = tmp_path / "run"
    assert main(["run", str(scenario), "--out", str(out), "--html", "--show", "both"]) == 0
    assert "collision shapes (translucent orange)" in (out / "replay.html").read_text()
    page = tmp_path / "visual.html"
    assert main(["replay", str(out), "--html", "--out", str(page)]) == 0
    assert "collision shapes" not in page.read_text()
    with pytest.raises(SystemExit):
        main(["replay", str(out), "--html", "--show", "meshes"])


DRAW_IN_A_FRESH_PROCESS = """
import sys
from pathlib import Path
import uvms_pin as up
from uvms_pin.apps.viz.meshcat_scene import recording_visualizer
from uvms_pin.apps.viz.robot_view import draw_bodies, geometry_groups
{before}
urdf = Path({urdf!r})
uvms = up.load_uvms(urdf)
geometry = geometry_groups(uvms.model, urdf, "visual")["visuals"]
viewer, window = recording_visualizer()
draw_bodies(viewer, uvms.model, geometry)
assert window.commands, "nothing drawn"
print(sorted(m for m in ("networkx", "trimesh") if m in sys.modules))
import trimesh  # importable again after the drawing
print(type(sys.modules["trimesh"]).__name__)
"""


@pytest.mark.parametrize(
    ("before", "viser", "imported"),
    [
        ("", False, "[]"),
        ("import trimesh", False, "['networkx', 'trimesh']"),
        ("", True, "['networkx', 'trimesh']"),  # viser importable: its viewer left whole
    ],
)
def test_drawing_the_robot_does_not_import_trimesh_for_pinocchios_viser_viewer(
    before, viser, imported, tmp_path
):
    """pinocchio.visualize's viser viewer would import trimesh (with scipy.spatial and
    networkx: 0.7 s) only to find viser missing: drawing the robot imports none of trimesh,
    and leaves a trimesh imported before (a mesh object's) and trimesh's import as they
    were. With viser importable (here a stand-in package), pinocchio's viewer is imported
    as pinocchio imports it."""
    env = dict(os.environ)
    if viser:
        (tmp_path / "viser").mkdir()
        (tmp_path / "viser" / "__init__.py").write_text("")
        env["PYTHONPATH"] = os.pathsep.join([str(tmp_path), env.get("PYTHONPATH", "")])
    code = DRAW_IN_A_FRESH_PROCESS.format(before=before, urdf=str(BLUEROV_ALPHA5))
    done = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
        env=env,
    )
    assert done.returncode == 0, done.stderr
    found, module = done.stdout.split("\n")[:2]
    assert found == imported
    assert module == "module"
