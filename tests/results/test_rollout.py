"""Rollout: preallocation, extra signals, truncation, atomic save and exact round trip."""

from __future__ import annotations

import json
import math
import os

import numpy as np
import pytest

import uvms_pin as up
from uvms_pin.errors import OutputError
from uvms_pin.results import rollout as rollout_module
from uvms_pin.results.atomic import write_json_atomic
from uvms_pin.results.rollout import ARRAY_FILE, META_FILE, Rollout

N, NQ, NV = 7, 11, 10


def _filled(seed: int = 0) -> Rollout:
    rng = np.random.default_rng(seed)
    metadata = {
        "seed": 3,
        "status": "ok",
        "gains": np.array([0.2, 5.0, 1.0 / 3.0]),  # numpy array in the metadata
        "matrix": np.arange(6.0).reshape(2, 3),
        "count": np.int64(12),
        "ratio": np.float64(1.0 / 7.0),
        "flag": np.bool_(True),
        "nested": {"k_f": [2.0, 2.0, 2.0], "name": "spring", "none": None},
        "not_a_number": float("nan"),
    }
    r = Rollout.allocate(N, NQ, NV, metadata)
    for name in Rollout._BASE:
        array = getattr(r, name)
        array[...] = rng.normal(size=array.shape)
    r.signal("funnel", 3)[...] = rng.normal(size=(N, 3))
    r.signal("xi", 1)[...] = rng.uniform(-1, 1, size=(N, 1))
    return r


def test_allocate_shapes_and_nan():
    r = Rollout.allocate(N, NQ, NV, {"a": 1})
    assert len(r) == N
    shapes = {
        "time_s": (N,),
        "q": (N, NQ),
        "v": (N, NV),
        "tau": (N, NV),
        "wrench_contact_world": (N, 6),
        "wrench_measured_world": (N, 6),
        "wrench_disturbance_body": (N, 6),
        "kinetic_energy_J": (N,),
        "potential_energy_J": (N,),
    }
    for name, shape in shapes.items():
        array = getattr(r, name)
        assert array.shape == shape, name
        assert np.all(np.isnan(array)), name  # NaN until written
    assert r.signals == {}
    assert r.metadata == {"a": 1}


def test_allocate_copies_metadata():
    meta = {"a": 1}
    r = Rollout.allocate(2, NQ, NV, meta)
    r.metadata["b"] = 2
    assert meta == {"a": 1}
    assert Rollout.allocate(2, NQ, NV).metadata == {}


def test_signal_allocates_once_and_returns_the_same_array():
    r = Rollout.allocate(N, NQ, NV)
    s = r.signal("e_x", 6)
    assert s.shape == (N, 6) and np.all(np.isnan(s))
    s[2] = 1.0
    again = r.signal("e_x", 6)
    assert again is s
    np.testing.assert_array_equal(r.signals["e_x"][2], np.ones(6))


def test_truncate_keeps_the_first_rows_of_everything():
    r = _filled()
    full = {name: getattr(r, name).copy() for name in Rollout._BASE}
    funnel = r.signals["funnel"].copy()
    r.truncate(3)
    assert len(r) == 3
    for name in Rollout._BASE:
        np.testing.assert_array_equal(getattr(r, name), full[name][:3])
    np.testing.assert_array_equal(r.signals["funnel"], funnel[:3])
    assert r.signals["xi"].shape == (3, 1)
    # a signal allocated after truncation has the new length
    assert r.signal("late", 2).shape == (3, 2)
    np.testing.assert_array_equal(r.total_energy_J, r.kinetic_energy_J + r.potential_energy_J)


def _assert_same(loaded: Rollout, original: Rollout) -> None:
    for name in Rollout._BASE:
        a, b = getattr(loaded, name), getattr(original, name)
        assert a.dtype == b.dtype and a.shape == b.shape, name
        np.testing.assert_array_equal(a, b)  # exact, bit for bit (NaN == NaN here)
    assert sorted(loaded.signals) == sorted(original.signals)
    for name, array in original.signals.items():
        np.testing.assert_array_equal(loaded.signals[name], array)


