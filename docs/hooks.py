"""MkDocs hook: the docstrings cross-reference in Sphinx's roles (:func:`name`), which Markdown
renders as a stray ':func:' before the code; the API pages and the proofs drop the role."""

from __future__ import annotations

import re
from typing import Any

ROLE = re.compile(r":(?:attr|class|data|exc|func|meth|mod|obj):(?=<code>)")


def on_page_content(html: str, **kwargs: Any) -> str:
    return ROLE.sub("", html)
