"""Hypothesis' profiles for the generated-input tests (`fuzz_bounds`), loaded before the
tests of this folder are collected: ``HYPOTHESIS_PROFILE=ci`` (the default, in ``make
test``) or ``campaign`` (``make fuzz``); and a copy of the shipped files to write inputs into."""

from __future__ import annotations

import shutil

import fuzz_bounds  # noqa: F401 (registers and loads the profile)
import pytest
from fuzz_documents import ROOT


@pytest.fixture(scope="module")
def copied_tree(tmp_path_factory):
    """A copy of scenarios/, studies/ and models/: a generated file written into it finds the
    files and modules the shipped one next to it names."""
    root = tmp_path_factory.mktemp("tree")
    for folder in ("scenarios", "studies", "models"):
        shutil.copytree(ROOT / folder, root / folder)
    return root
