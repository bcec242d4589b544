"""Low-discrepancy sample points shared by the papers' filtered importance sampling.

ImpastoR's specular FIS (``impastor.specular_lighting``, §3.5.2, Ferwerda) and the layered polymer
model's (``shrm.polymer.layered``) draw their lobe samples from the same point set.

References
----------
J. H. Halton, "On the efficiency of certain quasi-random sequences of points in evaluating
multi-dimensional integrals", Numerische Mathematik 2, 1960 (Hammersley points).
"""

from __future__ import annotations

import numpy as np

from reference.errors import require_positive_int

__all__ = ["hammersley"]


def hammersley(n_samples: int) -> np.ndarray:
    """The 2-D Hammersley point set: ``((k + ½)/K, radical inverse base 2 of k)``, shape (K, 2).

    Examples
    --------
    >>> hammersley(4)
    array([[0.125, 0.   ],
           [0.375, 0.5  ],
           [0.625, 0.25 ],
           [0.875, 0.75 ]])
    """
    K = require_positive_int(n_samples, "Hammersley points: n_samples", 1 << 20)
    k = np.arange(K, dtype=np.uint64)
    inverse = np.zeros(K)
    scale = 0.5
    while (k > 0).any():
        inverse += scale * (k & np.uint64(1)).astype(np.float64)
        k = k >> np.uint64(1)
        scale /= 2.0
    return np.stack([(np.arange(K) + 0.5) / K, inverse], axis=-1)
