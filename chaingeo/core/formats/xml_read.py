"""The one bounded XML reader for other people's files (BurrTools ``.xmpuzzle``).

Why: ElementTree builds any tree a file describes and writes it back by recursion, so a file of
a few kilobytes (gzip) could nest elements deeper than Python's stack (``RecursionError``) or
hold millions of them (a gigabyte of objects). Here the tree is built from ElementTree's pull
parser fed in chunks, its depth and element count checked as each element opens, before the
next chunk is read; :func:`to_text` writes an element back without recursion. A DOCTYPE is
refused first (:mod:`chaingeo.core.formats.xml_guard`), so no entity ever expands.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Final

from chaingeo.core.errors import ChainGeoError
from chaingeo.core.formats.xml_guard import doctype_problem

#: Bytes fed to the parser between two checks of the limits.
CHUNK: Final = 64 * 1024


class XmlRefused(ChainGeoError, ValueError):
    """XML this reader will not build; ``reason`` says why (the caller names the file)."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


def parse_bounded(data: bytes, max_depth: int, max_elements: int) -> ET.Element:
    """The root element of ``data``; :class:`XmlRefused` for a DOCTYPE, invalid XML, nesting
    deeper than ``max_depth`` or more than ``max_elements`` elements."""
    problem = doctype_problem(data)
    if problem is not None:
        raise XmlRefused(problem)
    parser: ET.XMLPullParser[ET.Element] = ET.XMLPullParser(events=("start", "end"))
    depth = elements = 0
    root: ET.Element | None = None
    try:
        for at in range(0, max(len(data), 1), CHUNK):
            parser.feed(data[at : at + CHUNK])
            for event, found in parser.read_events():  # type: ignore[misc]
                if event == "end":
                    depth -= 1
                    continue
                assert isinstance(found, ET.Element)  # "start" events carry the element
                element = found
                depth += 1
                elements += 1
                root = element if root is None else root
                if depth > max_depth:
                    raise XmlRefused(f"elements nested {depth} deep; at most {max_depth}")
                if elements > max_elements:
                    raise XmlRefused(f"more than {max_elements} elements")
                if element.tag[:1] == "{" or any(k[:1] == "{" for k in element.attrib):
                    raise XmlRefused(f"a namespaced name in <{element.tag[:60]}>")
        parser.close()
    except ET.ParseError as e:
        raise XmlRefused(f"invalid XML: {e}") from None
    assert root is not None  # close() raises on a document without an element
    return root


_CDATA: Final = {ord("&"): "&amp;", ord("<"): "&lt;", ord(">"): "&gt;"}
_ATTRIB: Final = {
    **_CDATA,
    ord('"'): "&quot;",
    ord("\r"): "&#13;",
    ord("\n"): "&#10;",
    ord("\t"): "&#09;",
}


def to_text(node: ET.Element) -> str:
    """``ET.tostring(node, encoding="unicode")`` without recursion (an explicit stack), for
    elements without namespaces, comments or processing instructions (expat's tree of a file
    holds none of the latter two; a namespaced tag is written as ElementTree keeps it)."""
    out: list[str] = []
    stack: list[tuple[ET.Element, bool]] = [(node, False)]
    while stack:
        el, closing = stack.pop()
        if closing:
            out.append(f"</{el.tag}>")
        else:
            attrs = "".join(f' {k}="{v.translate(_ATTRIB)}"' for k, v in el.items())
            if el.text or len(el):
                out.append(f"<{el.tag}{attrs}>")
                if el.text:
                    out.append(el.text.translate(_CDATA))
                stack.append((el, True))
                stack.extend((child, False) for child in reversed(el))
                continue
            out.append(f"<{el.tag}{attrs} />")
        if el.tail and el is not node:
            out.append(el.tail.translate(_CDATA))
    tail = node.tail
    return "".join(out) + (tail.translate(_CDATA) if tail else "")
