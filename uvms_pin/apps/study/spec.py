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
  ...), optionally with an element index (``initial.joint_positions_rad[3]``), optionally
  ``apply = "scale"`` (times the base value) or ``"add"`` (plus the base value).

Every mistake is found before any run starts and raised as `StudyError` naming the file
and the entry (``parameter[2] 'environment.stiffness_N_m'``).
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

from uvms_pin.errors import ScenarioError, StudyError
from uvms_pin.scenario.overrides import KEY_PATH, parse_key_path
from uvms_pin.scenario.schema import Table, is_number
from uvms_pin.scenario.toml import read_toml

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
            current = overrides[key] if key in overrides else _lookup(self.base_raw, key, None)
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


def _lookup(raw: dict[str, Any], key: str, default: Any = _MISSING) -> Any:
    node: Any = raw
    for part in key.split("."):
        if not isinstance(node, dict) or part not in node:
            if default is _MISSING:
                raise KeyError(key)
            return default
        node = node[part]
    return node


# ---- parsing ------------------------------------------------------------------------------


def load_study(path: str | Path) -> Study:
    """Read and check a study file; every run's scenario is known to load afterwards.

    Raises:
        StudyError: naming the file and the entry (missing base, unknown parameter path,
            empty range, unknown distribution, a value the scenario rejects, ...).
    """
    path = Path(path)
    source = str(path)
    raw = read_toml(path, StudyError)
    unknown = set(raw) - {"study", "fixed", "parameter", "report"}
    if unknown:
        raise StudyError(f"{source}: unknown table(s): {', '.join(sorted(unknown))}")
    top = Table(raw, "", source, error=StudyError)
    head = top.table_or_empty("study")
    name = head.string("name", path.stem)
    description = head.string("description", "")
    base_entry = head.string("base")
    seed = head.integer("seed", minimum=0)
    samples = head.integer("samples", 1, minimum=1)
    head.finish()
    base = (path.parent / base_entry).resolve()
    if not base.is_file():
        raise head.error("base", f"scenario '{base_entry}' not found ({base})")
    base_raw = read_toml(base, StudyError, f"{source}: study.base: '{base_entry}'")
    fixed = _fixed(raw.get("fixed", {}), source)
    entries = top.tables("parameter")
    if not entries:
        raise StudyError(f"{source}: needs at least one [[parameter]]")
    parameters = tuple(_parameter(entry, k, base_raw, fixed) for k, entry in enumerate(entries))
    seen = set()
    for p in parameters:
        if p.path in seen:
            raise StudyError(f"{source}: {p.entry}: the path is given twice")
        seen.add(p.path)
    report = raw.get("report", {})
    if not isinstance(report, dict):
        raise StudyError(f"{source}: [report] must be a table")
    _check_report(report, source, {p.path for p in parameters})
    study = Study(name, description, path, base, seed, samples, fixed, parameters, report, base_raw)
    _check_against_base(study, source)
    return study


def _fixed(table: Any, source: str) -> dict[str, Any]:
    """[fixed]: dotted scenario keys applied to every run (no plant factor)."""
    if not isinstance(table, dict):
        raise StudyError(f"{source}: [fixed] must be a table of dotted keys")
    fixed = _flatten(table)
    for key in fixed:
        if key.startswith(PLANT_PREFIX):
            raise StudyError(f"{source}: fixed.{key}: plant factors go in a [[parameter]]")
    return fixed


