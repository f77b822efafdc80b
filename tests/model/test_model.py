"""Loading a UVMS: bad input, the hydrodynamic URDF extension, derived coefficients, merging
of fixed links and the reference model.

Tolerances: URDF numbers are written with ``repr`` (17 significant digits), so a model built
from hand-transformed coefficients agrees with the loader's to round-off of a few 6x6
products: 1e-10 relative to the largest entry is ample and still catches any wrong sign,
missing transpose or misplaced lever arm (those are O(1) relative errors).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pinocchio as pin
import pytest
from conftest import REFERENCE_URDF, body_urdf, hydro_xml, random_configuration

import uvms_pin as up
from uvms_pin.hydro.geometry import box_hydro, cylinder_hydro, hydro_in_frame

G = 9.81
INERTIAL = (
    '<inertial><mass value="2.0"/>'
    '<inertia ixx="0.01" iyy="0.02" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial>'
)
GOOD_HYDRO = hydro_xml(0.002, (0, 0, 0.01), (1, 2, 3, 0.1, 0.1, 0.1))


def _s(values) -> str:
    """Numbers as URDF text, full double precision."""
    return " ".join(repr(float(x)) for x in np.ravel(values))


def _robot(*links: str, extra: str = "") -> str:
    return '<robot name="r">\n' + "\n".join(links) + "\n" + extra + "\n</robot>"


def _link(name: str, body: str) -> str:
    return f'<link name="{name}">{body}</link>'


def _fixed(parent: str, child: str, xyz=(0, 0, 0), rpy=(0, 0, 0)) -> str:
    return (
        f'<joint name="{child}_joint" type="fixed"><parent link="{parent}"/>'
        f'<child link="{child}"/><origin xyz="{_s(xyz)}" rpy="{_s(rpy)}"/></joint>'
    )


def _rng(seed: int) -> np.random.Generator:
    return np.random.default_rng(seed)


# ---- bad input: every case raises ModelError naming the file (and the link) --------------

_MATRIX_NOT_SYMMETRIC = np.eye(6)
_MATRIX_NOT_SYMMETRIC[0, 1] = 0.5  # [0, 1] != [1, 0]
_MATRIX_NOT_PSD = np.eye(6)
_MATRIX_NOT_PSD[0, 1] = _MATRIX_NOT_PSD[1, 0] = 2.0  # eigenvalues 3 and -1

BAD_HYDRO = {
    # id: (content of <hydrodynamics>, substrings the message must contain)
    "negative volume": ('<volume value="-0.001"/>', ["negative volume"]),
    "no volume": ('<center_of_buoyancy xyz="0 0 0"/>', ["no <volume>"]),
    "non-symmetric added mass": (
        f'<volume value="0.001"/><added_mass matrix="{_s(_MATRIX_NOT_SYMMETRIC)}"/>',
        ["added_mass", "symmetric"],
    ),
    "negative diagonal added mass": (
        '<volume value="0.001"/><added_mass diagonal="1 2 -3 0 0 0"/>',
        ["added_mass", ">= 0"],
    ),
    "added mass not PSD": (
        f'<volume value="0.001"/><added_mass matrix="{_s(_MATRIX_NOT_PSD)}"/>',
        ["added_mass", "positive semi-definite"],
    ),
    "unknown tag": (
        '<volume value="0.001"/><added_mas diagonal="1 1 1 1 1 1"/>',
        ["unknown tag <added_mas>", "added_mass"],
    ),
    "5 numbers in diagonal": (
        '<volume value="0.001"/><added_mass diagonal="1 2 3 4 5"/>',
        ["added_mass diagonal", "needs 6 numbers, got 5"],
    ),
    "35 numbers in matrix": (
        f'<volume value="0.001"/><added_mass matrix="{_s(np.eye(6).ravel()[:35])}"/>',
        ["added_mass matrix", "needs 36 numbers, got 35"],
    ),
    "2 numbers in center_of_buoyancy": (
        '<volume value="0.001"/><center_of_buoyancy xyz="0 0.1"/>',
        ["center_of_buoyancy", "needs 3 numbers, got 2"],
    ),
    "non-numeric volume": ('<volume value="lots"/>', ["volume", "non-numeric", "lots"]),
    "non-numeric diagonal": (
        '<volume value="0.001"/><linear_damping diagonal="1 2 x 4 5 6"/>',
        ["linear_damping", "non-numeric"],
    ),
    "non-finite value": ('<volume value="nan"/>', ["volume", "non-finite"]),
    "diagonal and matrix": (
        f'<volume value="0.001"/><added_mass diagonal="1 1 1 1 1 1" matrix="{_s(np.eye(6))}"/>',
        ["added_mass", "exactly one of"],
    ),
    "neither diagonal nor matrix": (
        '<volume value="0.001"/><added_mass/>',
        ["added_mass", "exactly one of"],
    ),
    "negative quadratic damping": (
        '<volume value="0.001"/><quadratic_damping diagonal="1 1 -1 1 1 1"/>',
        ["quadratic_damping", ">= 0"],
    ),
}


@pytest.mark.parametrize("case", list(BAD_HYDRO), ids=list(BAD_HYDRO))
def test_bad_hydrodynamics_raise_model_error_naming_file_and_link(write_urdf, case):
    content, expected = BAD_HYDRO[case]
    path = write_urdf(body_urdf(hydro=content))
    with pytest.raises(up.ModelError) as info:
        up.load_uvms(path, ee_frame="body", sensor_frame="body")
    message = str(info.value)
    assert str(path) in message
    assert "link 'body'" in message
    for part in expected:
        assert part in message, (part, message)
    assert info.value.path == str(path) and info.value.link == "body"


def test_model_error_is_a_uvms_pin_error():
    assert issubclass(up.ModelError, up.UvmsPinError)
    assert not issubclass(up.ModelError, up.ParameterError)


def test_missing_file(tmp_path):
    path = tmp_path / "nowhere.urdf"
    with pytest.raises(up.ModelError, match="file not found") as info:
        up.load_uvms(path)
    assert str(path) in str(info.value)
    with pytest.raises(up.ModelError, match="is a directory, not a URDF file"):
        up.load_uvms(tmp_path)


def test_malformed_xml(write_urdf):
    path = write_urdf('<robot name="r"><link name="body"></robot>')
    with pytest.raises(up.ModelError, match="not well-formed XML") as info:
        up.load_uvms(path)
    assert str(path) in str(info.value)


def test_root_not_robot(write_urdf):
    path = write_urdf('<sdf version="1.6"><model name="m"/></sdf>')
    with pytest.raises(up.ModelError, match=r"root element is <sdf>, expected <robot>") as info:
        up.load_uvms(path)
    assert str(path) in str(info.value)
    assert "uvms-pin import FILE --out model.urdf" in str(info.value)  # the way to load it


LINK_CASES = {
    "hydrodynamics without inertial": (
        _robot(
            _link("body", INERTIAL + f"<hydrodynamics>{GOOD_HYDRO}</hydrodynamics>"),
            _link("fin", f"<hydrodynamics>{GOOD_HYDRO}</hydrodynamics>"),
            _fixed("body", "fin"),
        ),
        "fin",
        ["has <hydrodynamics> but no <inertial>"],
    ),
    "collision without inertial": (
        _robot(
            _link("body", INERTIAL + f"<hydrodynamics>{GOOD_HYDRO}</hydrodynamics>"),
            _link("fin", '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>'),
            _fixed("body", "fin"),
        ),
        "fin",
        ["has <collision> geometry but no <inertial>"],
    ),
    "two hydrodynamics in one link": (
        _robot(
            _link(
                "body",
                INERTIAL + f"<hydrodynamics>{GOOD_HYDRO}</hydrodynamics>" * 2,
            )
        ),
        "body",
        ["more than one <hydrodynamics>"],
    ),
    "inline and top-level hydrodynamics": (
        _robot(
            _link("body", INERTIAL + f"<hydrodynamics>{GOOD_HYDRO}</hydrodynamics>"),
            extra=f'<hydrodynamics link="body">{GOOD_HYDRO}</hydrodynamics>',
        ),
        "body",
        ["more than one <hydrodynamics>"],
    ),
    "top-level hydrodynamics on an unknown link": (
        _robot(
            _link("body", INERTIAL + f"<hydrodynamics>{GOOD_HYDRO}</hydrodynamics>"),
            extra=f'<hydrodynamics link="nope">{GOOD_HYDRO}</hydrodynamics>',
        ),
        "nope",
        ["names a link that does not exist"],
    ),
    "dry link": (
        _robot(_link("body", INERTIAL)),
        "body",
        ["no <hydrodynamics>", "no collision", "allow_dry_links=True"],
    ),
    "mesh collision without hydrodynamics": (
        _robot(
            _link(
                "body",
                INERTIAL
                + '<collision><geometry><mesh filename="hull.stl"/></geometry></collision>',
            )
        ),
        "body",
        ["cannot derive hydrodynamics from collision <mesh>", "add a <hydrodynamics> element"],
    ),
}


@pytest.mark.parametrize("case", list(LINK_CASES), ids=list(LINK_CASES))
def test_bad_links_raise_model_error_naming_file_and_link(write_urdf, case):
    text, link, expected = LINK_CASES[case]
    path = write_urdf(text)
    with pytest.raises(up.ModelError) as info:
        up.load_uvms(path, ee_frame="body", sensor_frame="body")
    message = str(info.value)
    assert str(path) in message
    assert f"link '{link}'" in message
    for part in expected:
        assert part in message, (part, message)


_INERTIA = '<inertia ixx="0.01" iyy="0.02" izz="0.03" ixy="0" ixz="0" iyz="0"/>'
BAD_INERTIAL = {
    # urdfdom only prints these to stderr and Pinocchio loads a zero mass / zero inertia
    "no mass": (f"<inertial>{_INERTIA}</inertial>", "no <mass>"),
    "non-numeric mass": (f'<inertial><mass value="x"/>{_INERTIA}</inertial>', "non-numeric"),
    "negative mass": (f'<inertial><mass value="-2"/>{_INERTIA}</inertial>', "negative mass"),
    "no inertia": ('<inertial><mass value="2"/></inertial>', "no <inertia>"),
    "non-numeric inertia": (
        '<inertial><mass value="2"/>'
        '<inertia ixx="abc" iyy="0.02" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial>',
        "<inertia ixx> has a non-numeric value",
    ),
    "missing inertia entry": (
        '<inertial><mass value="2"/>'
        '<inertia ixx="0.01" iyy="0.02" izz="0.03" ixy="0" ixz="0"/></inertial>',
        "<inertia iyz> is missing",
    ),
    "negative principal moment": (
        '<inertial><mass value="2"/>'
        '<inertia ixx="-0.01" iyy="0.02" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial>',
        "not positive semi-definite",
    ),
    # positive diagonal, but the products of inertia make it indefinite: eigenvalues of
    # [[0.01, 0.02], [0.02, 0.01]] are 0.03 and -0.01
    "indefinite through the products": (
        '<inertial><mass value="2"/>'
        '<inertia ixx="0.01" iyy="0.01" izz="0.015" ixy="0.02" ixz="0" iyz="0"/></inertial>',
        "not positive semi-definite",
    ),
    "triangle inequality": (
        '<inertial><mass value="2"/>'
        '<inertia ixx="0.01" iyy="0.02" izz="0.05" ixy="0" ixz="0" iyz="0"/></inertial>',
        "triangle inequality",
    ),
    # a rotated frame: the diagonal alone satisfies I1 + I2 >= I3, the principal moments
    # (0.005, 0.01, 0.02) do not
    "triangle inequality in principal axes": (
        '<inertial><mass value="2"/>'
        '<inertia ixx="0.0125" iyy="0.0125" izz="0.01" ixy="0.0075" ixz="0" iyz="0"/></inertial>',
        "triangle inequality",
    ),
    "rotational inertia without mass": (
        f'<inertial><mass value="0"/>{_INERTIA}</inertial>',
        "zero mass but a rotational inertia",
    ),
}


@pytest.mark.parametrize("case", list(BAD_INERTIAL), ids=list(BAD_INERTIAL))
def test_bad_inertial_raises_model_error(write_urdf, case):
    inertial, expected = BAD_INERTIAL[case]
    path = write_urdf(
        _robot(_link("body", inertial + f"<hydrodynamics>{GOOD_HYDRO}</hydrodynamics>"))
    )
    with pytest.raises(up.ModelError) as info:
        up.load_uvms(path, ee_frame="body", sensor_frame="body")
    message = str(info.value)
    assert str(path) in message and "link 'body'" in message
    assert expected in message, message


@pytest.mark.parametrize(
    "inertia",
    [
        (0.0, 0.0, 0.0, 0.0, 0.0, 0.0),  # a point mass
        (0.01, 0.02, 0.03, 0.0, 0.0, 0.0),
        (0.01, 0.02, 0.03, 0.0, 0.0, 0.0),
        (0.0, 1 / 12, 1 / 12, 0.0, 0.0, 0.0),  # a thin rod along x: I1 = 0
        (0.25, 0.5, 0.75, 0.0, 0.0, 0.0),  # a flat plate: I3 = I1 + I2 exactly
        (0.025, 0.05, 0.0749, 0.0, 0.0, 0.0),  # the plate printed with 3 digits
    ],
)
def test_physical_inertias_load(write_urdf, inertia):
    """The limits of the admissible set (PSD, I1 + I2 = I3) load, and the loaded rigid
    mass matrix carries exactly the URDF's inertia."""
    ixx, iyy, izz, ixy, ixz, iyz = inertia
    path = write_urdf(
        _robot(
            _link(
                "body",
                '<inertial><mass value="2"/>'
                f'<inertia ixx="{ixx!r}" iyy="{iyy!r}" izz="{izz!r}" ixy="{ixy!r}" '
                f'ixz="{ixz!r}" iyz="{iyz!r}"/></inertial>'
                f"<hydrodynamics>{GOOD_HYDRO}</hydrodynamics>",
            )
        )
    )
    uvms = up.load_uvms(path, ee_frame="body", sensor_frame="body")
    np.testing.assert_allclose(uvms.model.inertias[1].inertia, np.diag([ixx, iyy, izz]), atol=1e-15)


