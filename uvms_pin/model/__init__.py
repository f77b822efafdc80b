"""The static model: URDF -> `UVMS` (Pinocchio model and per-link hydrodynamics), arms
mounted on vehicles, trim, thruster layouts, shipped files.

``from uvms_pin.model import UVMS, load_uvms`` works; the modules load on first use.
"""

from uvms_pin._lazy import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(
    __name__,
    {
        "uvms_pin.model.uvms": ("DEFAULT_WATER_DENSITY_KG_M3", "HydroBody", "UVMS"),
        "uvms_pin.model.urdf.load": ("load_uvms",),
        "uvms_pin.model.urdf.read": ("read_urdf_root",),
    },
)
