"""Study files (TOML) -> a list of runs, each with its overrides, plant factors and seed.

A study names a base scenario and the parameters to vary. Grid parameters (``values``,
``linspace``, ``logspace``) form a Cartesian product; random parameters (``distribution``)
are drawn ``samples`` times; every grid point is run with every sample (so grid points
share their random draws: common random numbers, which makes grid comparisons sharper).

Reproducibility: from the master ``seed``, sample k draws parameter ``path`` from
``SeedSequence(seed, spawn_key=(k, crc32(path)))`` and gets its scenario seed (sensor
noise) from ``SeedSequence(seed, spawn_key=(k, SEED_KEY))``. A draw depends on nothing
else, so adding a parameter or more samples leaves the existing runs unchanged, and their
run ids (a hash of the parameter values and the seed) let a rerun skip them.

Parameter paths:

- ``plant.mass_scale``, ``plant.added_mass_scale``, ``plant.damping_scale``,
  ``plant.buoyancy_scale``: factors applied to the loaded model (see `modify_plant`);
- any dotted key of the scenario TOML (``environment.stiffness_N_m``, ``controller.k_x``,
  ...), optionally with element indices (``initial.joint_positions_rad[3]``,
  ``actuation.thruster[0].max_forward_N``), optionally ``apply = "scale"`` (times the base
  value) or ``"add"`` (plus the base value).

Study files are read by `uvms_pin.apps.study.reader.load_study`.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import math
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from uvms_pin.scenario.overrides import KeyPath, parse_key_path

SEED_KEY = 0x5EED  # spawn-key component of a sample's scenario seed
PLANT_PREFIX = "plant."
PLANT_FACTORS = ("mass_scale", "added_mass_scale", "damping_scale", "buoyancy_scale")
DISTRIBUTIONS = ("uniform", "normal", "log-uniform")
APPLY_MODES = ("set", "scale", "add")


@dataclass(frozen=True)
class Parameter:
    """One varied quantity: where it goes, how it is applied, and its grid or distribution.

    Attributes:
        path: dotted key, optionally indexed (``initial.joint_positions_rad[3]``).
        entry: how error messages name it (``parameter[2] 'path'``).
        apply: "set", "scale" (times the base value) or "add" (plus the base value).
        grid: the values of a grid parameter, or None for a random one.
        distribution, args: the random law ("uniform": low, high; "normal": mean, std,
            optional low/high clip; "log-uniform": low, high > 0).
    """

    path: str
    entry: str
    apply: str = "set"
    grid: tuple[Any, ...] | None = None
    distribution: str | None = None
    args: dict[str, float] = field(default_factory=dict)

    @property
    def is_plant(self) -> bool:
        return self.path.startswith(PLANT_PREFIX)

    @property
    def column(self) -> str:
        """The study table's column of this parameter (see `column_name`)."""
        return column_name(self.path, self.apply)

    @property
    def key(self) -> str:
        """The scenario key without the element index."""
        return parse_key_path(self.path).key

    @property
    def index(self) -> int | None:
        return parse_key_path(self.path).index

    def draw(self, master_seed: int, sample: int) -> float:
        """This parameter's value in sample ``sample`` (independent of every other draw)."""
        ss = np.random.SeedSequence(master_seed, spawn_key=(sample, zlib.crc32(self.path.encode())))
        rng = np.random.default_rng(ss)
        a = self.args
        if self.distribution == "uniform":
            return float(rng.uniform(a["low"], a["high"]))
        if self.distribution == "log-uniform":
            return float(math.exp(rng.uniform(math.log(a["low"]), math.log(a["high"]))))
        value = float(rng.normal(a["mean"], a["std"]))
        return float(np.clip(value, a.get("low", -math.inf), a.get("high", math.inf)))


def column_name(path: str, apply: str = "set") -> str:
    """What a table column of a varied parameter holds: the value set (``path``), a factor
    on the base value (``path [x base]``) or an increment to it (``path [+ base]``): the
    column of a scaled 0.15 N amplitude holds 2.0, not newtons."""
    return {"set": path, "scale": f"{path} [x base]", "add": f"{path} [+ base]"}[apply]


@dataclass(frozen=True)
class Run:
    """One simulation of a study.

    Attributes:
        run_id: hash of the parameter values and the seed (the resume key).
        index: position in the study's run list; sample: the random-sample index.
        seed: the scenario seed (sensor noise).
        values: parameter path -> value, as varied (what the table records).
        overrides: dotted scenario keys -> values, ready for `load_scenario`.
        plant: plant factor name -> value (``mass_scale``, ...), 1.0 when not varied.
        columns: parameter path -> its table column (`column_name`).
    """

    run_id: str
    index: int
    sample: int
    seed: int
    values: dict[str, Any]
    overrides: dict[str, Any]
    plant: dict[str, float]
    columns: dict[str, str] = field(default_factory=dict)