def _two_joint_robot(lower: float, upper: float) -> str:
    return _robot(
        _link("body", INERTIAL + f"<hydrodynamics>{GOOD_HYDRO}</hydrodynamics>"),
        _link("arm", INERTIAL + f"<hydrodynamics>{GOOD_HYDRO}</hydrodynamics>"),
        '<joint name="shoulder" type="revolute"><parent link="body"/><child link="arm"/>'
        f'<axis xyz="0 0 1"/><limit lower="{lower}" upper="{upper}" effort="1" velocity="1"/>'
        "</joint>",
    )


def test_inverted_joint_limits_raise_model_error(write_urdf):
    path = write_urdf(_two_joint_robot(1.0, -1.0))
    with pytest.raises(up.ModelError) as info:
        up.load_uvms(path, ee_frame="arm", sensor_frame="arm")
    message = str(info.value)
    assert str(path) in message and "joint 'shoulder'" in message
    assert "lower = 1.0 > upper = -1.0" in message


@pytest.mark.parametrize("kind", ["revolute", "continuous", "prismatic"])
def test_a_zero_joint_axis_is_refused_naming_the_joint(write_urdf, kind):
    """It loaded, and the run then 'diverged at t = 0' on a singular articulated inertia."""
    text = _two_joint_robot(-1.0, 1.0).replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>')
    text = text.replace('type="revolute"', f'type="{kind}"')
    path = write_urdf(text)
    with pytest.raises(up.ModelError) as info:
        up.load_uvms(path, ee_frame="arm", sensor_frame="arm")
    assert str(path) in str(info.value)
    assert "joint 'shoulder': <axis xyz=\"0 0 0\"> is zero" in str(info.value)


