"""The water's optics and the camera's lights (`uvms_pin.perception.optics`): daylight and
backscatter laws, the lights' cones and the validation of their parameters."""

from __future__ import annotations

import numpy as np
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.perception.camera import CameraSpec
from uvms_pin.perception.optics import (
    JERLOV_KD_PER_M,
    Light,
    WaterOptics,
    backscatter,
    cone,
    cone_of_cosine,
)


def test_a_lights_direction_is_made_a_unit_vector():
    """Any non-zero direction is normalised (its sense kept); zero is refused."""
    light = Light(direction=(0.0, 3.0, 4.0))
    np.testing.assert_allclose(light.direction, (0.0, 0.6, 0.8), rtol=1e-15)
    with pytest.raises(ParameterError, match="must not be zero"):
        Light(direction=(0.0, 0.0, 0.0))


def test_cone_is_one_inside_zero_beyond_and_smoothstep_on_its_edge():
    """1 up to the half-angle (included), 1 - smoothstep over the edge (1/2 at its middle),
    0 beyond; with no edge a hard cone (1 up to and at the half-angle, 0 beyond, never NaN);
    `cone_of_cosine` of cos(angle) is `cone` of the angle."""
    half, edge = 0.4, 0.2
    angles = np.array([0.0, 0.2, 0.4, 0.45, 0.5, 0.55, 0.6, 0.9, np.pi])
    values = cone(angles, half, edge)
    s = np.clip((angles - half) / edge, 0.0, 1.0)
    np.testing.assert_allclose(values, 1.0 - s * s * (3.0 - 2.0 * s), atol=1e-15)
    assert values[2] == 1.0 and values[4] == pytest.approx(0.5, abs=1e-15)
    assert values[6] == pytest.approx(0.0, abs=1e-15) and values[-1] == 0.0
    assert np.all(np.diff(values) <= 0.0)
    hard = cone(angles, half, 0.0)
    np.testing.assert_array_equal(hard, (angles <= half).astype(float))
    for edge_rad in (edge, 0.0):
        np.testing.assert_allclose(
            cone_of_cosine(np.cos(angles), half, edge_rad), cone(angles, half, edge_rad), atol=1e-12
        )


def test_the_jerlov_types_grow_more_turbid_and_shift_from_blue_to_green_water():
    """Jerlov's K_d table read as the physics it records: from the clearest oceanic type (I)
    to the most turbid coastal one (9C) every channel attenuates at least as fast as in the
    type before; red always faster than green; the least attenuated colour is blue in the
    clear oceanic waters (I to II) and green from type III on (the coastal waters' yellow
    substance absorbs blue)."""
    order = ["I", "IA", "IB", "II", "III", "1C", "3C", "5C", "7C", "9C"]
    assert list(JERLOV_KD_PER_M) == order
    kd = np.array([JERLOV_KD_PER_M[name] for name in order])  # (types, R G B)
    assert np.all(kd > 0.0)
    assert np.all(np.diff(kd, axis=0) >= 0.0), "a type clearer than the one before it"
    assert np.all(np.diff(kd[:, [0, 2]], axis=0) > 0.0)  # red and blue strictly
    assert np.all(kd[:, 0] > kd[:, 1])
    least = ["RGB"[c] for c in np.argmin(kd, axis=1)]
    assert least == ["B"] * 4 + ["G"] * 6
    for name in order:  # the preset is the camera's default beta_D and beta_B too
        water = WaterOptics(water_type=name)
        np.testing.assert_array_equal(water.beta_d_per_m, JERLOV_KD_PER_M[name])
        np.testing.assert_array_equal(water.beta_b_per_m, JERLOV_KD_PER_M[name])


