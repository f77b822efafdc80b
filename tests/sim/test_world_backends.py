"""A world's runs stepped by the compiled core as by the Python reference: the landing on a
slope (the vehicle's contacts with fixed objects, friction, from 1.42 s: 13 samples) and a free box on
the seabed (its contacts from the start), the same states to rounding."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


@pytest.mark.parametrize(
    "stem, duration_s, signal",
    [
        # 2.2 s of the reference's contact search: 6 s of a core (`make test` runs it)
        pytest.param("seabed_landing", 2.2, "world_contact", marks=pytest.mark.slow),
        ("push_object", 0.6, "free_object_contact"),
    ],
)
def test_a_world_is_stepped_by_the_core_as_by_the_reference(stem, duration_s, signal):
    runs = {
        backend: simulate(
            load_scenario(
                SCENARIOS / f"{stem}.toml",
                {"scenario.duration_s": duration_s, "integrator.backend": backend},
            ),
            progress=False,
        )
        for backend in ("core", "python")
    }
    core, python = runs["core"], runs["python"]
    assert core.metadata["status"] == python.metadata["status"] == "ok"
    touching = np.abs(np.asarray(core.signals[signal]).reshape(len(core), -1)).sum(axis=1) > 0
    assert np.count_nonzero(touching) >= 10  # the contacts are in the compared span
    for name in ("q", "v"):
        a, b = getattr(core, name), getattr(python, name)
        scale = np.max(np.abs(b), axis=0) + 1.0
        assert np.max(np.abs(a - b) / scale) < 1e-9, name
    # the forces of a contact solve agree to its tolerance (3.6e-7 of the box's landing),
    # not to rounding
    forces = np.asarray(python.signals[signal])
    np.testing.assert_allclose(
        core.signals[signal], forces, rtol=0, atol=1e-5 * np.max(np.abs(forces)), err_msg=signal
    )
