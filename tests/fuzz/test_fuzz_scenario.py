"""The scenario reader given generated documents (`fuzz_documents`): a `Scenario` whose start
is finite, or a documented error naming the file; as nested dicts (`scenario_from_dict`) and
as TOML files (`load_scenario`, in a copy of the scenarios' folder so that relative paths and
the scenarios' own modules resolve)."""

from __future__ import annotations

import warnings

import numpy as np
from fuzz_bounds import copied_tree, examples, outcome
from fuzz_documents import ROOT, SCENARIOS, edited, toml_text
from hypothesis import given, settings
from hypothesis import strategies as st

from uvms_pin.errors import UvmsPinWarning
from uvms_pin.scenario.load import load_scenario, scenario_from_dict

AS_IF = ROOT / "scenarios" / "fuzzed.toml"


def _check_scenario(scenario) -> None:
    for robot in getattr(scenario, "robots", () if scenario is None else (scenario,)):
        assert np.all(np.isfinite(robot.q0)) and np.all(np.isfinite(robot.v0))


@settings(max_examples=examples(700))
@given(edited(SCENARIOS))
def test_a_scenario_dict_builds_or_is_refused_naming_the_file(named_doc):
    name, doc = named_doc
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UvmsPinWarning)
        scenario = outcome(
            lambda: scenario_from_dict(doc, AS_IF), f"{name} edited", named=("fuzzed.toml",)
        )
    _check_scenario(scenario)


@settings(max_examples=examples(300))
@given(edited(SCENARIOS), st.integers(0, 2))
def test_a_scenario_file_loads_or_is_refused_naming_the_file(named_doc, cut):
    """The document as TOML; ``cut``: 0 whole, 1 its last line cut in half, 2 a line twice."""
    name, doc = named_doc
    text = toml_text(doc)
    if cut == 1:
        text = text[: max(0, len(text) - len(text.splitlines()[-1] if text else "") // 2 - 1)]
    elif cut == 2 and text:
        text += text.splitlines()[0] + "\n"
    path = copied_tree() / "scenarios" / "fuzzed.toml"
    path.write_text(text, encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UvmsPinWarning)
        scenario = outcome(lambda: load_scenario(path), f"{name} as TOML", named=("fuzzed.toml",))
    _check_scenario(scenario)