def _flatten(table: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in table.items():
        dotted = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(_flatten(value, dotted + "."))
        else:
            out[dotted] = value
    return out


def _parameter(t: Table, k: int, base_raw: dict[str, Any], fixed: dict[str, Any]) -> Parameter:
    """One [[parameter]]: where it goes, how it is applied, its grid or its distribution."""
    path = t.string("path")
    t.label = f"parameter[{k}] '{path}'"
    if KEY_PATH.match(path) is None:
        raise t.fail("not a dotted key like 'environment.stiffness_N_m' or 'a.b[2]'")
    apply = t.string("apply", "set", APPLY_MODES)
    _check_target(t, path, apply, base_raw, fixed)
    kinds = [name for name in (*_GRIDS, "distribution") if t.has(name)]
    if len(kinds) != 1:
        raise t.fail("give exactly one of values, linspace, logspace, distribution")
    if kinds[0] == "distribution":
        distribution, args = _distribution(t)
        grid = None
    else:
        distribution, args = None, {}
        grid = _GRIDS[kinds[0]](t)
    t.finish()
    return Parameter(path, t.label, apply, grid, distribution, args)


def _check_target(
    t: Table, path: str, apply: str, base_raw: dict[str, Any], fixed: dict[str, Any]
) -> None:
    """A plant factor uvms-pin knows, or a scenario key whose base value fits ``apply``."""
    key, index = parse_key_path(path).key, parse_key_path(path).index
    if path.startswith(PLANT_PREFIX):
        if path[len(PLANT_PREFIX) :] not in PLANT_FACTORS or index is not None:
            known = ", ".join(PLANT_PREFIX + f for f in PLANT_FACTORS)
            raise t.fail(f"unknown plant factor; known: {known}")
        return
    base_value = fixed.get(key, _lookup(base_raw, key, None))
    if index is not None:
        if not isinstance(base_value, list):
            raise t.fail(f"'{key}' is not a list in the base scenario, it cannot be indexed")
        if int(index) >= len(base_value):
            raise t.fail(f"index {index} out of range: '{key}' has {len(base_value)} entries")
    elif apply != "set" and base_value is None:
        raise t.fail(f"apply = '{apply}' needs a value of '{key}' in the base scenario")


def _values(t: Table) -> tuple[Any, ...]:
    values = t.pop_raw("values")
    if not isinstance(values, list) or not values:
        raise t.fail("values: the list is empty")
    for v in values:
        if not (is_number(v) or (isinstance(v, list) and v and all(is_number(x) for x in v))):
            raise t.fail(f"values: {v!r} is not a finite number or list of numbers")
    return tuple(values)


def _spaced(kind: str):
    """A grid of ``count`` points from ``start`` to ``stop``, evenly (linspace) or
    geometrically (logspace) spaced: ``[start, stop, count]``."""

    def read(t: Table) -> tuple[float, ...]:
        spec = t.pop_raw(kind)
        if (
            not isinstance(spec, list)
            or len(spec) != 3
            or not all(is_number(x) for x in spec[:2])
            or isinstance(spec[2], bool)
            or not isinstance(spec[2], int)
        ):
            raise t.fail(f"{kind}: must be [start, stop, count], got {spec!r}")
        start, stop, count = spec
        if count < 1:
            raise t.fail(f"{kind}: empty range (count = {count})")
        if count > 1 and start == stop:
            raise t.fail(f"{kind}: empty range (start = stop = {start})")
        if kind == "logspace" and (start <= 0 or stop <= 0):
            raise t.fail(f"logspace: start and stop must be > 0, got {start}, {stop}")
        space = np.geomspace if kind == "logspace" else np.linspace
        return tuple(float(x) for x in space(start, stop, count))

    return read


#: grid key -> how the grid is read from a [[parameter]]
_GRIDS = {"values": _values, "linspace": _spaced("linspace"), "logspace": _spaced("logspace")}


def _distribution(t: Table) -> tuple[str, dict[str, float]]:
    """The random law of a [[parameter]] and its arguments, checked."""
    distribution = t.pop_raw("distribution")
    if distribution not in DISTRIBUTIONS:
        raise t.fail(f"unknown distribution {distribution!r}; known: {', '.join(DISTRIBUTIONS)}")
    normal = distribution == "normal"
    needed = ("mean", "std") if normal else ("low", "high")
    args: dict[str, float] = {}
    for name in (*needed, *(("low", "high") if normal else ())):
        if t.has(name):
            args[name] = t.number(name)
        elif name in needed:
            raise t.fail(f"distribution '{distribution}' needs '{name}'")
    if normal and args["std"] <= 0:
        raise t.fail(f"std must be > 0, got {args['std']}")
    if args.get("low", -math.inf) >= args.get("high", math.inf):
        raise t.fail(f"empty range: low = {args['low']} >= high = {args['high']}")
    if distribution == "log-uniform" and args["low"] <= 0:
        raise t.fail(f"log-uniform needs low > 0, got {args['low']}")
    return distribution, args


def _check_report(report: dict[str, Any], source: str, paths: set[str]) -> None:
    known = {"heatmaps", "metrics"}
    unknown = set(report) - known
    if unknown:
        raise StudyError(f"{source}: [report] has unknown key(s): {', '.join(sorted(unknown))}")
    for k, pair in enumerate(report.get("heatmaps", [])):
        if not (isinstance(pair, list) and len(pair) == 2 and set(pair) <= paths):
            raise StudyError(
                f"{source}: report.heatmaps[{k}]: must be two parameter paths, got {pair!r}"
            )
    metrics = report.get("metrics", [])
    if not isinstance(metrics, list) or not all(isinstance(m, str) for m in metrics):
        raise StudyError(f"{source}: report.metrics: must be a list of metric names")


# ---- checks against the base scenario (before any run) ------------------------------------


def _extremes(study: Study, runs: list[Run]) -> dict[str, list[Any]]:
    """Per parameter, the distinct values to try: min and max if numeric, else all."""
    out: dict[str, list[Any]] = {}
    for p in study.parameters:
        values = [r.values[p.path] for r in runs]
        if all(is_number(v) for v in values):
            bounds = [p.args[k] for k in ("low", "high") if k in p.args]  # the support
            out[p.path] = sorted({min(values), max(values), *bounds})
        else:
            distinct = {json.dumps(v): v for v in values}
            out[p.path] = list(distinct.values())
    return out


def _check_against_base(study: Study, source: str) -> None:
    """Load the base scenario with the fixed overrides; then with each parameter alone at
    each of its extremes over the runs (so a failure names its entry); then with the first
    run's overrides as a whole. Plant factors are checked for sign."""
    from uvms_pin.scenario.load import load_scenario

    try:
        load_scenario(study.base, study.fixed)
    except ScenarioError as exc:
        raise StudyError(f"{source}: study.base with [fixed]: {exc}") from exc
    for p in study.parameters:  # plant factors: the whole support, not only the draws
        if p.is_plant and p.distribution is not None:
            lowest = p.args.get("low", -math.inf)
            if p.apply == "add":
                lowest += 1.0
            name = p.path[len(PLANT_PREFIX) :]
            bad = lowest <= 0 if name == "mass_scale" else lowest < 0
            if bad:
                limit = "> 0" if name == "mass_scale" else ">= 0"
                raise StudyError(
                    f"{source}: {p.entry}: the factor must be {limit} over the whole "
                    f"distribution (give a low bound), its lowest value is {lowest}"
                )
    runs = study.runs()
    first = runs[0]
    extremes = _extremes(study, runs)
    for p in study.parameters:
        for value in extremes[p.path]:
            values = dict(first.values)
            values[p.path] = value
            overrides, plant = study.resolve(values)
            if p.is_plant:
                name = p.path[len(PLANT_PREFIX) :]
                bad = plant[name] <= 0 if name == "mass_scale" else plant[name] < 0
                if bad:
                    limit = "> 0" if name == "mass_scale" else ">= 0"
                    raise StudyError(
                        f"{source}: {p.entry}: the factor must be {limit}, got {plant[name]}"
                    )
                continue
            alone = dict(study.fixed)
            alone[p.key] = overrides[p.key]
            try:
                load_scenario(study.base, alone)
            except ScenarioError as exc:
                raise StudyError(f"{source}: {p.entry} = {value!r}: {exc}") from exc
    try:
        load_scenario(study.base, first.overrides)
    except ScenarioError as exc:
        raise StudyError(f"{source}: the first run's parameters together: {exc}") from exc
