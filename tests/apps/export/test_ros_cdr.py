"""The struct-packed CDR encoders (uvms_pin.apps.export.ros_cdr) write the bytes of
mcap-ros2-support's generic encoder, whatever the strings' lengths (the alignment)."""

from __future__ import annotations

import numpy as np
import pytest

from uvms_pin.apps.export.ros_cdr import ENCODERS
from uvms_pin.apps.export.ros_messages import odometry, transform
from uvms_pin.apps.export.ros_schemas import MESSAGE_DEFINITIONS

serialize_dynamic = pytest.importorskip("mcap_ros2._dynamic").serialize_dynamic


def _generic(name: str):
    return serialize_dynamic(name, MESSAGE_DEFINITIONS[name])[name]


@pytest.mark.parametrize("names", [("map", "odom"), ("a", "bb"), ("abc", "base_link_x"), ("", "e")])
def test_tf_bytes_equal_the_generic_encoder(names):
    rng = np.random.default_rng(len(names[0]) + 7 * len(names[1]))
    message = {
        "transforms": [
            transform(
                10**18 + k,
                names[k % 2],
                names[(k + 1) % 2] + "x" * k,
                rng.normal(size=3),
                rng.normal(size=4),
            )
            for k in range(5)
        ]
    }
    assert ENCODERS["tf2_msgs/TFMessage"](message) == _generic("tf2_msgs/TFMessage")(message)
    empty = {"transforms": []}
    assert ENCODERS["tf2_msgs/TFMessage"](empty) == _generic("tf2_msgs/TFMessage")(empty)


@pytest.mark.parametrize("frame, child", [("map", "base_link"), ("ab", "c"), ("", "")])
def test_odometry_bytes_equal_the_generic_encoder(frame, child):
    rng = np.random.default_rng(3)
    pose, twist = rng.normal(size=7), rng.normal(size=6)
    twist[3:] = np.nan  # the estimate's angular velocity
    message = odometry(946_684_800 * 10**9 + 123, frame, child, pose, twist)
    assert ENCODERS["nav_msgs/Odometry"](message) == _generic("nav_msgs/Odometry")(message)
