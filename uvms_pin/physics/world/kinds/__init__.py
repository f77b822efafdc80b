"""The kinds of world object, one module each (what a kind carries:
`uvms_pin.physics.world.kind`). Each module registers its kind on import; this list is
the one place a kind is named."""

from uvms_pin.physics.world.kinds import box, cylinder, ellipsoid, mesh, plane, sphere

__all__ = ["box", "cylinder", "ellipsoid", "mesh", "plane", "sphere"]
