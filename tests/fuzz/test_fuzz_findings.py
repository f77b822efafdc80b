"""What the generated inputs found, each kept as a plain test: the input, reduced, and the
documented error it now gets (before: the exception or crash named in each docstring)."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest
from fuzz_bounds import ROOT

from uvms_pin.errors import ModelError, ParameterError, ScenarioError, SimulationError
from uvms_pin.model.importer.convert import import_model
from uvms_pin.model.urdf.loaded import loaded_uvms
from uvms_pin.physics.dynamics import (
    bias_forces,
    forward_dynamics,
    forward_dynamics_derivatives,
    frame_wrench_to_generalized,
    mass_matrix,
    potential_energy,
)
from uvms_pin.scenario.load import scenario_from_dict

DATA = ROOT / "tests" / "model" / "importer" / "data"
REXROV, LRAUV = DATA / "rexrov_expanded.urdf", DATA / "lrauv_hydrodynamics.sdf"
UVMS = loaded_uvms(ROOT / "models" / "uvms_lbv150.urdf", water_density_kg_m3=1025.0)


def test_a_controller_that_is_no_table_is_named():
    """Was: AttributeError: 'int' object has no attribute 'get'."""
    doc = {"scenario": {"model": "uvms_lbv150", "duration_s": 1.0}, "controller": 5}
    with pytest.raises(ScenarioError, match=r"s.toml: \[controller\] must be a table, got int"):
        scenario_from_dict(doc, ROOT / "s.toml")


def _import(tmp_path, source, old: str, new: str, count: int = 1):
    path = tmp_path / f"bad{source.suffix}"
    text = source.read_text()
    assert old in text
    path.write_text(text.replace(old, new, count))
    return path


@pytest.mark.parametrize(
    ("source", "old", "new", "match"),
    [
        # was: ModelError without the file's name
        (LRAUV, "<uniform_fluid_density>1000", "<uniform_fluid_density>0", "must be positive"),
        (REXROV, "<fluid_density>1028.0", "<fluid_density>inf", "must be positive and finite"),
        # was: ValueError: could not convert string to float: ''
        (REXROV, '<mass value="0.001"/>', '<mass value=""/>', "<mass value=''> is not a finite"),
        (LRAUV, "<xyz>0 1 0</xyz>", "<xyz>0 1</xyz>", r"<xyz> must be 3 finite numbers, got '0 1'"),
        (LRAUV, "<lower>-0.261799</lower>", "<lower>nan</lower>", "<lower> must be 1 finite"),
        # was: KeyError: 'rexrov/thruster_0' (two thruster plugins naming one link)
        (REXROV, "<linkName>rexrov/thruster_1<", "<linkName>rexrov/thruster_0<", "two thruster"),
        # was: built through a division by zero (the propeller joint's axis 0 0 0: a NaN
        # thrust direction)
        (LRAUV, "<xyz>1 0 0</xyz>", "<xyz>0 0 0</xyz>", r"'propeller_joint': its axis must be"),
        # was: OverflowError: (34, 'Numerical result out of range') (k_t rho d^4)
        (LRAUV, "<propeller_diameter>0.2", "<propeller_diameter>1e300", r"\^4 .* not a finite"),
    ],
)
def test_an_import_error_names_the_file(tmp_path, source, old, new, match):
    path = _import(tmp_path, source, old, new)
    with pytest.raises(ModelError, match=match) as info:
        import_model(path, tmp_path / "out.urdf")
    assert str(info.value).startswith(str(path))
    assert not (tmp_path / "out.urdf").exists()


@pytest.mark.parametrize("frame_id", [-1, UVMS.model.nframes, 10**6, True, 1.0, "ee"])
def test_a_frame_that_is_no_frame_is_refused(frame_id):
    """Was: a segmentation fault (Pinocchio reads past its frames)."""
    with pytest.raises(ParameterError, match="frame_id"):
        frame_wrench_to_generalized(UVMS, pin.neutral(UVMS.model), frame_id, np.zeros(6))


def test_a_wrench_and_a_configuration_are_checked():
    """Was: NaN in tau_ext from a NaN wrench; any q length went to Pinocchio."""
    q = pin.neutral(UVMS.model)
    with pytest.raises(ParameterError, match="wrench_world_aligned contains a non-finite"):
        frame_wrench_to_generalized(UVMS, q, 1, np.array([np.nan, 0, 0, 0, 0, 0]))
    with pytest.raises(ParameterError, match="q must have shape"):
        frame_wrench_to_generalized(UVMS, q[:-1], 1, np.zeros(6))


def test_a_speed_whose_square_overflows_is_an_error_not_a_nan():
    """Was: h(q, zeta) and zeta_dot with NaN entries for a finite zeta of 1e300."""
    q, v = pin.neutral(UVMS.model), np.zeros(UVMS.nv)
    v[-1] = 1e300
    with pytest.raises(SimulationError, match=r"fastest entry of zeta, 1e\+300"):
        bias_forces(UVMS, q, v)
    with pytest.raises(SimulationError):  # (its articulated-body pass says where first)
        forward_dynamics(UVMS, q, v, np.zeros(UVMS.nv))


def test_a_gym_scenario_that_is_no_path_is_refused():
    """Was: TypeError: expected str, bytes or os.PathLike object, not int."""
    gym = pytest.importorskip("gymnasium")
    import uvms_pin.apps.gym  # noqa: F401

    with pytest.raises(ParameterError, match="scenario must be a file or a shipped"):
        gym.make("uvms_pin/StationKeeping-v0", scenario=3)


def test_a_quaternion_of_norm_1e300_is_named_not_a_nan_mass_matrix():
    """Was: M(q) full of NaN for q with a quaternion entry of 1e300 (a list, not an array);
    the potential energy NaN too (make fuzz, seed 22)."""
    q = [0.0] * UVMS.nq
    q[5] = 1e300
    with pytest.raises(ParameterError, match="'root_joint' has a quaternion of norm inf"):
        mass_matrix(UVMS, q)
    with pytest.raises(ParameterError, match="'root_joint' has a quaternion of norm inf"):
        potential_energy(UVMS, q)


# ---- found by the campaign (make fuzz, seed 20261204) ------------------------------------


def test_a_gym_action_scale_of_text_is_refused():
    """Was: ValueError: could not convert string to float: 'x'."""
    gym = pytest.importorskip("gymnasium")
    import uvms_pin.apps.gym  # noqa: F401

    with pytest.raises(ParameterError, match="action_scale must be 10 positive finite numbers"):
        gym.make("uvms_pin/StationKeeping-v0", action_scale="x")


def test_a_camera_reflectance_of_no_colours_is_named():
    """Was: ValueError: could not convert string to float: ':' (and a date: TypeError)."""
    import tomllib

    doc = tomllib.loads((ROOT / "scenarios" / "visual_approach.toml").read_text())
    doc["sensors"]["camera"][0]["reflectance"] = {"hull": ":"}
    with pytest.raises(ScenarioError, match=r"v.toml: .*reflectance must map label names"):
        scenario_from_dict(doc, ROOT / "scenarios" / "v.toml")


def test_a_study_heatmap_of_lists_is_named(tmp_path):
    """Was: TypeError: unhashable type: 'list'."""
    import tomllib

    from fuzz_documents import toml_text

    from uvms_pin.apps.study import load_study
    from uvms_pin.errors import StudyError

    doc = tomllib.loads((ROOT / "studies" / "sea_state.toml").read_text())
    doc["study"]["base"] = str(ROOT / "studies" / doc["study"]["base"])
    doc["report"]["heatmaps"] = [[["a"], "b"]]
    path = tmp_path / "s.toml"
    path.write_text(toml_text(doc))
    with pytest.raises(StudyError, match=r"s.toml: report.heatmaps\[0\]: must be two parameter"):
        load_study(path)


ONE_CYLINDER = """<robot name="r"><link name="hull">
  <inertial><mass value="10"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
  <collision><geometry><cylinder radius="1e300" length="1"/></geometry></collision>
