"""A free object held rigidly by a robot's link: the scenario's ``attached_to`` (and
``release_at_s``) on a free object (``[[world.objects]]``), solved as a constraint
(`uvms_pin.physics.constraints.attachments`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from uvms_pin.checks import number_fields
from uvms_pin.errors import ParameterError

__all__ = ["Attachment"]


@dataclass(frozen=True)
class Attachment:
    """Free object ``object_name`` held by the robot's link ``link`` from ``attach_at_s``
    [s] (0: the start) until ``release_at_s`` [s] (None: the run's end), at the pose the two
    have when it begins.

    What it leaves out: the grasp's own mechanics. The object cannot slip, turn or be
    pulled out whatever the load (a grasp by contact, `[gripper]`, holds by friction and
    lets go past it); the wrench the link exerts is the constraint's, not bounded by a
    grip force."""

    object_name: str
    link: str
    release_at_s: float | None = None
    attach_at_s: float = 0.0

    def __post_init__(self) -> None:
        what = f"the attachment of '{self.object_name}' to '{self.link}'"
        number_fields(self, what)
        if not (math.isfinite(self.attach_at_s) and self.attach_at_s >= 0.0):
            raise ParameterError(f"{what}: attach_at_s must be finite and >= 0 [s], got "
                                 f"{self.attach_at_s}")  # fmt: skip
        released = self.release_at_s
        if released is not None and not (math.isfinite(released) and released > self.attach_at_s):
            raise ParameterError(
                f"{what}: release_at_s must be finite and after attach_at_s "
                f"({self.attach_at_s} s), got {released}"
            )

    def held(self, time_s: float) -> bool:
        """Whether the link holds the object at ``time_s``."""
        return self.attach_at_s <= time_s and (
            self.release_at_s is None or time_s < self.release_at_s
        )
