"""The forward dynamics' derivatives at many states at once (identification, learning,
sampling-based planning): `forward_dynamics_derivatives_batch`.

Each state's Jacobians are those of `uvms_pin.physics.dynamics.forward_dynamics_derivatives`
at that state (docs/derivatives.md); the compiled core computes them on ``num_threads``
threads without the interpreter (src/uvms_core/batch_derivatives.hpp, each thread with its
own copy of the dynamics), the Python reference one state after the other.
"""

from __future__ import annotations

import numpy as np

from uvms_pin.checks import check_memory, finite_vector, flag, thread_count
from uvms_pin.errors import ParameterError
from uvms_pin.flow import FlowField
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.dynamics import CompiledDynamics
from uvms_pin.physics.configuration import NORM_TOLERANCE, checked_configuration
from uvms_pin.physics.dynamics import dynamics_of, forward_dynamics_derivatives, water_of_call
from uvms_pin.physics.reference import check_time

__all__ = ["forward_dynamics_derivatives_batch"]

Jacobians = tuple[np.ndarray, np.ndarray, np.ndarray]


def forward_dynamics_derivatives_batch(
    uvms: UVMS,
    q: np.ndarray,
    v: np.ndarray,
    tau: np.ndarray,
    *,
    current_world: np.ndarray | None = None,
    flow: FlowField | None = None,
    time_s: float | np.ndarray = 0.0,
    tau_ext: np.ndarray | None = None,
    backend: str = "core",
    free_surface: bool = False,
    num_threads: int = 1,
) -> Jacobians:
    """(da/dq, da/dv, da/dtau), each (n, nv, nv), at the n states (q[k], v[k], tau[k]).

    Entry [k] equals ``forward_dynamics_derivatives(uvms, q[k], v[k], tau[k], ...)`` with the
    same water; the result does not depend on ``num_threads``.

    Args:
        q: (n, nq) configurations, each on the manifold. v, tau: (n, nv) [rad/s, m/s; N, N m].
        current_world, flow, free_surface: the water, as in `forward_dynamics_derivatives`.
        time_s: when the flow is evaluated [s]: one time for all states, or (n,).
        tau_ext: (n, nv) generalized external forces (held fixed), or None.
        backend: "core" (compiled, threaded) or "python" (the reference, state by state).
        num_threads: threads of the compiled core (the GIL released while they run).

    Raises:
        ParameterError: a wrong shape, a non-finite entry, a configuration off its manifold
            (naming the state), a bad thread count, or Jacobians larger than the memory.
    """
    dynamics = dynamics_of(uvms, backend)
    water = water_of_call(uvms, current_world, flow)
    free_surface = flag("free_surface", free_surface)
    num_threads = thread_count(num_threads)
    shape, nv = np.shape(q), uvms.nv
    count = shape[0] if len(shape) == 2 else 0
    # before any copy of the states: the Jacobians and the states' own C-ordered copies
    check_memory(
        (3 * nv * nv + uvms.model.nq + 3 * nv) * count * 8.0,
        f"the Jacobians of {count} states ({count} x 3 x {nv} x {nv} floats)",
        "differentiate fewer states per call",
    )
    states = _states(uvms, q, v, tau, tau_ext)
    count = len(states[0])
    times = _times(time_s, count)
    struct = dynamics.flow_struct(water) if isinstance(dynamics, CompiledDynamics) else None
    if struct is None or isinstance(struct, Fallback):
        _check_configurations(uvms, states[0])
        return _one_by_one(uvms, states, times, water, backend, free_surface)
    out = tuple(np.empty((count, nv, nv)) for _ in range(3))
    q, v, tau, ext = states
    batch = dynamics.batch_derivatives(num_threads)
    # every q on its manifold in one compiled pass (in Python, 0.6 pin.aba per state); the
    # first one off it named by the reference's check
    bad = batch.first_off_manifold(q, NORM_TOLERANCE)
    if bad >= 0:
        checked_configuration(f"q[{bad}]", q[bad], uvms.model)
    batch.compute(q, v, tau, ext, times, struct, free_surface, *out)
    return out


def _check_configurations(uvms: UVMS, q: np.ndarray) -> None:
    """Each row of q on the configuration manifold, else ParameterError naming it."""
    for k, row in enumerate(q):
        checked_configuration(f"q[{k}]", row, uvms.model)


def _states(uvms: UVMS, q, v, tau, tau_ext) -> tuple:
    """(q, v, tau, tau_ext) as C-ordered float arrays of n rows, their shapes and values
    checked (q's manifold: by the caller)."""
    model = uvms.model
    q = _rows("q", q, model.nq)
    count = len(q)
    rows = [_rows(name, x, uvms.nv, count) for name, x in (("v", v), ("tau", tau))]
    ext = None if tau_ext is None else _rows("tau_ext", tau_ext, uvms.nv, count)
    return (q, *rows, ext)


def _rows(name: str, value, size: int, count: int | None = None) -> np.ndarray:
    """``value`` as a (count, size) C-ordered float array with finite entries."""
    try:
        array = np.ascontiguousarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"{name} must be an array of numbers of shape (n, {size})") from exc
    if array.ndim != 2 or array.shape[1] != size or (count is not None and len(array) != count):
        rows = "n" if count is None else str(count)
        raise ParameterError(f"{name} must have shape ({rows}, {size}), got {array.shape}")
    if not np.all(np.isfinite(array)):
        bad = int(np.argwhere(~np.isfinite(array))[0, 0])
        raise ParameterError(f"{name}[{bad}] contains a non-finite value")
    return array


def _times(time_s, count: int) -> np.ndarray:
    """One time per state [s]: ``time_s`` repeated, or its (count,) entries, each finite."""
    if np.ndim(time_s) == 0:
        return np.full(count, check_time(time_s))
    return finite_vector(f"time_s (one time or {count}, one a state)", time_s, count)


def _one_by_one(uvms, states, times, water, backend, free_surface) -> Jacobians:
    """The Python reference (or a flow the core has no counterpart of): state by state."""
    q, v, tau, ext = states
    calls = [
        forward_dynamics_derivatives(
            uvms, q[k], v[k], tau[k], flow=water, time_s=times[k],
            tau_ext=None if ext is None else ext[k], backend=backend, free_surface=free_surface,
        )
        for k in range(len(q))
    ]  # fmt: skip
    nv = uvms.nv
    return tuple(np.array([c[i] for c in calls]).reshape(len(q), nv, nv) for i in range(3))
