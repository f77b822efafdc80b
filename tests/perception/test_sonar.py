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
        ({"type": "multibeam", "range_noise_m": -0.1}, "range_noise_m"),
    ],
)
def test_a_bad_sonar_is_refused_naming_the_key(changes, key):
    with pytest.raises(ParameterError, match=key):
        SonarSpec("fls", **changes)
