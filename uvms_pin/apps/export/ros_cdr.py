"""CDR encoders of the bag's two most frequent messages, ``tf2_msgs/TFMessage`` and
``nav_msgs/Odometry``, by struct packing: the bytes ``mcap_ros2``'s generic encoder writes
(tests/apps/export/test_ros_cdr.py compares them), at a fraction of its time (it walks the
schema field by field; these two are most of a bag's messages and floats).

CDR (little endian): a 4-byte encapsulation header, then each field aligned to its size
counted from the end of that header; a string is its length with the NUL (uint32), its bytes
and the NUL; a sequence its count (uint32) and its items.
"""

from __future__ import annotations

import struct

__all__ = ["ENCODERS", "encode_odometry", "encode_tf"]

_HEADER = b"\x00\x01\x00\x00"  # CDR, little endian
_U32, _I32U32 = struct.Struct("<I"), struct.Struct("<iI")
_TRANSFORM = struct.Struct("<7d")
_ODOMETRY = struct.Struct("<85d")  # pose (7), covariance (36), twist (6), covariance (36)


def _align(buf: bytearray, size: int) -> None:
    buf.extend(b"\0" * (-(len(buf) - 4) % size))


def _string(buf: bytearray, text: str) -> None:
    data = text.encode() + b"\0"
    _align(buf, 4)
    buf += _U32.pack(len(data))
    buf += data


def _header(buf: bytearray, header: dict) -> None:
    _align(buf, 4)
    buf += _I32U32.pack(header["stamp"]["sec"], header["stamp"]["nanosec"])
    _string(buf, header["frame_id"])


def _xyz(v: dict) -> tuple[float, float, float]:
    return v["x"], v["y"], v["z"]


def encode_tf(message: dict) -> bytes:
    """A ``tf2_msgs/TFMessage`` (the dict `uvms_pin.apps.export.ros_messages.transform`
    builds, in ``{"transforms": [...]}``) as CDR."""
    buf = bytearray(_HEADER)
    transforms = message["transforms"]
    buf += _U32.pack(len(transforms))
    for t in transforms:
        _header(buf, t["header"])
        _string(buf, t["child_frame_id"])
        _align(buf, 8)
        rotation = t["transform"]["rotation"]
        buf += _TRANSFORM.pack(*_xyz(t["transform"]["translation"]), *_xyz(rotation), rotation["w"])
    return bytes(buf)


def encode_odometry(message: dict) -> bytes:
    """A ``nav_msgs/Odometry`` (`uvms_pin.apps.export.ros_messages.odometry`) as CDR."""
    buf = bytearray(_HEADER)
    _header(buf, message["header"])
    _string(buf, message["child_frame_id"])
    _align(buf, 8)
    pose, twist = message["pose"], message["twist"]
    orientation = pose["pose"]["orientation"]
    buf += _ODOMETRY.pack(
        *_xyz(pose["pose"]["position"]),
        *_xyz(orientation),
        orientation["w"],
        *pose["covariance"],
        *_xyz(twist["twist"]["linear"]),
        *_xyz(twist["twist"]["angular"]),
        *twist["covariance"],
    )
    return bytes(buf)


#: message type -> its fast encoder (the others go through mcap_ros2's)
ENCODERS = {"tf2_msgs/TFMessage": encode_tf, "nav_msgs/Odometry": encode_odometry}
