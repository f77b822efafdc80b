"""A camera's image in an environment's observation (``CameraObservation``).

The wrapped environment's observation becomes a dict: ``"state"``, the observation as it
was, and ``"image"``, the camera's colour image (H, W, 3) uint8 of the system's true state
after the step (`uvms_pin.perception.camera`: the same model as ``[[sensors.camera]]``), its
noise drawn from the episode's seed. With ``depth=True`` also ``"depth"`` (H, W) float32 [m]
(inf: nothing met, so that the observation stays in its space).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from uvms_pin.checks import check_memory
from uvms_pin.perception.camera import Camera, CameraSpec
from uvms_pin.perception.scene import scene_of
from uvms_pin.perception.sensor import SENSORS
from uvms_pin.perception.suite import PERCEPTION_SEED_INDEX

__all__ = ["CameraObservation"]


def _episode_stream(seed: int | None) -> np.random.Generator:
    """The camera's noise of an episode: the perception child of its seed's SeedSequence."""
    children = np.random.SeedSequence(seed or 0).spawn(PERCEPTION_SEED_INDEX + 1)
    return np.random.default_rng(children[PERCEPTION_SEED_INDEX].spawn(1)[0])


class CameraObservation(gym.ObservationWrapper):
    """``env`` observed through a camera: ``camera`` a `CameraSpec` or a table of its keys
    (as ``[[sensors.camera]]``'s)."""

    def __init__(self, env: gym.Env, camera: CameraSpec | dict[str, Any], *, depth: bool = False):
        super().__init__(env)
        if not isinstance(camera, CameraSpec):
            camera = CameraSpec.from_dict(dict(camera), "camera")
        pixels = camera.width * camera.height
        check_memory(  # a frame, and the observation space's bounds (low, high) of its arrays
            SENSORS["camera"].bytes(camera) + 2 * pixels * (3 + (4 if depth else 0)),
            f"a {camera.width} x {camera.height} camera observation",
            "lower the camera's width and height",
        )
        plant = env.unwrapped.scenario.plant
        self._scene = scene_of(
            plant.uvms, plant.world, surface=plant.free_surface, backend=plant.backend
        )
        self._camera = Camera(camera, self._scene, _episode_stream(None))
        self._depth = depth
        spaces = {
            "state": env.observation_space,
            "image": gym.spaces.Box(0, 255, (camera.height, camera.width, 3), np.uint8),
        }
        if depth:
            spaces["depth"] = gym.spaces.Box(0.0, np.inf, (camera.height, camera.width), np.float32)
        self.observation_space = gym.spaces.Dict(spaces)

    def reset(self, **kwargs):
        observation, info = self.env.reset(**kwargs)
        self._camera.rng = _episode_stream(self.env.unwrapped.episode_seed)
        return self.observation(observation), info

    def observation(self, observation: np.ndarray) -> dict[str, np.ndarray]:
        loop = self.env.unwrapped.loop
        state = loop.state
        robot, *bodies = loop.system.layout.split(state.q, state.v)
        free = len(loop.system.objects)  # the free objects, then the fixtures
        objects, fixtures = bodies[:free], bodies[free:]
        self._scene.update(robot[0], [q for q, _ in objects], [q for q, _ in fixtures])
        frame = self._camera.render()
        out = {"state": observation, "image": frame.rgb}
        if self._depth:
            depth = frame.depth_m.astype(np.float32)
            out["depth"] = np.where(np.isnan(depth), np.float32(np.inf), depth)
        return out
