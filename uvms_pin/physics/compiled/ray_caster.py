"""The perception's ray caster in the core (src/uvms_core/ray_caster.hpp): built here, as
every core object is, and filled by `uvms_pin.perception.compiled_caster` with the scene's
shapes (``add_plane``, ``add_sphere``, ...: the perception layer sits above this one, so its
shapes are not imported here)."""

from __future__ import annotations

from types import ModuleType
from typing import Any

__all__ = ["ray_caster"]


def ray_caster(core: ModuleType) -> Any:
    """An empty compiled ray caster (``_core.RayCaster``) of the extension ``core``."""
    return core.RayCaster()
