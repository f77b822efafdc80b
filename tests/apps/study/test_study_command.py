"""``uvms-pin sweep``'s own words (uvms_pin.apps.study.command): where the runs are run."""

from __future__ import annotations

import pytest

from uvms_pin.apps.study.command import _workers_text


@pytest.mark.parametrize(
    ("workers", "said"),
    [
        (0, "this process (serial)"),
        (None, "cpu-count local worker processes"),
        (1, "1 local worker process"),
        (3, "3 local worker processes"),
    ],
)
def test_the_workers_are_said_as_given(workers, said):
    assert _workers_text(workers) == said
