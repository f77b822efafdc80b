"""The public dynamics functions (`uvms_pin.physics.dynamics`) given generated arguments:
arrays of every size and value (NaN, infinities, magnitudes up to 1e300), other types, any
backend name, with and without a free surface: a finite result of the right shape, or a
documented error."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import REFERENCE_URDF
from fuzz_bounds import examples, outcome
from hypothesis import given, settings
from hypothesis import strategies as st

from uvms_pin.model.urdf.loaded import loaded_uvms
from uvms_pin.physics import dynamics

UVMS = loaded_uvms(REFERENCE_URDF, water_density_kg_m3=1025.0)
NQ, NV = UVMS.nq, UVMS.nv

entries = st.one_of(
    st.floats(-10.0, 10.0),
    st.sampled_from([0.0, -0.0, 1e-300, 1e6, -1e6, 1e300, math.nan, math.inf, -math.inf]),
)


def arrays(size: int):
    """Mostly the right size with physical values; sometimes another size, a huge or
    non-finite entry, a matrix, text or None."""
    right = st.lists(st.floats(-2.0, 2.0), min_size=size, max_size=size)
    return st.one_of(
        right.map(np.array),
        right.map(np.array),
        st.lists(entries, min_size=size, max_size=size).map(np.array),
        st.integers(0, size + 2).flatmap(lambda n: st.lists(entries, min_size=n, max_size=n)),
        st.sampled_from([None, "q", 3.0, np.zeros((size, 1)), np.zeros(size, dtype=complex)]),
    )


def _quaternion_normalised(q):
    if isinstance(q, np.ndarray) and q.shape == (NQ,) and np.all(np.isfinite(q)):
        q = q.copy()
        q[3:7] = q[3:7] / (np.linalg.norm(q[3:7]) or 1.0)
    return q


CALLS = {
    "mass_matrix": lambda a: dynamics.mass_matrix(UVMS, a["q"], **a["options"]),
    "bias_forces": lambda a: dynamics.bias_forces(
        UVMS, a["q"], a["v"], a["current"], **a["options"]
    ),
    "forward_dynamics": lambda a: dynamics.forward_dynamics(
        UVMS, a["q"], a["v"], a["tau"], a["current"], a["tau_ext"], **a["options"]
    ),
    "forward_dynamics_derivatives": lambda a: dynamics.forward_dynamics_derivatives(
        UVMS, a["q"], a["v"], a["tau"], current_world=a["current"], **a["options"]
    ),
    "kinetic_energy": lambda a: dynamics.kinetic_energy(UVMS, a["q"], a["v"], **a["options"]),
    "potential_energy": lambda a: dynamics.potential_energy(
        UVMS, a["q"], **{k: v for k, v in a["options"].items() if k != "backend"}
    ),
    "frame_wrench_to_generalized": lambda a: dynamics.frame_wrench_to_generalized(
        UVMS, a["q"], a["frame"], a["wrench"]
    ),
}

arguments = st.fixed_dictionaries(
    {
        "q": arrays(NQ).map(_quaternion_normalised),
        "v": arrays(NV),
        "tau": arrays(NV),
        "tau_ext": st.none() | arrays(NV),
        "current": arrays(3),
        "wrench": arrays(6),
        "frame": st.sampled_from([0, 1, len(UVMS.model.frames) - 1, len(UVMS.model.frames), -1]),
        "options": st.fixed_dictionaries(
            {},
            optional={
                "backend": st.sampled_from(["core", "python", "gpu", None]),
                "free_surface": st.sampled_from([True, False, 1, "yes"]),
                "time_s": st.sampled_from([0.0, 1.5, -1.0, math.nan, math.inf, "0"]),
            },
        ),
    }
)


#: an input entry beyond this may overflow a square (an energy, a norm) to infinity
OVERFLOWING = 1e150


def _huge(args) -> bool:
    arrays = [a for a in args.values() if isinstance(a, np.ndarray | list)]
    return any(np.any(np.abs(np.asarray(a, dtype=complex)) > OVERFLOWING) for a in arrays)


def _checked(name: str, result, args) -> None:
    """No NaN, ever; an infinity only from an input beyond `OVERFLOWING`."""
    for part in result if isinstance(result, tuple) else (result,):
        values = np.asarray(part, dtype=float)
        assert not np.any(np.isnan(values)), f"{name}: NaN in the result"
        assert _huge(args) or np.all(np.isfinite(values)), f"{name}: an infinite result"


@pytest.mark.parametrize("name", sorted(CALLS))
@settings(max_examples=examples(60))
@given(arguments)
def test_a_dynamics_function_returns_finite_numbers_or_refuses(name, args):
    result = outcome(lambda: CALLS[name](args), name)
    if result is not None:
        _checked(name, result, args)