@dataclass
class Study:
    """A parsed study file.

    Attributes:
        name, description: from [study]. path: the study file. base: the base scenario.
        seed: the master seed. samples: number of random samples per grid point.
        fixed: dotted overrides applied to every run (the [fixed] table).
        parameters: the varied quantities. report: options of the [report] table.
        base_raw: the base scenario's TOML as a dict (read once, for scale/add and indices).
    """

    name: str
    description: str
    path: Path
    base: Path
    seed: int
    samples: int
    fixed: dict[str, Any]
    parameters: tuple[Parameter, ...]
    report: dict[str, Any]
    base_raw: dict[str, Any]

    @property
    def grid_parameters(self) -> tuple[Parameter, ...]:
        return tuple(p for p in self.parameters if p.grid is not None)

    @property
    def random_parameters(self) -> tuple[Parameter, ...]:
        return tuple(p for p in self.parameters if p.grid is None)

    def runs(self) -> list[Run]:
        """Every run: each grid point (outer, in file order) times each sample (inner)."""
        grids = [p.grid for p in self.grid_parameters]
        out: list[Run] = []
        for point in itertools.product(*grids):
            for sample in range(self.samples):
                values = dict(zip((p.path for p in self.grid_parameters), point, strict=True))
                for p in self.random_parameters:
                    values[p.path] = p.draw(self.seed, sample)
                values = {p.path: values[p.path] for p in self.parameters}  # file order
                seed = sample_seed(self.seed, sample)
                overrides, plant = self.resolve(values)
                overrides["scenario.seed"] = seed
                columns = {p.path: p.column for p in self.parameters}
                out.append(
                    Run(
                        run_id(values, seed),
                        len(out),
                        sample,
                        seed,
                        values,
                        overrides,
                        plant,
                        columns,
                    )
                )
        return out

    def resolve(self, values: dict[str, Any]) -> tuple[dict[str, Any], dict[str, float]]:
        """Parameter values -> (scenario overrides, plant factors)."""
        overrides = copy.deepcopy(self.fixed)
        plant = dict.fromkeys(PLANT_FACTORS, 1.0)
        for p in self.parameters:
            value = values[p.path]
            if p.is_plant:
                name = p.path[len(PLANT_PREFIX) :]
                plant[name] = _combine(plant[name], value, p.apply)
                continue
            key, index = p.key, p.index
            current = overrides[key] if key in overrides else lookup(self.base_raw, key, None)
            if index is None:
                overrides[key] = _combine(current, value, p.apply)
            else:
                items = list(current)
                items[index] = _combine(items[index], value, p.apply)
                overrides[key] = items
        return overrides, plant


def sample_seed(master_seed: int, sample: int) -> int:
    """The scenario seed of sample ``sample`` (a 32-bit integer)."""
    ss = np.random.SeedSequence(master_seed, spawn_key=(sample, SEED_KEY))
    return int(ss.generate_state(1, dtype=np.uint32)[0])


def run_id(values: dict[str, Any], seed: int) -> str:
    """16 hex digits of SHA-256 over the canonical JSON of the values and the seed."""
    text = json.dumps({"seed": seed, "values": values}, sort_keys=True, default=_jsonable)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _jsonable(obj: Any) -> Any:
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    raise TypeError(type(obj).__name__)


def _combine(base: Any, value: Any, mode: str) -> Any:
    if mode == "set":
        return value
    if isinstance(base, list):
        arr = np.asarray(base, dtype=float)
        out = arr * value if mode == "scale" else arr + value
        return [float(x) for x in out]
    return float(base * value if mode == "scale" else base + value)


_MISSING = object()


def lookup(raw: dict[str, Any], key: str, default: Any = _MISSING) -> Any:
    """The value of the dotted ``key`` in ``raw``, its parts indexed or not
    (``actuation.thruster[0].max_forward_N``); ``default``, else KeyError, if absent."""
    node: Any = raw
    for name, index in KeyPath(key, key, None).parts:
        if not isinstance(node, dict) or name not in node:
            return _absent(key, default)
        node = node[name]
        if index is not None:
            if not isinstance(node, list) or index >= len(node):
                return _absent(key, default)
            node = node[index]
    return node


def _absent(key: str, default: Any) -> Any:
    if default is _MISSING:
        raise KeyError(key)
    return default
