"""The ``chain`` command line, the top layer: :mod:`chaingeo.cli.main` builds the parser from
one module per subcommand in :mod:`chaingeo.cli.commands`."""
