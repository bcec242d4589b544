import pytest

from shrm.orbit import demo_state


@pytest.fixture(scope="module")
def state():
    """A small built-in scene for render sessions and orbits (16-row environment, 12² image)."""
    return demo_state(
        brdf="lafortune",
        env_height=16,
        size=4,
        resolution=12,
        F_max=8,
        P_max=4,
        light_order=8,
        tol=0.05,
    )