def test_equal_joint_limits_load(write_urdf):
    uvms = up.load_uvms(write_urdf(_two_joint_robot(0.5, 0.5)), ee_frame="arm", sensor_frame="arm")
    assert uvms.model.lowerPositionLimit[7] == uvms.model.upperPositionLimit[7] == 0.5


MASS_VOLUME_WARNINGS = {
    "volume without mass": (
        '<inertial><mass value="0"/>'
        '<inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial>'
        f"<hydrodynamics>{GOOD_HYDRO}</hydrodynamics>",
        "displaces 0.002 m^3 of water but has zero mass",
    ),
    "mass without volume": (
        INERTIAL + f"<hydrodynamics>{hydro_xml(0.0)}</hydrodynamics>",
        "has 2 kg of mass but displaces no water",
    ),
}


def _hinged_fin(fin: str) -> str:
    """A body with mass and volume, and a link ``fin`` (its elements ``fin``) on the
    revolute joint ``hinge``: a rigid body of its own."""
    return _robot(
        _link("body", INERTIAL + f"<hydrodynamics>{GOOD_HYDRO}</hydrodynamics>"),
        _link("fin", fin),
        '<joint name="hinge" type="revolute"><parent link="body"/><child link="fin"/>'
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>',
    )


@pytest.mark.parametrize("case", list(MASS_VOLUME_WARNINGS), ids=list(MASS_VOLUME_WARNINGS))
def test_mass_volume_mismatch_warns_naming_file_and_link(write_urdf, case):
    """A rigid body (here the fin, on its own revolute joint) with buoyancy but no weight,
    or the reverse."""
    body, expected = MASS_VOLUME_WARNINGS[case]
    path = write_urdf(_hinged_fin(body))
    with pytest.warns(up.ModelWarning) as record:
        up.load_uvms(path, ee_frame="body", sensor_frame="body")
    messages = [str(w.message) for w in record]
    assert len(messages) == 1, messages
    assert str(path) in messages[0] and "link 'fin'" in messages[0]
    assert expected in messages[0], messages[0]


