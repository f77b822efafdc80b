"""Figures as objects (notebooks) or files (CLI); Rollout.plot by kind."""

from __future__ import annotations

import pytest
from conftest import ROOT
from matplotlib.figure import Figure

import uvms_pin as up
from uvms_pin.errors import ParameterError
from uvms_pin.results.figures.kinds import KINDS
from uvms_pin.results.figures.paper import plot_force
from uvms_pin.results.figures.standard import plot_pose


@pytest.fixture(scope="module")
def passive():
    scenario = up.load_scenario(
        ROOT / "scenarios" / "passive_still_water.toml", {"scenario.duration_s": 0.1}
    )
    return up.simulate(scenario, progress=False)


@pytest.fixture(scope="module")
def ppc():
    scenario = up.load_scenario(
        ROOT / "scenarios" / "realistic_force_tracking.toml", {"scenario.duration_s": 0.05}
    )
    return up.simulate(scenario, progress=False)


def test_plot_helpers_return_the_figure_without_a_path(passive, ppc, tmp_path):
    fig = plot_pose(passive)
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    assert isinstance(plot_force(ppc), Figure)
    path = plot_pose(passive, tmp_path / "pose.png")
    assert path == tmp_path / "pose.png" and path.stat().st_size > 1000


def test_plot_all_gives_the_figures_the_rollout_has_data_for(passive, ppc):
    assert set(passive.plot()) == {"pose", "velocities", "energy"}
    figures = ppc.plot()
    # no [task] and no [estimator] in the PPC's scenario
    assert set(figures) == set(KINDS) - {"tracking", "estimate"}
    assert all(isinstance(f, Figure) for f in figures.values())
    # one panel per first-level error; one per velocity error (vehicle 6 + arm, hidden spares)
    assert len(figures["first_level"].axes) == 6
    visible = [ax for ax in figures["second_level"].axes if ax.get_visible()]
    assert len(visible) == ppc.v.shape[1]


def test_plot_kind_errors_name_the_problem(passive):
    with pytest.raises(ParameterError, match=r"unknown plot kind 'forces'.*force"):
        passive.plot("forces")
    with pytest.raises(ParameterError, match=r"cannot plot 'first_level'.*e_x"):
        passive.plot("first_level")


def test_a_run_with_an_estimator_has_its_figure():
    from uvms_pin.scenario.load import load_scenario
    from uvms_pin.sim.run import simulate

    scenario = load_scenario(
        ROOT / "scenarios" / "estimator_station_keeping.toml", {"scenario.duration_s": 0.3}
    )
    rollout = simulate(scenario, progress=False)
    figure = rollout.plot("estimate")
    assert isinstance(figure, Figure) and len(figure.axes) == 12


def test_a_tracking_run_has_its_figure(tmp_path):
    from uvms_pin.scenario.load import load_scenario
    from uvms_pin.sim.run import simulate

    scenario = load_scenario(
        ROOT / "scenarios" / "lbv150_ee_circle.toml", {"scenario.duration_s": 0.3}
    )
    rollout = simulate(scenario, progress=False)
    figure = rollout.plot("tracking")
    assert isinstance(figure, Figure) and len(figure.axes) == 4
    with pytest.raises(ParameterError, match="task_reference_position"):
        simulate(load_scenario(ROOT / "scenarios" / "passive_still_water.toml",
                               {"scenario.duration_s": 0.06}), progress=False).plot("tracking")  # fmt: skip


def test_the_pose_figure_shows_the_motion_not_the_depth(passive):
    """z ~ -2 m on the axis of x and y flattened them: the start is taken out (and titled)."""
    fig = plot_pose(passive)
    ax_p = fig.axes[0]
    start = passive.q[0, :3]
    for line, k in zip(ax_p.get_lines(), range(3), strict=True):
        assert line.get_ydata()[0] == 0.0
        assert line.get_ydata()[-1] == pytest.approx(passive.q[-1, k] - start[k])
    assert f"z = {start[2]:.3g} m" in ax_p.get_title()


def test_the_energy_figure_of_a_driven_run_shows_the_balance(passive, ppc):
    from uvms_pin.results.figures.standard import plot_energy

    labels = [line.get_label() for line in plot_energy(ppc).axes[0].get_lines()]
    assert "work of tau" in labels and any(label.startswith("work of water") for label in labels)
    labels = [line.get_label() for line in plot_energy(passive).axes[0].get_lines()]
    assert "work of tau" not in labels  # nothing drives a passive run


def test_a_saved_figure_is_drawn_once_and_is_the_file_matplotlib_writes(
    passive, tmp_path, monkeypatch
):
    """`save_figure` lays the figure out once and draws it once: `savefig` would draw it
    twice after `Figure.tight_layout` (which leaves a placeholder layout engine). The file is
    byte for byte the one matplotlib writes after `tight_layout` with the engine left."""
    from uvms_pin.results.figures.standard import save_figure

    fig = plot_pose(passive)
    fig.tight_layout()
    fig.savefig(tmp_path / "matplotlib.png", dpi=120)
    draws = []
    original = Figure.draw

    def counted_draw(self, renderer):
        draws.append(renderer)
        return original(self, renderer)

    monkeypatch.setattr(Figure, "draw", counted_draw)
    assert save_figure(plot_pose(passive), tmp_path / "saved.png") == tmp_path / "saved.png"
    assert len(draws) == 1
    assert (tmp_path / "saved.png").read_bytes() == (tmp_path / "matplotlib.png").read_bytes()
