"""uuv_simulator's ``<hydrodynamic_model type="fossen">`` (its UnderwaterObject plugin) as
uvms-pin coefficients.

What the plugin computes (uuv_gazebo_plugins, HydrodynamicModel.cc, HMFossen): the link's
velocity nu (link frame, x forward, y left, z up) is turned into a frame rotated by pi about
x (x forward, y starboard, z down: "NED-like", SNAME) by T = diag(1, -1, -1, 1, -1, -1);
there, with the file's matrices A (added_mass), L (linear_damping), Q (quadratic_damping),

    tau_sname = -A nu_dot - C_A(nu) nu + (L + diag(Q) |nu|) nu,

and the wrench goes back to the link frame by T again. So in the link frame, where uvms-pin
wants them (tau = -M_A nu_dot - C_A nu - D_lin nu - diag(D_quad) |nu| nu):

    M_A = T A T,   D_lin = -T L T,   D_quad = -diag(Q).

The file's damping is negative (Fossen's X_u < 0); a positive entry would feed energy in
and is refused. The buoyancy block (volume, center_of_buoyancy in the link frame,
neutrally_buoyant, fluid_density) maps one to one. ``type="sphere"`` and ``type="cylinder"``
are this model with entries of A and Q computed from a shape (`uuv_shapes`).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from uvms_pin.errors import ModelError, ParameterError
from uvms_pin.hydro.params import HydroParams
from uvms_pin.model.importer.uuv_shapes import (
    IN_DEVELOPMENT,
    SHAPE_TAGS,
    SHAPES,
    shape_coefficients,
)
from uvms_pin.model.importer.xml import child_numbers, child_text

__all__ = ["LINK_FROM_SNAME", "fossen_hydro", "note_asymmetry"]

#: T: link frame (x fwd, y left, z up) <-> the plugin's SNAME frame (x fwd, y stbd, z down);
#: a rotation by pi about x, its own inverse, applied to [linear; angular].
LINK_FROM_SNAME = np.diag([1.0, -1.0, -1.0, 1.0, -1.0, -1.0])

_MAPPED = {"volume", "center_of_buoyancy", "hydrodynamic_model", "neutrally_buoyant"}
_MODEL_MAPPED = {"type", "added_mass", "linear_damping", "quadratic_damping"}
# asymmetry of an added-mass matrix below this (relative) is printing round-off
_SYMMETRY_NOTE_RELATIVE = 1e-12


def fossen_hydro(
    block: ET.Element,
    mass_kg: float,
    rho_kg_m3: float,
    where: str,
    notes: list[str],
) -> HydroParams:
    """One ``<link name=...>`` block of the UnderwaterObject plugin as `HydroParams` in the
    link frame. ``mass_kg`` is the link's mass (for ``neutrally_buoyant``), ``rho_kg_m3`` the
    plugin's fluid density. What is not carried over is appended to ``notes``."""
    link = block.get("name", "?")
    model = block.find("hydrodynamic_model")
    if model is None:
        raise ModelError(
            "uuv_simulator link block has no <hydrodynamic_model>", path=where, link=link
        )
    kind = child_text(model, "type")
    if kind != "fossen" and kind not in SHAPES:
        known = ", ".join(f'"{k}"' for k in ("fossen", *SHAPES))
        why = " (uuv_simulator logs it as still in development)" if kind in IN_DEVELOPMENT else ""
        raise ModelError(
            f'<hydrodynamic_model> type "{kind}" cannot be imported{why}; known: {known}',
            path=where,
            link=link,
        )
    shaped = kind in SHAPES
    _note_unmapped(block, _MAPPED | ({"box"} if shaped else set()), "", link, notes)
    _note_unmapped(
        model, _MODEL_MAPPED | (SHAPE_TAGS if shaped else set()), "<hydrodynamic_model>/", link,
        notes,
    )  # fmt: skip
    volume_m3 = _volume(block, mass_kg, rho_kg_m3, where, link, notes)
    cob = child_numbers(block, "center_of_buoyancy", (3,), where, link)
    added_sname = _matrix(model, "added_mass", where, link, diagonal_ok=False)
    quadratic_sname = np.diag(_matrix(model, "quadratic_damping", where, link, diagonal_ok=True))
    if shaped:
        added_sname, quadratic_sname = shape_coefficients(
            kind, model, block, rho_kg_m3, added_sname, quadratic_sname, where, link, notes
        )
    added = _sname_to_link(added_sname)
    linear = -_sname_to_link(_matrix(model, "linear_damping", where, link, diagonal_ok=True))
    quadratic = -quadratic_sname
    _note_off_diagonal_quadratic(model, where, link, notes)
    note_asymmetry(added, link, notes)
    try:
        return HydroParams(
            volume_m3,
            np.zeros(3) if cob is None else cob,
            0.5 * (added + added.T),
            linear,
            quadratic,
            origin=f"uuv_simulator {kind} model ({where})",
        )
    except ParameterError as exc:
        raise ModelError(
            f"{exc} (after the SNAME -> link frame change)", path=where, link=link
        ) from exc