@pytest.mark.parametrize("case", list(MASS_VOLUME_WARNINGS), ids=list(MASS_VOLUME_WARNINGS))
def test_a_buoyancy_link_fixed_to_a_mass_link_is_one_body_and_no_surprise(write_urdf, case):
    """Links merged by a fixed joint are one rigid body: a volume-only link (e.g. a centre of
    buoyancy of its own) on a link with mass warns only if the body as a whole mismatches."""
    body, _ = MASS_VOLUME_WARNINGS[case]
    path = write_urdf(
        _robot(
            _link("body", INERTIAL + f"<hydrodynamics>{GOOD_HYDRO}</hydrodynamics>"),
            _link("fin", body),
            _fixed("body", "fin"),
        )
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error", up.ModelWarning)
        up.load_uvms(path, ee_frame="body", sensor_frame="body")


def test_a_link_without_mass_or_volume_is_no_mismatch(write_urdf):
    """A link that neither weighs nor displaces (a frame carrier with a zero-volume
    <hydrodynamics>, say) has nothing to mismatch: no warning."""
    empty = (
        '<inertial><mass value="0"/>'
        '<inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial>'
        f"<hydrodynamics>{hydro_xml(0.0)}</hydrodynamics>"
    )
    path = write_urdf(_hinged_fin(empty))
    with warnings.catch_warnings():
        warnings.simplefilter("error", up.ModelWarning)
        up.load_uvms(path, ee_frame="body", sensor_frame="body")


def test_reference_model_loads_without_warnings(recwarn):
    up.load_uvms(REFERENCE_URDF)
    assert not [w for w in recwarn if issubclass(w.category, up.UvmsPinWarning)]


def test_top_level_hydrodynamics_without_link_attribute(write_urdf):
    path = write_urdf(
        _robot(
            _link("body", INERTIAL + f"<hydrodynamics>{GOOD_HYDRO}</hydrodynamics>"),
            extra=f"<hydrodynamics>{GOOD_HYDRO}</hydrodynamics>",
        )
    )
    with pytest.raises(up.ModelError, match='needs a link="NAME"') as info:
        up.load_uvms(path, ee_frame="body", sensor_frame="body")
    assert str(path) in str(info.value)


def test_allow_dry_links_accepts_a_dry_link(write_urdf):
    """With allow_dry_links the body has no hydrodynamics at all: M is the rigid mass matrix
    and h at rest is pure gravity (exact, 1e-12)."""
    uvms = up.load_uvms(
        write_urdf(_robot(_link("body", INERTIAL))),
        ee_frame="body",
        sensor_frame="body",
        allow_dry_links=True,
    )
    assert uvms.hydro_bodies == ()
    assert uvms.volume_m3 == 0.0
    q = uvms.neutral_configuration()
    np.testing.assert_allclose(
        up.mass_matrix(uvms, q), np.diag([2, 2, 2, 0.01, 0.02, 0.03]), atol=1e-12
    )
    h = up.bias_forces(uvms, q, np.zeros(6))
    np.testing.assert_allclose(h, [0, 0, 2.0 * G, 0, 0, 0], atol=1e-12)


def test_unknown_ee_frame_lists_available_frames(write_urdf):
    path = write_urdf(body_urdf(hydro=GOOD_HYDRO))
    with pytest.raises(up.ModelError) as info:
        up.load_uvms(path, ee_frame="gripper", sensor_frame="body")
    message = str(info.value)
    assert str(path) in message
    assert "'gripper' not found" in message
    assert "body" in message and "root_joint" in message  # the frames that do exist
    with pytest.raises(up.ModelError, match="'wrist' not found"):
        up.load_uvms(path, ee_frame="body", sensor_frame="wrist")


@pytest.mark.parametrize("density", [0.0, -1025.0, math.nan, math.inf])
def test_non_positive_water_density_is_a_parameter_error(write_urdf, density):
    path = write_urdf(body_urdf(hydro=GOOD_HYDRO))
    with pytest.raises(up.ParameterError, match="water_density"):
        up.load_uvms(path, water_density_kg_m3=density, ee_frame="body", sensor_frame="body")


# ---- the extension: inline and top-level are the same ------------------------------------


def _random_state(uvms, seed):
    rng = _rng(seed)
    q = random_configuration(uvms, rng)
    v = rng.normal(size=uvms.nv)
    current = rng.normal(size=3) * 0.3
    return q, v, current


def test_top_level_hydrodynamics_equals_inline(load_body, write_urdf):
    hydro = hydro_xml(
        0.004,
        (0.01, -0.02, 0.03),
        (1, 2, 3, 0.1, 0.2, 0.3),
        (4, 5, 6, 0.4, 0.5, 0.6),
        (7, 8, 9, 1, 1, 1),
    )
    inline = load_body(body_urdf(hydro=hydro))
    text = body_urdf().replace(
        "</robot>", f'<hydrodynamics link="body">{hydro}</hydrodynamics></robot>'
    )
    top = up.load_uvms(write_urdf(text, "top.urdf"), ee_frame="body", sensor_frame="body")
    assert top.hydro_bodies[0].params == inline.hydro_bodies[0].params
    for seed in range(3):
        q, v, current = _random_state(inline, seed)
        np.testing.assert_array_equal(up.mass_matrix(top, q), up.mass_matrix(inline, q))
        np.testing.assert_array_equal(
            up.bias_forces(top, q, v, current), up.bias_forces(inline, q, v, current)
        )


# ---- coefficients derived from collision geometry ----------------------------------------


def test_sphere_collision_gives_half_displaced_mass(load_body):
    """rho = 1000 (not the default) to see that the density reaches the derivation."""
    radius, rho = 0.1, 1000.0
    uvms = load_body(
        body_urdf(mass=5.0, collision=f'<sphere radius="{radius}"/>'), water_density_kg_m3=rho
    )
    (body,) = uvms.hydro_bodies
    volume = 4.0 / 3.0 * math.pi * radius**3
    assert body.params.derived
    assert body.name == "body/collision[0]"
    assert body.params.volume_m3 == pytest.approx(volume, rel=1e-14)
    np.testing.assert_allclose(
        body.params.added_mass, np.diag([0.5 * rho * volume] * 3 + [0.0] * 3), rtol=1e-14, atol=0
    )
    # and it is inside M: the translational diagonal is m + 0.5 rho V (exact up to round-off)
    mass = up.mass_matrix(uvms, uvms.neutral_configuration())
    np.testing.assert_allclose(np.diag(mass)[:3], 5.0 + 0.5 * rho * volume, rtol=1e-14)


COLLISIONS = {
    "box": ('<box size="0.3 0.2 0.1"/>', 0.3 * 0.2 * 0.1),
    "cylinder": ('<cylinder radius="0.05" length="0.4"/>', math.pi * 0.05**2 * 0.4),
}


@pytest.mark.parametrize("shape", list(COLLISIONS))
def test_box_and_cylinder_collisions_and_their_origin(write_urdf, shape):
    """Volume exact (1e-14), added mass symmetric PSD, and the collision <origin> moves the
    centre of buoyancy: at rest with the CoG at the link origin, h[3:] is minus the buoyancy
    moment r_b x (R^T rho V g e_z) about the origin, r_b the collision offset (1e-10 relative)."""
    geometry, volume = COLLISIONS[shape]
    offset = np.array([0.05, -0.02, 0.08])
    rpy = np.array([0.3, -0.4, 1.1])
    text = _robot(
        _link(
            "body",
            INERTIAL
            + f'<collision><origin xyz="{_s(offset)}" rpy="{_s(rpy)}"/>'
            + f"<geometry>{geometry}</geometry></collision>",
        )
    )
    uvms = up.load_uvms(write_urdf(text), ee_frame="body", sensor_frame="body")
    (body,) = uvms.hydro_bodies
    assert body.params.derived
    assert body.params.volume_m3 == pytest.approx(volume, rel=1e-14)
    added = uvms.added_mass_per_joint[1]
    np.testing.assert_allclose(added, added.T, atol=1e-12)
    assert np.linalg.eigvalsh(added).min() > -1e-12
    assert np.linalg.eigvalsh(added).max() > 0.1 * 1025 * volume  # not zero
    np.testing.assert_allclose(uvms.center_of_buoyancy_per_joint_m[1], offset, atol=1e-15)
    # the added mass at the link origin is the primitive's moved by its origin
    primitive = (
        box_hydro([0.3, 0.2, 0.1], 1025.0) if shape == "box" else cylinder_hydro(0.05, 0.4, 1025.0)
    )
    moved = hydro_in_frame(primitive, pin.rpy.rpyToMatrix(*rpy), offset)
    np.testing.assert_allclose(added, moved.added_mass, atol=1e-10 * np.abs(added).max())

    q = uvms.neutral_configuration()
    rotation = pin.rpy.rpyToMatrix(0.4, -0.3, 0.2)
    q[3:7] = pin.Quaternion(rotation).coeffs()
    h = up.bias_forces(uvms, q, np.zeros(6))
    buoyancy_body = rotation.T @ np.array([0.0, 0.0, 1025.0 * volume * G])
    expected_moment = np.cross(offset, buoyancy_body)
    assert np.linalg.norm(expected_moment) > 1e-2  # the check has teeth
    np.testing.assert_allclose(h[3:], -expected_moment, rtol=1e-10, atol=1e-12)
    # force: weight minus buoyancy, in body axes
    np.testing.assert_allclose(
        h[:3], rotation.T @ np.array([0, 0, 2.0 * G]) - buoyancy_body, rtol=1e-10, atol=1e-12
    )


# ---- links on fixed joints are merged exactly --------------------------------------------

PARENT_MASS, PARENT_INERTIA = 8.0, np.diag([0.2, 0.3, 0.4])
CHILD_MASS, CHILD_COM = 1.5, np.array([0.02, 0.01, -0.03])
CHILD_INERTIA = np.array([[0.02, 0.001, -0.002], [0.001, 0.03, 0.0015], [-0.002, 0.0015, 0.025]])
CHILD_XYZ = np.array([0.15, -0.08, 0.1])
CHILD_RPY = np.array([0.4, -0.3, 0.9])
PARENT_VOLUME, PARENT_COB = 0.007, np.array([0.0, 0.0, 0.02])
PARENT_ADDED = np.diag([3.0, 5.0, 6.0, 0.1, 0.2, 0.25])
PARENT_LINEAR = np.diag([4.0, 6.0, 7.0, 0.3, 0.4, 0.5])
CHILD_VOLUME, CHILD_COB = 0.0015, np.array([0.03, -0.01, 0.02])


def _child_added_mass() -> np.ndarray:
    """A full, symmetric positive definite 6x6 added mass with every coupling present."""
    a = _rng(42).normal(size=(6, 6))
    return a @ a.T + np.diag([1.0, 1.0, 1.0, 0.05, 0.05, 0.05])


def _child_linear_damping() -> np.ndarray:
    a = _rng(43).normal(size=(6, 6))
    return 0.5 * a @ a.T


def _motion_transform(rotation: np.ndarray, p: np.ndarray) -> np.ndarray:
    """X with nu_child = X nu_parent for a child at (R, p) in the parent, written by hand:
    v_c = R^T (v_p + w_p x p) = R^T v_p - R^T [p]x w_p, w_c = R^T w_p."""
    skew = np.array([[0, -p[2], p[1]], [p[2], 0, -p[0]], [-p[1], p[0], 0]])
    x = np.zeros((6, 6))
    x[:3, :3] = rotation.T
    x[:3, 3:] = -rotation.T @ skew
    x[3:, 3:] = rotation.T
    return x


def _inertial_xml(mass, com, inertia) -> str:
    i = inertia
    return (
        f'<inertial><origin xyz="{_s(com)}"/><mass value="{float(mass)!r}"/>'
        f'<inertia ixx="{float(i[0, 0])!r}" iyy="{float(i[1, 1])!r}" izz="{float(i[2, 2])!r}" '
        f'ixy="{float(i[0, 1])!r}" ixz="{float(i[0, 2])!r}" iyz="{float(i[1, 2])!r}"/></inertial>'
    )


def _hydro_full(volume, cob, added, linear, quadratic=(0.0,) * 6) -> str:
    return (
        f'<hydrodynamics><volume value="{float(volume)!r}"/><center_of_buoyancy xyz="{_s(cob)}"/>'
        f'<added_mass matrix="{_s(added)}"/><linear_damping matrix="{_s(linear)}"/>'
        f'<quadratic_damping diagonal="{_s(quadratic)}"/></hydrodynamics>'
    )


def _two_link_urdf(child_quadratic=(0.0,) * 6) -> str:
    parent = _link(
        "body",
        _inertial_xml(PARENT_MASS, np.zeros(3), PARENT_INERTIA)
        + _hydro_full(PARENT_VOLUME, PARENT_COB, PARENT_ADDED, PARENT_LINEAR),
    )
    child = _link(
        "pod",
        _inertial_xml(CHILD_MASS, CHILD_COM, CHILD_INERTIA)
        + _hydro_full(
            CHILD_VOLUME, CHILD_COB, _child_added_mass(), _child_linear_damping(), child_quadratic
        ),
    )
    return _robot(parent, child, _fixed("body", "pod", CHILD_XYZ, CHILD_RPY))


def _one_link_by_hand_urdf() -> str:
    """The same vehicle as one link, every child coefficient moved to the parent by hand."""
    rotation = pin.rpy.rpyToMatrix(*CHILD_RPY)  # URDF rpy: R = Rz(y) Ry(p) Rx(r)
    x = _motion_transform(rotation, CHILD_XYZ)
    # rigid body: combined mass, CoM, inertia about the combined CoM (parallel axis)
    mass = PARENT_MASS + CHILD_MASS
    child_com = CHILD_XYZ + rotation @ CHILD_COM
    com = CHILD_MASS * child_com / mass  # the parent's CoM is at its origin
    inertia = PARENT_INERTIA + rotation @ CHILD_INERTIA @ rotation.T
    for m, c in ((PARENT_MASS, np.zeros(3)), (CHILD_MASS, child_com)):
        d = c - com
        inertia = inertia + m * (d @ d * np.eye(3) - np.outer(d, d))
    # hydrodynamics: energies add (X^T A X), volumes add, CoB is the volume-weighted centroid
    volume = PARENT_VOLUME + CHILD_VOLUME
    cob = (PARENT_VOLUME * PARENT_COB + CHILD_VOLUME * (CHILD_XYZ + rotation @ CHILD_COB)) / volume
    added = PARENT_ADDED + x.T @ _child_added_mass() @ x
    linear = PARENT_LINEAR + x.T @ _child_linear_damping() @ x
    return _robot(
        _link("body", _inertial_xml(mass, com, inertia) + _hydro_full(volume, cob, added, linear))
    )


def test_fixed_child_link_equals_hand_merged_single_link(load_body):
    """M and h (velocity, current, gravity, buoyancy, added mass, linear damping) of a body
    with a child on a fixed joint equal those of one link carrying the hand-transformed
    coefficients: X^T A X, X^T D X, transformed CoB, parallel-axis inertia. Tolerance 1e-10
    relative to the largest entry (round-off of 6x6 products, see module docstring)."""
    merged = load_body(_two_link_urdf())
    by_hand = load_body(_one_link_by_hand_urdf())
    assert merged.nv == by_hand.nv == 6
    assert len(merged.hydro_bodies) == 2
    assert merged.volume_m3 == pytest.approx(PARENT_VOLUME + CHILD_VOLUME, rel=1e-14)
    for seed in range(4):
        q, v, current = _random_state(merged, seed)
        m1, m2 = up.mass_matrix(merged, q), up.mass_matrix(by_hand, q)
        np.testing.assert_allclose(m1, m2, rtol=0, atol=1e-10 * np.abs(m2).max())
        h1, h2 = up.bias_forces(merged, q, v, current), up.bias_forces(by_hand, q, v, current)
        np.testing.assert_allclose(h1, h2, rtol=0, atol=1e-10 * np.abs(h2).max())


def test_hydro_in_frame_agrees_with_hand_transform():
    """geometry.hydro_in_frame (used for derived coefficients) is the same map as the hand
    X^T A X and CoB transform used above (1e-12 relative)."""
    rotation = pin.rpy.rpyToMatrix(*CHILD_RPY)
    child = up.HydroParams(
        CHILD_VOLUME, CHILD_COB, _child_added_mass(), _child_linear_damping(), np.zeros(6)
    )
    moved = hydro_in_frame(child, rotation, CHILD_XYZ)
    x = _motion_transform(rotation, CHILD_XYZ)
    scale = np.abs(moved.added_mass).max()
    np.testing.assert_allclose(moved.added_mass, x.T @ child.added_mass @ x, atol=1e-12 * scale)
    np.testing.assert_allclose(
        moved.center_of_buoyancy_m, CHILD_XYZ + rotation @ CHILD_COB, atol=1e-15
    )


def test_quadratic_damping_of_a_fixed_child_is_exact_in_its_own_frame(load_body):
    """Quadratic damping is not a linear map, so it cannot be moved to the parent; the
    loader evaluates it per link in the child's frame. Hand computation: nu_child =
    X nu_body, nu_r = nu_child - [R_wc^T v_c; 0], w = -D_q |nu_r| nu_r, tau = X^T w on the
    free-flyer (the body's LOCAL Jacobian is the identity). 1e-10 relative."""
    quadratic = np.array([20.0, 30.0, 40.0, 0.5, 0.7, 0.9])
    with_quad = load_body(_two_link_urdf(quadratic))
    without = load_body(_two_link_urdf())
    rotation = pin.rpy.rpyToMatrix(*CHILD_RPY)
    x = _motion_transform(rotation, CHILD_XYZ)
    for seed in range(4):
        q, v, current = _random_state(with_quad, seed)
        got = up.bias_forces(with_quad, q, v, current) - up.bias_forces(without, q, v, current)
        rotation_world_body = pin.Quaternion(q[3:7]).toRotationMatrix()
        nu_r = x @ v
        nu_r[:3] -= (rotation_world_body @ rotation).T @ current
        expected = x.T @ (quadratic * np.abs(nu_r) * nu_r)  # h holds minus the fluid wrench
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-10 * np.abs(expected).max())


