"""Spherical harmonics, prefiltering and SH reflection maps after Herbert et al."""

__all__: list[str] = []
