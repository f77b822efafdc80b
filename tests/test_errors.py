"""The project's own exceptions (uvms_pin.errors): what their messages say, from their
attributes, so that a caller can report either."""

from __future__ import annotations

import pytest

from uvms_pin.errors import FunnelViolation, ModelError


def test_a_funnel_violation_says_where_when_and_by_how_much():
    """|xi| = |e| / rho: an error of -0.6 against a bound of 0.5 is 1.2 funnels out."""
    exc = FunnelViolation(level="first", component="f_x", time_s=3.25, error=-0.6, bound=0.5)
    message = str(exc)
    assert message.startswith("funnel violated at t = 3.250000 s: first error 'f_x' = -0.6")
    assert "reached its bound rho = 0.5 (|xi| = 1.200000 >= 1)" in message
    assert (exc.level, exc.component, exc.time_s, exc.error, exc.bound) == (
        "first", "f_x", 3.25, -0.6, 0.5,
    )  # fmt: skip


@pytest.mark.parametrize(
    ("path", "link", "expected"),
    [
        ("m.urdf", "arm", "m.urdf: link 'arm': has no inertia"),
        ("m.urdf", None, "m.urdf: has no inertia"),
        (None, "arm", "link 'arm': has no inertia"),
        (None, None, "has no inertia"),
    ],
)
def test_a_model_error_names_the_file_then_the_link(path, link, expected):
    exc = ModelError("has no inertia", path=path, link=link)
    assert str(exc) == expected and (exc.path, exc.link) == (path, link)