# ---- the reference model ------------------------------------------------------------------


def test_reference_model_sizes_and_frames(reference_uvms):
    uvms = reference_uvms
    assert (uvms.nq, uvms.nv, uvms.n_arm_joints) == (11, 10, 4)
    assert uvms.model.frames[uvms.ee_frame_id].name == "ee"
    assert uvms.model.frames[uvms.sensor_frame_id].name == "ft_sensor"
    assert uvms.source == str(REFERENCE_URDF)


def test_reference_model_is_neutrally_buoyant(reference_uvms):
    assert abs(reference_uvms.net_buoyancy_N) < 0.01
    assert reference_uvms.mass_kg == pytest.approx(11.99, abs=1e-9)  # URDF header comment


def test_reference_hydro_comes_from_the_urdf(reference_uvms):
    names = sorted(b.name for b in reference_uvms.hydro_bodies)
    assert names == ["arm_link1", "arm_link2", "arm_link3", "arm_link4", "base_link", "tool"]
    for body in reference_uvms.hydro_bodies:
        assert not body.params.derived, body.name
        assert body.params.origin == "URDF"
    # the tool rides on the sensor on fixed joints: merged into arm_joint4's body
    tool = next(b for b in reference_uvms.hydro_bodies if b.name == "tool")
    assert reference_uvms.model.names[tool.joint_id] == "arm_joint4"
    np.testing.assert_allclose(tool.placement_in_joint.translation, [0.08, 0, 0], atol=1e-15)


