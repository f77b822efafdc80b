"""Reading a ROS 2 bag back with rosbags (an independent reader, with its own copy of the ROS 2
message definitions) and comparing every message with the rollout it was written from (1e-9):
the links' poses by composing the TF tree read back against Pinocchio's world placements of
the same frames. Used by tests/apps/export/test_ros_bag.py and the command's tests."""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import numpy as np
import pinocchio as pin
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_typestore

from uvms_pin.apps.export.ros_bag import rollout_model
from uvms_pin.apps.export.ros_messages import EPOCH_NS
from uvms_pin.results.joint_positions import arm_positions
from uvms_pin.sim.navigation.depth import ATMOSPHERIC_PRESSURE_PA, GRAVITY_M_S2

TOL = 1e-9


def read_bag(path: Path) -> dict[str, list[tuple[int, object]]]:
    """topic -> [(log time [ns], message)], decoded by rosbags with ROS 2 Humble's types."""
    store = get_typestore(Stores.ROS2_HUMBLE)
    out: dict[str, list] = defaultdict(list)
    with Reader(path) as reader:
        for connection, time_ns, raw in reader.messages():
            msgtype = connection.msgtype
            if "/msg/" not in msgtype:
                pkg, name = msgtype.split("/")
                msgtype = f"{pkg}/msg/{name}"
            out[connection.topic].append((time_ns, store.deserialize_cdr(raw, msgtype)))
    return dict(out)


def _vec(v) -> np.ndarray:
    return np.array([v.x, v.y, v.z])


def _quat(q) -> np.ndarray:
    return np.array([q.x, q.y, q.z, q.w])


def _stamp(header) -> int:
    return header.stamp.sec * 10**9 + header.stamp.nanosec


def _se3(t) -> pin.SE3:
    quat = _quat(t.rotation)
    return pin.SE3(pin.Quaternion(quat).toRotationMatrix(), _vec(t.translation))


def _close(a, b) -> None:
    np.testing.assert_allclose(np.asarray(a, float), np.asarray(b, float), rtol=0, atol=TOL)


def _world_placements(static: list, dynamic: list) -> dict[str, pin.SE3]:
    """Each frame's placement in ``map``, composed along the TF tree read back."""
    parent_of = {t.child_frame_id: (t.header.frame_id, _se3(t.transform)) for t in static + dynamic}
    placed = {"map": pin.SE3.Identity()}

    def world(frame: str) -> pin.SE3:
        if frame not in placed:
            parent, local = parent_of[frame]
            placed[frame] = world(parent) * local
        return placed[frame]

    return {frame: world(frame) for frame in parent_of}


def check_bag(rollout, bag: dict) -> None:
    """Every message of ``bag`` against ``rollout`` (1e-9)."""
    n = len(rollout)
    times = [EPOCH_NS + round(float(t) * 1e9) for t in rollout.time_s]
    uvms = rollout_model(rollout)
    model, data = uvms.model, uvms.model.createData()
    (static_time, static), *_ = bag["/tf_static"]
    assert len(bag["/tf_static"]) == 1 and static_time == times[0]
    for topic in ("/tf", "/odometry/truth"):
        assert [t for t, _ in bag[topic]] == times, topic
    world = (rollout.metadata.get("world") or {}).get("world") or {}
    free = [o["name"] for o in world.get("free_objects", ())]
    kinds = (pin.FrameType.BODY, pin.FrameType.OP_FRAME)
    frame_ids = [fid for fid, f in enumerate(model.frames) if f.type in kinds]
    for k in range(n):
        tf = bag["/tf"][k][1].transforms
        assert all(_stamp(t.header) == times[k] for t in tf)
        placements = _world_placements(static.transforms, tf)
        pin.framesForwardKinematics(model, data, rollout.q[k])
        for fid in frame_ids:
            got = placements[model.frames[fid].name]
            _close(got.translation, data.oMf[fid].translation)
            _close(got.rotation, data.oMf[fid].rotation)
        for frame, placed in _sensor_frames(rollout, model, data).items():
            _close(placements[frame].translation, placed.translation)
            _close(placements[frame].rotation, placed.rotation)
        for j, name in enumerate(free):
            state = rollout.signals["free_objects"][k, 13 * j : 13 * j + 7]
            _close(placements[name].translation, state[:3])
            _close(placements[name].rotation, pin.Quaternion(state[3:7]).toRotationMatrix())
        odom = bag["/odometry/truth"][k][1]
        _close(
            [*_vec(odom.pose.pose.position), *_quat(odom.pose.pose.orientation)], rollout.q[k, :7]
        )
        _close([*_vec(odom.twist.twist.linear), *_vec(odom.twist.twist.angular)], rollout.v[k, :6])
        if uvms.ee_frame_id is not None:
            rotation = data.oMf[uvms.ee_frame_id].rotation
            for topic, logged in (
                ("/ee/wrench", rollout.wrench_contact_world[k]),
                ("/ft_sensor/wrench", rollout.wrench_measured_world[k]),
            ):
                time_ns, message = bag[topic][k]
                assert time_ns == times[k]
                assert message.header.frame_id == model.frames[uvms.ee_frame_id].name
                force, torque = _vec(message.wrench.force), _vec(message.wrench.torque)
                _close(np.concatenate([rotation @ force, rotation @ torque]), logged)
    _check_joints(rollout, bag, times)
    _check_navigation(rollout, bag, times)
    _check_world(world, bag)
    _check_perception(rollout, bag)


