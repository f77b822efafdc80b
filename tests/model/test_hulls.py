"""The hulls a free surface cuts, read from the URDF: collision shapes fitted to the
<hydrodynamics> volume and centre of buoyancy, derived primitives, equivalent spheres."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import body_urdf, hydro_xml

import uvms_pin as up
from uvms_pin.hydro.hull import SurfaceAt
from uvms_pin.model.summary import model_summary


def test_collision_shapes_are_fitted_to_the_hydrodynamics(load_body):
    """Two boxes (0.02 m^3 of geometry) for a 0.01 m^3 body whose centre of buoyancy is
    0.05 m above the boxes' centroid: volumes scaled by 1/2, pieces moved up by 0.05 m."""
    text = body_urdf(
        mass=10.0, hydro=hydro_xml(0.01, cob=(0, 0, 0.1)), collision='<box size="0.5 0.2 0.1"/>'
    )
    second = '<collision><origin xyz="0 0 0.1"/><geometry><box size="0.5 0.2 0.1"/></geometry></collision>'
    uvms = load_body(text.replace("</collision>", "</collision>" + second, 1))
    (hull,) = uvms.surface_bodies.hulls
    assert not hull.equivalent_sphere and len(hull.pieces) == 2
    assert hull.volume_scale == pytest.approx(0.5)
    np.testing.assert_allclose([p.translation_m[2] for p in hull.pieces], [0.05, 0.15], atol=1e-15)
    deep = hull.wet(np.eye(3), np.array([0.0, 0.0, -5.0]), SurfaceAt())
    assert deep.volume_m3 == pytest.approx(0.01)
    np.testing.assert_allclose(deep.center_of_buoyancy_m, [0, 0, 0.1], atol=1e-15)
    assert "its collision box, box, volume scaled by 0.5 to V" in model_summary(uvms)


def test_a_derived_body_is_its_own_primitive(load_body):
    uvms = load_body(body_urdf(mass=1.0, collision='<cylinder radius="0.05" length="0.4"/>'))
    (hull,) = uvms.surface_bodies.hulls
    assert hull.volume_scale == pytest.approx(1.0, rel=1e-14)
    assert hull.pieces[0].shape.label == "cylinder"
    assert uvms.volume_m3 == pytest.approx(math.pi * 0.05**2 * 0.4)


def test_a_volume_without_geometry_floats_as_a_sphere_and_the_summary_says_so(load_body):
    uvms = load_body(body_urdf(mass=1.0, hydro=hydro_xml(0.002, cob=(0.1, 0, 0))))
    (hull,) = uvms.surface_bodies.hulls
    assert hull.equivalent_sphere
    assert hull.pieces[0].shape.radius_m == pytest.approx((3 * 0.002 / (4 * math.pi)) ** (1 / 3))
    np.testing.assert_allclose(hull.pieces[0].translation_m, [0.1, 0, 0])
    assert "a sphere of its volume at r_b" in model_summary(uvms)


def test_a_body_with_neither_volume_nor_geometry_is_always_wet(load_body):
    with pytest.warns(up.ModelWarning, match="displaces no water"):
        uvms = load_body(body_urdf(mass=1.0, hydro=hydro_xml(0.0, added=(1, 1, 1, 0, 0, 0))))
    assert len(uvms.surface_bodies) == 0
    assert uvms.surface_bodies.added_mass_without_hull_per_joint[1][0, 0] == 1.0
    q = uvms.neutral_configuration()
    q[2] = 3.0  # high in the air: its added mass stays
    mass = up.mass_matrix(uvms, q, free_surface=True)
    assert mass[0, 0] == pytest.approx(2.0)


def test_an_unreadable_collision_mesh_leaves_a_sphere_with_a_warning(load_body):
    """A link with <hydrodynamics> loads as before; its hull falls back to the sphere."""
    text = body_urdf(mass=1.0, hydro=hydro_xml(0.001), collision='<mesh filename="missing.stl"/>')
    with pytest.warns(up.ModelWarning, match="sphere of the link's volume"):
        uvms = load_body(text)
    assert uvms.surface_bodies.hulls[0].equivalent_sphere


@pytest.mark.parametrize(
    "collision, needle",
    [
        ("", "<collision> has no <geometry> shape"),  # an empty <geometry/>
        ('<box size="12000 0.2 0.1"/>', "<box size> = 12000 0.2 0.1 m cannot be physical"),
        ('<sphere radius="-20000"/>', "<sphere radius> = -20000 m cannot be physical"),
    ],
)
def test_a_collision_without_a_shape_or_beyond_ten_kilometres_is_refused(
    write_urdf, collision, needle
):
    """Refused where the body's water is derived from it; with <hydrodynamics>, said, and
    the surface cuts an equivalent sphere instead."""
    for hydro in (None, hydro_xml(0.01)):
        text = body_urdf(mass=10.0, hydro=hydro, collision="<box/>")
        text = text.replace("<geometry><box/></geometry>", f"<geometry>{collision}</geometry>")
        path = write_urdf(text)
        if hydro is None:
            with pytest.raises(up.ModelError, match=needle):
                up.load_uvms(path, ee_frame="body", sensor_frame="body")
        else:
            with pytest.warns(up.ModelWarning, match=needle):
                uvms = up.load_uvms(path, ee_frame="body", sensor_frame="body")
            assert uvms.surface_bodies.hulls[0].equivalent_sphere
