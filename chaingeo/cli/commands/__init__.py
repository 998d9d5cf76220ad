"""One module per ``chain`` subcommand; see :mod:`chaingeo.cli.main`."""
