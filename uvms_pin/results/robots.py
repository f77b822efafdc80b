"""The result of a run of several robots: one `Rollout` per robot, on the same time axis.

``rollouts.robot(name)`` is that robot's rollout, with every view a single robot's has
(``q``, ``v``, ``to_dataframe()``, ``plot()``, ``metrics()``); ``to_dataframe()`` puts
every robot's columns side by side, each prefixed by the robot's name (``bluerov_a/q.vehicle.x_m``);
``metrics()`` has a block per robot (``object_metrics()`` one per free object); ``save``
writes each robot's rollout in a directory of its name and ``metrics.json`` (the blocks)
beside them.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from uvms_pin.errors import ParameterError
from uvms_pin.results.atomic import write_json_atomic
from uvms_pin.results.free_objects import free_object_summary
from uvms_pin.results.outdir import given_path
from uvms_pin.results.rollout import Rollout
from uvms_pin.results.status import RunStatus

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.figure import Figure

__all__ = ["ROBOTS_FILE", "RobotRollouts"]

#: what `RobotRollouts.save` writes beside the robots' directories: the metrics per robot
ROBOTS_FILE = "metrics.json"


class RobotRollouts:
    """Each robot's rollout of one run (``rollouts``: name -> `Rollout`, in the
    scenario's order) and what the run records as a whole (``metadata``: the robots'
    names, their seeds, the wall time)."""

    def __init__(self, rollouts: Mapping[str, Rollout], metadata: dict[str, Any] | None = None):
        if not rollouts:
            raise ParameterError("a run of several robots has at least one robot")
        self.rollouts = dict(rollouts)
        self.metadata = {"robots": list(self.rollouts), **(metadata or {})}

    @property
    def names(self) -> list[str]:
        return list(self.rollouts)

    def robot(self, name: str) -> Rollout:
        """The rollout of the robot ``name``."""
        try:
            return self.rollouts[name]
        except KeyError:
            raise ParameterError(f"no robot '{name}' in this run (robots: {self.names})") from None

    @property
    def status(self) -> RunStatus:
        """How the run ended: the first robot's status that is not ok, else ok (every
        robot's rollout ends at the same sample)."""
        statuses = [r.status for r in self.rollouts.values()]
        return next((s for s in statuses if not s.ok), statuses[0])

    def __len__(self) -> int:
        return len(next(iter(self.rollouts.values())))

    def metrics(self) -> dict[str, dict[str, float]]:
        """Each robot's metrics (`Rollout.metrics`), by name."""
        return {name: r.metrics() for name, r in self.rollouts.items()}

    def object_metrics(self) -> dict[str, dict[str, float]]:
        """Each free object's summary, by name (the objects are the first robot's rollout's
        signal ``free_objects``; `uvms_pin.results.free_objects.free_object_summary`): where
        it ended (``final_x_m``, ``final_y_m``, ``final_z_m``), how far it moved from where it
        started (``displacement_m``) and its greatest speed (``max_speed_m_s``); none without
        free objects."""
        return free_object_summary(next(iter(self.rollouts.values())))

    def to_dataframe(self) -> pd.DataFrame:
        """Every robot's table (`Rollout.to_dataframe`) side by side on the time index,
        each column prefixed ``name/``; ``attrs["units"]`` likewise."""
        import pandas as pd

        frames, units = [], {}
        for name, rollout in self.rollouts.items():
            frame = rollout.to_dataframe().add_prefix(f"{name}/")
            units.update({f"{name}/{c}": u for c, u in frame.attrs.get("units", {}).items()})
            frame.attrs = {}
            frames.append(frame)
        out = pd.concat(frames, axis=1)
        out.attrs["units"] = units
        return out

    def plot(self, kind: str | None = None) -> dict[str, Figure | dict[str, Figure]]:
        """Each robot's figures (`Rollout.plot`), by name."""
        return {name: r.plot(kind) for name, r in self.rollouts.items()}

    def save(self, directory: str | Path) -> Path:
        """Each robot's rollout in ``directory/<name>/`` and ``metrics.json`` (a block per
        robot, with its status and seed; with free objects, a block per object:
        `object_metrics`) in ``directory``.

        Raises:
            ParameterError: a metric of your own failed (`checked_metrics`), once every file
                is written: the robot's block holds the built-in metrics and
                ``extra_metrics_error``.
        """
        from uvms_pin.results.metrics import checked_metrics

        out = given_path("directory", directory)
        blocks, failures = {}, []
        for name, rollout in self.rollouts.items():
            metrics, failure = checked_metrics(rollout)
            blocks[name] = {
                "status": rollout.metadata.get("status"),
                "seed": rollout.metadata.get("seed"),
                **({} if failure is None else {"extra_metrics_error": str(failure)}),
                **metrics,
            }
            failures += [failure] if failure is not None else []
            rollout.save(out / name)
        objects = self.object_metrics()
        write_json_atomic(
            out / ROBOTS_FILE, {"robots": blocks, **({"objects": objects} if objects else {})}
        )
        if failures:
            raise failures[0]
        return out

    @classmethod
    def load(cls, directory: str | Path) -> RobotRollouts:
        """The rollouts `save` wrote in ``directory``."""
        src = given_path("directory", directory)
        return cls({name: Rollout.load(src / name) for name in cls.names_in(src)})

    @staticmethod
    def names_in(directory: str | Path) -> list[str]:
        """The robots of the run of several `save` wrote in ``directory``; ParameterError
        saying why when it holds none."""
        import json

        src = Path(directory)
        try:
            text = (src / ROBOTS_FILE).read_text(encoding="utf-8")
            return [str(name) for name in json.loads(text)["robots"]]
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise ParameterError(f"{src} holds no run of several robots ({exc})") from exc
