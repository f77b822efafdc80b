"""The world's fixtures as drawn: each fixture's links at its logged joint positions.

A fixture (``[[world.objects]] type = "urdf"``, `uvms_pin.physics.world.fixture`) is its URDF
placed in the world; its record (`Fixture.record`) names the file, the root's pose and the
initial joint positions, and the rollout logs its joints as the signal named after it
(components: its joints, ``<fixture>.<joint>_rad`` or ``_m``). Its links are drawn from the
URDF's ``<visual>`` elements, or from its ``<collision>`` shapes when it has none, under
``world/fixtures/<name>/<joint>/<piece>`` (`uvms_pin.apps.viz.robot_view.draw_bodies`); only
the body nodes ``world/fixtures/<name>/<joint>`` move, to the joint's pose at the logged
joint positions (the root's bodies hang on ``universe``, which stays at the identity).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import meshcat
import numpy as np
import pinocchio as pin

from uvms_pin.apps.viz.robot_view import Pose, body_poses, draw_bodies, geometry_groups
from uvms_pin.errors import VizError
from uvms_pin.physics.world.fixture import fixture

__all__ = ["FixtureView"]

#: the fixtures' colour (RGBA): a painted steel grey
FIXTURE_RGBA = np.array([0.62, 0.66, 0.7, 1.0])
#: the water density the placed model is built with (the drawing does not depend on it)
_DENSITY = 1025.0


@dataclass(frozen=True)
class FixtureView:
    """One fixture as drawn.

    Attributes:
        name: the fixture's name (its signal's and its nodes' name).
        model: its fixed-base model placed in the world (joint 0 the world).
        geometry: the geometry drawn (its visuals, else its collision shapes).
        q0: its joints' initial positions [rad or m] (drawn when no row is logged).
    """

    name: str
    model: pin.Model
    geometry: pin.GeometryModel
    q0: np.ndarray

    @classmethod
    def from_record(cls, record: dict[str, Any]) -> FixtureView:
        """From a fixture's record (`Fixture.record`); VizError when its URDF is gone."""
        path = Path(record["path"])
        if not path.is_file():
            raise VizError(f"fixture {record['name']!r}: its URDF {path} is not there")
        placed = fixture(
            record["name"],
            path,
            (record["position_world_m"], record["rpy_rad"]),
            joint_positions=record.get("joint_positions"),
            water_density_kg_m3=_DENSITY,
        )
        model = placed.uvms.model
        visuals = geometry_groups(model, path, "visual")["visuals"]
        if visuals.ngeoms == 0:
            visuals = geometry_groups(model, path, "collision")["collisions"]
        return cls(placed.name, model, visuals, placed.q0.copy())

    @property
    def prefix(self) -> str:
        return f"world/fixtures/{self.name}"

    def build(self, node: meshcat.Visualizer) -> None:
        """Draw the links under ``node`` (the scene's ``world/fixtures/<name>``)."""
        draw_bodies(node, self.model, self.geometry, FIXTURE_RGBA)

    def poses(self, joints: np.ndarray | None) -> dict[str, Pose]:
        """Pose of each body node at the joint positions ``joints`` (a logged row of the
        fixture's signal; None: its initial positions)."""
        q = self.q0 if joints is None else np.asarray(joints, dtype=float).reshape(-1)
        if q.shape != self.q0.shape:
            q = self.q0  # a row that does not fit: the initial pose rather than a wrong one
        data = self.model.createData()
        pin.forwardKinematics(self.model, data, q)
        return body_poses(self.model, data, self.geometry, self.prefix)
