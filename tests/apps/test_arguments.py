"""What the commands share: comma-separated name lists and the --set option."""

from __future__ import annotations

import argparse
import re

import pytest

from uvms_pin.apps import arguments
from uvms_pin.apps.arguments import add_set_option, comma_names, count, nonempty, positive
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


def test_a_count_takes_its_bounds_and_refuses_beyond_them_saying_why():
    parse = count(1, 8, "the grid's points")
    assert (parse("1"), parse("8")) == (1, 8)
    for text, message in (("0", "must be an integer >= 1, got 0"),
                          ("9", "must be an integer <= 8 (the grid's points), got 9"),
                          ("2.5", "must be an integer, got '2.5'")):  # fmt: skip
        with pytest.raises(argparse.ArgumentTypeError, match=re.escape(message)):
            parse(text)
    assert count(0)("123456") == 123456  # no maximum


def test_a_process_count_is_at_most_four_per_cpu(monkeypatch):
    monkeypatch.setattr(arguments.os, "cpu_count", lambda: 2)
    parse = arguments.process_count(1)
    assert parse("8") == 8
    with pytest.raises(argparse.ArgumentTypeError, match=r"<= 8 \(4 per CPU, 2 CPUs here\)"):
        parse("9")
    monkeypatch.setattr(arguments.os, "cpu_count", lambda: None)  # unknown: one CPU
    assert arguments.process_count(1)("4") == 4
    with pytest.raises(argparse.ArgumentTypeError, match="1 CPUs here"):
        arguments.process_count(1)("5")


@pytest.mark.parametrize("text", ["0", "-1", "nan", "inf", "x"])
def test_positive_refuses_zero_negative_and_not_finite(text):
    with pytest.raises(argparse.ArgumentTypeError):
        positive(text)
    assert positive("0.1") == 0.1
    with pytest.raises(argparse.ArgumentTypeError, match="must be a path, got '  '"):
        nonempty("a path")("  ")
