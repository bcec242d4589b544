import numpy as np
import pytest

from reference.errors import SpecrefError
from validation.studies.metrics import delta_E_stats


def test_delta_E_stats_against_numpy_definitions(rng):
    d = rng.uniform(0, 3, 101)
    stats = delta_E_stats(d)
    # Source: the definitions (population std; 90th percentile by linear interpolation).
    assert stats["mean"] == pytest.approx(np.sum(d) / d.size, rel=1e-14)
    assert stats["std"] == pytest.approx(np.sqrt(np.mean((d - d.mean()) ** 2)), rel=1e-12)
    assert stats["p90"] == pytest.approx(np.sort(d)[90], rel=1e-14)  # 101 values: index 90 exactly
    assert stats["max"] == d.max()
    with pytest.raises(SpecrefError, match="no values"):
        delta_E_stats([])
