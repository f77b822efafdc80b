"""One arm's row of a comparison (uvms_pin.apps.arms.one_arm): what its status says when the
arm could not be run."""

from __future__ import annotations

import pytest

from uvms_pin.apps.arms import one_arm
from uvms_pin.apps.arms.settings import CompareSettings
from uvms_pin.errors import ModelError, ScenarioError


@pytest.mark.parametrize(
    ("raised", "status"),
    [
        (ScenarioError("arm_target_rad has 4 entries, the model's arm has 6 joints"),
         "scenario error"),
        (ModelError("the arm's URDF has no joint"), "model error"),
    ],
)  # fmt: skip
def test_a_refusal_is_the_status_of_what_refused(monkeypatch, tmp_path, raised, status):
    """A scenario whose task does not fit the arm is a scenario error, not a model error
    (the arm's model was fine); a model the arm cannot be built from stays a model error."""

    def refuse(row, job):
        raise raised

    monkeypatch.setattr(one_arm, "_fill_row", refuse)
    name = one_arm.REFERENCE
    row = one_arm.run_one_arm(name, "s.toml", str(tmp_path), "v.urdf", (0, 0, 0), None,
                              CompareSettings())  # fmt: skip
    assert row["status"] == status and str(raised) in row["reason"]
