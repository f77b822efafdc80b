"""Numbers as text: exact round trip for files, significant digits for messages and tables."""

from __future__ import annotations

import math

import numpy as np

from uvms_pin.results.format import cell_text, numbers_text


def test_exact_text_reads_back_as_the_same_floats():
    values = np.array([0.1, 1 / 3, -2.5e-17, 123456789.123456789, 0.0])
    text = numbers_text(values)
    assert np.array_equal(np.array([float(x) for x in text.split()]), values)
    assert numbers_text([1.0, 2.0], sep=", ") == "1.0, 2.0"


def test_significant_digits_and_cells():
    assert numbers_text([math.pi, 2.0], digits=3) == "3.14 2"
    assert numbers_text(np.float64(1.5)) == "1.5"
    assert cell_text(math.pi) == "3.142"
    assert cell_text(np.float32(2.0), digits=3) == "2"
    assert cell_text(math.nan) == "" and cell_text(math.nan, nan_text="nan") == "nan"
    assert cell_text("ok") == "ok" and cell_text(3) == "3"
