"""A rollout as a ROS 2 bag: one MCAP file, ROS 2 message schemas, CDR-encoded (docs/ros.md).

Topics (each message stamped `uvms_pin.apps.export.ros_messages.stamp_ns` of its sample):

- ``/tf_static`` (``tf2_msgs/TFMessage``, once): ``map`` -> ``odom`` (identity: the truth
  does not drift), every link or named frame fixed to its parent, every fixed world object
  in ``map``;
- ``/tf`` (every sample): ``odom`` -> the vehicle's root link (the true pose), every link
  behind a moving joint in its parent, every free object in ``map``;
- ``/joint_states`` (``sensor_msgs/JointState``): the arm's joint positions [rad or m],
  velocities and the generalized forces ``tau`` on them [N m or N];
- ``/odometry/truth`` (``nav_msgs/Odometry``): the vehicle's pose in ``map`` and its body
  twist; ``/odometry/estimate`` when the run had a navigation estimator (its angular
  velocity NaN: the filter does not estimate it);
- ``/ee/wrench`` and ``/ft_sensor/wrench`` (``geometry_msgs/WrenchStamped``) when the model
  has an end-effector: the true contact wrench (what the end-effector exerts on the
  environment) and what the force/torque sensor reported, at the end-effector point in its
  frame's axes;
- ``/imu`` (``sensor_msgs/Imu``) and ``/depth`` (``sensor_msgs/FluidPressure``, p_atm +
  rho g d [Pa]) when the run had those sensors; ``/thrusters`` (``sensor_msgs/JointState``,
  the thrust of each thruster [N] as ``effort``) when it had thrusters;
- ``/world/markers`` (``visualization_msgs/MarkerArray``, once) when it had world objects;
- each camera's and sonar's images at its firings and its frame in ``/tf_static``
  (`uvms_pin.apps.export.ros_perception`).
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from uvms_pin.apps.export.ros_encoding import TopicEncoder
from uvms_pin.apps.export.ros_perception import PerceptionTopics
from uvms_pin.apps.export.ros_sample import (
    MAP,
    TOPIC_TYPES,
    Message,
    SampleRecord,
    SampleTopics,
    records_of,
)
from uvms_pin.errors import VizError
from uvms_pin.model.urdf.load import load_uvms
from uvms_pin.model.uvms import DEFAULT_WATER_DENSITY_KG_M3
from uvms_pin.results.atomic import atomic_path

if TYPE_CHECKING:
    from uvms_pin.model.uvms import UVMS
    from uvms_pin.results.rollout_data import RolloutData

__all__ = ["MAP", "SavedRunTopics", "messages", "write_mcap"]


def _writer_class():
    """mcap's writer (the ``ros`` extra)."""
    from uvms_pin.apps.export.ros_encoding import missing_ros_extra

    try:
        from mcap.writer import Writer
    except ImportError as exc:
        raise missing_ros_extra("the MCAP export") from exc
    return Writer


def rollout_model(rollout: RolloutData, urdf: str | Path | None = None) -> UVMS:
    """The model a rollout ran (``metadata['model_source']``, or ``urdf``): its kinematics
    give the links' frames."""
    source = Path(urdf) if urdf is not None else rollout.metadata.get("model_source")
    if not source or not Path(source).is_file():
        raise VizError(
            f"model file {source!r} of the rollout not found: the export needs its "
            "kinematics; pass the URDF explicitly (uvms-pin export DIR --urdf FILE)"
        )
    world = rollout.metadata.get("world") or {}
    density = float(world.get("water_density_kg_m3", DEFAULT_WATER_DENSITY_KG_M3))
    return load_uvms(source, water_density_kg_m3=density)


def write_mcap(rollout: RolloutData, path: str | Path, *, urdf: str | Path | None = None) -> Path:
    """Write ``rollout`` to ``path`` as a ROS 2 MCAP bag (the topics of this module's
    docstring); the file appears whole or not at all (written aside, then renamed)."""
    writer_class = _writer_class()
    if len(rollout) == 0:
        raise VizError("the rollout has no sample to export")
    uvms = rollout_model(rollout, urdf)
    if rollout.q.shape[1] != uvms.model.nq:
        raise VizError(
            f"the rollout's q has {rollout.q.shape[1]} entries, its model {uvms.model.nq}: "
            "not the model it ran (pass --urdf)"
        )
    topics = SavedRunTopics(rollout, uvms)
    encoder = TopicEncoder(topics.types)
    with atomic_path(path) as tmp, open(tmp, "wb") as stream:
        writer = writer_class(stream)
        writer.start(profile="ros2", library="uvms-pin")
        channels = {}
        for topic, message, time_ns in messages(rollout, topics):
            if topic not in channels:  # a channel for each topic the run has data for
                name, text = encoder.schema(topic)
                schema = writer.register_schema(name, "ros2msg", text.encode())
                channels[topic] = writer.register_channel(topic, "cdr", schema)
            writer.add_message(channels[topic], time_ns, encoder.encode(topic, message), time_ns)
        writer.finish()
    return Path(path)


def perception_topics(rollout: RolloutData, uvms: UVMS) -> PerceptionTopics:
    """The rollout's cameras and sonars as topics, their frames placed at its first sample."""
    data = uvms.model.createData()
    pin.framesForwardKinematics(uvms.model, data, rollout.q[0])
    return PerceptionTopics(rollout, uvms.model, data)


class SavedRunTopics:
    """A saved run's messages: its samples' (`SampleTopics`: ``static``, ``at``) with its
    cameras' and sonars' (`PerceptionTopics`): their frames in the one ``/tf_static``, each
    firing's messages after its sample's. ``types``: every topic's ROS 2 type (for a
    `TopicEncoder`); ``joint_kinds`` as `SampleTopics`'. What the bag holds and a live view
    of the saved run sends."""

    def __init__(self, rollout: RolloutData, uvms: UVMS):
        self.samples = SampleTopics(rollout.metadata, uvms)
        self.seen = perception_topics(rollout, uvms)
        self.types = TOPIC_TYPES | self.seen.types
        self.joint_kinds = self.samples.joint_kinds

    def static(self, time_s: float, q: np.ndarray) -> Iterator[Message]:
        for topic, message, time_ns in self.samples.static(time_s, q):
            if topic == "/tf_static":  # one message: the sensors' frames with the links'
                message["transforms"].extend(self.seen.static_transforms(time_ns))
            yield topic, message, time_ns

    def at(self, record: SampleRecord) -> Iterator[Message]:
        yield from self.samples.at(record)
        yield from self.seen.at(record.time_s)


def messages(rollout: RolloutData, topics: SavedRunTopics) -> Iterator[Message]:
    """Every message of the bag of ``rollout`` (``topics``: its `SavedRunTopics`), in time
    order (the static ones first)."""
    yield from topics.static(float(rollout.time_s[0]), rollout.q[0])
    for record in records_of(rollout):
        yield from topics.at(record)
