"""The taskset id ``chaingeo-env`` for verifiers: the module it names, here or installed.

verifiers 0.4 resolves a taskset, environment or harness id by importing the top-level module
the id names (``chaingeo-env`` -> ``chaingeo_env``) and has no other lookup. In a process that
imports :mod:`chaingeo.integrations.verifiers`, :func:`install_alias` makes that module this
package's (nothing to install). For verifiers' command line, which starts without
chaingeo, the one-file plugin distribution in ``plugin/`` is installed beside chaingeo by
:func:`install_plugin` (``python -m chaingeo.integrations.verifiers install``): it works from
the wheel as from a clone.
"""

from __future__ import annotations

import importlib.machinery
import importlib.util
import shutil
import subprocess
import sys
import tempfile
import types
from pathlib import Path

PLUGIN_MODULE = "chaingeo_env"
#: The plugin distribution's folder (pyproject.toml and the module), shipped as package data.
PLUGIN_DIR = Path(__file__).resolve().parent / "plugin"


def install_alias() -> None:
    """Make ``chaingeo_env`` importable in this process, unless the plugin is installed."""
    if PLUGIN_MODULE in sys.modules or importlib.util.find_spec(PLUGIN_MODULE) is not None:
        return
    from chaingeo.integrations.verifiers.environment import ChainGeoEnv
    from chaingeo.integrations.verifiers.harness import ChainGeoHarness
    from chaingeo.integrations.verifiers.taskset import ChainGeoTaskset

    alias = types.ModuleType(PLUGIN_MODULE, "CHAIN-geo's verifiers classes (in-process alias)")
    alias.__spec__ = importlib.machinery.ModuleSpec(PLUGIN_MODULE, None)
    alias.ChainGeoEnv = ChainGeoEnv  # type: ignore[attr-defined]
    alias.ChainGeoHarness = ChainGeoHarness  # type: ignore[attr-defined]
    alias.ChainGeoTaskset = ChainGeoTaskset  # type: ignore[attr-defined]
    alias.__all__ = ["ChainGeoEnv", "ChainGeoHarness", "ChainGeoTaskset"]  # type: ignore[attr-defined]
    sys.modules[PLUGIN_MODULE] = alias


def install_plugin(pip_args: list[str] | None = None) -> int:
    """``pip install`` the plugin distribution into this interpreter's environment, from a
    copy of the shipped folder (an installed package's folder may be read-only); pip's exit
    status."""
    with tempfile.TemporaryDirectory(prefix="chaingeo-env-") as tmp:
        source = Path(tmp) / "plugin"
        shutil.copytree(PLUGIN_DIR, source, ignore=shutil.ignore_patterns("build", "*.egg-info"))
        command = [
            sys.executable,
            "-m",
            "pip",
            "install",
            "--no-deps",
            *(pip_args or []),
            str(source),
        ]
        return subprocess.call(command)
