"""The replay of several robots (`uvms_pin.results.robots.RobotRollouts`): one page, every
robot drawn.

The page is the first robot's replay (`uvms_pin.apps.viz.replay`: its world, its forces, its
tip's trail, the camera on every robot's path) with the other robots' geometry beside it,
posed at each of the first robot's samples (the rollouts of one run share their samples).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import meshcat
import numpy as np

from uvms_pin.apps.viz.meshcat_scene import Frame, Pose
from uvms_pin.apps.viz.replay import replay_html, scene_for_rollout, write_page
from uvms_pin.results.robots import RobotRollouts
from uvms_pin.results.rollout import Rollout

__all__ = ["OtherRobots", "robots_replay_html", "write_robots_replay"]


class OtherRobots:
    """The robots drawn beside the first: each (name, rollout) of ``rollouts``, under the
    scene node ``others/<name>``."""

    def __init__(self, rollouts: Sequence[tuple[str, Rollout]]):
        self.robots = [(name, scene_for_rollout(r), r.q) for name, r in rollouts]
        points = [q[:, :3] for _, _, q in self.robots]
        self.extent_world_m = np.vstack(points) if points else np.zeros((0, 3))

    def build(self, root: meshcat.Visualizer) -> None:
        """Each robot's geometry (the one its own replay draws)."""
        for name, scene, _ in self.robots:
            scene._build_robot(root[f"others/{name}"])

    def poses(self, sample: int) -> dict[str, Pose]:
        """Each robot's geometry posed at its ``sample``-th logged state."""
        out: dict[str, Pose] = {}
        for name, scene, q in self.robots:
            for path, pose in scene.poses(Frame(0.0, q[sample])).items():
                if path.startswith("robot/"):
                    out[f"others/{name}/{path}"] = pose
        return out


def robots_replay_html(rollouts: RobotRollouts, **kw: Any) -> str:
    """The replay page of every robot of ``rollouts`` (`replay_html`'s keywords)."""
    first, *rest = rollouts.names
    others = OtherRobots([(name, rollouts.robot(name)) for name in rest])
    return replay_html(rollouts.robot(first), others=others, **kw)


def write_robots_replay(rollouts: RobotRollouts, path: str | Path, **kw: Any) -> Path:
    """Write the replay page of every robot to ``path`` (atomically); returns the path."""
    return write_page(robots_replay_html(rollouts, **kw), path)
