"""Scripts that precompute expensive oracle values into ``tests/data/*.json``."""
