"""ROS 2 messages as CDR bytes, with their schemas: one encoder for the bag and the live
server. The two most frequent types go through `uvms_pin.apps.export.ros_cdr`'s struct
packing, the others through mcap-ros2-support's generic encoder (the ``ros`` extra)."""

from __future__ import annotations

from collections.abc import Callable, Mapping

from uvms_pin.apps.export.ros_cdr import ENCODERS
from uvms_pin.apps.export.ros_sample import TOPIC_TYPES
from uvms_pin.apps.export.ros_schemas import MESSAGE_DEFINITIONS
from uvms_pin.errors import OptionalDependencyError

__all__ = ["TopicEncoder", "missing_ros_extra"]


def missing_ros_extra(what: str) -> OptionalDependencyError:
    """The error for ``what`` (e.g. "the MCAP export") without the ``ros`` extra."""
    return OptionalDependencyError(
        f'{what} needs mcap and mcap-ros2-support: pip install "uvms-pin[ros]"'
    )


class TopicEncoder:
    """Each topic's ROS 2 type and message definition (`schema`) and its messages as CDR
    bytes (`encode`); an encoder is made once per type.

    Args:
        types: the topics' ROS 2 types (topic -> type name), `TOPIC_TYPES`'s and, for a
            bag, its cameras' and sonars' (`uvms_pin.apps.export.ros_perception`).

    Raises (at construction): OptionalDependencyError without mcap-ros2-support.
    """

    def __init__(self, types: Mapping[str, str] = TOPIC_TYPES) -> None:
        self.types = types
        try:
            from mcap_ros2._dynamic import serialize_dynamic
        except ImportError as exc:
            raise missing_ros_extra("the ROS 2 encoding") from exc
        self._serialize_dynamic = serialize_dynamic
        self._encoders: dict[str, Callable[[dict], bytes]] = {}

    def schema(self, topic: str) -> tuple[str, str]:
        """(ROS 2 type, its message definition text) of ``topic`` (one of ``types``)."""
        name = self.types[topic]
        return name, MESSAGE_DEFINITIONS[name]

    def encode(self, topic: str, message: dict) -> bytes:
        """``message`` (the dict the builders of `uvms_pin.apps.export.ros_messages` make)
        of ``topic`` as CDR."""
        name = self.types[topic]
        encoder = self._encoders.get(name)
        if encoder is None:
            encoder = ENCODERS.get(name) or self._serialize_dynamic(name, MESSAGE_DEFINITIONS[name])[name]  # fmt: skip
            self._encoders[name] = encoder
        return encoder(message)
