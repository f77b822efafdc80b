"""A run's cameras and sonars together: fired over its logged states, their images kept
beside the rollout (`uvms_pin.results.perception`).

A sensor of ``rate_hz`` fires at the first logged sample at or after each of its instants
k / rate_hz (k = 0, 1, ...): at its rate when the log period divides its period, else at the
log's grid nearest after. Firing reads the logged state (the robot's q, each free object's
pose and each fixture's joint positions): the loop itself is untouched, so a run with
sensors gives the same rollout as without them, whatever path (compiled or Python) ran it.
Each sensor draws its noise from its own stream of the run's seed (`PERCEPTION_SEED_INDEX`),
in the order of the scenario.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from uvms_pin.checks import check_memory
from uvms_pin.errors import PerceptionWarning

# the sensor kinds, each registered by its module on import: the one list of them
from uvms_pin.perception import camera, sonar  # noqa: F401
from uvms_pin.perception.scene import Scene
from uvms_pin.perception.sensor import SENSORS, mount_frame, spec_record
from uvms_pin.results.rollout_data import RolloutData

__all__ = [
    "PERCEPTION_SEED_INDEX",
    "PerceptionSpec",
    "SceneLog",
    "check_mounts",
    "firing_rows",
    "fixture_positions",
    "perceive",
]

#: The child of the run's SeedSequence the perception sensors draw from (the measurement
#: noise uses children 0-5, the navigation sensors 6).
PERCEPTION_SEED_INDEX = 7


@dataclass(frozen=True)
class PerceptionSpec:
    """The run's cameras and sonars: (kind name, spec) pairs, in the scenario's order."""

    sensors: tuple[tuple[str, Any], ...] = ()

    @property
    def fitted(self) -> bool:
        return bool(self.sensors)

    @property
    def in_loop(self) -> list[Any]:
        """The cameras that also fire in the loop (``in_loop``: `uvms_pin.perception.loop`)."""
        return [spec for kind, spec in self.sensors if getattr(spec, "in_loop", False)]

    @property
    def names(self) -> list[str]:
        return [spec.name for _, spec in self.sensors]


def check_mounts(
    spec: PerceptionSpec,
    model: Any,
    duration_s: float = 0.0,
    log_period_s: float | None = None,
    control_period_s: float | None = None,
) -> None:
    """Before a run, not after it: ParameterError naming the sensor and its ``link`` when the
    robot's model has no such frame, or when the images of ``duration_s`` [s] would not fit
    in memory; a `PerceptionWarning` for a sensor faster than the log of ``log_period_s``
    [s] (it fires at logged samples: on the log's grid, `firing_rows`; its images counted
    so, at most one a logged sample), and for an ``in_loop`` sensor faster than the control
    ticks of ``control_period_s`` [s] (its controller reads it at a tick at the most)."""
    total = 0.0
    for kind_name, own in spec.sensors:
        mount_frame(model, own.link, f"{kind_name} '{own.name}'")
        firings = math.floor(duration_s * own.rate_hz) + 1
        if log_period_s is not None:  # one firing a logged sample at the most
            firings = min(firings, math.floor(duration_s / log_period_s + 1e-9) + 1)
        total += firings * SENSORS[kind_name].bytes(own)
        ticks = control_period_s
        if getattr(own, "in_loop", False) and ticks and own.rate_hz * ticks > 1.0 + 1e-9:
            warnings.warn(
                f"{kind_name} '{own.name}' is read by the controller at its ticks: at "
                f"{1.0 / ticks:g} Hz at the most, not its rate_hz = {own.rate_hz:g} "
                f"(control.period_s = {ticks:g} s)",
                PerceptionWarning,
                stacklevel=2,
            )
        if log_period_s is not None and own.rate_hz * log_period_s > 1.0 + 1e-9:
            warnings.warn(
                f"{kind_name} '{own.name}' fires at logged samples: at {1.0 / log_period_s:g} "
                f"Hz, not its rate_hz = {own.rate_hz:g} (output.log_period_s = "
                f"{log_period_s:g} s; {1.0 / own.rate_hz:g} s or less gives its rate)",
                PerceptionWarning,
                stacklevel=2,
            )
    check_memory(
        total,
        f"the images of {', '.join(spec.names)} over {duration_s:g} s",
        "lower their rate_hz or their size",
    )


def firing_rows(time_s: np.ndarray, rate_hz: float) -> np.ndarray:
    """The rows of ``time_s`` (sorted) a sensor of ``rate_hz`` fires at: the first at or
    after each k / rate_hz (within 1e-9 s), each row once."""
    if len(time_s) == 0:
        return np.zeros(0, dtype=np.int64)
    instants = np.arange(0.0, float(time_s[-1]) + 1e-9, 1.0 / rate_hz)
    rows = np.searchsorted(time_s, instants - 1e-9, side="left")
    return np.unique(rows[rows < len(time_s)])


def object_poses(rollout: RolloutData, n_objects: int) -> np.ndarray:
    """Each row's free-object poses (T, n, 7) from the logged ``free_objects`` signal."""
    if n_objects == 0:
        return np.zeros((len(rollout), 0, 7))
    states = rollout.signals["free_objects"].reshape(len(rollout), n_objects, 13)
    return states[:, :, :7]