def test_daylight_decays_exponentially_and_backscatter_saturates_to_the_veiling_light():
    """E(d) = E0 exp(-K_d d) (clamped at the surface), B_inf = b E(camera depth), and
    backscatter B_inf (1 - exp(-beta_B z)): zero at zero range, half of B_inf at
    z = ln 2 / beta_B, B_inf at infinite range."""
    water = WaterOptics(water_type="II", surface_irradiance=2.0, backscatter_albedo=0.3)
    kd = water.kd_per_m
    np.testing.assert_allclose(water.daylight(np.array([5.0]))[0], 2.0 * np.exp(-5.0 * kd))
    np.testing.assert_allclose(water.daylight(np.array([-1.0]))[0], [2.0] * 3)  # above: E0
    veiling = water.veiling_light(5.0)
    np.testing.assert_allclose(veiling, 0.3 * 2.0 * np.exp(-5.0 * kd), rtol=1e-15)
    beta = water.beta_b_per_m
    ranges = np.array([0.0, np.log(2.0) / beta[1], np.inf])
    b = backscatter(veiling, ranges, beta)
    np.testing.assert_array_equal(b[0], np.zeros(3))
    assert b[1, 1] == pytest.approx(0.5 * veiling[1], rel=1e-14)
    np.testing.assert_allclose(b[2], veiling, rtol=1e-15)


def test_water_optics_accepts_clear_values_at_their_bounds_and_refuses_beyond():
    """Attenuation and backscatter of 0 (clear water), night (E0 = 0) and albedos 0 and 1 are
    accepted; negative coefficients, a negative or infinite irradiance, an albedo above 1
    are refused."""
    WaterOptics(attenuation_per_m=(0.0, 0.0, 0.0), backscatter_per_m=(0.0, 0.1, 0.0))
    WaterOptics(surface_irradiance=0.0, backscatter_albedo=0.0)
    WaterOptics(backscatter_albedo=1.0)
    Light(intensity=0.0, edge_rad=0.0)
    bad = [
        ({"attenuation_per_m": (0.1, -0.01, 0.1)}, "attenuation_per_m"),
        ({"backscatter_per_m": (0.1, 0.1)}, "backscatter_per_m"),
        ({"surface_irradiance": -1.0}, "surface_irradiance"),
        ({"surface_irradiance": np.inf}, "surface_irradiance"),
        ({"backscatter_albedo": 1.5}, "backscatter_albedo"),
    ]
    for changes, match in bad:
        with pytest.raises(ParameterError, match=match):
            WaterOptics(**changes)
    for changes, match in (
        ({"intensity": -1.0}, "intensity"),
        ({"half_angle_rad": 0.0}, "half_angle_rad"),
        ({"edge_rad": -0.1}, "edge_rad"),
    ):
        with pytest.raises(ParameterError, match=match):
            Light(**changes)


@pytest.mark.parametrize(
    ("owner", "changes", "match"),
    [
        (WaterOptics, {"attenuation_per_m": (np.inf, 0.1, 0.1)}, "attenuation_per_m"),
        (WaterOptics, {"backscatter_per_m": (0.1, np.nan, 0.1)}, "backscatter_per_m"),
        (Light, {"position_m": (np.nan, 0.0, 0.0)}, "position_m"),
        (Light, {"position_m": (0.1, 0.0)}, "position_m"),
        (Light, {"direction": (np.inf, 0.0, 0.0)}, "direction"),
        (Light, {"direction": (1.0, 0.0)}, "direction"),
        (Light, {"intensity": np.inf}, "intensity"),
        (Light, {"intensity": np.nan}, "intensity"),
        (Light, {"edge_rad": np.inf}, "edge_rad"),
        (Light, {"half_angle_rad": np.nan}, "half_angle_rad"),
    ],
)
def test_water_and_lights_refuse_non_finite_or_misshapen_values_by_name(owner, changes, match):
    """An inf or nan coefficient, light position, direction, intensity or edge is refused
    by name, as a light's position or direction of two numbers. Accepted, an inf direction
    became nan; in the benchmark's view (benchmarks/bench_perception.py) an inf intensity
    made the radiance nan wherever its cone is 0 (7,460 of 76,800 pixels), a nan position
    every pixel's, each read as 0 counts: a black image, no error."""
    with pytest.raises(ParameterError, match=match):
        owner(**changes)


def test_a_cameras_light_refused_names_the_camera_and_the_light():
    """A light of a camera's table refused says which camera and which light."""
    table = {"lights": [{"intensity": 2.0}, {"direction": [0.0, 0.0, np.inf]}]}
    with pytest.raises(ParameterError, match=r"camera 'front': lights\[1\]: .*direction"):
        CameraSpec.from_dict({"name": "front", **table}, "camera 'front'")
