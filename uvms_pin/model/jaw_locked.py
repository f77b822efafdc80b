"""A model with its jaw locked: what the arm's controllers are built on.

The arm's controllers (PPC, task priority, the baselines, MPC) see the vehicle and the arm
joints only. They are built on the same URDF with every jaw joint made fixed at a position
(`uvms_pin.model.mount.joints.lock_joint`): the fingers then ride on the wrist as rigid
bodies, so the controllers' kinematics, masses and hydrodynamics are those of the UVMS with
its jaw held there. The plant keeps the jaw's joints (`uvms_pin.model.jaw.JawJoints`).
"""

from __future__ import annotations

import tempfile
from collections.abc import Sequence
from pathlib import Path

from uvms_pin.model.jaw import JawJoints
from uvms_pin.model.mount.joints import lock_joint
from uvms_pin.model.mount.links import resolve_meshes
from uvms_pin.model.mount.text import urdf_text, write_text_file
from uvms_pin.model.urdf.load import load_uvms
from uvms_pin.model.urdf.read import read_urdf_root
from uvms_pin.model.uvms import UVMS

__all__ = ["jaw_locked"]


def jaw_locked(uvms: UVMS, jaw: JawJoints, positions: Sequence[float]) -> UVMS:
    """``uvms`` (loaded from its URDF, ``uvms.source``) with the joints of ``jaw`` fixed at
    ``positions`` [rad or m, one per jaw joint, inside their limits]; the same end-effector
    and sensor frames and water density.

    Raises:
        ParameterError: a position outside its joint's limits.
    """
    path = Path(uvms.source)
    root = read_urdf_root(path)
    lock = dict(zip(jaw.names, (float(p) for p in positions), strict=True))
    for joint in root.findall("joint"):
        if joint.get("name") in lock:
            lock_joint(joint, lock[joint.get("name")], path)
    for link in root.findall("link"):  # the file moves: its meshes are found by absolute paths
        resolve_meshes(link, path, (), needs_collision=False)
    frames = uvms.model.frames
    with tempfile.TemporaryDirectory() as folder:
        locked = write_text_file(Path(folder) / path.name, urdf_text(root))
        out = load_uvms(
            locked,
            water_density_kg_m3=uvms.water_density_kg_m3,
            ee_frame=None if uvms.ee_frame_id is None else frames[uvms.ee_frame_id].name,
            sensor_frame=None
            if uvms.sensor_frame_id is None
            else frames[uvms.sensor_frame_id].name,
        )
    out.source = str(path)
    return out