</link></robot>"""


def test_a_collision_cylinder_of_1e300_m_is_refused(tmp_path):
    """Was: OverflowError: (34, 'Numerical result out of range') deriving its drag (r^5)."""
    from uvms_pin.model.urdf.load import load_uvms

    path = tmp_path / "huge.urdf"
    path.write_text(ONE_CYLINDER)
    with pytest.raises(ModelError, match=r"huge.urdf: link 'hull': <cylinder radius> = 1e300 m"):
        load_uvms(path)


def test_a_camera_light_that_is_no_table_is_named():
    """Was: TypeError: 'datetime.date' object is not iterable (the second campaign)."""
    import datetime
    import tomllib

    doc = tomllib.loads((ROOT / "scenarios" / "visual_approach.toml").read_text())
    doc["sensors"]["camera"][0]["lights"] = [datetime.date(2026, 12, 4)]
    with pytest.raises(ScenarioError, match=r"v.toml: .*lights must be tables"):
        scenario_from_dict(doc, ROOT / "scenarios" / "v.toml")


def test_a_plane_normal_of_1e300_is_a_direction_not_a_nan():
    """Was: a NaN normal (its norm overflowed to inf: 'invalid value encountered in divide')."""
    from uvms_pin.physics.world.objects import checked

    params, _ = checked(
        "seabed", "plane", {"point_world_m": [0, 0, -10], "normal_world": [1e300, 0, 1]}, (0.5, 0.4)
    )
    np.testing.assert_allclose(params["normal_world"], [1.0, 0.0, 1e-300], rtol=1e-15)
    assert np.all(np.isfinite(params["normal_world"]))


def test_a_camera_water_type_that_is_no_name_is_refused_by_key():
    """Was: TypeError: unhashable type: 'list' (a list looked up among the Jerlov types)."""
    import tomllib

    path = ROOT / "scenarios" / "visual_approach.toml"
    doc = tomllib.loads(path.read_text())
    doc["sensors"]["camera"][0]["water_type"] = ["IB"]
    with pytest.raises(ScenarioError, match=r"water_type must be a Jerlov type .* got \['IB'\]"):
        scenario_from_dict(doc, path)


@pytest.mark.parametrize(
    ("key", "value"),
    [("horizontal_fov_rad", float("inf")), ("horizontal_fov_rad", 0.0), ("width", 0)],
)
def test_the_visual_servos_camera_of_no_focal_length_is_refused(key, value):
    """Was: built through 'invalid value encountered in tan' (an infinite field of view: a
    NaN focal length, every command of the run NaN)."""
    import tomllib

    doc = tomllib.loads((ROOT / "scenarios" / "visual_approach.toml").read_text())
    doc["controller"][key] = value
    with pytest.raises(ScenarioError, match=rf"v.toml: .*{key} must be"):
        scenario_from_dict(doc, ROOT / "scenarios" / "v.toml")


@pytest.mark.parametrize("backend", ["core", "python"])
def test_derivatives_at_a_position_of_1e300_are_an_error_not_a_nan(backend):
    """Was: da/dq, da/dv full of NaN (the core) for a vehicle 1e300 m up (its lever arms'
    products overflow, inf - inf), where the dynamics themselves stay finite."""
    q = pin.neutral(UVMS.model)
    q[2] = 1e300
    zero = np.zeros(UVMS.nv)
    with pytest.raises(SimulationError, match="not finite for finite inputs"):
        forward_dynamics_derivatives(UVMS, q, zero, zero, backend=backend)


@pytest.mark.parametrize(
    ("key", "value", "said"),
    [
        ("axis_world", [0.0, 0.0, 0.0], "axis_world must be a direction"),
        ("depth_m", float("inf"), "depth_m must be finite"),  # (make fuzz, seed 16)
        ("mouth_world_m", [0.75, float("nan"), -2.25], "mouth_world_m must be finite"),
    ],
)
def test_the_hot_stabs_targets_of_no_place_are_refused(key, value, said):
    """Was: built through 'invalid value encountered in divide' (axis_world = [0, 0, 0])
    or '... in multiply' (depth_m = inf): NaN standoff and insertion points."""
    import tomllib

    doc = tomllib.loads((ROOT / "scenarios" / "hot_stab.toml").read_text())
    doc["controller"][key] = value
    with pytest.raises(ScenarioError, match=rf"h.toml: .*{said}"):
        scenario_from_dict(doc, ROOT / "scenarios" / "h.toml")


def test_a_free_box_3_nm_thick_is_refused_not_a_crash():
    """Was: a segmentation fault (qhull, inside coal's convex hull, on flat points): a free
    box 0.3 x 0.3 m and 1e-9 m thick took the process down while the scenario was read."""
    from uvms_pin.physics.world.kind import convex_hull
    from uvms_pin.scenario.load import load_scenario

    thin = {"world.objects[1].size_m": [0.3, 0.3, 1e-9]}
    with pytest.raises(ScenarioError, match=r"\[world.objects\[1\]\]: .*span a volume"):
        load_scenario(ROOT / "scenarios" / "push_object.toml", thin)
    square = np.array([[x, y, 0.0] for x in (0.0, 1.0) for y in (0.0, 1.0)] * 2)
    with pytest.raises(ParameterError, match="flat"):
        convex_hull(square)
    with warnings.catch_warnings():  # one point repeated: no 0 / 0 on the way to the refusal
        warnings.simplefilter("error")
        with pytest.raises(ParameterError, match=r"flat \(thickness 0 of"):
            convex_hull(np.ones((5, 3)))
    with pytest.raises(ParameterError, match="4 or more finite points"):
        convex_hull(np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, np.nan, 1.0]]))
    box = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1e-3)])
    assert convex_hull(box).num_points == 8  # 1 mm thick: a body


def test_a_control_period_of_1e300_s_is_no_overflow_in_the_jaws_servo():
    """Was: OverflowError: (34, 'Numerical result out of range') (the jaw servo's gain cap
    I / (4 T^2) squared the period) while hot_stab.toml was read: the servo's gains are
    capped to 0, and the scenario is refused by name (its log period is no multiple)."""
    from uvms_pin.control.jaw_servo import JawSchedule, JawServo
    from uvms_pin.errors import PlausibilityWarning
    from uvms_pin.model.jaw import JawJoints
    from uvms_pin.scenario.load import load_scenario

    hot_stab = ROOT / "scenarios" / "hot_stab.toml"
    with pytest.warns(PlausibilityWarning), pytest.raises(ScenarioError, match="integer multiple"):
        load_scenario(hot_stab, {"control.period_s": 1e300})
    jaws = ROOT / "models" / "uvms_bluerov2_alpha5_jaws.urdf"
    model = loaded_uvms(jaws, water_density_kg_m3=1025.0).model
    servo = JawServo.for_model(model, JawJoints.of(model), 10.0, JawSchedule(), period_s=1e300)
    assert np.all(servo.stiffness == 0.0) and np.all(servo.damping == 0.0)


@pytest.mark.parametrize("backend", ["python", "core"])
def test_a_velocity_of_none_is_refused_by_name_by_both_backends(backend):
    """Was (the reference, make fuzz seed 23): Boost.Python.ArgumentError from
    pin.forwardKinematics(model, data, q, None, ...) for bias_forces and forward_dynamics
    given v = None with a q of zeros (a q now refused first: its quaternion is no rotation)."""
    q = pin.neutral(UVMS.model)
    with pytest.raises(ParameterError, match="v must have shape"):
        bias_forces(UVMS, q, None, backend=backend)
    with pytest.raises(ParameterError, match="v must have shape"):
        forward_dynamics(UVMS, q, None, None, backend=backend)
