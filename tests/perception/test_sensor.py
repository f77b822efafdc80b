"""The checks every sensor spec shares: counts and fields of view, their messages."""

from __future__ import annotations

import re

import numpy as np
import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.perception.camera import CameraSpec
from uvms_pin.perception.scene import Scene
from uvms_pin.perception.sensor import SENSORS
from uvms_pin.perception.sonar import SonarSpec
from uvms_pin.physics.world.objects import plane


@pytest.mark.parametrize(
    ("spec", "changes", "message"),
    [
        (CameraSpec, {"width": 0}, "camera 'c': width must be an integer in [1, 8192], got 0"),
        (
            CameraSpec,
            {"height": 2.0},
            "camera 'c': height must be an integer in [1, 8192], got 2.0",
        ),
        (SonarSpec, {"bins": 8193}, "sonar 'c': bins must be an integer in [1, 8192], got 8193"),
        (
            CameraSpec,
            {"width": True},
            "camera 'c': width must be an integer in [1, 8192], got True",
        ),
        (
            SonarSpec,
            {"rays_per_beam": 1025},
            "sonar 'c': rays_per_beam must be an integer in [1, 1024], got 1025",
        ),
        (
            CameraSpec,
            {"horizontal_fov_rad": 3.5},
            "camera 'c': horizontal_fov_rad must be in (0, pi), got 3.5",
        ),
        (
            SonarSpec,
            {"vertical_fov_rad": -0.1},
            "sonar 'c': vertical_fov_rad must be in (0, pi), got -0.1",
        ),
    ],
)
def test_a_count_or_field_of_view_out_of_range_is_refused_in_full(spec, changes, message):
    with pytest.raises(ParameterError, match=f"^{re.escape(message)}$"):
        spec("c", **changes)


def test_a_count_given_as_a_numpy_integer_is_taken_as_the_int_it_is():
    """``width=np.int64(64)`` (a size computed with numpy): 64, stored as an int (it was
    refused as "must be an integer ..., got 64")."""
    camera = CameraSpec("c", width=np.int64(64), height=np.uint16(48))
    sonar = SonarSpec("s", beams=np.int32(16))
    assert (camera.width, camera.height, sonar.beams) == (64, 48, 16)
    assert type(camera.width) is int and type(sonar.beams) is int


def test_the_largest_counts_and_widest_fields_of_view_are_accepted():
    CameraSpec("c", width=8192, height=1, horizontal_fov_rad=3.14)
    SonarSpec("c", beams=4096, bins=8192, rays_per_beam=1, vertical_fov_rad=3.14)


@pytest.mark.parametrize(
    "spec",
    [
        CameraSpec("cam", width=40, height=30),
        SonarSpec("fls", beams=16, bins=64),
        SonarSpec("mbes", type="multibeam", beams=24, bins=32),
        SonarSpec("alt", type="altimeter", beams=1, bins=50),
    ],
    ids=lambda spec: spec.name,
)
def test_the_bytes_counted_before_a_run_are_those_a_firing_records(reference_uvms, spec):
    """The memory check before a run (`suite.check_mounts`) counts each firing as its kind's
    ``bytes``: exactly the arrays a firing of that sensor records."""
    seabed = plane("seabed", [0.0, 0.0, -25.0], [0.0, 0.0, 1.0], 0.5, 0.4)
    scene = Scene(reference_uvms, [seabed])
    q = reference_uvms.neutral_configuration()
    q[:3] = [0.0, 0.0, -20.0]
    scene.update(q)
    kind = next(k for k in SENSORS.values() if isinstance(spec, k.spec))
    fired = kind.make(spec, scene, np.random.default_rng(0)).fire()
    assert kind.bytes(spec) == sum(array.nbytes for array in fired.values())
