"""The ROS 2 messages of a run, one logged sample at a time: what the MCAP bag writes
(`uvms_pin.apps.export.ros_bag`) and the Foxglove live server streams
(`uvms_pin.apps.viz.foxglove_live`), built by the same code so the two carry the same
messages (docs/ros.md lists the topics).

A sample is a `SampleRecord`: a saved rollout gives one per row (`records_of`), a running
simulation one per logged `uvms_pin.sim.sample.Sample` (`record_of_sample`).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

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
from uvms_pin.apps.export.ros_world import FREE_STATE, markers, object_pose
from uvms_pin.model.uvms import DEFAULT_WATER_DENSITY_KG_M3
from uvms_pin.results.joint_positions import arm_positions
from uvms_pin.sim.navigation.depth import ATMOSPHERIC_PRESSURE_PA, GRAVITY_M_S2

if TYPE_CHECKING:
    from uvms_pin.model.uvms import UVMS
    from uvms_pin.results.rollout_data import RolloutData
    from uvms_pin.sim.sample import Sample

__all__ = [
    "MAP",
    "TOPIC_TYPES",
    "Message",
    "SampleRecord",
    "SampleTopics",
    "record_of_sample",
    "records_of",
]

MAP = "map"
_IDENTITY = (np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0]))

# (topic, message, time [ns])
Message = tuple[str, dict, int]

_TF, _JOINTS = "tf2_msgs/TFMessage", "sensor_msgs/JointState"
#: every topic a run can have, with its ROS 2 message type
TOPIC_TYPES = {
    "/tf_static": _TF,
    "/tf": _TF,
    "/joint_states": _JOINTS,
    "/thrusters": _JOINTS,
    "/odometry/truth": "nav_msgs/Odometry",
    "/odometry/estimate": "nav_msgs/Odometry",
    "/ee/wrench": "geometry_msgs/WrenchStamped",
    "/ft_sensor/wrench": "geometry_msgs/WrenchStamped",
    "/imu": "sensor_msgs/Imu",
    "/depth": "sensor_msgs/FluidPressure",
    "/world/markers": "visualization_msgs/MarkerArray",
}


@dataclass(frozen=True)
class SampleRecord:
    """One logged sample: t [s], the true state q (nq,), v (nv,), the applied tau (nv,),
    the arm's joint positions (one per joint [rad or m]), the true and measured
    end-effector wrenches in world axes (6,) and the logged signals of that sample by name
    (each a 1-D array)."""

    time_s: float
    q: np.ndarray
    v: np.ndarray
    tau: np.ndarray
    joint_positions: np.ndarray
    wrench_contact_world: np.ndarray
    wrench_measured_world: np.ndarray
    signals: dict[str, np.ndarray]


def records_of(rollout: RolloutData) -> Iterator[SampleRecord]:
    """Each row of a saved rollout as a `SampleRecord` (the arm's positions computed for
    all rows at once)."""
    kinds = _joint_kinds(rollout.metadata)
    positions = arm_positions(rollout.q[:, 7:], kinds)
    signals = rollout.signals
    for k in range(len(rollout)):
        yield SampleRecord(
            float(rollout.time_s[k]),
            rollout.q[k],
            rollout.v[k],
            rollout.tau[k],
            positions[k],
            rollout.wrench_contact_world[k],
            rollout.wrench_measured_world[k],
            {name: values[k] for name, values in signals.items()},
        )


def record_of_sample(sample: Sample, joint_kinds: list[str]) -> SampleRecord:
    """A running simulation's logged ``sample`` as a `SampleRecord` (a copy: the loop
    reuses its arrays)."""
    signals = {}
    for name, values in sample.signals.items():
        signals[name] = np.array(getattr(values, "values", values), dtype=float).reshape(-1)
    q = np.array(sample.q, dtype=float)
    return SampleRecord(
        float(sample.time_s),
        q,
        np.array(sample.v, dtype=float),
        np.array(sample.tau_applied, dtype=float),
        arm_positions(q[7:], joint_kinds),
        np.array(sample.contact_world, dtype=float),
        np.array(sample.measurement.wrench_world, dtype=float),
        signals,
    )


def _joint_kinds(metadata: dict[str, Any]) -> list[str]:
    names = list(metadata.get("arm_joint_names", ()))
    return list(metadata.get("arm_joint_kinds") or ["revolute"] * len(names))


class SampleTopics:
    """The messages of a run: its static ones (`static`) and those of each sample (`at`),
    for the topics the run has data for.

    Args:
        metadata: the run's metadata (a rollout's, or `uvms_pin.sim.log.run_metadata` with
            the world's record under ``"world"`` before a run): arm joint names and kinds,
            signal units (the thrusters' names), the world and the water density.
        uvms: the model the run simulates (its kinematics give the links' frames).
    """

    def __init__(self, metadata: dict[str, Any], uvms: UVMS):
        self.model, self.data = uvms.model, uvms.model.createData()
        self.tree = LinkTree.of(self.model)
        self.root = self.tree.names[0]
        run_world = metadata.get("world") or {}
        self.world = run_world.get("world") or {}
        self.joint_names = list(metadata.get("arm_joint_names", ()))
        self.joint_kinds = _joint_kinds(metadata)
        self.ee = None if uvms.ee_frame_id is None else int(uvms.ee_frame_id)
        self.free = [o["name"] for o in self.world.get("free_objects", ())]
        units = metadata.get("signal_units") or {}
        self.thrusters = (units.get("thrust") or {}).get("components", [])
        density = float(run_world.get("water_density_kg_m3", DEFAULT_WATER_DENSITY_KG_M3))
        self.pascal_per_m = density * GRAVITY_M_S2

    def static(self, time_s: float, q: np.ndarray) -> Iterator[Message]:
        """``/tf_static`` (map -> odom, every link fixed to its parent, every fixed world
        object in map) and the world's ``/world/markers``, at the first sample (t, q)."""
        time_ns = stamp_ns(time_s)
        tree = self.tree
        translations, quaternions = relative_placements(self.model, self.data, tree, q)
        out = [transform(time_ns, MAP, ODOM, *_IDENTITY)]
        for k, name in enumerate(tree.names):
            if not tree.moving[k]:
                out.append(transform(time_ns, tree.parents[k], name, translations[k], quaternions[k]))  # fmt: skip
        for record in self.world.get("objects", ()):
            out.append(transform(time_ns, MAP, record["name"], *object_pose(record)))
        yield "/tf_static", {"transforms": out}, time_ns
        if self.world.get("objects") or self.world.get("free_objects"):
            yield "/world/markers", markers(time_ns, self.world, q[:3]), time_ns

    def at(self, record: SampleRecord) -> Iterator[Message]:
        """The messages of one sample: ``/tf``, ``/joint_states``, ``/odometry/truth``, then
        the wrenches, the navigation sensors and the thrusters the run has."""
        time_ns = stamp_ns(record.time_s)
        yield "/tf", {"transforms": self._moving(record, time_ns)}, time_ns
        if self.joint_names:
            joints = (record.joint_positions, record.v[6:], record.tau[6:])
            yield "/joint_states", joint_state(time_ns, self.joint_names, *joints), time_ns
        truth = odometry(time_ns, MAP, self.root, record.q[:7], record.v[:6])
        yield "/odometry/truth", truth, time_ns
        yield from self._sensors(record, time_ns)

    def _moving(self, record: SampleRecord, time_ns: int) -> list[dict]:
        tree = self.tree
        translations, quaternions = relative_placements(self.model, self.data, tree, record.q)
        out = [
            transform(time_ns, tree.parents[j], name, translations[j], quaternions[j])
            for j, name in enumerate(tree.names)
            if tree.moving[j]
        ]
        if self.free:
            states = record.signals["free_objects"].reshape(-1, FREE_STATE)
            for name, state in zip(self.free, states, strict=True):
                out.append(transform(time_ns, MAP, name, state[:3], state[3:7]))
        return out

    def _sensors(self, record: SampleRecord, time_ns: int) -> Iterator[Message]:
        """The wrenches (after `_moving`'s kinematics), the navigation and the thrusters."""
        signals = record.signals
        if self.ee is not None:
            rotation = self.data.oMf[self.ee].rotation  # world <- ee, this sample's kinematics
            frame = self.model.frames[self.ee].name
            for topic, w in (("/ee/wrench", record.wrench_contact_world), ("/ft_sensor/wrench", record.wrench_measured_world)):  # fmt: skip
                in_ee = np.concatenate([rotation.T @ w[:3], rotation.T @ w[3:6]])
                yield topic, wrench(time_ns, frame, in_ee), time_ns
        if "estimate" in signals:
            yield "/odometry/estimate", _estimate(time_ns, self.root, signals["estimate"]), time_ns
        if "imu_gyro" in signals and "imu_accel" in signals:
            message = imu(time_ns, self.root, signals["imu_gyro"], signals["imu_accel"])
            yield "/imu", message, time_ns
        if "depth" in signals:
            pressure = ATMOSPHERIC_PRESSURE_PA + self.pascal_per_m * float(signals["depth"][0])
            yield "/depth", _fluid_pressure(time_ns, self.root, pressure), time_ns
        if self.thrusters and "thrust" in signals:
            message = joint_state(time_ns, self.thrusters, effort=signals["thrust"])
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
