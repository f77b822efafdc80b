"""The Gymnasium constructors (``gym.make`` and ``gym.make_vec`` of the registered
environments) given generated arguments: an environment whose first observation is finite,
or a documented error; sizes (``num_envs``, ``num_threads``) up to 10^18 are refused from
the memory they would take, before it is taken."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from fuzz_bounds import examples, outcome
from hypothesis import given, settings
from hypothesis import strategies as st

gym = pytest.importorskip("gymnasium")
import uvms_pin.apps.gym  # noqa: E402,F401 (registers the environments)
from uvms_pin.errors import UvmsPinWarning  # noqa: E402

numbers = st.sampled_from([0.0, -1.0, 0.01, 1.0, 1e9, math.nan, math.inf, "1", None, True])
single = st.fixed_dictionaries(
    {
        "id": st.sampled_from(
            ["uvms_pin/StationKeeping-v0", "uvms_pin/ForceTracking-v0", "uvms_pin/PoseTracking-v0"]
        )
    },
    optional={
        "action_scale": st.sampled_from([0.5, -1.0, 0.0, math.nan, [1.0] * 3, "x"]),
        "clip_actions": st.sampled_from([True, False, "no", 0]),
        "initial_position_noise_m": numbers,
        "initial_joint_noise_rad": numbers,
        "effort_weight": numbers,
        "failure_penalty": numbers,
        # (not "human" nor a non-text: gymnasium's make handles those before our constructor)
        "render_mode": st.sampled_from([None, "rgb_array", "ansi"]),
        "overrides": st.sampled_from(
            [
                {},
                {"scenario.duration_s": -1},
                {"control.period_s": 0.0},
                {"nope": 1},
                {"scenario.duration_s": 1e12},
                {"initial.position_world_m": [math.nan, 0, 0]},
            ]
        ),
        "scenario": st.sampled_from(["missing.toml", "scenarios/passive_current.toml", 3]),
    },
)
sizes = st.one_of(st.integers(1, 3), st.sampled_from([0, -1, 10**6, 10**9, 10**18, 2.0, "2", None]))
vector = st.fixed_dictionaries(
    {
        "id": st.sampled_from(["uvms_pin/StationKeeping-v0", "uvms_pin/ForceTracking-v0"]),
        "num_envs": sizes,
        "num_threads": sizes,
    },
    optional={"autoreset_mode": st.sampled_from(["next_step", "same_step", "later", 1])},
)


@settings(max_examples=examples(60))
@given(single)
def test_make_builds_or_refuses(kwargs):
    kwargs = dict(kwargs)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UvmsPinWarning)
        env = outcome(lambda: gym.make(kwargs.pop("id"), **kwargs), f"make {kwargs}")
        if env is not None:
            observation, _ = env.reset(seed=0)
            assert np.all(np.isfinite(observation))
            env.close()


@settings(max_examples=examples(60))
@given(vector)
def test_make_vec_builds_or_refuses_sizes_from_their_memory(kwargs):
    kwargs = dict(kwargs)
    env = outcome(
        lambda: gym.make_vec(kwargs.pop("id"), vectorization_mode="vector_entry_point", **kwargs),
        f"make_vec {kwargs}",
    )
    if env is not None:
        observation, _ = env.reset(seed=0)
        assert np.all(np.isfinite(observation))
        env.close()