def test_save_load_round_trips_exactly(tmp_path):
    """Every array bit for bit; metadata values exactly, numpy arrays and scalars included
    (JSON holds them as lists and Python numbers; float64 repr round-trips exactly)."""
    original = _filled()
    original.wrench_contact_world[0, 0] = np.nan  # a NaN survives too
    out = original.save(tmp_path / "run")
    assert out == tmp_path / "run"
    loaded = Rollout.load(out)
    _assert_same(loaded, original)
    meta = loaded.metadata
    assert set(meta) == set(original.metadata)
    np.testing.assert_array_equal(np.array(meta["gains"]), original.metadata["gains"])
    assert meta["gains"][2] == 1.0 / 3.0  # exact, not rounded
    np.testing.assert_array_equal(np.array(meta["matrix"]), original.metadata["matrix"])
    assert meta["count"] == 12 and isinstance(meta["count"], int)
    assert meta["ratio"] == 1.0 / 7.0
    assert meta["flag"] is True
    assert meta["nested"] == original.metadata["nested"]
    assert np.isnan(meta["not_a_number"])
    # and a second save/load of the loaded rollout is identical (a fixed point)
    again = Rollout.load(loaded.save(tmp_path / "again"))
    _assert_same(again, original)
    assert json.dumps(again.metadata, sort_keys=True) == json.dumps(meta, sort_keys=True)


def test_truncated_and_empty_rollouts_round_trip(tmp_path):
    r = _filled()
    r.truncate(0)
    _assert_same(Rollout.load(r.save(tmp_path / "empty")), r)


def _listing(directory) -> list[str]:
    return sorted(os.listdir(directory))


def test_save_writes_no_stray_files(tmp_path):
    _filled().save(tmp_path)
    assert _listing(tmp_path) == sorted([ARRAY_FILE, META_FILE])
    _filled(1).save(tmp_path)  # overwriting leaves nothing behind either
    assert _listing(tmp_path) == sorted([ARRAY_FILE, META_FILE])
    _assert_same(Rollout.load(tmp_path), _filled(1))


class _Boom(RuntimeError):
    pass


def test_failing_writer_leaves_no_partial_file(tmp_path, monkeypatch):
    """np.savez_compressed writes some bytes and then fails: neither a rollout.npz nor a
    temporary file may remain, and the error propagates."""

    def broken_savez(file, **arrays):
        file.write(b"PK\x03\x04 half a zip archive")
        file.flush()
        raise _Boom("disk full")

    monkeypatch.setattr(rollout_module.np, "savez_compressed", broken_savez)
    with pytest.raises(_Boom):
        _filled().save(tmp_path / "run")
    assert _listing(tmp_path / "run") == []


def test_failing_writer_keeps_the_previous_rollout(tmp_path, monkeypatch):
    """A failed overwrite leaves the earlier complete rollout.npz untouched."""
    first = _filled(0)
    first.save(tmp_path)
    before = (tmp_path / ARRAY_FILE).read_bytes()

    def broken_savez(file, **arrays):
        file.write(b"garbage")
        raise _Boom("interrupted")

    monkeypatch.setattr(rollout_module.np, "savez_compressed", broken_savez)
    with pytest.raises(_Boom):
        _filled(1).save(tmp_path)
    assert (tmp_path / ARRAY_FILE).read_bytes() == before
    assert _listing(tmp_path) == sorted([ARRAY_FILE, META_FILE])


def test_unserialisable_metadata_writes_nothing(tmp_path):
    """Metadata that JSON cannot hold fails before any file is written: no lone .npz in a
    fresh directory, and an earlier rollout in the same directory stays a consistent pair."""
    r = _filled()
    r.metadata["bad"] = object()
    with pytest.raises(TypeError, match="not JSON serialisable"):
        r.save(tmp_path / "fresh")
    assert _listing(tmp_path / "fresh") == []

    _filled(0).save(tmp_path / "old")
    with pytest.raises(TypeError, match="not JSON serialisable"):
        r.save(tmp_path / "old")
    assert _listing(tmp_path / "old") == sorted([ARRAY_FILE, META_FILE])
    _assert_same(Rollout.load(tmp_path / "old"), _filled(0))


