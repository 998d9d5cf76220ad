"""The one base of every exception CHAIN-geo defines.

Why: a caller (the ``chain`` command, a notebook, a harness) can tell the project's own refusals
from a bug with one ``except ChainGeoError``; each error keeps its builtin base too (``ValueError``,
``RuntimeError``, ...), so older ``except ValueError`` handlers still catch it.
"""

from __future__ import annotations


class ChainGeoError(Exception):
    """Raised, through a subclass, for anything CHAIN-geo refuses or cannot do."""
