"""Pictures written next to each generated level: the packed assembly and the pieces handed out.

The generator takes this function as a parameter (it sits below the environments and does not
import the renderer); it draws with :mod:`chaingeo.envs.render` (deterministic PNG bytes, no
GUI), so worker processes can call it.
"""

from __future__ import annotations

from typing import Final

from chaingeo.core.level import Level
from chaingeo.envs.render import render_level_tray, render_solution_views

PictureSet = dict[str, bytes]
#: The solved level is drawn from this view.
ASSEMBLY_VIEW: Final = "iso"


def level_pictures(level: Level) -> PictureSet:
    """``{"assembly": png, "pieces": png}``: the level solved, and its pieces as handed out."""
    return {
        "assembly": render_solution_views(level, views=(ASSEMBLY_VIEW,))[ASSEMBLY_VIEW],
        "pieces": render_level_tray(level),
    }
