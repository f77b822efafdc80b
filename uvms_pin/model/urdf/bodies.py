"""Each link's hydrodynamics on the Pinocchio joint that carries it.

Pinocchio merges links attached by fixed joints into their parent joint's body. Each link
keeps its own coefficients, as a `HydroBody` on that joint with the link's placement in the
joint frame, so nothing is approximated by the merge. Mass and displaced volume are compared
per merged body: a buoyancy link beside a mass link is fine.
"""

from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import pinocchio as pin

from uvms_pin.errors import ModelError, ModelWarning
from uvms_pin.hydro.hull import HullPiece
from uvms_pin.model.urdf.collision import collision_hydro, collision_piece
from uvms_pin.model.urdf.hydrodynamics import parse_hydro
from uvms_pin.model.urdf.inertial import check_inertial
from uvms_pin.model.urdf.read import single
from uvms_pin.model.uvms import HydroBody

__all__ = ["hydro_bodies", "link_carrier"]


@dataclass
class _WetBody:
    """What the links of one merged body that have hydrodynamics add up to."""

    mass_kg: float = 0.0
    volume_m3: float = 0.0
    links: list[str] = field(default_factory=list)


def hydro_bodies(
    model: pin.Model,
    links: dict[str, ET.Element],
    hydro_elements: dict[str, ET.Element],
    water_density_kg_m3: float,
    where: str,
    *,
    derive_missing: bool,
    allow_dry_links: bool,
    base_dir: Path,
    package_dirs: Sequence[str | Path],
) -> list[HydroBody]:
    """The hydrodynamic bodies of every link with an <inertial>, in file order.

    A link's <hydrodynamics> gives one body; without it, each collision primitive gives one
    (``derive_missing``); a link with mass and neither is an error unless
    ``allow_dry_links``. Warns (`ModelWarning`) for a merged body that displaces water but
    weighs nothing, or the reverse.
    """
    bodies: list[HydroBody] = []
    wet: dict[int, _WetBody] = {}  # per Pinocchio joint (merged body)
    for name, link in links.items():
        if not _has_inertial(link, name in hydro_elements, where, name):
            continue  # a frame-only link: no body, no hydrodynamics
        mass_kg = check_inertial(single(link, "inertial", where, name), where, name)
        joint_id, placement = link_carrier(model, name, where)
        hydro = hydro_elements.get(name)
        collisions = link.findall("collision")
        if hydro is not None:
            params = parse_hydro(hydro, where, name)
            hull = _hull_pieces(collisions, where, name, base_dir, package_dirs)
            own = [HydroBody(name, joint_id, placement, params, hull)]
        elif collisions and derive_missing:
            own = []
            for k, collision in enumerate(collisions):
                origin, params = collision_hydro(
                    collision, water_density_kg_m3, where, name, base_dir, package_dirs
                )
                # the shape in the body's frame: a mesh's body sits at its bounding
                # primitive's frame, not at the collision origin
                to_body = origin.inverse()
                piece = collision_piece(collision, where, name, base_dir, package_dirs).placed(
                    to_body.rotation, to_body.translation
                )
                own.append(
                    HydroBody(
                        f"{name}/collision[{k}]", joint_id, placement * origin, params, (piece,)
                    )
                )
        elif not allow_dry_links:
            raise ModelError(
                "has mass but no <hydrodynamics> element and no collision primitive to derive "
                "coefficients from (pass allow_dry_links=True to accept a dry link)",
                path=where,
                link=name,
            )
        else:
            own = []  # a dry link accepted by allow_dry_links is no surprise
        if own:
            body = wet.setdefault(joint_id, _WetBody())
            body.mass_kg += mass_kg
            body.volume_m3 += sum(b.params.volume_m3 for b in own)
            body.links.append(name)
        bodies += own
    for body in wet.values():
        _warn_on_mass_volume_mismatch(body.mass_kg, body.volume_m3, where, "', '".join(body.links))
    return bodies


def _hull_pieces(
    collisions: list[ET.Element],
    where: str,
    link: str,
    base_dir: Path,
    package_dirs: Sequence[str | Path],
) -> tuple[HullPiece, ...]:
    """The link's collision shapes as hull pieces (link frame). A shape that cannot be read
    (a mesh not found) is left out with a `ModelWarning`: the body then floats as a sphere
    of its volume (its coefficients come from <hydrodynamics>, so it loads as before)."""
    pieces = []
    for collision in collisions:
        try:
            pieces.append(collision_piece(collision, where, link, base_dir, package_dirs))
        except ModelError as exc:
            warnings.warn(
                f"{exc}; the free surface cuts a sphere of the link's volume instead",
                ModelWarning,
                stacklevel=4,
            )
            return ()
    return tuple(pieces)


def _has_inertial(link: ET.Element, has_hydro: bool, where: str, name: str) -> bool:
    """Whether the link is a body; hydrodynamics or collision geometry need one."""
    has_inertial = link.find("inertial") is not None
    if has_hydro and not has_inertial:
        raise ModelError("has <hydrodynamics> but no <inertial>", path=where, link=name)
    if link.findall("collision") and not has_inertial:
        raise ModelError("has <collision> geometry but no <inertial>", path=where, link=name)
    return has_inertial


def link_carrier(model: pin.Model, link: str, where: str) -> tuple[int, pin.SE3]:
    """(Pinocchio joint whose body carries ``link``, the link's placement in its frame)."""
    frame_id = model.getFrameId(link, pin.BODY)
    if frame_id >= len(model.frames):
        raise ModelError("not found in the Pinocchio model", path=where, link=link)
    frame = model.frames[frame_id]
    return int(frame.parentJoint), frame.placement


def _warn_on_mass_volume_mismatch(mass_kg: float, volume_m3: float, where: str, link: str):
    """A link that displaces water but weighs nothing (or the reverse) is legal but rarely
    meant: buoyancy without weight (or weight without buoyancy) on that link."""
    if volume_m3 > 0.0 and mass_kg == 0.0:
        cause = f"displaces {volume_m3:.6g} m^3 of water but has zero mass"
    elif mass_kg > 0.0 and volume_m3 == 0.0:
        cause = f"has {mass_kg:.6g} kg of mass but displaces no water (zero volume)"
    else:
        return
    # stacklevel: this function, hydro_bodies, load_uvms, then load_uvms's caller
    warnings.warn(f"{where}: link '{link}': {cause}", ModelWarning, stacklevel=4)
