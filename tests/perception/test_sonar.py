"""The sonars: where a plane's echo falls, the altimeter's altitude, seeded speckle."""

from __future__ import annotations

import numpy as np
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.perception.scene import Scene
from uvms_pin.perception.sonar import Sonar, SonarSpec
from uvms_pin.physics.world.objects import plane


def _scene(uvms, objects) -> Scene:
    scene = Scene(uvms, objects)
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


@pytest.mark.parametrize(
    ("changes", "key"),
    [
        ({"type": "sidescan"}, "type"),
        ({"beams": 0}, "beams"),
        ({"type": "altimeter", "beams": 4}, "beams"),
        ({"max_range_m": 0.05}, "max_range_m"),
        ({"vertical_fov_rad": 0.0}, "vertical_fov_rad"),
    ],
)
def test_a_bad_sonar_is_refused_naming_the_key(changes, key):
    with pytest.raises(ParameterError, match=key):
        SonarSpec("fls", **changes)
