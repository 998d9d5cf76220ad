"""The tests, laid out like the packages they test (tests/core, tests/solvers/cover, ...).

Every folder is a package (``__init__.py``; tests/conformance/test_layout.py checks), so
pytest's default import mode (``prepend``) imports each test module by its dotted path from
the checkout (``tests.core.`` and the file's name): two folders may hold the same basename,
and test modules import what they share from :mod:`tests.support`, never from each other."""