def _sname_to_link(matrix_sname: np.ndarray) -> np.ndarray:
    """T A T: a 6x6 matrix of the plugin's SNAME frame in the link frame."""
    return LINK_FROM_SNAME @ matrix_sname @ LINK_FROM_SNAME


def _matrix(model: ET.Element, tag: str, where: str, link: str, *, diagonal_ok: bool) -> np.ndarray:
    """The 6x6 matrix of ``tag`` (36 numbers row-major, or 6 for a diagonal where the
    plugin accepts it); zero when absent, as in the plugin."""
    counts = (6, 36) if diagonal_ok else (36,)
    values = child_numbers(model, tag, counts, where, link)
    if values is None:
        return np.zeros((6, 6))
    return np.diag(values) if values.size == 6 else values.reshape(6, 6)


def _volume(
    block: ET.Element, mass_kg: float, rho_kg_m3: float, where: str, link: str, notes: list[str]
) -> float:
    """The displaced volume [m^3]; ``neutrally_buoyant`` true makes it m / rho."""
    flag = (child_text(block, "neutrally_buoyant") or "0").lower()
    if flag in ("1", "true"):
        notes.append(
            f"link '{link}': neutrally_buoyant: volume written as m / rho = "
            f"{mass_kg / rho_kg_m3:.6g} m^3 (the plugin's <volume> is then unused)"
        )
        return mass_kg / rho_kg_m3
    volume = child_numbers(block, "volume", (1,), where, link)
    if volume is None:
        raise ModelError("uuv_simulator link block has no <volume>", path=where, link=link)
    return float(volume[0])


def _note_unmapped(
    element: ET.Element, mapped: set[str], prefix: str, link: str, notes: list[str]
) -> None:
    for child in element:
        if child.tag not in mapped:
            notes.append(
                f"link '{link}': <{prefix}{child.tag}> not mapped (no uvms-pin counterpart)"
            )


def _note_off_diagonal_quadratic(
    model: ET.Element, where: str, link: str, notes: list[str]
) -> None:
    """The plugin reads a 36-number quadratic_damping but uses only its diagonal; so do we."""
    full = _matrix(model, "quadratic_damping", where, link, diagonal_ok=True)
    if np.any(full - np.diag(np.diag(full))):
        notes.append(
            f"link '{link}': off-diagonal <quadratic_damping> entries dropped "
            "(uuv_simulator uses only the diagonal too)"
        )


def note_asymmetry(added: np.ndarray, link: str, notes: list[str]) -> None:
    asymmetry = float(np.max(np.abs(added - added.T)))
    if asymmetry > _SYMMETRY_NOTE_RELATIVE * max(1.0, float(np.max(np.abs(added)))):
        notes.append(
            f"link '{link}': <added_mass> is not symmetric (largest |A - A^T| = {asymmetry:.6g}); "
            "written as its symmetric part (A + A^T)/2, which is what has kinetic energy"
        )
