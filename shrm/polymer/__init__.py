"""Herbert et al.'s polymers: Kubelka–Munk chips, characterization, tint, the hybrid, its oracle.

- :mod:`~shrm.polymer.kubelka_munk` — the two-flux Kubelka–Munk slab that generates the chip matrix
  (§3.1, Herbert et al.).
- :mod:`~shrm.polymer.characterization` — chip-matrix files and their look-up.
- :mod:`~shrm.polymer.tint` — the spot-colour library of ``Tint_polymer`` (Eq. (2), Herbert et al.).
- :mod:`~shrm.polymer.hybrid` — Eqs. (1)–(5), Herbert et al., as spectral terms.
- :mod:`~shrm.polymer.material` — the ``polymer`` scene material and its environment shader.
- :mod:`~shrm.polymer.oracle` — the layered physical model behind Eq. (1), Herbert et al., by brute
  force.
- :mod:`~shrm.polymer.layered` — that layered model from prefiltered maps: a real-time model beyond
  the hybrid.
"""

from __future__ import annotations

from shrm.polymer import characterization, hybrid, kubelka_munk, layered, material, oracle, tint
from shrm.polymer.characterization import *  # noqa: F403
from shrm.polymer.hybrid import *  # noqa: F403
from shrm.polymer.kubelka_munk import *  # noqa: F403
from shrm.polymer.layered import *  # noqa: F403
from shrm.polymer.material import *  # noqa: F403
from shrm.polymer.oracle import *  # noqa: F403
from shrm.polymer.tint import *  # noqa: F403

__all__ = sorted(
    {
        *kubelka_munk.__all__,
        *characterization.__all__,
        *tint.__all__,
        *hybrid.__all__,
        *material.__all__,
        *oracle.__all__,
        *layered.__all__,
    }
)
