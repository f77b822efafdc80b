"""The derivatives at many states at once (`up.forward_dynamics_derivatives_batch`): each
state's Jacobians are the single call's, for any number of threads and either backend; bad
input is refused naming what is wrong, memory before it is taken."""

from __future__ import annotations

import numpy as np
import pytest

import uvms_pin as up
from tests.conftest import random_state
from uvms_pin.errors import ParameterError
from uvms_pin.flow import AiryWave, UniformCurrent
from uvms_pin.physics import batch_derivatives
from uvms_pin.physics.dynamics import water_of_call

CURRENT = np.array([0.3, -0.1, 0.05])


def _states(uvms, count: int, seed: int = 3):
    rng = np.random.default_rng(seed)
    rows = [random_state(uvms, rng) for _ in range(count)]
    return tuple(np.array([r[i] for r in rows]) for i in range(3))


def _single(uvms, q, v, tau, **kw):
    times = kw.pop("time_s", np.zeros(len(q)))
    ext = kw.pop("tau_ext", None)
    calls = [
        up.forward_dynamics_derivatives(
            uvms, q[k], v[k], tau[k], time_s=times[k],
            tau_ext=None if ext is None else ext[k], **kw,
        )
        for k in range(len(q))
    ]  # fmt: skip
    return tuple(np.array([c[i] for c in calls]) for i in range(3))


@pytest.mark.parametrize("num_threads", [1, 2, 3])
def test_batch_equals_the_single_calls_in_a_current(reference_uvms, num_threads):
    uvms = reference_uvms
    q, v, tau = _states(uvms, 7)
    ext = np.random.default_rng(5).normal(size=tau.shape)
    batch = up.forward_dynamics_derivatives_batch(
        uvms, q, v, tau, current_world=CURRENT, tau_ext=ext, num_threads=num_threads
    )
    single = _single(uvms, q, v, tau, current_world=CURRENT, tau_ext=ext)
    for got, want in zip(batch, single, strict=True):
        assert got.shape == (7, uvms.nv, uvms.nv)
        np.testing.assert_array_equal(got, want)  # the same arithmetic, whatever the thread


def test_batch_in_waves_at_one_time_per_state_under_the_surface(reference_uvms):
    uvms = reference_uvms
    q, v, tau = _states(uvms, 5)
    q[:, 2] = np.linspace(-0.3, -2.0, 5)  # the first hulls cut by the surface
    waves = AiryWave(amplitude_m=0.3, period_s=5.0, heading_rad=0.4, water_depth_m=30.0)
    times = np.linspace(0.0, 4.0, 5)
    kw = dict(flow=waves, free_surface=True)
    batch = up.forward_dynamics_derivatives_batch(
        uvms, q, v, tau, time_s=times, num_threads=2, **kw
    )
    single = _single(uvms, q, v, tau, time_s=times, **kw)
    for got, want in zip(batch, single, strict=True):
        np.testing.assert_array_equal(got, want)

    # without a time, every state is taken at t = 0, as a single call's default
    at_zero = up.forward_dynamics_derivatives_batch(uvms, q, v, tau, num_threads=2, **kw)
    single = _single(uvms, q, v, tau, **kw)
    for got, want in zip(at_zero, single, strict=True):
        np.testing.assert_array_equal(got, want)


def test_python_reference_batch_agrees_with_the_core(reference_uvms):
    uvms = reference_uvms
    q, v, tau = _states(uvms, 3)
    core = up.forward_dynamics_derivatives_batch(uvms, q, v, tau, current_world=CURRENT)
    python = up.forward_dynamics_derivatives_batch(
        uvms, q, v, tau, current_world=CURRENT, backend="python"
    )
    for got, want in zip(python, core, strict=True):
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9)


def test_no_state_gives_empty_jacobians(reference_uvms):
    uvms = reference_uvms
    empty = np.empty((0, uvms.nv))
    out = up.forward_dynamics_derivatives_batch(uvms, np.empty((0, uvms.model.nq)), empty, empty)
    assert all(x.shape == (0, uvms.nv, uvms.nv) for x in out)


def test_current_world_equals_the_uniform_current_and_follows_a_changed_array(reference_uvms):
    uvms = reference_uvms
    q, v, tau = (x[0] for x in _states(uvms, 1))
    current = CURRENT.copy()
    first = up.forward_dynamics_derivatives(uvms, q, v, tau, current_world=current)
    same = up.forward_dynamics_derivatives(uvms, q, v, tau, flow=UniformCurrent(CURRENT))
    for a, b in zip(first, same, strict=True):
        np.testing.assert_array_equal(a, b)
    current[0] = -0.6  # the same array, another current: not the kept one
    changed = up.forward_dynamics_derivatives(uvms, q, v, tau, current_world=current)
    want = up.forward_dynamics_derivatives(uvms, q, v, tau, flow=UniformCurrent(current.copy()))
    assert not np.allclose(changed[1], first[1])
    for a, b in zip(changed, want, strict=True):
        np.testing.assert_array_equal(a, b)


