"""The sonars: where a plane's echo falls, the altimeter's altitude, seeded speckle."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.perception.scene import Scene
from uvms_pin.perception.sonar import Sonar, SonarSpec
from uvms_pin.physics.world.objects import plane, solid

#: the scene's backend, set for each test by `_both_backends`
BACKEND = "core"


@pytest.fixture(autouse=True, params=["core", "python"])
def _both_backends(request, monkeypatch):
    """Every test on the compiled caster and on the Python reference."""
    monkeypatch.setattr(sys.modules[__name__], "BACKEND", request.param)


def _scene(uvms, objects) -> Scene:
    scene = Scene(uvms, objects, backend=BACKEND)
    q = uvms.neutral_configuration()
    q[:3] = [0.0, 0.0, -20.0]
    scene.update(q)
    return scene


@pytest.mark.parametrize("distance_m", [2.0, 7.3, 15.55])
def test_a_wall_echoes_in_the_range_bin_of_its_distance(reference_uvms, distance_m):
    wall = plane("wall", [distance_m, 0.0, -20.0], [-1.0, 0.0, 0.0], 0.5, 0.4)
    spec = SonarSpec("fls", beams=64, bins=256, max_range_m=20.0, speckle=False)
    sonar = Sonar(spec, _scene(reference_uvms, [wall]), np.random.default_rng(0))
    image = sonar.intensity()
    centre = np.argmin(np.abs(spec.bearing_rad))
    strongest = spec.range_m[np.argmax(image[:, centre])]
    step = spec.range_m[1] - spec.range_m[0]
    assert abs(strongest - distance_m) <= step
    # off the axis the wall is farther: range / cos(bearing)
    side = np.argmin(np.abs(spec.bearing_rad - 0.5))
    off = spec.range_m[np.argmax(image[:, side])]
    assert abs(off - distance_m / np.cos(spec.bearing_rad[side])) <= 2 * step


def test_the_altimeter_hears_the_seabed_at_its_altitude(reference_uvms):
    seabed = plane("seabed", [0.0, 0.0, -23.2], [0.0, 0.0, 1.0], 0.5, 0.4)
    spec = SonarSpec("alt", type="altimeter", beams=1, bins=500, max_range_m=10.0,
                     horizontal_fov_rad=0.1, rpy_rad=(0.0, np.pi / 2, 0.0))  # fmt: skip
    sonar = Sonar(spec, _scene(reference_uvms, [seabed]), np.random.default_rng(0))
    profile = sonar.intensity()[:, 0]
    assert abs(spec.range_m[np.argmax(profile)] - 3.2) <= spec.range_m[1] - spec.range_m[0]


@pytest.mark.parametrize("tilt_rad", [0.0, 0.15, -0.2])
@pytest.mark.parametrize("altitude_m", [0.4, 3.0, 15.0])
def test_the_altimeter_reads_its_distance_to_the_seabed(reference_uvms, altitude_m, tilt_rad):
    """Its reading is the echo's first arrival: the seabed's distance along its normal
    (flat, or sloping within the 25 degree cone), to the spacing of its rays about the axis
    (5e-5 of it), whatever the altitude and with the speckle on; the centre of gravity of
    its echo would read 1.3 % more. Nothing within its ranges: NaN, and the reading is what
    its record keeps (`beam_range_m`, one beam)."""
    normal = np.array([np.sin(tilt_rad), 0.0, np.cos(tilt_rad)])
    seabed = plane("seabed", [0.0, 0.0, -20.0 - altitude_m], normal, 0.5, 0.4)
    raw = {"name": "alt", "type": "altimeter", "rpy_rad": [0.0, np.pi / 2, 0.0],
           "position_m": [0.1, 0.05, -0.1]}  # fmt: skip
    spec = SonarSpec.from_dict(raw, "alt")
    fired = Sonar(spec, _scene(reference_uvms, [seabed]), np.random.default_rng(0)).fire()
    distance = (np.array([0.1, 0.05, -20.1]) - [0.0, 0.0, -20.0 - altitude_m]) @ normal
    assert fired["beam_range_m"].shape == (1,) and fired["beam_intensity"][0] > 0.0
    assert fired["beam_range_m"][0] == pytest.approx(distance, rel=5e-5)
    assert fired["beam_range_m"][0] >= distance
    deep = SonarSpec.from_dict({**raw, "max_range_m": 0.9 * distance}, "alt")
    nothing = Sonar(deep, _scene(reference_uvms, [seabed]), np.random.default_rng(0)).fire()
    assert np.isnan(nothing["beam_range_m"][0]) and nothing["beam_intensity"][0] == 0.0


def test_the_altimeters_cone_is_round_over_a_slope_steeper_than_it(reference_uvms):
    """Its rays all within the cone's half-angle, so a slope steeper than the cone (0.3 rad
    against 0.22) reads alike whichever way it faces: the nearest the cone hears,
    d / cos(slope - half), to the rays' spacing. Its rays were a square grid of bearings and
    elevations, its corners 17 degrees off the axis of a 12.6 degree cone: facing the
    diagonal the slope read its perpendicular distance, 0.4 % nearer."""
    slope = 0.3
    readings = []
    for azimuth in (0.0, np.pi / 4, np.pi / 2, 3 * np.pi / 4):
        normal = [np.sin(slope) * np.cos(azimuth), np.sin(slope) * np.sin(azimuth), np.cos(slope)]
        seabed = plane("seabed", [0.0, 0.0, -24.0], normal, 0.5, 0.4)
        spec = SonarSpec("alt", type="altimeter", rpy_rad=(0.0, np.pi / 2, 0.0), speckle=False,
                         range_noise_m=0.0)  # fmt: skip
        sonar = Sonar(spec, _scene(reference_uvms, [seabed]), np.random.default_rng(0))
        off_axis = np.arccos(np.clip(sonar.rays[:, 0], -1.0, 1.0))
        assert off_axis.max() <= 0.5 * spec.horizontal_fov_rad + 1e-12
        readings.append(sonar.fire()["beam_range_m"][0])
    distance = 4.0 * np.cos(slope)  # from the sonar's origin to the plane, along its normal
    nearest = distance / np.cos(slope - 0.5 * spec.horizontal_fov_rad)
    assert np.ptp(readings) < 2e-4
    np.testing.assert_allclose(readings, nearest, rtol=1e-3)
    assert min(readings) >= nearest


def test_an_altimeter_by_its_type_alone_has_one_narrow_beam_and_hears_the_seabed(
    reference_uvms,
):
    """``type = "altimeter"`` and nothing else: one beam, a 0.44 rad cone (the Ping's 25
    degrees); a fan's type keeps its 256 beams over 2 rad. Under it a seabed sloping 20
    degrees, 3 m down: the cone's rays meet it from 2.84 m (the ray 7.5 degrees off its
    normal) to 3.34 m, and the echo is there. With the fan's 2 rad as its cone (the default
    before), the altimeter on the vehicle's body heard the robot's own links at 0.16 m."""
    spec = SonarSpec.from_dict(
        {"name": "alt", "type": "altimeter", "rpy_rad": [0.0, np.pi / 2, 0.0]}, "alt"
    )
    assert (spec.beams, spec.horizontal_fov_rad) == (1, 0.44)
    for kind in ("imaging", "multibeam"):
        fan = SonarSpec("s", type=kind)
        assert (fan.beams, fan.horizontal_fov_rad) == (256, 2.0)
    slope = np.deg2rad(20.0)
    seabed = plane("seabed", [0.0, 0.0, -23.0], [np.sin(slope), 0.0, np.cos(slope)], 0.5, 0.4)
    sonar = Sonar(spec, _scene(reference_uvms, [seabed]), np.random.default_rng(0))
    heard = spec.range_m[np.argmax(sonar.intensity()[:, 0])]
    bin_m = spec.range_m[1] - spec.range_m[0]
    assert 2.84 - bin_m <= heard <= 3.34 + bin_m


def test_the_same_seed_gives_the_same_speckle(reference_uvms):
    wall = plane("wall", [5.0, 0.0, -20.0], [-1.0, 0.0, 0.0], 0.5, 0.4)

    def image(seed):
        spec = SonarSpec("fls", beams=32, bins=64)
        return Sonar(spec, _scene(reference_uvms, [wall]), np.random.default_rng(seed)).intensity()

    np.testing.assert_array_equal(image(1), image(1))
    assert not np.array_equal(image(1), image(2))


def _multibeam(uvms, altitude_m, objects=(), **changes) -> Sonar:
    """A multibeam looking down (its fan across the track) ``altitude_m`` above a seabed."""
    seabed = plane("seabed", [0.0, 0.0, -20.0 - altitude_m], [0.0, 0.0, 1.0], 0.5, 0.4)
    spec = {"type": "multibeam", "beams": 31, "bins": 400, "max_range_m": 10.0,
            "horizontal_fov_rad": 1.6, "vertical_fov_rad": 0.02, "speckle": False,
            "rpy_rad": (0.0, np.pi / 2, 0.0), **changes}  # fmt: skip
    return Sonar(SonarSpec("mbes", **spec), _scene(uvms, [seabed, *objects]),
                 np.random.default_rng(3))  # fmt: skip


def test_a_multibeam_profiles_a_flat_seabed_at_altitude_over_cos_bearing(reference_uvms):
    sonar = _multibeam(reference_uvms, 3.0)
    fired = sonar.fire()
    # each beam's slant range to the plane 3 m below: h / cos(bearing), the fan's 0.02 rad
    # along the track lengthening it by at most h (1 / cos(0.01) - 1) = 1.5e-4 m
    expected = 3.0 / np.cos(sonar.spec.bearing_rad)
    np.testing.assert_allclose(fired["beam_range_m"], expected, rtol=0, atol=2e-4)
    assert fired["intensity"].shape == (400, 31)
    # the echo falls off with incidence (cos^2) and range: the nadir beam is the loudest
    assert np.argmax(fired["beam_intensity"]) == 15


def test_a_multibeam_sees_an_object_on_the_seabed_and_nothing_beyond_its_range(
    reference_uvms,
):
    crate = solid("crate", "box", {"size_m": [0.6, 8.0, 1.0]}, [0.0, -1.5, -22.5],
                  [0, 0, 0], 0.5, 0.4)  # fmt: skip
    fired = _multibeam(reference_uvms, 3.0, [crate]).fire()
    bearing = SonarSpec("mbes", type="multibeam", beams=31, horizontal_fov_rad=1.6).bearing_rad
    # the crate's top (1 m high, from y = -1.5 - 4 m to +2.5 m: starboard of the vehicle
    # and under it) is 2 m below the sonar: the beams pointing at it read 2 / cos(bearing)
    on_top = np.abs(2.0 * np.tan(bearing) + 1.5) < 1.9  # within its top's width, margin
    np.testing.assert_allclose(fired["beam_range_m"][on_top], 2.0 / np.cos(bearing[on_top]),
                               atol=2e-4)  # fmt: skip
    far = _multibeam(reference_uvms, 12.0).fire()  # the seabed beyond max_range_m
    assert np.all(np.isnan(far["beam_range_m"])) and np.all(far["beam_intensity"] == 0.0)


def test_a_multibeams_range_noise_is_seeded(reference_uvms):
    def ranges(seed):
        sonar = _multibeam(reference_uvms, 3.0, range_noise_m=0.05, speckle=True)
        sonar.rng = np.random.default_rng(seed)
        return sonar.fire()["beam_range_m"]

    np.testing.assert_array_equal(ranges(1), ranges(1))
    error = ranges(2) - 3.0 / np.cos(np.linspace(-0.8, 0.8, 31))
    assert not np.array_equal(ranges(1), ranges(2))
    assert 0.02 < np.std(error) < 0.1  # the noise's 0.05 m


@pytest.mark.parametrize(
    ("changes", "key"),
    [
        ({"type": "sidescan"}, "type"),
        ({"beams": 0}, "beams"),
        ({"type": "altimeter", "beams": 4}, "beams"),
        ({"max_range_m": 0.05}, "max_range_m"),
        ({"vertical_fov_rad": 0.0}, "vertical_fov_rad"),
        ({"type": "altimeter", "horizontal_fov_rad": "wide"}, "horizontal_fov_rad"),
        ({"type": "multibeam", "range_noise_m": -0.1}, "range_noise_m"),
    ],
)
def test_a_bad_sonar_is_refused_naming_the_key(changes, key):
    with pytest.raises(ParameterError, match=key):
        SonarSpec("fls", **changes)


def test_range_bins_are_centred_and_bearings_span_the_fov():
    """The bins split [min, max) into equal slices, range_m their centres; a multi-beam
    sonar's bearings span its horizontal FOV symmetrically, an altimeter's one beam looks
    along its axis (bearing 0)."""
    spec = SonarSpec("fls", beams=5, bins=8, min_range_m=1.0, max_range_m=5.0)
    np.testing.assert_allclose(spec.range_m, 1.0 + 0.5 * (np.arange(8) + 0.5), rtol=1e-15)
    half = 0.5 * spec.horizontal_fov_rad
    np.testing.assert_allclose(spec.bearing_rad, np.linspace(-half, half, 5), rtol=1e-15)
    two = SonarSpec("two", beams=2, bins=8)
    np.testing.assert_allclose(
        two.bearing_rad, [-0.5 * two.horizontal_fov_rad, 0.5 * two.horizontal_fov_rad]
    )
    altimeter = SonarSpec("alt", type="altimeter", beams=1, bins=8, horizontal_fov_rad=0.1)
    np.testing.assert_array_equal(altimeter.bearing_rad, [0.0])


def test_echo_falls_with_two_way_absorption_and_spherical_spreading(reference_uvms):
    """echo = reflectivity cos^2(incidence) w 10^(-2 alpha r / 10) / r^2: each ray's echo
    times r^2 10^(0.2 alpha r) is the same for a wall at 4 m or 8 m and for alpha = 0 or
    0.3 dB/m (the same ray meets both walls at the same incidence)."""
    heard = {}
    for distance in (4.0, 8.0):
        for alpha in (0.0, 0.3):
            wall = plane("wall", [distance, 0.0, -20.0], [-1.0, 0.0, 0.0], 0.5, 0.4)
            spec = SonarSpec("fls", beams=16, bins=200, max_range_m=20.0, speckle=False,
                             absorption_db_per_m=alpha)  # fmt: skip
            sonar = Sonar(spec, _scene(reference_uvms, [wall]), np.random.default_rng(0))
            _, _, r, echo = sonar.echoes()
            assert len(echo) == len(sonar.rays)  # every ray meets the wall
            heard[distance, alpha] = echo * r**2 * 10.0 ** (0.2 * alpha * r)
    reference = heard[4.0, 0.0]
    assert np.all(reference > 0.0)
    for value in heard.values():
        np.testing.assert_allclose(value, reference, rtol=1e-9)


def test_beam_patterns_are_half_power_at_the_fov_edge_and_sinc_squared_across_beams(
    reference_uvms,
):
    """A forward-looking sonar's rays are weighted by 2^(-(elevation / half vertical FOV)^2)
    (half power at the FOV's edge), an altimeter's by 2^(-(angle off axis / half FOV)^2);
    the beams are formed with sinc^2 taps half a beamwidth apart: symmetric, summing to 1,
    centre over first neighbour pi^2/4 (1 / sinc(1/2)^2) and the first null one beamwidth
    away (the outer taps zero)."""
    wall = plane("wall", [5.0, 0.0, -20.0], [-1.0, 0.0, 0.0], 0.5, 0.4)
    scene = _scene(reference_uvms, [wall])
    spec = SonarSpec("fls", beams=8, bins=64, vertical_fov_rad=0.4, rays_per_beam=9)
    sonar = Sonar(spec, scene, np.random.default_rng(0))
    elevation = np.arcsin(sonar.rays[:, 2])
    np.testing.assert_allclose(sonar.weight, 0.5 ** ((elevation / 0.2) ** 2), rtol=1e-12)
    taps = sonar.taps
    np.testing.assert_allclose(taps, taps[::-1], rtol=1e-15)
    assert taps.sum() == pytest.approx(1.0, rel=1e-15)
    assert taps[2] / taps[1] == pytest.approx(np.pi**2 / 4.0, rel=1e-12)
    np.testing.assert_allclose(taps[[0, 4]], 0.0, atol=1e-16)

    altimeter = SonarSpec("alt", type="altimeter", beams=1, bins=64, horizontal_fov_rad=0.3,
                          rays_per_beam=5)  # fmt: skip
    sonar = Sonar(altimeter, scene, np.random.default_rng(0))
    off_axis = np.arccos(np.clip(sonar.rays[:, 0], -1.0, 1.0))
    # the fan is a square grid of bearing and elevation: off-axis angle^2 ~ b^2 + e^2
    bearing = np.arctan2(sonar.rays[:, 1], sonar.rays[:, 0])
    elevation = np.arcsin(sonar.rays[:, 2])
    np.testing.assert_allclose(
        sonar.weight, 0.5 ** ((bearing**2 + elevation**2) / 0.15**2), rtol=1e-2
    )
    assert np.argmax(sonar.weight) == np.argmin(off_axis)


@pytest.mark.parametrize("kind", ["imaging", "altimeter"])
def test_the_rays_fill_the_fan_symmetrically_about_the_acoustic_axis(reference_uvms, kind):
    """A fan's rays sit at the centres of n equal slices of its vertical field of view
    (+-(1 - 1/n) of its half, symmetric: their mean elevation 0); an altimeter's grid of n
    x n at the centres of its cone's slices, symmetric in bearing and elevation: their mean
    direction the acoustic axis x."""
    n, half = 8, 0.2
    fov = {"vertical_fov_rad": 2 * half} if kind == "imaging" else {"horizontal_fov_rad": 2 * half}
    beams = 4 if kind == "imaging" else 1
    spec = SonarSpec("s", type=kind, beams=beams, bins=16, rays_per_beam=n, **fov)
    wall = plane("wall", [5.0, 0.0, -20.0], [-1.0, 0.0, 0.0], 0.5, 0.4)
    sonar = Sonar(spec, _scene(reference_uvms, [wall]), np.random.default_rng(0))
    elevation = np.arcsin(sonar.rays[:, 2])
    centres = half * ((np.arange(n) + 0.5) / n * 2.0 - 1.0)
    np.testing.assert_allclose(np.unique(elevation.round(12)), centres, rtol=0, atol=1e-12)
    assert elevation.mean() == pytest.approx(0.0, abs=1e-15)
    if kind == "altimeter":
        bearing = np.arctan2(sonar.rays[:, 1], sonar.rays[:, 0])
        np.testing.assert_allclose(np.unique(bearing.round(12)), centres, rtol=0, atol=1e-12)
        mean = sonar.rays.mean(axis=0)
        np.testing.assert_allclose(mean / np.linalg.norm(mean), [1.0, 0.0, 0.0], atol=1e-15)


def test_a_firing_is_written_into_the_arrays_given(reference_uvms):
    """`Sonar.fire(out)`: the run's stack of images written into, the same values."""
    expected = _multibeam(reference_uvms, 3.0).fire()
    out = {key: np.zeros_like(value) for key, value in expected.items()}
    assert _multibeam(reference_uvms, 3.0).fire(out) is out
    for key, value in expected.items():
        np.testing.assert_array_equal(out[key], value)
    with pytest.raises(ParameterError, match="mbes"):
        _multibeam(reference_uvms, 3.0).fire({"intensity": out["intensity"]})
