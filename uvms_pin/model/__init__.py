"""The static model: URDF -> `UVMS` (Pinocchio model and per-link hydrodynamics), arms
mounted on vehicles, trim, thruster layouts, shipped files.

``from uvms_pin.model import UVMS, load_uvms`` works; the modules load on first use.
"""

from uvms_pin._lazy import lazy_exports

_EXPORTS = {
    "DEFAULT_WATER_DENSITY_KG_M3": "uvms_pin.model.uvms",
    "HydroBody": "uvms_pin.model.uvms",
    "UVMS": "uvms_pin.model.uvms",
    "load_uvms": "uvms_pin.model.urdf.load",
    "read_urdf_root": "uvms_pin.model.urdf.read",
}
__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
