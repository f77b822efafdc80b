"""The study reader given generated study files (the shipped studies and docs/studies.md's,
edited as `fuzz_documents` edits scenarios): a `Study` or a documented error naming the file."""

from __future__ import annotations

import tomllib
import warnings

from fuzz_bounds import copied_tree, examples, outcome
from fuzz_documents import ROOT, edited, toml_text
from hypothesis import given, settings

from uvms_pin.apps.study import load_study
from uvms_pin.errors import UvmsPinWarning

STUDIES = {p.name: tomllib.loads(p.read_text()) for p in sorted((ROOT / "studies").glob("*.toml"))}


@settings(max_examples=examples(300))
@given(edited(STUDIES))
def test_a_study_file_loads_or_is_refused_naming_the_file(named_doc):
    name, doc = named_doc
    path = copied_tree() / "studies" / "fuzzed.toml"
    path.write_text(toml_text(doc), encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UvmsPinWarning)
        study = outcome(lambda: load_study(path), f"{name} edited", named=("fuzzed.toml",))
    assert study is None or len(study.runs()) >= 1
