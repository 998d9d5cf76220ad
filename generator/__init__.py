"""Level generation at scale: pure functions of (config, seed, index)."""
