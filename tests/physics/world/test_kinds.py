"""The registry of world-object kinds (`uvms_pin.physics.world.kind`): one entry per kind,
the one check naming the key it refuses, and everything the rest of the package asks of a
kind (the scenario reader's keys, the views' drawing, the compiled core's shape) given by
the kind itself."""

from __future__ import annotations

import coal
import numpy as np
import pytest
import uvms_pin._core as core

from uvms_pin.errors import ParameterError
from uvms_pin.physics.compiled.world import _geometry
from uvms_pin.physics.world.kind import KINDS, register
from uvms_pin.physics.world.objects import kind_names, object_kind, plane, solid
from uvms_pin.scenario.objects import KEY_READERS


def test_every_kind_is_registered_once():
    assert {"plane", "box", "sphere", "cylinder", "mesh"} <= set(kind_names())
    with pytest.raises(ParameterError, match="registered already"):
        register(KINDS["box"])
    with pytest.raises(ParameterError, match="unknown world-object type 'cone'"):
        object_kind("cone")


def test_the_scenario_reader_reads_every_key_a_kind_declares():
    for kind in KINDS.values():
        assert kind.keys, kind.name
        for key in kind.keys:
            assert key.holds in KEY_READERS, (kind.name, key.name)


def test_the_one_check_names_the_key_it_refuses():
    with pytest.raises(ParameterError, match="size_m must be > 0") as refused:
        solid("crate", "box", {"size_m": [1, -1, 1]}, [0, 0, 0], [0, 0, 0], 0.6, 0.5)
    assert refused.value.key == "size_m"
    for given in ("0.4", None, [0.4]):  # was: float()'s ValueError or TypeError
        with pytest.raises(ParameterError, match="radius_m must be a number") as refused:
            solid("ball", "sphere", {"radius_m": given}, [0, 0, 0], [0, 0, 0], 0.6, 0.5)
        assert refused.value.key == "radius_m"
    with pytest.raises(ParameterError, match="normal_world must be non-zero") as refused:
        plane("floor", [0, 0, 0], [0, 0, 0], 0.6, 0.5)
    assert refused.value.key == "normal_world"
    with pytest.raises(ParameterError, match="friction_static >= friction_kinetic"):
        solid("crate", "box", {"size_m": [1, 1, 1]}, [0, 0, 0], [0, 0, 0], 0.4, 0.5)


def test_what_a_kind_gives_the_views_and_the_core_is_its_own():
    crate = solid("crate", "box", {"size_m": [1, 2, 3]}, [0, 0, -1], [0, 0, 0.3], 0.6, 0.5)
    drawing = object_kind("box").drawing(crate.record())
    assert drawing.geometry == "Box" and list(drawing.args[0]) == [1.0, 2.0, 3.0]
    kind, sizes, points = _geometry(crate.shape, core)
    assert kind == core.ContactKind.box and sizes.tolist() == [1.0, 2.0, 3.0]
    assert points.shape == (3, 0)
    floor = plane("floor", [0, 0, -10], [0, 0, 2], 0.6, 0.5)
    assert floor.is_plane and isinstance(floor.shape, coal.Halfspace)
    assert floor.record()["normal_world"] == [0.0, 0.0, 1.0]  # normalised by the check
    assert object_kind("plane").drawing(floor.record()).unbounded
    assert object_kind("plane").free is None  # a plane cannot be free
    assert np.isinf(floor.bound_radius_m)
    # meshcat's cylinder lies along its y: drawn turned onto the object's z, length first
    pipe = solid("pipe", "cylinder", {"radius_m": 0.2, "length_m": 3.0}, [0, 0, 0], [0, 0, 0],
                 0.6, 0.5)  # fmt: skip
    drawn = object_kind("cylinder").drawing(pipe.record())
    assert drawn.geometry == "Cylinder" and list(drawn.args) == [3.0, 0.2]
    turn = np.asarray(drawn.rotation_in_object)
    np.testing.assert_allclose(turn @ [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], atol=1e-15)
    np.testing.assert_allclose(turn.T @ turn, np.eye(3), atol=1e-15)
    assert np.linalg.det(turn) == pytest.approx(1.0)
