"""A library built without the wrinkle capability answers UNSUPPORTED, never crashes."""
import numpy as np
import pytest

import pleat


def test_wrinkle_calls_unsupported(grid5):
    if pleat.has_feature("wrinkle"):
        pytest.skip("library has the wrinkle capability")
    with pytest.raises(pleat.PleatError) as e:
        pleat.Cwf.from_arrays(grid5, np.zeros(grid5.edge_count), np.zeros(25))
    assert e.value.status == "UNSUPPORTED"
