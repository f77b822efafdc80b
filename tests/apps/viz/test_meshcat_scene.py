"""The scene's geometry: arrows as long as the stated scale, the spring from its anchor to
the tip, the URDF visuals where Pinocchio places them; and the example script, headless."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pinocchio as pin
import pytest
from viz_support import ROOT

from uvms_pin.apps.viz.meshcat_scene import (
    EnvironmentView,
    Frame,
    SceneStyle,
    UvmsScene,
    pose_matrix,
    recording_visualizer,
)
from uvms_pin.apps.viz.robot_view import piece_placement
from uvms_pin.errors import VizError


@pytest.fixture(scope="module")
def scene(reference_uvms):
    q = reference_uvms.neutral_configuration()
    tip = UvmsScene(reference_uvms).ee_position(q)
    env = EnvironmentView.from_record({"type": "spring", "anchor_world_m": None}, tip)
    return UvmsScene(
        reference_uvms,
        environment=env,
        current_world_m_s=[0.3, 0.1, 0.0],
        show_desired=True,
        style=SceneStyle(force_scale_m_per_N=0.25),
    )


def _tip_of_arrow(poses, path) -> np.ndarray:
    """World point of the arrow's head tip."""
    group = pose_matrix(poses[path])
    head = poses[f"{path}/head"]
    head_len = 4.0 * SceneStyle().arrow_radius_m * head[2][1]
    return (group @ np.array([0.0, head[0][1] + 0.5 * head_len, 0.0, 1.0]))[:3]


def test_force_arrows_start_at_the_tip_and_are_scale_times_force_long(scene, reference_uvms):
    q = reference_uvms.neutral_configuration()
    q[8] = 0.4
    force = np.array([0.6, -0.2, 0.3])
    poses = scene.poses(Frame(0.0, q, force, np.array([0.8, 0.0, 0.0])))
    tip = scene.ee_position(q)
    np.testing.assert_allclose(poses["forces/measured"][0], tip)
    np.testing.assert_allclose(_tip_of_arrow(poses, "forces/measured"), tip + 0.25 * force)
    np.testing.assert_allclose(
        _tip_of_arrow(poses, "forces/desired"), tip + np.array([0.2, 0.0, 0.0]), atol=1e-12
    )
    # the current arrow: 1 m per m/s, above the vehicle
    np.testing.assert_allclose(
        _tip_of_arrow(poses, "current") - poses["current"][0], [0.3, 0.1, 0.0], atol=1e-12
    )


def test_zero_or_missing_force_hides_the_arrow(scene, reference_uvms):
    q = reference_uvms.neutral_configuration()
    poses = scene.poses(Frame(0.0, q, np.zeros(3), None))
    for path in ("forces/measured", "forces/desired"):
        assert np.all(poses[path][2] < 1e-5)


def test_the_spring_runs_from_its_anchor_to_the_tip(scene, reference_uvms):
    q = reference_uvms.neutral_configuration()
    q[:3] = [0.1, -0.05, 0.02]
    poses = scene.poses(Frame(0.0, q))
    spring = pose_matrix(poses["environment/spring"])
    np.testing.assert_allclose(spring @ [0, 0, 0, 1], [*scene.environment.point_world_m, 1])
    np.testing.assert_allclose((spring @ [0, 1, 0, 1])[:3], scene.ee_position(q), atol=1e-12)


def test_visuals_are_placed_as_pinocchio_places_them(scene, reference_uvms):
    """Each piece is drawn at its body's pose times its fixed placement (scale included):
    where Pinocchio places it."""
    model = reference_uvms.model
    q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
    poses = scene.poses(Frame(0.0, q))
    visuals = scene.geometry["visuals"]
    data = model.createData()
    geom_data = pin.GeometryData(visuals)
    pin.forwardKinematics(model, data, q)
    pin.updateGeometryPlacements(model, data, visuals, geom_data)
    assert len(visuals.geometryObjects) >= 10
    for k, obj in enumerate(visuals.geometryObjects):
        body = pose_matrix(poses[f"robot/visuals/{model.names[obj.parentJoint]}"])
        expected = geom_data.oMg[k].homogeneous
        expected[:3, :3] *= np.asarray(obj.meshScale)[None, :]
        np.testing.assert_allclose(body @ piece_placement(obj), expected, atol=1e-12)


def test_the_static_scene_draws_the_robot_and_the_environment(scene):
    vis, window = recording_visualizer()
    scene.build(vis)
    blob = b"".join(window.commands)
    for path in (
        b"/meshcat/uvms_pin/robot/visuals/root_joint/base_link_0",
        b"environment/anchor",
        b"floor",
    ):
        assert path in blob


def test_a_model_without_urdf_file_is_a_clear_error(reference_uvms):
    uvms = reference_uvms.copy()
    uvms.source = "mount_arm(a + b)"
    with pytest.raises(VizError, match="no URDF file"):
        UvmsScene(uvms)


def test_show_model_script_runs_headless(tmp_path):
    out = tmp_path / "model.html"
    result = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "show_model.py"), "--html", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    text = out.read_text()
    assert "base_link_0" not in text  # commands are msgpack/base64, the page is one file
    assert "MeshCat.Viewer" in text and len(text) > 500_000
