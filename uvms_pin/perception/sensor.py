"""What a kind of perception sensor is, and the one registry of them (``[[sensors.<name>]]``).

A kind is one module of this package that calls `register` with its `PerceptionKind` on
import: its spec (a frozen dataclass whose fields are its table's keys, checked where it is
built), how a sensor is made from the spec and a `uvms_pin.perception.scene.Scene`, and what
it records when it fires. `uvms_pin.perception.suite` imports every kind (the one list of
them) and fires them without naming any.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping
from dataclasses import MISSING, asdict, dataclass, fields
from typing import Any

import numpy as np
import pinocchio as pin

from uvms_pin.checks import number_fields
from uvms_pin.errors import ParameterError
from uvms_pin.physics.kinematics import frame_id_from_name

__all__ = [
    "SENSORS",
    "Mounted",
    "PerceptionKind",
    "check_counts",
    "check_fields_of_view",
    "check_mount",
    "mount_frame",
    "register",
    "spec_from_dict",
    "spec_record",
    "written",
]


@dataclass(frozen=True)
class PerceptionKind:
    """One kind of perception sensor.

    Attributes:
        name: its tables ``[[sensors.<name>]]``.
        spec: its spec's class (a frozen dataclass; ``from_dict`` builds it from a table).
        make: (spec, scene, random generator) -> the sensor, whose ``fire(out=None)``
            gives the arrays it records at one firing (name -> array), written into ``out``
            (the same names and arrays' shapes) when given.
        constants: (sensor) -> the arrays it records once (a sonar's range bins), by name.
        bytes: (spec) -> what one firing records [bytes].
    """

    name: str
    spec: type
    make: Callable[[Any, Any, np.random.Generator], Any]
    constants: Callable[[Any], dict[str, np.ndarray]] = lambda sensor: {}
    bytes: Callable[[Any], float] = lambda spec: 0.0


#: ``[[sensors.<name>]]`` -> its kind, filled by each sensor's module on import
SENSORS: dict[str, PerceptionKind] = {}


def register(kind: PerceptionKind) -> PerceptionKind:
    """Add ``kind`` to `SENSORS` (a second kind of the same name is an error)."""
    if SENSORS.setdefault(kind.name, kind) is not kind:
        raise ParameterError(f"a perception sensor '{kind.name}' is registered already")
    return kind


def _value(label: str, key: str, default: Any, value: Any) -> Any:
    """``value`` of ``key`` converted to the type of its ``default``."""
    bad = ParameterError(f"{label}: {key} must be like {default!r}, got {value!r}")
    if isinstance(default, bool):
        if not isinstance(value, bool):
            raise bad
        return value
    if isinstance(default, int) and not isinstance(default, bool):
        if isinstance(value, bool) or not isinstance(value, int):
            raise bad
        return value
    if isinstance(default, float):
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise bad
        return float(value)
    if isinstance(default, tuple):
        if not isinstance(value, list | tuple) or len(value) != len(default):
            raise bad
        if not all(isinstance(v, int | float) and not isinstance(v, bool) for v in value):
            raise bad
        return tuple(float(v) for v in value)
    if default is None or isinstance(default, str):
        return value
    raise bad


def spec_from_dict(cls: type, raw: Mapping[str, Any], label: str, **given: Any) -> Any:
    """``cls`` from a table's keys (its fields'; each converted to its default's type), with
    ``given`` fields set by the caller: ParameterError naming an unknown or missing key."""
    known = {f.name: f for f in fields(cls)}
    unknown = sorted(set(raw) - set(known) - set(given))
    if unknown:
        raise ParameterError(f"{label}: unknown key(s) {', '.join(unknown)}")
    values: dict[str, Any] = dict(given)
    for name, f in known.items():
        if name in given:
            continue
        default = f.default if f.default is not MISSING else None
        if name not in raw:
            if f.default is MISSING:
                raise ParameterError(f"{label}: {name} is required")
            continue
        values[name] = _value(label, name, default, raw[name])
    return cls(**values)


def spec_record(spec: Any) -> dict[str, Any]:
    """A sensor's spec as the plain values a run's metadata keeps (its fields by name; a
    light a table of its own): what a reader of the saved run needs to place and read its
    images (the MCAP export's sensor frames and camera intrinsics); tuples as lists, as the
    saved metadata reads back."""
    return json.loads(json.dumps(asdict(spec)))


class Mounted:
    """A sensor on a frame of the robot's model (``spec.link``; None: the vehicle's body), its
    own frame there at ``spec.position_m`` [m] and ``spec.rpy_rad`` [rad] (roll-pitch-yaw),
    seeing ``scene``."""

    def __init__(self, spec: Any, scene: Any, label: str):
        self.scene = scene
        self.frame_id = mount_frame(scene.uvms.model, spec.link, label)
        rotation = pin.rpy.rpyToMatrix(np.asarray(spec.rpy_rad, dtype=float))
        self.in_link = pin.SE3(rotation, np.asarray(spec.position_m, dtype=float))

    def placement(self) -> pin.SE3:
        """Its frame in the world, after the scene's update."""
        return self.scene.frame_placement(self.frame_id) * self.in_link


def written(
    fired: dict[str, np.ndarray], out: dict[str, np.ndarray] | None, label: str
) -> dict[str, np.ndarray]:
    """A firing's arrays ``fired`` copied into ``out`` (the same names and shapes) when
    given (ParameterError naming ``label`` otherwise), else ``fired``."""
    if out is None:
        return fired
    if set(out) != set(fired) or any(out[k].shape != v.shape for k, v in fired.items()):
        raise ParameterError(f"{label}: out must hold {', '.join(fired)} of one firing's shapes")
    for key, value in fired.items():
        out[key][...] = value
    return out


def check_mount(spec: Any, label: str) -> None:
    """ParameterError unless ``spec``'s name is a non-empty string, its numbers numbers
    (`number_fields`), its ``position_m`` and ``rpy_rad`` finite 3-vectors and its
    ``rate_hz`` finite and > 0."""
    if not isinstance(spec.name, str) or not spec.name:
        raise ParameterError(f"{label}: name must be a non-empty string, got {spec.name!r}")
    number_fields(spec, label)
    for key in ("position_m", "rpy_rad"):
        try:
            value = np.asarray(getattr(spec, key), dtype=float)
        except (TypeError, ValueError):
            value = np.asarray(None)  # not numbers: refused below, as a wrong shape
        if value.shape != (3,) or not np.all(np.isfinite(value)):
            raise ParameterError(
                f"{label}: {key} must be 3 finite numbers, got {getattr(spec, key)!r}"
            )
    if spec.link is not None and not isinstance(spec.link, str):
        raise ParameterError(f"{label}: link must be a frame's name, got {spec.link!r}")
    if not (math.isfinite(spec.rate_hz) and spec.rate_hz > 0.0):
        raise ParameterError(f"{label}: rate_hz must be finite and > 0, got {spec.rate_hz}")


def check_counts(spec: Any, label: str, most: Mapping[str, int]) -> None:
    """ParameterError unless each field of ``spec`` named in ``most`` (pixels, beams, bins,
    rays) is an integer from 1 to its entry there (a numpy integer is taken as the int it
    is, written back; a bool is not a count)."""
    for key, largest in most.items():
        value = getattr(spec, key)
        whole = isinstance(value, int | np.integer) and not isinstance(value, bool | np.bool_)
        if not (whole and 1 <= value <= largest):
            raise ParameterError(
                f"{label}: {key} must be an integer in [1, {largest}], got {value!r}"
            )
        object.__setattr__(spec, key, int(value))


def check_fields_of_view(spec: Any, label: str, keys: tuple[str, ...]) -> None:
    """ParameterError unless each field of ``spec`` named in ``keys`` is an angle in
    (0, pi) [rad]."""
    for key in keys:
        value = getattr(spec, key)
        if isinstance(value, bool) or not (
            isinstance(value, int | float) and 0.0 < value < math.pi
        ):
            raise ParameterError(f"{label}: {key} must be in (0, pi), got {value}")


def mount_frame(model: pin.Model, link: str | None, label: str) -> int:
    """The frame a sensor is mounted on: ``link``, or the vehicle's body (the first body
    frame on the free-flyer joint 1). ParameterError naming ``link`` when the model has none."""
    if link is None:
        for k, frame in enumerate(model.frames):
            if frame.parentJoint == 1 and frame.type == pin.FrameType.BODY:
                return k
        raise ParameterError(f"{label}: the model has no vehicle body frame; give link")
    return frame_id_from_name(model, link, f"{label}: link")
