"""Cameras in the loop: images a controller reads from its measurement.

A camera with ``in_loop = true`` also fires during the run, at the first control tick at or
after each of its instants k / rate_hz, from the system's true state at that tick (the robot,
every free object and every fixture). Its latest image is in the measurement the controller
is given, ``measurement.images[name]`` (`LoopImage`), until the next one. Its noise comes
from its own stream of the run's seed (`LOOP_SEED_INDEX`), apart from the images fired over
the log.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from uvms_pin.perception.camera import Camera, CameraSpec
from uvms_pin.perception.scene import Scene

__all__ = ["LOOP_SEED_INDEX", "LoopCameras", "LoopImage"]

#: The child of the run's SeedSequence the cameras in the loop draw from.
LOOP_SEED_INDEX = 8


@dataclass(frozen=True)
class LoopImage:
    """A camera's image as a controller reads it: ``time_s`` when it was taken, ``depth_m``
    (H, W) (NaN: nothing met), ``rgb`` (H, W, 3) uint8, ``label`` (H, W) and
    ``label_names`` (label k is ``label_names[k - 1]``); read-only arrays."""

    time_s: float
    depth_m: np.ndarray
    rgb: np.ndarray
    label: np.ndarray
    label_names: tuple[str, ...]


class LoopCameras:
    """The cameras ``specs`` of a run, in ``scene``, seeded from ``seed``."""

    def __init__(self, specs: Sequence[CameraSpec], scene: Scene, seed: int):
        root = np.random.SeedSequence(seed).spawn(LOOP_SEED_INDEX + 1)[LOOP_SEED_INDEX]
        streams = root.spawn(len(specs))
        self.scene = scene
        self.cameras = [
            Camera(spec, scene, np.random.default_rng(stream))
            for spec, stream in zip(specs, streams, strict=True)
        ]
        self._next = [0] * len(self.cameras)  # each camera's next instant k
        self._images: dict[str, LoopImage] = {}
        self.images = MappingProxyType(self._images)

    def due(self, time_s: float) -> list[int]:
        """The cameras whose instant has come at the control tick ``time_s``."""
        return [
            k
            for k, camera in enumerate(self.cameras)
            if time_s >= self._next[k] / camera.spec.rate_hz - 1e-9
        ]

    def update(
        self,
        time_s: float,
        q: np.ndarray,
        object_poses: Sequence[np.ndarray],
        fixture_positions: Sequence[np.ndarray] | None = None,
        other_robots: Sequence[np.ndarray] | None = None,
    ) -> None:
        """At the control tick ``time_s``: the cameras whose instant has come fire, from the
        robot's ``q``, the free objects' poses (7,) each, the fixtures' joint positions and
        the other robots' configurations (None: where they are)."""
        due = self.due(time_s)
        if not due:
            return
        self.scene.update(q, object_poses, fixture_positions, other_robots)
        names = tuple(self.scene.names)
        for k in due:
            camera = self.cameras[k]
            frame = camera.render()
            for array in (frame.depth_m, frame.rgb, frame.label):
                array.setflags(write=False)
            self._images[camera.spec.name] = LoopImage(
                time_s, frame.depth_m, frame.rgb, frame.label, names
            )
            rate = camera.spec.rate_hz
            self._next[k] = int(np.floor(time_s * rate + 1e-9)) + 1
