# SPDX-License-Identifier: BSD-3-Clause
"""The module's array conversions fed whatever numpy can hold (Hypothesis):
every dtype, shape, memory order and value either converts to exactly the
numbers given or raises ValueError (or TypeError for a Python type that is
no array at all), never a crash or a wrong value."""
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import radargauss as rg

DTYPES = st.one_of(hnp.floating_dtypes(), hnp.integer_dtypes(), hnp.boolean_dtypes(), hnp.complex_number_dtypes(),
                   st.just(np.dtype("U3")))
ARRAYS = hnp.arrays(DTYPES, hnp.array_shapes(min_dims=0, max_dims=3, min_side=0, max_side=5))
SETTINGS = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def convertible(array, shape):
    """Whether the conversion must succeed: a float array of the shape, finite."""
    return (array.dtype.kind == "f" and array.dtype.itemsize in (4, 8) and array.ndim == len(shape)
            and all(s < 0 or array.shape[i] == s for i, s in enumerate(shape)) and np.isfinite(array).all())


@SETTINGS
@given(ARRAYS, st.booleans())
def test_scan_points_convert_exactly_or_raise(array, fortran):
    if fortran and array.ndim > 1:
        array = np.asfortranarray(array)
    if convertible(array, (-1, 3)):
        assert np.array_equal(rg.Scan(array).points, array.astype(np.float64))
    else:
        with pytest.raises((ValueError, TypeError)):
            rg.Scan(array)


@SETTINGS
@given(hnp.arrays(np.float64, st.integers(0, 6).map(lambda n: (n, 3)), elements=st.floats(-1e6, 1e6)), ARRAYS)
def test_scan_doppler_converts_exactly_or_raises(points, doppler):
    if convertible(doppler, (len(points),)):
        assert np.array_equal(rg.Scan(points, doppler=doppler).doppler, doppler.astype(np.float64))
    else:
        with pytest.raises((ValueError, TypeError)):
            rg.Scan(points, doppler=doppler)


@SETTINGS
@given(st.recursive(st.one_of(st.floats(), st.integers(-2**70, 2**70), st.text(max_size=2), st.none()),
                    lambda inner: st.lists(inner, max_size=4), max_leaves=20))
def test_nested_lists_convert_or_raise(value):
    try:
        array = np.asarray(value, dtype=np.float64)
    except (ValueError, TypeError, OverflowError):
        array = None
    if array is not None and convertible(array, (-1, 3)):
        assert np.array_equal(rg.Scan(value).points, array)
    else:
        with pytest.raises((ValueError, TypeError)):
            rg.Scan(value)


def test_strided_views_convert_exactly():
    base = np.arange(60, dtype=np.float32).reshape(10, 6)
    for view in (base[:, ::2], base[::3, :3], base.T.copy().T[:, 1:4]):
        assert np.array_equal(rg.Scan(view).points, view.astype(np.float64))