def fixture_positions(rollout: RolloutData, names: Sequence[str]) -> list[np.ndarray] | None:
    """Each fixture's logged joint positions (T, its nq), the signal named after it; None
    when the run logged none of them (the fixtures then stay at their start)."""
    if not names or any(name not in rollout.signals for name in names):
        return None
    return [np.asarray(rollout.signals[name], dtype=float) for name in names]


@dataclass(frozen=True)
class SceneLog:
    """What poses a scene at each logged row: the robot's ``q`` (T, nq), each free object's
    pose (T, n, 7), each fixture's joint positions (T, its nq) and each other robot's
    configuration (T, its nq) of a run of several (None: they stay where they are)."""

    q: np.ndarray
    object_poses: np.ndarray
    fixtures: list[np.ndarray] | None = None
    others: list[np.ndarray] | None = None

    def pose(self, scene: Scene, row: int) -> None:
        """``scene`` as the log has it at ``row``."""
        scene.update(
            self.q[row],
            list(self.object_poses[row]),
            None if self.fixtures is None else [f[row] for f in self.fixtures],
            None if self.others is None else [q[row] for q in self.others],
        )


def perceive(
    rollout: RolloutData,
    spec: PerceptionSpec,
    scene: Scene,
    seed: int,
    n_objects: int = 0,
    log: SceneLog | None = None,
) -> None:
    """Fire every sensor of ``spec`` over ``rollout``'s logged states in ``scene`` (its
    free objects ``n_objects``; ``log``: what poses the scene, when not all in ``rollout``:
    a run of several robots), keeping their images in ``rollout.perception`` and what
    they are in its metadata's ``perception``: each sensor's kind, rate, the model frame it
    is mounted on (``frame``) and its whole spec (``spec``, `spec_record`)."""
    root = np.random.SeedSequence(seed).spawn(PERCEPTION_SEED_INDEX + 1)[PERCEPTION_SEED_INDEX]
    streams = root.spawn(max(1, len(spec.sensors)))
    if log is None:  # one robot: its rollout logs the world too
        log = SceneLog(
            rollout.q,
            object_poses(rollout, n_objects),
            fixture_positions(rollout, scene.fixture_names),
        )
    described = rollout.metadata.setdefault("perception", {})
    for (kind_name, own), stream in zip(spec.sensors, streams, strict=False):
        kind = SENSORS[kind_name]
        sensor = kind.make(own, scene, np.random.default_rng(stream))
        rows = firing_rows(rollout.time_s, own.rate_hz)
        fired, above = _fire(sensor, scene, log, rows)
        if above:  # its images and echoes are formed as in water: said, not silently
            warnings.warn(
                f"{kind_name} '{own.name}' was above the free surface at {len(above)} of its "
                f"{len(rows)} firings (the first at t = {rollout.time_s[above[0]]:g} s): what "
                "it recorded there is formed as if under water",
                PerceptionWarning,
                stacklevel=2,
            )
        rollout.perception[own.name] = {
            "time_s": rollout.time_s[rows].copy(),
            **fired,
            **kind.constants(sensor),
        }
        described[own.name] = {
            "kind": kind_name,
            "rate_hz": own.rate_hz,
            "frame": scene.uvms.model.frames[sensor.frame_id].name,  # the link it is on
            "spec": spec_record(own),
        }
        if kind_name == "camera":
            described[own.name]["label_names"] = list(scene.names)


#: the size of the processor's large pages [bytes] (x86-64's 2 MiB)
HUGE_PAGE = 1 << 21


def stack_of(shape: tuple[int, ...], dtype: np.dtype) -> np.ndarray:
    """An uninitialised array of ``shape`` and ``dtype`` for a sensor's images, starting on a
    `HUGE_PAGE` boundary when it is larger than one: the kernel then maps (and zeroes) it by
    whole large pages when it is first written, not 4 KiB at a time (a 320 x 240 camera's
    images of 2 s at 10 Hz, 14.5 MB: about 3,500 page faults otherwise, 5 ms)."""
    dtype = np.dtype(dtype)
    size = math.prod(shape) * dtype.itemsize
    if size < HUGE_PAGE:
        return np.empty(shape, dtype=dtype)
    raw = np.empty(size + HUGE_PAGE, dtype=np.uint8)
    skip = -raw.ctypes.data % HUGE_PAGE
    return raw[skip : skip + size].view(dtype).reshape(shape)


def _fire(
    sensor: Any, scene: Scene, log: SceneLog, rows: Sequence[int]
) -> tuple[dict[str, np.ndarray], list[int]]:
    """The sensor's arrays at each of ``rows``, stacked (`stack_of`), and the rows it fired
    at from above the free surface (in the air): the first firing's
    arrays give the stack's; each later firing is written into those same arrays, warm in
    the cache, then copied into its place in order (a camera writes its pixels tile by
    tile, which straight into memory not yet touched cost more than the copy:
    `benchmarks/bench_perception.py`'s camera run 1.82-1.84x -> 1.72-1.73x)."""
    stacked: dict[str, np.ndarray] = {}
    warm: dict[str, np.ndarray] = {}
    above = []  # the firings from above the free surface (in the air)
    for k, row in enumerate(rows):
        log.pose(scene, row)
        if scene.has_surface and sensor.placement().translation[2] > 0.0:
            above.append(row)
        if k == 0:
            warm = sensor.fire()
            for key, value in warm.items():
                stacked[key] = stack_of((len(rows), *value.shape), value.dtype)
        else:
            sensor.fire(warm)
        for key, values in stacked.items():
            np.copyto(values[k], warm[key])
    return stacked, above
