"""Helpers the tests share (strategies, reference oracles, fake environments and servers, the
tests' data folders). Not a test module: test modules import from here, never from each other."""