def _total_centres(uvms, q):
    """(weight W, CoG), (buoyancy B, CoB) of the whole system in the world frame."""
    model, data = uvms.model, uvms.model.createData()
    cog = pin.centerOfMass(model, data, q).copy()
    pin.forwardKinematics(model, data, q)
    moment = sum(
        uvms.volume_per_joint_m3[j] * data.oMi[j].act(uvms.center_of_buoyancy_per_joint_m[j])
        for j in range(1, model.njoints)
    )
    return cog, moment / uvms.volume_m3


def test_reference_model_rights_itself_in_roll_and_pitch(reference_uvms):
    """At the neutral arm, level: the CoB is above the CoG, and tilting by +-0.05 rad in roll
    (pitch) raises (lowers) h's roll (pitch) component, i.e. the net moment opposes the tilt.
    Per body h_roll(phi) = sin(phi) sum z F - cos(phi) sum y F (likewise in pitch with x), so
    (h(a) - h(-a)) / (2 sin a) is exactly the metacentric stiffness B z_b - W z_g: 1e-9
    relative (round-off only)."""
    uvms = reference_uvms
    q0 = uvms.neutral_configuration()
    q0[7:] = 0.0
    cog, cob = _total_centres(uvms, q0)
    assert cob[2] > cog[2] + 1e-3
    weight = uvms.mass_kg * G
    buoyancy = uvms.water_density_kg_m3 * uvms.volume_m3 * G
    stiffness = buoyancy * cob[2] - weight * cog[2]
    assert stiffness > 0.0
    angle = 0.05
    for axis, rpy in ((3, (angle, 0, 0)), (4, (0, angle, 0))):
        h = {}
        for sign in (1, -1):
            q = q0.copy()
            q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(*(sign * np.array(rpy)))).coeffs()
            h[sign] = up.bias_forces(uvms, q, np.zeros(uvms.nv))[axis]
        assert h[1] > h[-1]
        slope = (h[1] - h[-1]) / (2 * math.sin(angle))
        assert slope == pytest.approx(stiffness, rel=1e-9)
