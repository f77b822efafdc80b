"""Which Gazebo plugin an element is: by its ``filename`` (uuv_simulator's shared libraries)
or its ``name``/``filename`` (gz-sim's systems)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from enum import Enum

__all__ = ["PluginKind", "plugin_kind"]


class PluginKind(Enum):
    """The plugins the importer reads; everything else is reported as not mapped."""

    UUV_HYDRO = "uuv_simulator UnderwaterObject"
    UUV_THRUSTER = "uuv_simulator Thruster"
    GZ_HYDRO = "gz-sim Hydrodynamics"
    GZ_THRUSTER = "gz-sim Thruster"
    GZ_BUOYANCY = "gz-sim Buoyancy"
    GZ_LIFT_DRAG = "gz-sim LiftDrag"
    UUV_FIN = "uuv_simulator Fin"


# (substring of filename or name, kind); first match wins
_SIGNATURES = (
    # not AdvancedLiftDrag (other parameters): its names hold neither string
    ("systems::liftdrag", PluginKind.GZ_LIFT_DRAG),
    ("gz-sim-lift-drag-system", PluginKind.GZ_LIFT_DRAG),
    ("underwater_object", PluginKind.UUV_HYDRO),
    ("uuv_fin", PluginKind.UUV_FIN),
    ("uuv_thruster", PluginKind.UUV_THRUSTER),
    ("hydrodynamics", PluginKind.GZ_HYDRO),
    ("gz::sim::systems::thruster", PluginKind.GZ_THRUSTER),
    ("thruster-system", PluginKind.GZ_THRUSTER),
    ("buoyancy", PluginKind.GZ_BUOYANCY),
)


def plugin_kind(plugin: ET.Element) -> PluginKind | None:
    """The kind of a ``<plugin>`` element, None for one the importer does not read."""
    text = f"{plugin.get('filename', '')} {plugin.get('name', '')}".lower()
    for signature, kind in _SIGNATURES:
        if signature in text:
            return kind
    return None
