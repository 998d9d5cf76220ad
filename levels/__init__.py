"""The shipped level suite (``chain-level/1`` files), installed as the package data of
``chaingeo.levels``; code finds it with :func:`chaingeo.core.suite.suite_folder`."""
