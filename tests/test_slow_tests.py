"""The list of slow tests (tests/slow_tests.py) names tests that exist: a renamed or moved
test would otherwise join `make check` unnoticed."""

from __future__ import annotations

import re

from conftest import ROOT
from slow_tests import LONG_FILES, SLOW_MODULES, SLOW_TESTS


def test_every_slow_module_and_test_exists():
    for path in SLOW_MODULES + LONG_FILES:
        assert (ROOT / path).exists(), path
    for name in SLOW_TESTS:
        path, _, function = name.partition("::")
        text = (ROOT / path).read_text()
        assert re.search(rf"^def {function}\(", text, re.MULTILINE), name
