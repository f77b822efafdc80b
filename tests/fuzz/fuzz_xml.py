"""XML documents mutated from shipped ones, for the generated-input tests of URDF loading and
``uvms-pin import``: an element removed or twice, an attribute (or a text) set to zero, a
negative, NaN, an infinity, a huge number, a wrong count of numbers or no number, a reference
(a joint's parent or child, a mesh) broken or pointing at another link."""

from __future__ import annotations

import copy
import xml.etree.ElementTree as ET

from hypothesis import strategies as st

NUMBER_TEXTS = ("0", "-1", "nan", "inf", "-inf", "1e300", "-1e-300", "", "abc", "1 2",
                "0 0 0", "1 1 1 1 1 1 1", "-0.1 0.2 nan", "1e9", "0.0 0 -0")  # fmt: skip


def _elements(root: ET.Element) -> list[tuple[ET.Element, ET.Element]]:
    """(parent, child) of every element below the root."""
    return [(parent, child) for parent in root.iter() for child in parent]


def _remove(draw, root: ET.Element) -> None:
    parent, child = draw(st.sampled_from(_elements(root)))
    parent.remove(child)


def _duplicate(draw, root: ET.Element) -> None:
    parent, child = draw(st.sampled_from(_elements(root)))
    parent.insert(list(parent).index(child) + 1, copy.deepcopy(child))


def _attribute(draw, root: ET.Element) -> None:
    held = [(e, name) for e in root.iter() for name in e.attrib]
    if held:
        element, name = draw(st.sampled_from(held))
        element.set(name, draw(st.sampled_from(NUMBER_TEXTS) | st.text(max_size=8)))


def _text(draw, root: ET.Element) -> None:
    leaves = [e for e in root.iter() if len(e) == 0]
    draw(st.sampled_from(leaves)).text = draw(st.sampled_from(NUMBER_TEXTS))


def _reference(draw, root: ET.Element) -> None:
    refs = [e for e in root.iter() if e.tag in ("parent", "child") or "link" in e.attrib]
    names = [e.get("name") for e in root.iter("link")] + ["missing_link", ""]
    if refs:
        element = draw(st.sampled_from(refs))
        key = "link" if "link" in element.attrib else next(iter(element.attrib), "link")
        element.set(key, draw(st.sampled_from(names)))


EDITS = (_remove, _duplicate, _attribute, _text, _reference)


@st.composite
def mutated(draw, documents: dict[str, str], max_edits: int = 3):
    """(a name of ``documents`` (name -> XML text), the text with 1 to ``max_edits`` edits)."""
    name = draw(st.sampled_from(list(documents)))
    root = ET.fromstring(documents[name])
    for _ in range(draw(st.integers(1, max_edits))):
        if len(root) == 0:
            break
        draw(st.sampled_from(EDITS))(draw, root)
    return name, ET.tostring(root, encoding="unicode")
