"""Controllers: one small interface (`Controller`), one file per law."""

from uvms_pin.control.base import Controller, ZeroController

__all__ = ["Controller", "ZeroController"]