def test_a_kept_current_is_reused_by_its_bytes_and_a_bad_one_still_refused(reference_uvms):
    """`water_of_call` hands a current given again (the same float64 bytes) the flow it
    built for it without checking it again; anything else is checked: a non-finite entry,
    a wrong shape, zero (still water), another dtype or a list."""
    uvms = reference_uvms
    kept = water_of_call(uvms, CURRENT.copy(), None)
    assert water_of_call(uvms, CURRENT.copy(), None) is kept  # the same bytes, another array
    assert water_of_call(uvms, CURRENT.astype(np.float32).astype(float), None) is not None
    for bad, message in [
        (np.array([np.nan, 0.0, 0.0]), "current_world contains a non-finite value"),
        (np.r_[CURRENT, 0.0], "current_world must have shape"),
        (CURRENT[:2], "current_world must have shape"),
    ]:
        with pytest.raises(ParameterError, match=message):
            water_of_call(uvms, bad, None)
    assert water_of_call(uvms, np.zeros(3), None) is None
    assert water_of_call(uvms, list(CURRENT), None).velocity_world_m_s.tolist() == list(CURRENT)
    assert water_of_call(uvms, CURRENT.astype(np.float32), None) is not None


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda s: (s[0][:, :5], *s[1:]), r"q must have shape \(n, "),
        (lambda s: (s[0], s[1][:-1], s[2]), r"v must have shape \(3, "),
        (lambda s: (s[0], s[1], np.where(np.arange(3)[:, None] == 2, np.nan, s[2])), r"tau\[2\]"),
        (
            lambda s: (s[0] * np.r_[1, 1, 1, 2, 2, 2, 2, np.ones(len(s[0][0]) - 7)], *s[1:]),
            r"q\[0\]",
        ),
        (lambda s: ("abc", *s[1:]), "q must"),
    ],
    ids=["q columns", "v rows", "nan tau", "q off manifold", "not numbers"],
)
def test_bad_states_are_refused_by_name(reference_uvms, change, message):
    args = change(_states(reference_uvms, 3))
    with pytest.raises(ParameterError, match=message):
        up.forward_dynamics_derivatives_batch(reference_uvms, *args)


def test_bad_threads_and_times_are_refused(reference_uvms):
    q, v, tau = _states(reference_uvms, 3)
    with pytest.raises(ParameterError, match="num_threads"):
        up.forward_dynamics_derivatives_batch(reference_uvms, q, v, tau, num_threads=0)
    with pytest.raises(ParameterError, match=r"time_s \(one time or 3, one a state\) must have"):
        up.forward_dynamics_derivatives_batch(reference_uvms, q, v, tau, time_s=[0.0, 1.0])
    with pytest.raises(ParameterError, match=r"time_s .* contains a non-finite value"):
        up.forward_dynamics_derivatives_batch(reference_uvms, q, v, tau, time_s=[0.0, np.nan, 1])
    with pytest.raises(ParameterError, match=r"time_s .* must be 3 numbers"):
        up.forward_dynamics_derivatives_batch(reference_uvms, q, v, tau, time_s=["a", "b", "c"])


def test_more_states_than_memory_are_refused_before_anything_is_copied(reference_uvms):
    uvms = reference_uvms
    q = np.broadcast_to(uvms.neutral_configuration(), (10**9, uvms.model.nq))  # no memory
    v = np.broadcast_to(np.zeros(uvms.nv), (10**9, uvms.nv))
    with pytest.raises(ParameterError, match=r"would take .* GiB"):
        up.forward_dynamics_derivatives_batch(uvms, q, v, v)


def test_the_memory_asked_for_is_what_the_call_keeps(reference_uvms, monkeypatch):
    """The bytes checked before anything is copied are the three Jacobians it returns plus
    its C-ordered copies of q, v, tau and tau_ext: nothing left out, nothing counted twice."""
    asked, check_memory = [], batch_derivatives.check_memory

    def recorded(needed_bytes, *args, **kwargs):
        asked.append(needed_bytes)
        return check_memory(needed_bytes, *args, **kwargs)

    monkeypatch.setattr(batch_derivatives, "check_memory", recorded)
    uvms = reference_uvms
    q, v, tau = _states(uvms, 5)
    out = up.forward_dynamics_derivatives_batch(uvms, q, v, tau, tau_ext=0.1 * tau)
    copies = (q.nbytes, v.nbytes, tau.nbytes, tau.nbytes)  # tau_ext: tau's shape
    assert asked == [sum(j.nbytes for j in out) + sum(copies)]
