"""The player's HTML pages and static files (shipped in the wheel; no CDN, works offline).

The pages are fixed templates: the only values written into them are a level id and the study
flag, escaped; everything a level or the game says reaches the page as JSON over the WebSocket
and is set as text (``textContent``), never as markup.
"""

from __future__ import annotations

from html import escape
from importlib import resources
from typing import TYPE_CHECKING, Final

from chaingeo.integrations.serve.errors import NotFoundError

if TYPE_CHECKING:
    from chaingeo.integrations.serve.environment import Catalog

PACKAGE: Final = "chaingeo.integrations.serve"
MEDIA: Final = {
    ".js": "text/javascript",
    ".css": "text/css",
    ".txt": "text/plain; charset=utf-8",
    ".html": "text/html; charset=utf-8",
}


def static_file(name: str) -> tuple[bytes, str]:
    """A shipped static file's bytes and media type (names are checked by the guard)."""
    suffix = name[name.rfind(".") :] if "." in name else ""
    media = MEDIA.get(suffix)
    file = resources.files(PACKAGE).joinpath("static", name)
    if media is None or not file.is_file():
        raise NotFoundError(f"no static file {name[:100]!r}")
    return file.read_bytes(), media


def _template(name: str) -> str:
    return resources.files(PACKAGE).joinpath("static", name).read_text(encoding="utf-8")


def index_page(catalog: Catalog) -> str:
    """Every level, linked to its player (a study lists nothing: its levels are assigned)."""
    if catalog.study is not None:
        rows = '<p>This server runs a study. <a href="/play/study">Start</a>.</p>'
    else:
        items = [
            f'<tr><td><a href="/play/{escape(lv.id)}">{escape(lv.id)}</a></td>'
            f"<td>{escape(lv.family)}</td><td>{escape(lv.difficulty)}</td>"
            f"<td>{escape(lv.goal)}</td><td>{lv.optimal_steps}</td></tr>"
            for lv in catalog.levels.values()
        ]
        rows = (
            "<table><thead><tr><th>level</th><th>family</th><th>difficulty</th><th>goal</th>"
            "<th>fewest steps</th></tr></thead><tbody>" + "".join(items) + "</tbody></table>"
        )
    return _template("index.html").replace("{{rows}}", rows)


def player_page(level_id: str, study: bool) -> str:
    return (
        _template("player.html")
        .replace("{{level}}", escape(level_id, quote=True))
        .replace("{{study}}", "1" if study else "0")
    )
