"""Evaluation protocols as files: ``chain eval --config chain-paper`` and ``-T config=...``.

A config is a TOML file: the shipped ones live in ``chaingeo/evaluation/configs/`` (package
data, listed by :func:`config_names` and in ``chain eval --help``); any other path works too.
Both doors (``chain eval`` and the inspect_ai task) read the same :class:`EvalConfig`, so "the
paper's protocol" is one file rather than a set of flags to remember. Fields (all optional):
``description``, ``protocols`` (``interactive`` and/or ``oneshot``), ``history_window``,
``images``, ``text_state``, ``oneshot_view``, ``temperature``, ``top_p``, ``max_tokens``,
``max_steps`` (absent: each level's own budget) and ``samples``.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, fields, replace
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from chaingeo.core.errors import ChainGeoError

if TYPE_CHECKING:  # the episode module is heavy; `chain eval --help` lists configs without it
    from chaingeo.core.level import Level
    from chaingeo.evaluation.episode import ProtocolConfig

SUFFIX = ".toml"
ProtocolName = Literal["interactive", "oneshot"]
PROTOCOLS: tuple[ProtocolName, ...] = ("interactive", "oneshot")


class ConfigError(ChainGeoError, ValueError):
    """An evaluation config that cannot be found or read."""


@dataclass(frozen=True)
class EvalConfig:
    name: str = "default"
    description: str = ""
    protocols: tuple[ProtocolName, ...] = ("interactive",)
    history_window: int = 5
    images: bool = True
    text_state: bool = False
    oneshot_view: str = "iso"
    temperature: float | None = None
    top_p: float | None = None
    max_tokens: int | None = None
    max_steps: int | None = None
    samples: int = 1

    def protocol(self, name: ProtocolName, **overrides: Any) -> ProtocolConfig:
        """The episode protocol ``name`` under this config."""
        from chaingeo.evaluation.episode import ProtocolConfig

        fields_: dict[str, Any] = {
            "history_window": self.history_window,
            "text_state": self.text_state,
            "oneshot_view": self.oneshot_view,
        }
        return ProtocolConfig(name=name, **{**fields_, **overrides})

    def sampling(self) -> dict[str, Any]:
        """The model's sampling options this config sets (temperature, top_p, max_tokens)."""
        out = {"temperature": self.temperature, "top_p": self.top_p, "max_tokens": self.max_tokens}
        return {k: v for k, v in out.items() if v is not None}

    def budgeted(self, levels: list[Level]) -> list[Level]:
        """``levels`` with this config's step budget, when it sets one (else their own)."""
        if self.max_steps is None:
            return levels
        return [replace(lv, max_steps=self.max_steps) for lv in levels]


def config_names() -> list[str]:
    """The shipped configs, by name."""
    folder = resources.files("chaingeo.evaluation").joinpath("configs")
    return sorted(p.name[: -len(SUFFIX)] for p in folder.iterdir() if p.name.endswith(SUFFIX))


def load_config(name_or_path: str | Path) -> EvalConfig:
    """A shipped config by name, or a TOML file by path."""
    text, name = _read(str(name_or_path))
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ConfigError(f"config {name}: not TOML: {e}") from None
    return _parse(name, data)


def _read(ref: str) -> tuple[str, str]:
    if ref in config_names():
        folder = resources.files("chaingeo.evaluation").joinpath("configs")
        return folder.joinpath(ref + SUFFIX).read_text("utf-8"), ref
    path = Path(ref)
    if path.suffix == SUFFIX and path.is_file():
        return path.read_text("utf-8"), path.stem
    shipped = ", ".join(config_names())
    raise ConfigError(f"no config {ref!r}: name a shipped one ({shipped}) or a {SUFFIX} file")


_TYPES: dict[str, tuple[type, ...]] = {
    "description": (str,),
    "protocols": (list,),
    "history_window": (int,),
    "images": (bool,),
    "text_state": (bool,),
    "oneshot_view": (str,),
    "temperature": (int, float),
    "top_p": (int, float),
    "max_tokens": (int,),
    "max_steps": (int,),
    "samples": (int,),
}


def _parse(name: str, data: dict[str, Any]) -> EvalConfig:
    known = {f.name for f in fields(EvalConfig)} - {"name"}
    unknown = sorted(set(data) - known)
    if unknown:
        raise ConfigError(f"config {name}: unknown field(s) {', '.join(unknown)}")
    for key, value in data.items():
        bad_bool = isinstance(value, bool) and bool not in _TYPES[key]
        if bad_bool or not isinstance(value, _TYPES[key]):
            raise ConfigError(f"config {name}: {key} = {value!r} has the wrong type")
    protocols = tuple(data.pop("protocols", ["interactive"]))
    if not protocols or any(p not in PROTOCOLS for p in protocols):
        raise ConfigError(f"config {name}: protocols must be among {', '.join(PROTOCOLS)}")
    for key in ("history_window", "max_steps", "samples", "max_tokens"):
        if key in data and data[key] < (0 if key == "history_window" else 1):
            raise ConfigError(f"config {name}: {key} = {data[key]} is out of range")
    return EvalConfig(name=name, protocols=protocols, **data)
