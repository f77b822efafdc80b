"""A controller factory that says what it builds (`ControllerSpec`): what a scenario's
``[controller]`` table becomes and what a rollout records of its controller.

A scenario's controller is built once when the scenario is read (`ControllerSpec.checked`:
a bad parameter is refused then, before any run), and that controller is the one the first
run on that model gets: one build per run. Later runs, copies and pickles build their own.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from uvms_pin.control.base import Controller
from uvms_pin.model.uvms import UVMS

ControllerFactory = Callable[[UVMS], Controller]


class FirstBuild:
    """One controller built ahead for one model, handed out once (`ControllerSpec.checked`).
    Not copied, not pickled: a copy of a scenario builds its own controller."""

    def __init__(self) -> None:
        self._kept: list[tuple[UVMS, Controller]] = []

    def keep(self, uvms: UVMS, controller: Controller) -> None:
        self._kept[:] = [(uvms, controller)]

    def take(self, uvms: UVMS) -> Controller | None:
        """The controller kept for this very ``uvms`` (then forgotten), else None."""
        kept = self._kept
        if kept and kept[0][0] is uvms:
            return kept.pop()[1]
        return None

    def __deepcopy__(self, memo: dict) -> FirstBuild:
        return FirstBuild()

    def __reduce__(self):
        return (FirstBuild, ())


@dataclass(frozen=True)
class ControllerSpec:
    """A controller factory that says what it builds: ``spec(uvms) -> Controller``.

    Attributes:
        type: what it is ("none", "ppc", a baseline or "package.module:ClassName").
        params: the parameters the controller is built with, as recorded in rollouts
            (for "ppc": every gain and funnel after defaults and broadcasting).
        build: makes a fresh controller for a loaded model.
    """

    type: str
    params: dict[str, Any] = field(default_factory=dict)
    build: ControllerFactory = field(default=None, repr=False)
    #: built from the scenario file's [controller] table (its ``raw`` then records it)
    from_file: bool = field(default=False, compare=False)
    #: the controller `checked` built, for the first call on its model
    first: FirstBuild = field(default_factory=FirstBuild, init=False, repr=False, compare=False)

    def __call__(self, uvms: UVMS) -> Controller:
        """A fresh controller for ``uvms``: the one `checked` built for it, the first time;
        else a new build."""
        controller = self.first.take(uvms)
        return self.build(uvms) if controller is None else controller

    def checked(self, uvms: UVMS) -> ControllerSpec:
        """This spec, its controller for ``uvms`` built now (its constructor refuses a bad
        parameter here, before any run: the exception propagates) and kept for the first
        call on this same model, so that a scenario read then run builds it once."""
        self.first.keep(uvms, self.build(uvms))
        return self
