"""``python -m chaingeo.integrations.verifiers install [PIP OPTIONS]``: install the plugin that
lets verifiers' command line find the taskset id ``chaingeo-env``."""

from __future__ import annotations

import sys

from chaingeo.integrations.verifiers.plugin_module import PLUGIN_DIR, install_plugin

USAGE = (
    "usage: python -m chaingeo.integrations.verifiers install [PIP OPTIONS]\n"
    "  installs the plugin distribution chaingeo-env (taskset id chaingeo-env for vf-eval)\n"
    f"  from {PLUGIN_DIR}"
)


def main(argv: list[str]) -> int:
    if not argv or argv[0] != "install":
        print(USAGE, file=sys.stderr)
        return 2
    return install_plugin(argv[1:])


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
