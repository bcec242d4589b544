"""Scripts that precompute expensive references and package data (run with ``python -m``)."""
