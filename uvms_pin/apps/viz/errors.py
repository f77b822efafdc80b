"""Errors of the visualisation adapters (subclasses of `uvms_pin.errors.UvmsPinError`)."""

from __future__ import annotations

from uvms_pin.errors import UvmsPinError


class VizError(UvmsPinError):
    """A scene, a replay or a live view cannot be built (missing model file, bad rollout)."""


class LiveServerError(VizError):
    """The live meshcat server cannot be started or stopped."""


class PortInUseError(LiveServerError):
    """The requested port on the loopback interface is already taken."""

    def __init__(self, host: str, port: int):
        super().__init__(
            f"port {port} on {host} is already in use: choose another with --port "
            "(or --port 0 for any free port)"
        )
        self.host = host
        self.port = port
