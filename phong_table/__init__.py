"""Spectral Phong tables after Wang, Chern & Lee (issue: spectral Phong tables)."""

__all__: list[str] = []
