"""A run's cameras and sonars as ROS 2 messages: what the MCAP bag adds to the samples' topics
(`uvms_pin.apps.export.ros_bag`; docs/ros.md lists them).

Each sensor's frame is a TF frame fixed to the link it is mounted on (``/tf_static``): a
camera's ``<name>_optical_frame`` (z along the optical axis, x right, y down, as ROS
cameras), a sonar's ``<name>_frame`` (x along the acoustic axis); ``<name>`` is the sensor's
name made a ROS name (`ros_name`). At each firing:

- a camera: ``/<name>/image_raw`` (``sensor_msgs/Image``, rgb8), ``/<name>/camera_info``
  (``sensor_msgs/CameraInfo``: the ideal pinhole the images are, no distortion),
  ``/<name>/depth/image`` (32FC1 z-depth [m], REP 118: +Inf where the ray met nothing) and
  ``/<name>/labels`` (16UC1: the label of what each pixel sees, 0 nothing; the names in the
  run's metadata);
- a sonar: ``/<name>/image`` (32FC1, one row per range bin from the nearest, one column per
  beam from the first bearing), a multibeam's detections ``/<name>/scan``
  (``sensor_msgs/LaserScan`` in its frame, REP 117: +Inf where a beam heard nothing) and an
  altimeter's reading ``/<name>/range`` (``sensor_msgs/Range``, ultrasound, its cone's
  full angle as the field of view; +Inf when it heard nothing).

The images are the rollout's (`uvms_pin.results.perception`), bit for bit; a run saved
before its metadata kept the sensors' specs has none of these topics.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from typing import Any

import numpy as np
import pinocchio as pin

from uvms_pin.apps.export.ros_messages import header, stamp_ns, transform
from uvms_pin.errors import PerceptionWarning, VizError
from uvms_pin.perception.camera import CameraSpec
from uvms_pin.results.perception import FILE
from uvms_pin.results.signal import component_label

__all__ = ["PerceptionTopics", "altimeter_range", "camera_info", "laser_scan", "ros_name"]

# (topic, message, time [ns])
Message = tuple[str, dict, int]

_IMAGE, _INFO, _SCAN = "sensor_msgs/Image", "sensor_msgs/CameraInfo", "sensor_msgs/LaserScan"
_RANGE = "sensor_msgs/Range"
#: sensor_msgs/Range's radiation type of a sonar
_ULTRASOUND = 0


def _image(time_ns: int, frame: str, pixels: np.ndarray, encoding: str) -> dict[str, Any]:
    """``sensor_msgs/Image`` of ``pixels`` (H, W) or (H, W, channels), little-endian, rows
    packed (step = W x bytes per pixel)."""
    height, width = pixels.shape[:2]
    data = np.ascontiguousarray(pixels)
    return {
        "header": header(time_ns, frame),
        "height": height,
        "width": width,
        "encoding": encoding,
        "is_bigendian": 0,
        "step": data.nbytes // max(height, 1),
        "data": data.tobytes(),
    }


def camera_info(time_ns: int, frame: str, spec: dict[str, Any]) -> dict[str, Any]:
    """``sensor_msgs/CameraInfo`` of a camera's spec (its recorded fields): the camera's
    own focal length on both axes (`CameraSpec.focal_px`, W / 2 / tan(hfov / 2) [px]), the
    principal point at the image's centre (cx = W / 2 - 1/2, cy = H / 2 - 1/2 in ROS's pixel
    coordinates, the top-left pixel's centre at (0, 0)), no distortion."""
    width, height = int(spec["width"]), int(spec["height"])
    f = CameraSpec(
        "info", width=width, height=height, horizontal_fov_rad=float(spec["horizontal_fov_rad"])
    ).focal_px
    cx, cy = 0.5 * width - 0.5, 0.5 * height - 0.5
    return {
        "header": header(time_ns, frame),
        "height": height,
        "width": width,
        "distortion_model": "plumb_bob",
        "d": [0.0] * 5,
        "k": [f, 0.0, cx, 0.0, f, cy, 0.0, 0.0, 1.0],
        "r": [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        "p": [f, 0.0, cx, 0.0, 0.0, f, cy, 0.0, 0.0, 0.0, 1.0, 0.0],
        "binning_x": 0,
        "binning_y": 0,
        "roi": {"x_offset": 0, "y_offset": 0, "height": 0, "width": 0, "do_rectify": False},
    }


def laser_scan(
    time_ns: int, frame: str, spec: dict[str, Any], bearing_rad: np.ndarray, range_m, intensity
) -> dict[str, Any]:
    """``sensor_msgs/LaserScan`` of a multibeam's detections: its beams' bearings evenly from
    the first, NaN (heard nothing) sent as +Inf (REP 117)."""
    step = float(bearing_rad[1] - bearing_rad[0]) if len(bearing_rad) > 1 else 0.0
    ranges = np.where(np.isnan(range_m), np.inf, range_m).astype(np.float32)
    return {
        "header": header(time_ns, frame),
        "angle_min": float(bearing_rad[0]),
        "angle_max": float(bearing_rad[-1]),
        "angle_increment": step,
        "time_increment": 0.0,
        "scan_time": 1.0 / float(spec["rate_hz"]),
        "range_min": float(spec["min_range_m"]),
        "range_max": float(spec["max_range_m"]),
        "ranges": ranges.tolist(),
        "intensities": np.asarray(intensity, dtype=np.float32).tolist(),
    }


def altimeter_range(time_ns: int, frame: str, spec: dict[str, Any], range_m: float) -> dict:
    """``sensor_msgs/Range`` of an altimeter's reading: ultrasound, the field of view its
    cone's full angle, NaN (heard nothing) sent as +Inf (REP 117)."""
    return {
        "header": header(time_ns, frame),
        "radiation_type": _ULTRASOUND,
        "field_of_view": float(spec["horizontal_fov_rad"]),
        "min_range": float(spec["min_range_m"]),
        "max_range": float(spec["max_range_m"]),
        "range": float(np.inf if np.isnan(range_m) else range_m),
    }


def ros_name(name: str) -> str:
    """A sensor's name as a ROS name's token: letters, digits and underscores (anything else
    an underscore), not starting with a digit."""
    return component_label(name)


def _mount(model: pin.Model, data: pin.Data, frame_name: str) -> tuple[str, pin.SE3]:
    """The TF frame a sensor's mount frame hangs from and the mount's placement in it: the
    mount itself when it is a link or a named frame (the bag's TF frames), else the link of
    its joint (its placement there fixed), else the world (``map``). ``data``: kinematics
    done."""
    if not model.existFrame(frame_name):
        raise VizError(
            f"the run's sensor is mounted on frame '{frame_name}', which the model has not: "
            "not the model it ran (pass --urdf)"
        )
    fid = model.getFrameId(frame_name)
    frame = model.frames[fid]
    if frame.type in (pin.FrameType.BODY, pin.FrameType.OP_FRAME):
        return frame_name, pin.SE3.Identity()
    for k, other in enumerate(model.frames):
        if other.type == pin.FrameType.BODY and other.parentJoint == frame.parentJoint != 0:
            return other.name, data.oMf[k].actInv(data.oMf[fid])
    return "map", data.oMf[fid]


class PerceptionTopics:
    """The messages of a rollout's cameras and sonars: their frames (`static_transforms`,
    for the bag's one ``/tf_static``) and each firing's messages (`at`).

    Args:
        rollout: the run (its ``perception`` arrays and metadata).
        model, data: the model it ran, ``data`` with the first sample's frame placements.
    """

    def __init__(self, rollout: Any, model: pin.Model, data: pin.Data):
        described = rollout.metadata.get("perception") or {}
        self.sensors = [
            (name, about)
            for name, about in described.items()
            if name in rollout.perception and "spec" in about and "frame" in about
        ]
        unseen = [name for name in described if name not in rollout.perception]
        if unseen:  # the bag is written without them: said, not silently
            warnings.warn(
                f"the run's {', '.join(map(repr, unseen))} left out of the bag: no images "
                f"loaded ({FILE} was not found beside rollout.npz)",
                PerceptionWarning,
                stacklevel=2,
            )
        tokens: dict[str, str] = {}  # ROS name -> the sensor's own
        for name, _ in self.sensors:
            other = tokens.setdefault(ros_name(name), name)
            if other != name:  # one topic and one TF frame would carry both, interleaved
                raise VizError(
                    f"sensors '{other}' and '{name}' have the same ROS name "
                    f"'{ros_name(name)}' (letters, digits and underscores): rename one in "
                    "the scenario and run it again"
                )
        self.arrays = rollout.perception
        self.types: dict[str, str] = {}
        self._frames: dict[str, tuple[str, str, pin.SE3]] = {}  # (its frame, parent, pose)
        for name, about in self.sensors:
            try:
                self._add(name, about, model, data)
            except (KeyError, TypeError, ValueError, IndexError) as exc:
                raise VizError(
                    f"the run's record of sensor '{name}' is damaged ({type(exc).__name__}: "
                    f"{exc}): rerun the scenario"
                ) from exc

    def _add(self, name: str, about: dict[str, Any], model: pin.Model, data: pin.Data) -> None:
        """A sensor's frame and topics, what its messages read checked here (a damaged
        record fails before anything is written)."""
        spec = about["spec"]
        suffix = "_optical_frame" if about["kind"] == "camera" else "_frame"
        parent, mount = _mount(model, data, about["frame"])
        in_link = pin.SE3(
            pin.rpy.rpyToMatrix(np.asarray(spec["rpy_rad"], dtype=float).reshape(3)),
            np.asarray(spec["position_m"], dtype=float).reshape(3),
        )
        arrays = self.arrays[name]
        if about["kind"] == "camera":
            camera_info(0, "", spec)
            shapes = {arrays[k].shape[:3] for k in ("rgb", "depth_m", "label")}
            if len(shapes) != 1 or arrays["time_s"].shape[0] != next(iter(shapes))[0]:
                raise ValueError("its images' shapes disagree")
        else:
            for key in ("rate_hz", "min_range_m", "max_range_m", "horizontal_fov_rad"):
                float(spec[key])
            if arrays["intensity"].shape[0] != arrays["time_s"].shape[0]:
                raise ValueError("its images and times disagree")
        self._frames[name] = (f"{ros_name(name)}{suffix}", parent, mount * in_link)
        self.types.update(self._topic_types(name, about["kind"], spec, arrays))

    @staticmethod
    def _topic_types(name: str, kind: str, spec: dict, arrays: dict) -> dict[str, str]:
        base = f"/{ros_name(name)}"
        if kind == "camera":
            topics = ("image_raw", "depth/image", "labels")
            return {f"{base}/{t}": _IMAGE for t in topics} | {f"{base}/camera_info": _INFO}
        out = {f"{base}/image": _IMAGE}
        if "beam_range_m" in arrays:  # a multibeam's detections, an altimeter's reading
            out |= {f"{base}/range": _RANGE} if _altimeter(spec) else {f"{base}/scan": _SCAN}
        return out

    def static_transforms(self, time_ns: int) -> list[dict]:
        """Each sensor's frame in the frame it is mounted on (fixed)."""
        out = []
        for child, parent, placement in self._frames.values():
            quaternion = pin.Quaternion(placement.rotation).coeffs()
            out.append(transform(time_ns, parent, child, placement.translation, quaternion))
        return out

    def at(self, time_s: float) -> Iterator[Message]:
        """The messages of the sensors that fired at rollout time ``time_s`` [s] (each
        firing is a logged sample's; the same messages however often, in whatever order,
        a time is asked for: a live view asks for the first sample's twice)."""
        for name, about in self.sensors:
            arrays = self.arrays[name]
            times = arrays["time_s"]
            k = int(np.searchsorted(times, time_s))
            if k < len(times) and float(times[k]) == time_s:
                yield from self._fired(name, about, arrays, k, stamp_ns(time_s))

    def _fired(self, name: str, about: dict, arrays: dict, k: int, time_ns: int):
        frame = self._frames[name][0]
        name = ros_name(name)  # its topics
        if about["kind"] == "camera":
            depth = arrays["depth_m"][k]
            depth = np.where(np.isnan(depth), np.float32(np.inf), depth).astype("<f4")
            yield f"/{name}/image_raw", _image(time_ns, frame, arrays["rgb"][k], "rgb8"), time_ns
            yield f"/{name}/camera_info", camera_info(time_ns, frame, about["spec"]), time_ns
            yield f"/{name}/depth/image", _image(time_ns, frame, depth, "32FC1"), time_ns
            labels = arrays["label"][k].astype("<u2")
            yield f"/{name}/labels", _image(time_ns, frame, labels, "16UC1"), time_ns
            return
        intensity = np.asarray(arrays["intensity"][k], dtype="<f4")
        yield f"/{name}/image", _image(time_ns, frame, intensity, "32FC1"), time_ns
        if "beam_range_m" in arrays and _altimeter(about["spec"]):
            reading = altimeter_range(time_ns, frame, about["spec"], arrays["beam_range_m"][k][0])
            yield f"/{name}/range", reading, time_ns
        elif "beam_range_m" in arrays:
            scan = laser_scan(
                time_ns, frame, about["spec"], arrays["bearing_rad"],
                arrays["beam_range_m"][k], arrays["beam_intensity"][k],
            )  # fmt: skip
            yield f"/{name}/scan", scan, time_ns


def _altimeter(spec: dict[str, Any]) -> bool:
    """The sonar of ``spec`` (its record) is an altimeter: one reading, not a scan."""
    return spec.get("type") == "altimeter"
