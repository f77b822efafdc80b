"""Importing uuv_simulator's sphere and cylinder hydrodynamic models (HMSphere, HMCylinder):
the added mass and drag its plugin computes from the shape, and the plugin's wrench."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pinocchio as pin
import pytest

from uvms_pin.errors import ModelError
from uvms_pin.hydro.added_mass import kirchhoff_wrench
from uvms_pin.hydro.damping import damping_wrench
from uvms_pin.model.importer.convert import import_model
from uvms_pin.model.importer.fossen import LINK_FROM_SNAME as T
from uvms_pin.model.urdf.load import load_uvms
from uvms_pin.physics.dynamics import mass_matrix

RHO = 1028.0
BOX = "<box><width>0.2</width><length>0.9</length><height>0.3</height></box>"


def vehicle(model_body: str, box: str = BOX, extra: str = "") -> str:
    """A one-link vehicle whose uuv_simulator plugin block has ``model_body`` in its
    <hydrodynamic_model> (and ``box``, ``extra`` in the link block)."""
    return f"""<robot name="v">
  <link name="v/base_link">
    <inertial><mass value="10"/><origin xyz="0 0 0"/>
      <inertia ixx="0.5" ixy="0" ixz="0" iyy="0.5" iyz="0" izz="0.5"/></inertial>
  </link>
  <gazebo>
    <plugin filename="libuuv_underwater_object_ros_plugin.so" name="uuv_plugin">
      <fluid_density>{RHO}</fluid_density>
      <link name="v/base_link">
        <volume>0.0097</volume>
        {box}
        <center_of_buoyancy>0 0 0.01</center_of_buoyancy>
        {extra}
        <hydrodynamic_model>{model_body}</hydrodynamic_model>
      </link>
    </plugin>
  </gazebo>
</robot>"""


def imported(tmp_path, text: str, out: bool = False):
    source = tmp_path / "v.urdf"
    source.write_text(text)
    target = tmp_path / "out.urdf" if out else None
    return import_model(source, target), target


def plugin_wrench(added_sname, linear_sname, quadratic_sname, nu):
    """uuv_simulator's HMFossen wrench in the link frame (its formula, SNAME frame)."""
    nu_s = T @ nu
    d = -linear_sname - np.diag(quadratic_sname * np.abs(nu_s))
    ab = added_sname @ nu_s
    sa = -pin.skew(ab[:3])
    c_a = np.block([[np.zeros((3, 3)), sa], [sa, -pin.skew(ab[3:])]])
    return T @ (-d @ nu_s - c_a @ nu_s)


def ours(params, nu):
    return damping_wrench(params.linear_damping, params.quadratic_damping, nu) - kirchhoff_wrench(
        params.added_mass, nu
    )


def test_a_sphere_has_half_its_displaced_water_as_added_mass_and_its_drag(tmp_path):
    r = 0.1
    result, _ = imported(tmp_path, vehicle("<type>sphere</type><radius>0.1</radius>"))
    params = result.hydro["v/base_link"]
    half_water = 0.5 * RHO * 4.0 / 3.0 * math.pi * r**3
    np.testing.assert_allclose(np.diag(params.added_mass), [half_water] * 3 + [0] * 3, rtol=1e-15)
    drag = 0.5 * RHO * 0.5 * math.pi * r**2  # C_d = 0.5 of the section pi r^2
    np.testing.assert_allclose(params.quadratic_damping, [drag] * 3 + [0] * 3, rtol=1e-15)
    assert not np.any(params.linear_damping)
    assert not np.any(params.added_mass - np.diag(np.diag(params.added_mass)))
    # what the block states besides is kept, as for type="fossen"
    assert params.volume_m3 == 0.0097
    np.testing.assert_array_equal(params.center_of_buoyancy_m, [0, 0, 0.01])


def test_a_sphere_keeps_the_files_other_fossen_entries(tmp_path):
    """The plugin's sphere is its Fossen model with the translations' diagonal overwritten:
    a linear damping, rotational added mass or quadratic damping in the file stay."""
    body = (
        "<type>sphere</type><radius>0.1</radius>"
        "<added_mass>" + " ".join(["0"] * 21 + ["0.7"] + ["0"] * 14) + "</added_mass>"
        "<linear_damping>-1 -2 -3 -4 -5 -6</linear_damping>"
        "<quadratic_damping>-9 -9 -9 -0.4 -0.5 -0.6</quadratic_damping>"
    )
    params = imported(tmp_path, vehicle(body))[0].hydro["v/base_link"]
    assert params.added_mass[3, 3] == 0.7 and params.added_mass[0, 0] != 0.0
    np.testing.assert_array_equal(np.diag(params.linear_damping), [1, 2, 3, 4, 5, 6])
    np.testing.assert_array_equal(params.quadratic_damping[3:], [0.4, 0.5, 0.6])
    assert params.quadratic_damping[0] == pytest.approx(0.5 * RHO * 0.5 * math.pi * 0.01)


