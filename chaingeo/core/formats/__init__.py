"""Readers and writers for other projects' level formats."""
