"""The project's exception hierarchy: every failure the user can cause has a type here."""

from __future__ import annotations

import traceback
from pathlib import Path

_PACKAGE_DIR = str(Path(__file__).resolve().parent)


class UvmsPinError(Exception):
    """Base class of every error raised on purpose by uvms-pin.

    ``user_traceback``: when the error is an exception of the user's own code (a custom
    controller), the frames of that code as text (`user_traceback`), shown as such by the
    command line; "" otherwise.
    """

    user_traceback: str = ""


def user_traceback(exc: BaseException) -> str:
    """The traceback of ``exc`` without uvms-pin's own outer frames: from the first frame of
    the user's code (a file outside the package) to the exception; "" if none is."""
    frames = traceback.extract_tb(exc.__traceback__)
    first = next(
        (k for k, frame in enumerate(frames) if not frame.filename.startswith(_PACKAGE_DIR)),
        None,
    )
    if first is None:
        return ""
    lines = traceback.format_list(frames[first:])
    lines += traceback.format_exception_only(type(exc), exc)
    return "Traceback (most recent call last):\n" + "".join(lines)


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


class PlausibilityWarning(UvmsPinWarning):
    """A value far outside what any vehicle, water or sea has (a volume in litres, a period
    in milliseconds?): the message names it, gives the number and the usual range. A value
    that cannot be physical at all is refused instead."""


class ObservabilityWarning(UvmsPinWarning):
    """The estimator the controller is given cannot observe part of the state: without a
    position fix (USBL, depth) or a velocity one (DVL, USBL), an IMU's integration drifts
    without bound. The message names what is unobservable and the sensor that would fix it."""


class ActuationWarning(UvmsPinWarning):
    """The actuators left out part of what the controller commanded for a reason the
    scenario does not state (a wrench component no thruster can produce): the message names
    the components and the largest value dropped."""


class PerceptionWarning(UvmsPinWarning):
    """A camera or sonar cannot give what its table asks: it fires at logged samples, and
    the log is slower than its ``rate_hz``. The message names the sensor, both rates and
    the ``output.log_period_s`` that would give its own."""


class ParameterError(UvmsPinError, ValueError):
    """An argument has the wrong shape, a non-finite value or is out of its valid range."""


class InitialOverlapError(ParameterError):
    """Two bodies overlap at the start of a run deeper than the tolerance (a free object
    placed inside the robot, another free object, a fixed object or the seabed): the
    contact would start compressed and fling them apart.

    Attributes:
        first, second: the two bodies' names. depth_m: how deep they overlap [m].
        tolerance_m: the deepest overlap allowed there [m].
    """

    def __init__(self, first: str, second: str, depth_m: float, tolerance_m: float, how: str):
        self.first, self.second, self.depth_m, self.tolerance_m = (
            first,
            second,
            depth_m,
            tolerance_m,
        )
        depth_mm, tolerance_mm = depth_m * 1e3, tolerance_m * 1e3
        super().__init__(
            f"'{first}' and '{second}' overlap by {depth_mm:.3g} mm at the start (more than "
            f"the {tolerance_mm:.2g} mm tolerance): {how}"
        )


class StiffModeError(ParameterError):
    """A spring-damper the run integrates explicitly (a world contact, a compliant joint
    stop, the end-effector's environment) is unstable at the integrator's fixed step: the
    run is refused before it starts (`uvms_pin.sim.stiffness`).

    Attributes:
        mode: the `uvms_pin.sim.stiff_modes.StiffMode` (what, k, c, m_eff).
        integrator: its name. step_s: the run's step [s]. largest_stable_step_s: h* [s].
    """

    def __init__(self, mode, integrator: str, step_s: float, largest_stable_step_s: float):
        self.mode, self.integrator = mode, integrator
        self.step_s, self.largest_stable_step_s = step_s, largest_stable_step_s
        # + 0.0: no "-0" for an undamped mode's real part
        rates = ", ".join(
            f"{r.real + 0.0:.4g}{r.imag + 0.0:+.4g}j" for r in map(complex, mode.rates)
        )
        super().__init__(
            f"{mode.describe()} is unstable at the {integrator} step of {step_s:g} s "
            f"(its rates lambda = {rates} 1/s leave the step's stability region): the largest "
            f"stable step is {largest_stable_step_s:.3g} s. Take [integrator] step_s at most "
            f"that (it must divide the control or log period){mode.remedy}."
        )


class ScenarioError(UvmsPinError):
    """A scenario or study file is malformed: unknown key, wrong type, missing entry."""


class StudyError(UvmsPinError):
    """A study file is malformed or names something the base scenario does not have."""


class OutputError(UvmsPinError):
    """An output path cannot be written, is in use, or holds results that are not this run's."""


class ResourceError(UvmsPinError, OSError):
    """The system refused what a command needed after its inputs were checked: a full disk,
    a directory removed meanwhile. An `OSError` whose ``filename`` is the file uvms-pin was
    writing (not its temporary name); the command line exits with status 4 for it.
    """


class DataError(UvmsPinError):
    """A measurement data set is missing, malformed or unusable; the message names the file."""


class NotShippedError(UvmsPinError, FileNotFoundError):
    """A file asked of `uvms_pin.shipped_path` is not shipped with this install (a
    FileNotFoundError too, as it was)."""


class CoreUnavailableError(UvmsPinError, ImportError):
    """The compiled core is missing, stale or built against another Pinocchio; the message
    says how to rebuild it."""


class OptionalDependencyError(UvmsPinError, ImportError):
    """A feature needs a package of an optional extra that is not installed; the message
    says which extra to install."""


class CoreFallbackWarning(UvmsPinWarning):
    """Something the compiled core has no counterpart of runs on the (slower) Python
    reference; the message says what and why."""


class NodeErrorWarning(UvmsPinWarning):
    """A node of an optimal-control problem raised outside `uvms_pin.ocp.problems.solve`
    (crocoddyl's ``problem.calc`` called directly): the error could not cross crocoddyl's
    C++ code, the node's outputs are placeholders."""


class SimulationError(UvmsPinError):
    """The simulation cannot continue (non-finite state, integrator failure)."""


class ControllerError(SimulationError):
    """The controller raised while the run was going (``compute``, ``reset``, ``signals``):
    the run stops there with status ``error``, its rollout kept (``exc.rollout``).

    Attributes name the method and the time; ``__cause__`` is the controller's exception and
    ``user_traceback`` its frames when the controller is the user's own code.
    """

    def __init__(self, method: str, time_s: float, cause: BaseException, *, users: bool):
        super().__init__(
            f"the controller's {method}() raised at t = {time_s:.6g} s: "
            f"{type(cause).__name__}: {cause}"
        )
        self.method = method
        self.time_s = time_s
        if users:
            self.user_traceback = user_traceback(cause)


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