def test_write_json_atomic(tmp_path):
    path = tmp_path / "metrics.json"
    write_json_atomic(path, {"rmse": np.float64(0.5), "values": np.arange(3)})
    assert json.loads(path.read_text()) == {"rmse": 0.5, "values": [0, 1, 2]}
    assert _listing(tmp_path) == ["metrics.json"]


def _strict_json(text: str):
    """``text`` parsed as standard JSON: NaN, Infinity and -Infinity refused."""

    def refuse(token):
        raise ValueError(f"not standard JSON: {token}")

    return json.loads(text, parse_constant=refuse)


def test_json_files_are_standard_json_with_null_for_non_finite_numbers(tmp_path):
    """metrics.json and the other summaries are read by jq, JavaScript...: a metric not
    defined for a run (NaN: no funnel to end a transient) or an infinite one is null,
    at any depth, numpy's included."""
    path = tmp_path / "metrics.json"
    payload = {
        "transient_end_s": math.nan,
        "peak": np.float64(np.inf),
        "nested": {"low": -math.inf, "values": np.array([1.0, np.nan]), "n": np.int64(3)},
        "list": [np.float32(np.nan), 2.5],
    }
    write_json_atomic(path, payload)
    assert _strict_json(path.read_text()) == {
        "transient_end_s": None,
        "peak": None,
        "nested": {"low": None, "values": [1.0, None], "n": 3},
        "list": [None, 2.5],
    }


def test_rollout_metadata_keeps_non_finite_numbers_exactly(tmp_path):
    """rollout.json is read back by Rollout.load: a NaN or infinite value in the metadata
    comes back as itself (not None)."""
    r = _filled()
    r.metadata.update(limit=-math.inf, unknown=math.nan)
    r.save(tmp_path / "r")
    back = Rollout.load(tmp_path / "r").metadata
    assert back["limit"] == -math.inf and math.isnan(back["unknown"])


def test_load_without_rollout_raises_parameter_error(tmp_path):
    with pytest.raises(up.ParameterError, match="holds no rollout"):
        Rollout.load(tmp_path)
    with pytest.raises(up.ParameterError, match="holds no rollout"):
        Rollout.load(tmp_path / "does_not_exist")
    # half a rollout (arrays without metadata) is not a rollout either
    _filled().save(tmp_path / "half")
    (tmp_path / "half" / META_FILE).unlink()
    with pytest.raises(up.ParameterError, match="holds no rollout"):
        Rollout.load(tmp_path / "half")


def test_a_path_that_is_none_or_a_file_is_refused_by_name(tmp_path):
    """save, load and to_mcap given None (a TypeError of pathlib's before), save given a
    file (FileExistsError) or a folder it cannot write in: uvms-pin's errors naming it, and
    nothing written."""
    r = _filled()
    for call in (r.save, Rollout.load, r.to_mcap):
        with pytest.raises(up.ParameterError, match="must be a path, got None"):
            call(None)
    (tmp_path / "afile").write_text("x")
    with pytest.raises(OutputError, match="afile: is a file; give a directory"):
        r.save(tmp_path / "afile")
    with pytest.raises(OutputError, match="is under a file"):
        r.save(tmp_path / "afile" / "run")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile"]


@pytest.mark.parametrize("text", ["[1, 2]", "3", '"a rollout"', "{", "null"])
def test_a_rollout_json_that_is_not_an_object_is_named(tmp_path, text):
    """rollout.json edited into a list, a number, a string, broken or null: ParameterError
    naming the file (or the damaged rollout), not a TypeError."""
    _filled().save(tmp_path / "r")
    (tmp_path / "r" / META_FILE).write_text(text)
    with pytest.raises(up.ParameterError, match=r"(rollout\.json: a JSON object expected|damaged)"):
        Rollout.load(tmp_path / "r")
