"""A URDF file as a checked kinematic tree: links and joints by name, in file order, each
link's parent joint and child joints, one root; errors name the file, the link or joint, and
what is wrong."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path

from uvms_pin.errors import ModelError
from uvms_pin.model.urdf.read import read_urdf_root

__all__ = ["MOVING_JOINT_TYPES", "URDFTree"]

#: URDF joint types that move (the others here: fixed; floating and planar are refused).
MOVING_JOINT_TYPES = ("revolute", "continuous", "prismatic")


class URDFTree:
    """A parsed URDF with its kinematic tree checked (links, joints, parents, root).

    Attributes:
        root: the <robot> element (the elements are the file's, not copies).
        path: the file, for error messages.
        links, joints: elements by name; link_order, joint_order: names in file order.
        parent_joint: link -> the joint whose child it is (not for the root).
        children: link -> the joints whose parent it is.
        root_link: the one link without a parent.
    """

    def __init__(self, root: ET.Element, path: Path):
        self.root = root
        self.path = path
        self.links: dict[str, ET.Element] = {}
        self.link_order: list[str] = []
        self.joints: dict[str, ET.Element] = {}
        self.joint_order: list[str] = []
        self.parent_joint: dict[str, str] = {}
        self.children: dict[str, list[str]] = {}
        self._read_links()
        self._read_joints()
        self.root_link = self._single_root()

    @classmethod
    def read(cls, path: Path) -> URDFTree:
        """The checked tree of the URDF file at ``path``."""
        return cls(read_urdf_root(path), path)

    def _named(self, tag: str) -> Iterator[tuple[str, ET.Element]]:
        """(name, element) of every ``<tag>`` of the file (ModelError for one with no name)."""
        for element in self.root.findall(tag):
            name = element.get("name")
            if not name:
                raise ModelError(f"a <{tag}> has no name", path=str(self.path))
            yield name, element

    def _read_links(self) -> None:
        for name, link in self._named("link"):
            if name in self.links:
                raise ModelError("is defined twice", path=str(self.path), link=name)
            self.links[name] = link
            self.link_order.append(name)
        if not self.links:
            raise ModelError("no <link> elements", path=str(self.path))
        self.children = {n: [] for n in self.links}

    def _read_joints(self) -> None:
        where = str(self.path)
        for name, joint in self._named("joint"):
            if name in self.joints:
                raise ModelError(f"joint '{name}' is defined twice", path=where)
            parent, child = self._ends(joint, name)
            if child in self.parent_joint:
                raise ModelError(
                    f"closed chain: the link has two parents (joints '{self.parent_joint[child]}' "
                    f"and '{name}'); URDF and Pinocchio need a tree",
                    path=where,
                    link=child,
                )
            self.joints[name] = joint
            self.joint_order.append(name)
            self.parent_joint[child] = name
            self.children[parent].append(name)

    def _ends(self, joint: ET.Element, name: str) -> tuple[str, str]:
        """(parent link, child link) of a joint, both links of this file."""
        where = str(self.path)
        parent_el, child_el = joint.find("parent"), joint.find("child")
        if parent_el is None or child_el is None:
            raise ModelError(f"joint '{name}' needs <parent> and <child>", path=where)
        parent, child = parent_el.get("link"), child_el.get("link")
        for role, link in (("parent", parent), ("child", child)):
            if link not in self.links:
                raise ModelError(
                    f"joint '{name}': unknown {role} link '{link}'", path=where, link=link
                )
        return parent, child

    def _single_root(self) -> str:
        """The one link without a parent, every link below it."""
        where = str(self.path)
        roots = [n for n in self.link_order if n not in self.parent_joint]
        if len(roots) != 1:
            raise ModelError(
                f"expected one root link, found {len(roots)}: {', '.join(roots) or 'none'} "
                "(a cycle or a disconnected part)",
                path=where,
            )
        if len(self.subtree(roots[0])) != len(self.links):
            raise ModelError("the joints form a cycle", path=where)
        return roots[0]

    def require_link(self, name: str, role: str) -> str:
        """``name`` if it is a link of this file; else a ModelError naming ``role`` and the
        links there are."""
        if name not in self.links:
            raise ModelError(
                f"{role} '{name}' is not a link of this file; links are: "
                + ", ".join(self.link_order),
                path=str(self.path),
                link=name,
            )
        return name

    def child_of(self, joint: str) -> str:
        return self.joints[joint].find("child").get("link")

    def parent_of(self, joint: str) -> str:
        return self.joints[joint].find("parent").get("link")

    def is_moving(self, joint: str) -> bool:
        return self.joints[joint].get("type") in MOVING_JOINT_TYPES

    def subtree(self, link: str) -> list[str]:
        """``link`` and every link below it (depth first)."""
        out, stack = [], [link]
        while stack:
            current = stack.pop()
            out.append(current)
            stack.extend(self.child_of(j) for j in self.children[current])
        return out

    def path_joints(self, base: str, tip: str) -> list[str]:
        """The joints from ``base`` down to ``tip`` (``tip`` below ``base``)."""
        joints = []
        current = tip
        while current != base:
            joint = self.parent_joint[current]
            joints.append(joint)
            current = self.parent_of(joint)
        return joints[::-1]

    def moving_below(self, link: str) -> int:
        """How many moving joints there are below ``link``."""
        return sum(
            1
            for n in self.subtree(link)
            if n in self.parent_joint and n != link and self.is_moving(self.parent_joint[n])
        )

    def moving_above(self, joint: str) -> bool:
        """Whether a moving joint is on the way from ``joint`` up to the root."""
        link = self.parent_of(joint)
        while link in self.parent_joint:
            above = self.parent_joint[link]
            if self.is_moving(above):
                return True
            link = self.parent_of(above)
        return False
