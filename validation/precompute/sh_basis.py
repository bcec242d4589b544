"""Precompute real SH values with mpmath at hard points into ``validation/data/sh_basis.json``.

Run ``python -m validation.precompute.sh_basis`` to regenerate. Points: θ within 1e-12 to 1e-1 of
0 and π (where sin^m θ underflows), θ = 0.377 (sin θ ≈ 1/e, where the plain float64 recurrence
first breaks, near l ≈ 1930) and the equator; l from 0 to 2500 with m ∈ {0, 1, l/2, l-1, l}. Each
value is computed at 50 digits and checked at 80 (``validation.studies.oracles.converged_mp``).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import mpmath

from reference.files import write_text_atomic
from validation.studies.oracles import converged_mp, sh_basis_mp

DEGREES = (0, 1, 2, 10, 99, 100, 101, 199, 200, 500, 999, 1000, 1500, 1930, 2000, 2100, 2200)
DEGREES += (2300, 2400, 2500)
THETAS = (
    1e-12,
    1e-6,
    1e-1,
    0.377,
    1.0,
    math.pi / 2,
    math.pi - 1e-1,
    math.pi - 1e-6,
    math.pi - 1e-12,
)
PHI = 0.7
DPS, CHECK_DPS = 50, 80
OUT = Path(__file__).resolve().parents[1] / "data" / "sh_basis.json"


def orders_for(l: int) -> list[int]:
    """Orders m ∈ {0, 1, l/2, l-1, l}, and m = 0.36 l for l >= 1500, with both signs for m > 0.

    m ≈ l sin θ at sin θ = 1/e is where the plain recurrence's sectoral start underflows while
    Y_lm is O(1).
    """
    extra = (int(0.36 * l),) if l >= 1500 else ()
    ms = sorted({m for m in (0, 1, l // 2, l - 1, l, *extra) if 0 <= m <= l})
    return sorted({s * m for m in ms for s in (1, -1)})


def compute(degrees=DEGREES, thetas=THETAS) -> list[list[float]]:
    """``[l, m, theta, phi, value]`` rows at the precomputed points."""
    rows = []
    for l in degrees:
        for m in orders_for(l):
            for theta in thetas:
                value = converged_mp(sh_basis_mp, l, m, theta, PHI, low=DPS, high=CHECK_DPS)
                rows.append([l, m, theta, PHI, value])
    return rows


def main() -> Path:
    """Write ``validation/data/sh_basis.json``."""
    data = {
        "description": "real orthonormal SH with Condon-Shortley phase, y-up lat-long angles",
        "dps": DPS,
        "check_dps": CHECK_DPS,
        "mpmath": mpmath.__version__,
        "script": "validation/precompute/sh_basis.py",
        "columns": ["l", "m", "theta", "phi", "value"],
        "points": compute(),
    }
    return write_text_atomic(OUT, json.dumps(data, indent=0))


if __name__ == "__main__":
    main()
