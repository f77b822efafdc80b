"""What the commands share: comma-separated name lists and the --set option."""

from __future__ import annotations

import argparse

import pytest

from uvms_pin.apps.arguments import add_set_option, comma_names
from uvms_pin.errors import ParameterError


def test_comma_names_strips_and_refuses_empty_or_repeated_names():
    assert comma_names("--arms", " reference, ur5 ") == ["reference", "ur5"]
    with pytest.raises(ParameterError, match=r"--arms 'a,,b': give comma-separated arm names"):
        comma_names("--arms", "a,,b", "arm names")
    with pytest.raises(ParameterError, match="give comma-separated names, none empty"):
        comma_names("--controllers", " ")
    with pytest.raises(ParameterError, match=r"'b,a,b,a': a, b given twice"):
        comma_names("--controllers", "b,a,b,a")


def test_set_option_collects_assignments():
    parser = argparse.ArgumentParser()
    add_set_option(parser, "override")
    assert parser.parse_args([]).set == []
    assert parser.parse_args(["--set", "a=1", "--set", "b.c=[2]"]).set == ["a=1", "b.c=[2]"]
