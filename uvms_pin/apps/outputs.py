"""What a run leaves in its output directory: the rollout, ``metrics.json``, its figures."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.results.rollout import ARRAY_FILE, META_FILE, Rollout

METRICS_FILE = "metrics.json"
#: what `write_results` writes: the run itself, before its figures
RESULT_FILES = (ARRAY_FILE, META_FILE, METRICS_FILE)
#: a kind of figure: rollout, output directory -> the files written
FigureWriter = Callable[[Rollout, Path], list[Path]]


def write_outputs(rollout: Rollout, out: Path) -> list[Path]:
    """Rollout, metrics.json and figures into ``out``; the figures' paths. A metric of your
    own that fails is raised once they are written (`write_results`)."""
    failure = write_results(rollout, out)
    figures = write_figures(rollout, out)
    if failure is not None:
        raise failure
    return figures


def write_results(rollout: Rollout, out: Path) -> ParameterError | None:
    """``rollout.npz``, ``rollout.json`` and ``metrics.json`` (`RESULT_FILES`) into ``out``,
    each written whole or not at all. A metric of your own that fails (`checked_metrics`)
    does not lose the run: ``metrics.json`` holds the built-in metrics and, as
    ``extra_metrics_error``, what went wrong; its error is returned (None: none failed)."""
    from uvms_pin.results.atomic import write_json_atomic
    from uvms_pin.results.metrics import checked_metrics

    metrics, failure = checked_metrics(rollout)
    out.mkdir(parents=True, exist_ok=True)
    rollout.save(out)
    write_json_atomic(
        out / METRICS_FILE,
        {
            "status": rollout.metadata.get("status"),
            "error": rollout.metadata.get("error", ""),
            "seed": rollout.metadata.get("seed"),
            **({} if failure is None else {"extra_metrics_error": str(failure)}),
            **metrics,
        },
    )
    return failure


def write_figures(
    rollout: Rollout, out: Path, checkpoint: Callable[[], None] | None = None
) -> list[Path]:
    """Every figure the rollout has data for (none below two samples) into ``out``;
    ``checkpoint`` is called before each kind of figure (a Ctrl-C noted meanwhile raises
    there: `uvms_pin.apps.interrupts`)."""
    figures: list[Path] = []
    for write in _figure_writers(checkpoint or _no_checkpoint):
        figures += write(rollout, out)
    return figures


def _no_checkpoint() -> None:
    """No interruption point (the figures of a library call)."""


def _figure_writers(checkpoint: Callable[[], None]) -> Iterator[FigureWriter]:
    """The figure writers, each after a ``checkpoint`` (matplotlib imported after the first)."""
    checkpoint()
    from uvms_pin.results.figures.estimate import estimate_figures
    from uvms_pin.results.figures.objects import objects_figures
    from uvms_pin.results.figures.paper import paper_figures
    from uvms_pin.results.figures.perception import perception_figures
    from uvms_pin.results.figures.standard import standard_figures
    from uvms_pin.results.figures.tracking import tracking_figures

    for write in (
        paper_figures,
        standard_figures,
        tracking_figures,
        estimate_figures,
        objects_figures,
        perception_figures,
        _flow_figure,
        _surface_figure,
    ):
        yield write
        checkpoint()


def _flow_figure(rollout: Rollout, out: Path) -> list[Path]:
    """flow.png when the run had waves or a varying current (not for a uniform current)."""
    from uvms_pin.apps.viz.flow_plots import FLOW_FIGURE, plot_flow_seen
    from uvms_pin.flow import UniformCurrent, flow_from_record
    from uvms_pin.model.urdf.load import load_uvms

    world = rollout.metadata.get("world") or {}
    flow = flow_from_record(world.get("flow"))
    if flow is None or isinstance(flow, UniformCurrent) or len(rollout) == 0:
        return []
    density = float(world["water_density_kg_m3"])
    uvms = load_uvms(rollout.metadata["model_source"], water_density_kg_m3=density)
    return [plot_flow_seen(rollout, uvms, flow, out / FLOW_FIGURE)]


def _surface_figure(rollout: Rollout, out: Path) -> list[Path]:
    """surface.png when the run had a free surface and some body left the water in part."""
    from uvms_pin.apps.viz.surface_plots import SURFACE_FIGURE, plot_waterline
    from uvms_pin.flow import flow_from_record
    from uvms_pin.model.urdf.load import load_uvms

    world = rollout.metadata.get("world") or {}
    fractions = rollout.signals.get("wet_fraction")
    if not world.get("free_surface") or fractions is None or len(rollout) == 0:
        return []
    if np.all(fractions >= 1.0 - 1e-9):
        return []
    density = float(world["water_density_kg_m3"])
    uvms = load_uvms(rollout.metadata["model_source"], water_density_kg_m3=density)
    flow = flow_from_record(world.get("flow"))
    return [plot_waterline(rollout, uvms, flow, out / SURFACE_FIGURE)]