@pytest.mark.parametrize("axis", ["i", "j", "k"])
def test_a_cylinders_wrench_is_the_plugins_for_random_velocities(tmp_path, axis):
    r, length = 0.05, 0.4  # L / 2r = 4: C_circ 0.87, C_len 0.74
    body = f"<type>cylinder</type><radius>{r}</radius><length>{length}</length><axis>{axis}</axis>"
    params = imported(tmp_path, vehicle(body))[0].hydro["v/base_link"]
    a = "ijk".index(axis)
    across = [b for b in range(3) if b != a]
    # the plugin's matrices (HMCylinder), SNAME frame and signs
    added = np.zeros((6, 6))
    quadratic = np.zeros(6)
    added[a, a] = RHO * math.pi * r**2
    quadratic[a] = -0.5 * 0.87 * math.pi * r**2 * RHO
    for b in across:
        added[b, b] = RHO * math.pi * r**2 * length
        added[3 + b, 3 + b] = RHO * math.pi * r**2 * length**3 / 12.0
        quadratic[b] = -0.5 * 0.74 * r * length * RHO
    rng = np.random.default_rng(7)
    for nu in rng.normal(size=(20, 6)):
        np.testing.assert_allclose(
            ours(params, nu),
            plugin_wrench(added, np.zeros((6, 6)), quadratic, nu),
            rtol=1e-12,
            atol=1e-12,
        )
    # the added mass about the axis itself is none: a cylinder turning about it moves no water
    assert params.added_mass[3 + a, 3 + a] == 0.0


@pytest.mark.parametrize(
    ("ratio", "circular", "lengthwise"),
    [(0.5, 0.91, 0.63), (1.5, 0.85, 0.68), (3.0, 0.87, 0.74), (4.5, 0.99, 0.74), (6.0, 0.99, 0.82),
     (20.0, 0.99, 0.98), (50.0, 0.99, 0.98),
     # each bound itself: the plugin's bands include their upper bound (dimRatio <= 2, ...)
     (1.0, 0.91, 0.63), (2.0, 0.85, 0.68), (4.0, 0.87, 0.74), (5.0, 0.99, 0.74),
     (10.0, 0.99, 0.82), (12.0, 0.99, 0.98)],
)  # fmt: skip
def test_the_cylinders_drag_coefficients_are_the_plugins_table(
    tmp_path, ratio, circular, lengthwise
):
    r = 0.5  # L = 2 r ratio = ratio exactly: a bound is met, not missed by a rounding
    length = 2 * r * ratio
    body = f"<type>cylinder</type><radius>{r}</radius><length>{length}</length><axis>k</axis>"
    result, _ = imported(tmp_path, vehicle(body))
    q = result.hydro["v/base_link"].quadratic_damping
    assert q[2] == pytest.approx(0.5 * circular * math.pi * r**2 * RHO, rel=1e-14)
    assert q[0] == q[1] == pytest.approx(0.5 * lengthwise * r * length * RHO, rel=1e-14)
    unset = [n for n in result.not_mapped if "leaves the axial drag coefficient unset" in n]
    assert len(unset) == (1 if ratio > 7 else 0)


def test_a_cylinder_without_sizes_takes_the_boxs_as_the_plugin_does(tmp_path):
    """No <radius>, <length> or <axis>: the box's smallest side (not its half) as the
    radius, its largest as the length, its longest direction (y here) as the axis."""
    result, _ = imported(tmp_path, vehicle("<type>cylinder</type>"))
    given, _ = imported(
        tmp_path,
        vehicle("<type>cylinder</type><radius>0.2</radius><length>0.9</length><axis>j</axis>"),
    )
    np.testing.assert_array_equal(
        result.hydro["v/base_link"].added_mass, given.hydro["v/base_link"].added_mass
    )
    np.testing.assert_array_equal(
        result.hydro["v/base_link"].quadratic_damping, given.hydro["v/base_link"].quadratic_damping
    )
    (note,) = [n for n in result.not_mapped if "cylinder of r" in n]
    assert "r = 0.2 m, L = 0.9 m along y" in note
    assert "radius: the <box>'s smallest side" in note and "axis: the <box>'s longest" in note


def test_an_imported_cylinder_arm_link_loads_and_adds_its_added_mass(tmp_path):
    body = "<type>cylinder</type><radius>0.05</radius><length>0.4</length><axis>i</axis>"
    result, out = imported(tmp_path, vehicle(body), out=True)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        uvms = load_uvms(out, water_density_kg_m3=RHO)
    (body_params,) = [b.params for b in uvms.hydro_bodies]
    assert body_params == result.hydro["v/base_link"]
    m = mass_matrix(uvms, uvms.neutral_configuration())
    rigid = np.diag([10, 10, 10, 0.5, 0.5, 0.5])
    np.testing.assert_allclose(m, rigid + body_params.added_mass, rtol=0, atol=1e-12)


@pytest.mark.parametrize(
    ("body", "box", "match"),
    [
        (
            "<type>box</type>",
            BOX,
            'type "box" cannot be imported \\(uuv_simulator logs it as still',
        ),
        ("<type>spheroid</type>", BOX, 'type "spheroid" cannot be imported \\(uuv_simulator'),
        ("<type>ellipse</type>", BOX, 'known: "fossen", "sphere", "cylinder"'),
        ("<type>sphere</type>", "", "needs a <radius> or a <box>"),
        ("<type>cylinder</type><radius>0.1</radius><length>1</length>", "", "needs an <axis>"),
        ("<type>cylinder</type><axis>x</axis>", BOX, '<axis> must be "i", "j" or "k"'),
        ("<type>sphere</type><radius>-0.1</radius>", BOX, "<radius> must be > 0"),
        ("<type>sphere</type><radius>a</radius>", BOX, "non-numeric"),
        ("<type>sphere</type>", BOX.replace("0.2", "0"), "<box> sides must be > 0"),
    ],
)
def test_a_shape_model_the_importer_cannot_read_is_refused_naming_it(tmp_path, body, box, match):
    source = tmp_path / "bad.urdf"
    source.write_text(vehicle(body, box))
    out = tmp_path / "out.urdf"
    with pytest.raises(ModelError, match=match) as caught:
        import_model(source, out)
    assert "v/base_link" in str(caught.value)
    assert not out.exists()
