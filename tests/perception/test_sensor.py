"""The checks every sensor spec shares: counts and fields of view, their messages."""

from __future__ import annotations

import re

import pytest

from uvms_pin.errors import ParameterError
from uvms_pin.perception.camera import CameraSpec
from uvms_pin.perception.sonar import SonarSpec


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


def test_the_largest_counts_and_widest_fields_of_view_are_accepted():
    CameraSpec("c", width=8192, height=1, horizontal_fov_rad=3.14)
    SonarSpec("c", beams=4096, bins=8192, rays_per_beam=1, vertical_fov_rad=3.14)
