"""The project's exception hierarchy: every failure the user can cause has a type here."""

from __future__ import annotations


class UvmsPinError(Exception):
    """Base class of every error raised on purpose by uvms-pin."""


class ModelError(UvmsPinError):
    """A model file (URDF, hydrodynamic extension) is malformed or physically invalid.

    The message names the file, the link and what is wrong.
    """

    def __init__(self, message: str, *, path: str | None = None, link: str | None = None):
        prefix = ""
        if path is not None:
            prefix += f"{path}: "
        if link is not None:
            prefix += f"link '{link}': "
        super().__init__(prefix + message)
        self.path = path
        self.link = link


class UvmsPinWarning(UserWarning):
    """Base class of every warning issued by uvms-pin (the CLI prints them as warnings)."""


class ModelWarning(UvmsPinWarning):
    """A model loads but looks physically suspicious (e.g. a link with volume and no mass).

    The message names the file, the link and what is suspicious.
    """


class ShortenedRunWarning(UvmsPinWarning):
    """A scenario runs shorter than its ``duration_s`` because ``UVMS_PIN_MAX_DURATION_S``
    is set (`uvms_pin.sim.shortened`); the message names the file and both durations."""


class ParameterError(UvmsPinError, ValueError):
    """An argument has the wrong shape, a non-finite value or is out of its valid range."""


class ScenarioError(UvmsPinError):
    """A scenario or study file is malformed: unknown key, wrong type, missing entry."""


class StudyError(UvmsPinError):
    """A study file is malformed or names something the base scenario does not have."""


class OutputError(UvmsPinError):
    """An output path cannot be written, is in use, or holds results that are not this run's."""


class DataError(UvmsPinError):
    """A measurement data set is missing, malformed or unusable; the message names the file."""


class CoreUnavailableError(UvmsPinError, ImportError):
    """The compiled core is missing, stale or built against another Pinocchio; the message
    says how to rebuild it."""


class CoreFallbackWarning(UvmsPinWarning):
    """Something the compiled core has no counterpart of runs on the (slower) Python
    reference; the message says what and why."""


class SimulationError(UvmsPinError):
    """The simulation cannot continue (non-finite state, integrator failure)."""


class FunnelViolation(SimulationError):
    """A prescribed-performance error left its funnel: |e(t)| >= rho(t).

    Attributes name the level, component, time, error and bound so that callers can
    report it without parsing the message.
    """

    def __init__(self, *, level: str, component: str, time_s: float, error: float, bound: float):
        super().__init__(
            f"funnel violated at t = {time_s:.6f} s: {level} error '{component}' = {error:.6g} "
            f"reached its bound rho = {bound:.6g} (|xi| = {abs(error) / bound:.6f} >= 1)"
        )
        self.level = level
        self.component = component
        self.time_s = time_s
        self.error = error
        self.bound = bound


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
