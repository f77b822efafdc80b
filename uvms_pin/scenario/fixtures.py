"""``[[world.objects]] type = "urdf"``: a fixture (`uvms_pin.physics.world.fixture`), an
articulated body whose root is fixed in the world.

Keys: ``path`` (the URDF, relative to the scenario's folder, else to the shipped
``models/``), ``position_world_m`` and ``rpy_rad`` (its root link's frame), ``name``,
``joint_positions_rad`` (a table joint name -> position, or a list of one position per
moving joint in the file's order; [rad] for a revolute joint, [m] for a prismatic one;
absent: 0), ``friction_static`` and ``friction_kinetic`` (mu against its links). Its masses,
limits, damping and joint friction are its URDF's: ``mass_kg``, ``density_kg_m3`` and
``fixed = false`` are refused.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from uvms_pin.errors import ParameterError
from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.fixture import FIXTURE_TYPE, Fixture, fixture, fixture_path
from uvms_pin.scenario.schema import Table, is_number

__all__ = ["FIXTURE_KEYS", "read_fixture"]

#: the keys of a fixture's table besides type, name and the friction
FIXTURE_KEYS = ("path", "position_world_m", "rpy_rad", "joint_positions_rad")


def read_fixture(
    t: Table, name: str, law: ContactLaw, base_dir: Path, water_density_kg_m3: float
) -> Fixture:
    """The fixture of the table ``t`` (its ``type`` and ``name`` read), or the scenario's
    error naming the file and the key."""
    for key in ("mass_kg", "density_kg_m3"):
        if t.has(key):
            raise t.error(key, f'a fixture (type = "{FIXTURE_TYPE}") has its URDF\'s masses')
    if not t.boolean("fixed", True):
        raise t.error("fixed", f'a fixture (type = "{FIXTURE_TYPE}") has its root fixed')
    mu_s = t.number("friction_static", law.friction_static, nonneg=True)
    mu_k = t.number("friction_kinetic", min(law.friction_kinetic, mu_s), nonneg=True)
    entry = t.string("path")
    try:
        path = fixture_path(entry, base_dir)
    except ParameterError as exc:
        raise t.error("path", str(exc)) from exc
    pose = (t.vector("position_world_m", 3), t.vector("rpy_rad", 3, [0.0, 0.0, 0.0]))
    positions = _joint_positions(t)
    try:
        out = fixture(
            name, path, pose, joint_positions=positions,
            water_density_kg_m3=water_density_kg_m3, friction=(mu_s, mu_k),
        )  # fmt: skip
    except ParameterError as exc:
        key = getattr(exc, "key", None)
        raise (t.fail(str(exc)) if key is None else t.error(key, str(exc))) from exc
    t.finish()
    return out


def _joint_positions(t: Table) -> Any:
    """``joint_positions_rad``: a table of numbers by joint name, a list of numbers, or
    None when absent."""
    key = "joint_positions_rad"
    raw = t.pop_raw(key, None)
    if raw is None:
        return None
    values = list(raw.values()) if isinstance(raw, dict) else raw
    if not isinstance(values, list) or not all(is_number(v) for v in values):
        raise t.error(
            key, f"must be a table joint name -> number or a list of numbers, got {raw!r}"
        )
    return {str(k): float(v) for k, v in raw.items()} if isinstance(raw, dict) else values
