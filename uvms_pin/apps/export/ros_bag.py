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
- ``/world/markers`` (``visualization_msgs/MarkerArray``, once) when it had world objects.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from uvms_pin.apps.export.ros_cdr import ENCODERS
from uvms_pin.apps.export.ros_frames import ODOM, LinkTree, relative_placements
from uvms_pin.apps.export.ros_messages import (
    header,
    imu,
    joint_state,
    odometry,
    stamp_ns,
    transform,
    wrench,
)
from uvms_pin.apps.export.ros_schemas import MESSAGE_DEFINITIONS
from uvms_pin.apps.export.ros_world import FREE_STATE, markers, object_pose
from uvms_pin.errors import OptionalDependencyError, VizError
from uvms_pin.model.urdf.load import load_uvms
from uvms_pin.model.uvms import DEFAULT_WATER_DENSITY_KG_M3
from uvms_pin.results.atomic import atomic_path
from uvms_pin.results.joint_positions import arm_positions
from uvms_pin.sim.navigation.depth import ATMOSPHERIC_PRESSURE_PA, GRAVITY_M_S2

if TYPE_CHECKING:
    from uvms_pin.model.uvms import UVMS
    from uvms_pin.results.rollout_data import RolloutData

__all__ = ["MAP", "write_mcap"]

MAP = "map"
_IDENTITY = (np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]))

# (topic, message or None, bag time [ns]) as written, in time order
Message = tuple[str, dict, int]


def _libraries():
    """mcap's writer and mcap-ros2-support's encoder factory (the ``ros`` extra)."""
    try:
        from mcap.writer import Writer
        from mcap_ros2._dynamic import serialize_dynamic
    except ImportError as exc:
        raise OptionalDependencyError(
            'the MCAP export needs mcap and mcap-ros2-support: pip install "uvms-pin[ros]"'
        ) from exc
    return Writer, serialize_dynamic


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
    writer_class, serialize_dynamic = _libraries()
    if len(rollout) == 0:
        raise VizError("the rollout has no sample to export")
    uvms = rollout_model(rollout, urdf)
    if rollout.q.shape[1] != uvms.model.nq:
        raise VizError(
            f"the rollout's q has {rollout.q.shape[1]} entries, its model {uvms.model.nq}: "
            "not the model it ran (pass --urdf)"
        )
    with atomic_path(path) as tmp, open(tmp, "wb") as stream:
        writer = writer_class(stream)
        writer.start(profile="ros2", library="uvms-pin")
        types, channels, encoders = _topic_types(), {}, {}
        for topic, message, time_ns in messages(rollout, uvms):
            if topic not in channels:  # a channel for each topic the run has data for
                name = types[topic]
                text = MESSAGE_DEFINITIONS[name]
                schema = writer.register_schema(name, "ros2msg", text.encode())
                channels[topic] = writer.register_channel(topic, "cdr", schema)
                encoders[topic] = ENCODERS.get(name) or serialize_dynamic(name, text)[name]
            writer.add_message(channels[topic], time_ns, encoders[topic](message), time_ns)
        writer.finish()
    return Path(path)


def _topic_types() -> dict[str, str]:
    tf, joints = "tf2_msgs/TFMessage", "sensor_msgs/JointState"
    return {
        "/tf_static": tf,
        "/tf": tf,
        "/joint_states": joints,
        "/thrusters": joints,
        "/odometry/truth": "nav_msgs/Odometry",
        "/odometry/estimate": "nav_msgs/Odometry",
        "/ee/wrench": "geometry_msgs/WrenchStamped",
        "/ft_sensor/wrench": "geometry_msgs/WrenchStamped",
        "/imu": "sensor_msgs/Imu",
        "/depth": "sensor_msgs/FluidPressure",
        "/world/markers": "visualization_msgs/MarkerArray",
    }


def messages(rollout: RolloutData, uvms: UVMS) -> Iterator[Message]:
    """Every message of the bag, in time order (the static ones first)."""
    model, data = uvms.model, uvms.model.createData()
    tree = LinkTree.of(model)
    world = (rollout.metadata.get("world") or {}).get("world") or {}
    t0 = stamp_ns(rollout.time_s[0])
    translations, quaternions = relative_placements(model, data, tree, rollout.q[0])
    yield "/tf_static", {"transforms": _static(t0, tree, translations, quaternions, world)}, t0
    if world.get("objects") or world.get("free_objects"):
        yield "/world/markers", markers(t0, world, rollout.q[0, :3]), t0
    per_sample = _SampleTopics(rollout, uvms, tree, world)
    for k in range(len(rollout)):
        yield from per_sample.at(k, data)


def _static(time_ns: int, tree: LinkTree, translations, quaternions, world: dict) -> list[dict]:
    out = [transform(time_ns, MAP, ODOM, *_IDENTITY)]
    for k, name in enumerate(tree.names):
        if not tree.moving[k]:
            out.append(transform(time_ns, tree.parents[k], name, translations[k], quaternions[k]))
    for record in world.get("objects", ()):
        out.append(transform(time_ns, MAP, record["name"], *object_pose(record)))
    return out