def _exported_sensors(rollout) -> dict[str, dict]:
    """The sensors the bag has topics for: those whose spec the metadata keeps."""
    described = rollout.metadata.get("perception") or {}
    return {name: about for name, about in described.items() if "spec" in about}


def _sensor_frames(rollout, model, data) -> dict[str, pin.SE3]:
    """Each camera's optical frame and sonar's frame in the world, from the sample whose
    kinematics ``data`` holds: its mount frame's placement times its spec's pose there."""
    out = {}
    for name, about in _exported_sensors(rollout).items():
        spec = about["spec"]
        mount = data.oMf[model.getFrameId(about["frame"])]
        in_link = pin.SE3(
            pin.rpy.rpyToMatrix(np.array(spec["rpy_rad"])), np.array(spec["position_m"])
        )
        suffix = "_optical_frame" if about["kind"] == "camera" else "_frame"
        out[name + suffix] = mount * in_link
    return out


def _pixels(message, dtype, channels: int = 1) -> np.ndarray:
    assert message.is_bigendian == 0
    row = message.width * channels * np.dtype(dtype).itemsize
    assert message.step == row
    shape = (message.height, message.width) + ((channels,) if channels > 1 else ())
    return np.frombuffer(bytes(message.data), dtype=np.dtype(dtype).newbyteorder("<")).reshape(
        shape
    )


def _check_perception(rollout, bag: dict) -> None:
    """Each camera's and sonar's firings: the images bit for bit (no return: +Inf), the
    camera's intrinsics projecting each pixel's own ray onto that pixel, the multibeam's
    detections as a LaserScan."""
    from uvms_pin.perception.camera import CameraSpec, pixel_rays

    for name, about in _exported_sensors(rollout).items():
        arrays, kind = rollout.perception[name], about["kind"]
        times = [EPOCH_NS + round(float(t) * 1e9) for t in arrays["time_s"]]
        image_topic = f"/{name}/image_raw" if kind == "camera" else f"/{name}/image"
        assert [t for t, _ in bag[image_topic]] == times, image_topic
        frame = name + ("_optical_frame" if kind == "camera" else "_frame")
        for k, (_, message) in enumerate(bag[image_topic]):
            assert message.header.frame_id == frame
            if kind == "camera":
                assert message.encoding == "rgb8"
                np.testing.assert_array_equal(_pixels(message, np.uint8, 3), arrays["rgb"][k])
                depth = bag[f"/{name}/depth/image"][k][1]
                assert depth.encoding == "32FC1"
                expected = np.where(np.isnan(arrays["depth_m"][k]), np.inf, arrays["depth_m"][k])
                np.testing.assert_array_equal(_pixels(depth, np.float32), expected)
                labels = bag[f"/{name}/labels"][k][1]
                assert labels.encoding == "16UC1"
                np.testing.assert_array_equal(_pixels(labels, np.uint16), arrays["label"][k])
            else:
                assert message.encoding == "32FC1"
                np.testing.assert_array_equal(_pixels(message, np.float32), arrays["intensity"][k])
        if kind == "camera":
            spec = CameraSpec(**{**about["spec"], "lights": ()})
            for _, info in bag[f"/{name}/camera_info"]:
                k_matrix = np.array(info.k).reshape(3, 3)
                rays = pixel_rays(spec)  # row by row: pixel (row, column)
                projected = rays @ k_matrix.T
                pixel = projected[:, :2] / projected[:, 2:]
                rows, columns = np.divmod(np.arange(spec.width * spec.height), spec.width)
                _close(pixel, np.column_stack([columns, rows]) + 0.0)
                assert (info.width, info.height) == (spec.width, spec.height)
                assert not np.any(info.d)
        elif "beam_range_m" in arrays and about["spec"]["type"] == "altimeter":
            readings = bag[f"/{name}/range"]
            assert len(readings) == len(arrays["time_s"])
            for k, (_, reading) in enumerate(readings):
                assert reading.header.frame_id == frame and reading.radiation_type == 0
                assert reading.field_of_view == np.float32(about["spec"]["horizontal_fov_rad"])
                assert reading.max_range == np.float32(about["spec"]["max_range_m"])
                expected = arrays["beam_range_m"][k][0]
                assert reading.range == np.float32(np.inf if np.isnan(expected) else expected)
        elif "beam_range_m" in arrays:
            bearing = arrays["bearing_rad"]
            for k, (_, scan) in enumerate(bag[f"/{name}/scan"]):
                assert scan.header.frame_id == frame
                angles = scan.angle_min + scan.angle_increment * np.arange(len(scan.ranges))
                np.testing.assert_allclose(angles, bearing, atol=1e-6)  # float32 fields
                assert scan.angle_max == np.float32(bearing[-1])
                ranges = np.where(
                    np.isnan(arrays["beam_range_m"][k]), np.inf, arrays["beam_range_m"][k]
                )
                np.testing.assert_array_equal(scan.ranges, ranges.astype(np.float32))
                np.testing.assert_array_equal(scan.intensities, arrays["beam_intensity"][k])


