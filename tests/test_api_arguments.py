"""The flat API's entry points (``up.X``) given the wrong kind of argument (None, a number
for a name, a string for a number, a stray keyword): each refuses it with uvms-pin's own
error naming the argument. Before, each of these was a TypeError, a ValueError, an
AttributeError or a Boost.Python ArgumentError from deeper down, or (a flag given as a
string) was read by its truth."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import REFERENCE_URDF, ROOT

import uvms_pin as up
from uvms_pin.errors import ParameterError, UvmsPinError

VEHICLE = up.shipped_path("models/bluerov2_heavy.urdf")
ARM = up.shipped_path("models/reach_alpha5.urdf")
POSE = [0.1, 0.0, -0.1, 0.0, 0.0, 0.0]  # not a pose: the options are refused first
MOUNT = ([0.1, 0.0, -0.1], [0.0, 0.0, 0.0])


@pytest.fixture(scope="module")
def uvms() -> up.UVMS:
    return up.load_uvms(REFERENCE_URDF)


CASES = {
    "load_uvms: a density as a string": (
        lambda u: up.load_uvms(REFERENCE_URDF, water_density_kg_m3="1025"),
        "water_density_kg_m3 must be a number",
    ),
    "load_uvms: a frame's index for its name": (
        lambda u: up.load_uvms(REFERENCE_URDF, ee_frame=3),
        "ee_frame must be a frame's name",
    ),
    "load_uvms: a flag as a string": (
        lambda u: up.load_uvms(REFERENCE_URDF, derive_missing="no"),
        "derive_missing must be True or False",
    ),
    "import_model: no path": (lambda u: up.import_model(None), "path must be"),
    "load_scenario: no path": (lambda u: up.load_scenario(None), "path must be"),
    "mount_arm: an option it does not have": (
        lambda u: up.mount_arm(VEHICLE, ARM, POSE, bogus=1),
        "unknown option.*bogus.*arm_base_link",
    ),
    "mount_arm: a trim that is neither a flag nor a TrimSpec": (
        lambda u: up.mount_arm(VEHICLE, ARM, POSE, trim="yes"),
        "trim must be",
    ),
    "mount_arm: a flag as a string": (
        lambda u: up.mount_arm(VEHICLE, ARM, MOUNT, moving_jaw="yes"),
        "moving_jaw must be True or False",
    ),
    "mount_arm: a locked position as a string": (
        lambda u: up.mount_arm(VEHICLE, ARM, MOUNT, lock_positions={"alpha_axis_e": "0.5"}),
        r"lock_positions\['alpha_axis_e'\] must be a number",
    ),
    "mount_arm: locked positions that are no table": (
        lambda u: up.mount_arm(VEHICLE, ARM, MOUNT, lock_positions="alpha_axis_e"),
        "lock_positions must be a dict",
    ),
    "mount_arm: a file to save to that is no path": (
        lambda u: up.mount_arm(VEHICLE, ARM, MOUNT, save_urdf=3),
        "save_urdf must be a path",
    ),
    "SimulationSettings: a duration as a string": (
        lambda u: up.SimulationSettings("2", up.RK4()),
        "duration_s must be a number",
    ),
    "SimulationSettings: no integrator": (
        lambda u: up.SimulationSettings(1.0, None),
        "integrator must be an Integrator",
    ),
    "Plant: no model": (lambda u: up.Plant(None), "uvms must be a UVMS"),
    "Plant: a flag as a string": (
        lambda u: up.Plant(u, free_surface="no"),
        "free_surface must be True or False",
    ),
    "Plant: a world that is not one": (lambda u: up.Plant(u, world=1), "world must be a World"),
    "Plant: a disturbance that is not a function": (
        lambda u: up.Plant(u, disturbance=[0.0] * 6),
        "disturbance must be a function",
    ),
    "System: no plant": (lambda u: up.System(None), "plant must be a Plant"),
    "World: no list of objects": (
        lambda u: up.World(u, None),
        "objects must be a list of WorldObject",
    ),
    "World: an object that is not one": (
        lambda u: up.World(u, [1]),
        r"objects\[0\] must be a WorldObject",
    ),
    "Measurement: a configuration of strings": (
        lambda u: up.Measurement(0.0, "level", [0.0] * u.nv, [0.0] * 6),
        "measurement q must be numbers",
    ),
    "SumFlow: a field that is not one": (
        lambda u: up.SumFlow((up.UniformCurrent([0.1, 0, 0]), 1)),
        "SumFlow adds FlowFields",
    ),
    "DepthProfileCurrent: depths as a string": (
        lambda u: up.DepthProfileCurrent([0.1, 0, 0], "deep", [1.0, 0.5]),
        "depths_m and factors",
    ),
    "IrregularSea: a height as a string": (
        lambda u: up.IrregularSea("1", 8.0),
        "significant_height_m must be a number",
    ),
    "IrregularSea: a frequency range of one number": (
        lambda u: up.IrregularSea(1.0, 8.0, frequency_range=(0.5,)),
        "frequency_range",
    ),
}


@pytest.mark.parametrize("case", list(CASES))
def test_an_entry_point_refuses_the_wrong_kind_of_argument_by_name(case, uvms):
    call, message = CASES[case]
    with pytest.raises(ParameterError, match=message):
        call(uvms)


@pytest.mark.parametrize("backend", ["core", "python"])
def test_a_plants_acceleration_names_a_wrong_input(uvms, backend):
    """`Plant.acceleration` (the right-hand side a Python loop integrates) and `ee_state`
    given a state of the wrong kind or size: ParameterError naming it, checked only after
    the core or Pinocchio refused the call (nanobind's TypeError, Boost.Python's
    ArgumentError or Pinocchio's ValueError before)."""
    import pinocchio as pin

    plant = up.Plant(uvms, backend=backend)
    q, v, tau = pin.neutral(uvms.model), np.zeros(uvms.nv), np.zeros(uvms.nv)
    q[2] = -3.0
    assert np.all(np.isfinite(plant.acceleration(0.0, q, v, tau)))
    for args, name in (
        (("0", q, v, tau), "time_s must be a number"),
        ((0.0, None, v, tau), "q must"),
        ((0.0, q, v[:3], tau), "v must have shape"),
        ((0.0, q, v, "zero"), "tau must be"),
    ):
        with pytest.raises(ParameterError, match=name):
            plant.acceleration(*args)
    with pytest.raises(ParameterError, match="q must be"):
        plant.ee_state("level", v)


def test_one_package_folder_may_be_given_alone(uvms, monkeypatch):
    """``package_dirs="models"`` was read as the folders "m", "o", "d", ...: one folder is
    now taken as the list of it (what reaches the mesh search is looked at: the reference
    model has no package:// mesh, so the loaded model alone could not tell)."""
    import uvms_pin.model.urdf.load as load

    searched = []
    bodies = load.hydro_bodies

    def recording(*args, **kwargs):
        searched.append(tuple(kwargs["package_dirs"]))
        return bodies(*args, **kwargs)

    monkeypatch.setattr(load, "hydro_bodies", recording)
    folder = str(ROOT / "models")
    alone = up.load_uvms(REFERENCE_URDF, package_dirs=folder)
    listed = up.load_uvms(REFERENCE_URDF, package_dirs=[folder])
    assert searched == [(folder,), (folder,)]
    assert alone.nv == listed.nv == uvms.nv


def test_the_refusals_are_uvms_pins_errors():
    assert issubclass(ParameterError, UvmsPinError)