class _SampleTopics:
    """The messages of one logged sample (the topics the run has data for)."""

    def __init__(self, rollout: RolloutData, uvms: UVMS, tree: LinkTree, world: dict):
        self.rollout, self.model, self.tree = rollout, uvms.model, tree
        meta, signals = rollout.metadata, rollout.signals
        self.root = tree.names[0]
        self.joint_names = list(meta.get("arm_joint_names", ()))
        kinds = meta.get("arm_joint_kinds") or ["revolute"] * len(self.joint_names)
        self.joint_positions = arm_positions(rollout.q[:, 7:], kinds)
        self.ee = None if uvms.ee_frame_id is None else int(uvms.ee_frame_id)
        self.free = [o["name"] for o in world.get("free_objects", ())]
        units = meta.get("signal_units") or {}
        self.thrusters = (units.get("thrust") or {}).get("components", [])
        density = float((meta.get("world") or {}).get("water_density_kg_m3", DEFAULT_WATER_DENSITY_KG_M3))  # fmt: skip
        self.pascal_per_m = density * GRAVITY_M_S2
        self.signals = signals

    def at(self, k: int, data: pin.Data) -> Iterator[Message]:
        r, time_ns = self.rollout, stamp_ns(self.rollout.time_s[k])
        yield "/tf", {"transforms": self._moving(k, time_ns, data)}, time_ns
        if self.joint_names:
            joints = (self.joint_positions[k], r.v[k, 6:], r.tau[k, 6:])
            yield "/joint_states", joint_state(time_ns, self.joint_names, *joints), time_ns
        yield "/odometry/truth", odometry(time_ns, MAP, self.root, r.q[k, :7], r.v[k, :6]), time_ns
        yield from self._sensors(k, time_ns, data)

    def _moving(self, k: int, time_ns: int, data: pin.Data) -> list[dict]:
        tree = self.tree
        translations, quaternions = relative_placements(self.model, data, tree, self.rollout.q[k])
        out = [
            transform(time_ns, tree.parents[j], name, translations[j], quaternions[j])
            for j, name in enumerate(tree.names)
            if tree.moving[j]
        ]
        if self.free:
            states = self.signals["free_objects"][k].reshape(-1, FREE_STATE)
            for name, state in zip(self.free, states, strict=True):
                out.append(transform(time_ns, MAP, name, state[:3], state[3:7]))
        return out

    def _sensors(self, k: int, time_ns: int, data: pin.Data) -> Iterator[Message]:
        """The wrenches (after `_moving`'s kinematics), the navigation and the thrusters."""
        r, signals = self.rollout, self.signals
        if self.ee is not None:
            rotation = data.oMf[self.ee].rotation  # world <- ee, kinematics of sample k
            frame = self.model.frames[self.ee].name
            for topic, w in (("/ee/wrench", r.wrench_contact_world[k]), ("/ft_sensor/wrench", r.wrench_measured_world[k])):  # fmt: skip
                in_ee = np.concatenate([rotation.T @ w[:3], rotation.T @ w[3:6]])
                yield topic, wrench(time_ns, frame, in_ee), time_ns
        if "estimate" in signals:
            yield (
                "/odometry/estimate",
                _estimate(time_ns, self.root, signals["estimate"][k]),
                time_ns,
            )
        if "imu_gyro" in signals and "imu_accel" in signals:
            message = imu(time_ns, self.root, signals["imu_gyro"][k], signals["imu_accel"][k])
            yield "/imu", message, time_ns
        if "depth" in signals:
            pressure = ATMOSPHERIC_PRESSURE_PA + self.pascal_per_m * float(signals["depth"][k, 0])
            yield "/depth", _fluid_pressure(time_ns, self.root, pressure), time_ns
        if self.thrusters and "thrust" in signals:
            message = joint_state(time_ns, self.thrusters, effort=signals["thrust"][k])
            yield "/thrusters", message, time_ns


def _estimate(time_ns: int, root: str, estimate: np.ndarray) -> dict[str, Any]:
    """The estimator's state (x y z, qx qy qz qw, world velocity) as Odometry: its velocity
    turned into the estimated body axes; angular velocity NaN (not estimated)."""
    pose = estimate[:7]
    norm = float(np.linalg.norm(pose[3:7]))
    rotation = pin.Quaternion(pose[3:7] / norm).toRotationMatrix() if norm > 0 else np.eye(3)
    twist = np.concatenate([rotation.T @ estimate[7:10], np.full(3, np.nan)])
    return odometry(time_ns, MAP, root, pose, twist)


def _fluid_pressure(time_ns: int, frame: str, pressure_Pa: float) -> dict[str, Any]:
    return {"header": header(time_ns, frame), "fluid_pressure": pressure_Pa, "variance": 0.0}