def _check_joints(rollout, bag: dict, times: list[int]) -> None:
    meta = rollout.metadata
    names = meta.get("arm_joint_names", [])
    if not names:
        assert "/joint_states" not in bag
        return
    positions = arm_positions(rollout.q[:, 7:], meta["arm_joint_kinds"])
    assert [t for t, _ in bag["/joint_states"]] == times
    for k, (_, message) in enumerate(bag["/joint_states"]):
        assert list(message.name) == names
        _close(message.position, positions[k])
        _close(message.velocity, rollout.v[k, 6:])
        _close(message.effort, rollout.tau[k, 6:])
    if "thrust" in rollout.signals:
        thrusters = meta["signal_units"]["thrust"]["components"]
        for k, (_, message) in enumerate(bag["/thrusters"]):
            assert list(message.name) == thrusters
            _close(message.effort, rollout.signals["thrust"][k])
        assert len(bag["/thrusters"]) == len(times)


def _nan_close(a, b) -> None:
    np.testing.assert_allclose(
        np.asarray(a, float), np.asarray(b, float), rtol=0, atol=TOL, equal_nan=True
    )


def _check_navigation(rollout, bag: dict, times: list[int]) -> None:
    signals = rollout.signals
    assert ("estimate" in signals) == ("/odometry/estimate" in bag)
    assert ("imu_gyro" in signals) == ("/imu" in bag)
    assert ("depth" in signals) == ("/depth" in bag)
    for k, (time_ns, message) in enumerate(bag.get("/odometry/estimate", [])):
        assert time_ns == times[k]
        estimate = signals["estimate"][k]
        pose = message.pose.pose
        _nan_close([*_vec(pose.position), *_quat(pose.orientation)], estimate[:7])
        rotation = pin.Quaternion(estimate[3:7] / np.linalg.norm(estimate[3:7])).toRotationMatrix()
        _nan_close(rotation @ _vec(message.twist.twist.linear), estimate[7:10])
        assert np.isnan(_vec(message.twist.twist.angular)).all()
    for k, (_, message) in enumerate(bag.get("/imu", [])):
        _nan_close(_vec(message.angular_velocity), signals["imu_gyro"][k])
        _nan_close(_vec(message.linear_acceleration), signals["imu_accel"][k])
        assert message.orientation_covariance[0] == -1.0
    density = (rollout.metadata.get("world") or {}).get("water_density_kg_m3", 1025.0)
    for k, (_, message) in enumerate(bag.get("/depth", [])):
        depth_m = (message.fluid_pressure - ATMOSPHERIC_PRESSURE_PA) / (density * GRAVITY_M_S2)
        _nan_close(depth_m, signals["depth"][k, 0])


def _check_world(world: dict, bag: dict) -> None:
    objects = [*world.get("objects", ()), *world.get("free_objects", ())]
    if not objects:
        assert "/world/markers" not in bag
        return
    ((_, message),) = bag["/world/markers"]
    assert [m.header.frame_id for m in message.markers] == [o["name"] for o in objects]
    static = {t.child_frame_id: t for t in bag["/tf_static"][0][1].transforms}
    for record in world.get("objects", ()):
        placed = _se3(static[record["name"]].transform)
        _close(placed.translation, record["position_world_m"])
        _close(placed.rotation, record["rotation_world"])
