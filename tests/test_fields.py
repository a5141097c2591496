"""regrasp.fields' fast path for plain vectors (plain_numbers) against its numpy path: the same
array for every accepted input, the same refusal for every other (hypothesis)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, strategies as st

from regrasp.errors import ArgumentError
from regrasp.fields import MAX_MAGNITUDE, check_array, check_finite, check_vector, plain_numbers

NUMBER = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**400, 10**400), st.booleans(),
                   st.sampled_from([MAX_MAGNITUDE, -MAX_MAGNITUDE, np.nextafter(MAX_MAGNITUDE, np.inf), 0, -0.0]))


def _slow(x, n: int):
    """check_vector without the fast path."""
    a = check_array(x, "v")
    if a.shape != (n,):
        raise ArgumentError("shape", "v")
    return check_finite(a, "v")


def _outcome(fn, x, n):
    try:
        return fn(x, n).tolist()
    except ArgumentError:
        return "refused"


@given(values=st.lists(NUMBER, min_size=0, max_size=5), as_tuple=st.booleans())
def test_the_fast_path_answers_as_numpy_does(values, as_tuple):
    x = tuple(values) if as_tuple else values
    for n in (3, len(values)):
        fast = _outcome(lambda v, k: check_vector(v, k, "v"), x, n)
        assert fast == _outcome(_slow, x, n), (x, n)


@given(values=st.lists(st.floats(allow_nan=True, allow_infinity=True, width=64), min_size=3, max_size=3),
       dtype=st.sampled_from(["float64", "float32", "int64"]))
def test_arrays_take_the_fast_path_with_the_same_answer(values, dtype):
    with np.errstate(invalid="ignore", over="ignore"):
        a = np.array(values).astype(dtype)
    assert _outcome(lambda v, k: check_vector(v, k, "v"), a, 3) == _outcome(_slow, a, 3)


@pytest.mark.parametrize("x", [[1, 2.5, -3], (0.0, 1e9, -1e9), np.array([1.0, 2.0, 3.0]), np.arange(3)])
def test_plain_vectors_are_plain(x):
    assert plain_numbers(x, 3) == [float(v) for v in x]


@pytest.mark.parametrize("x", [[1, 2], [True, 1, 2], [np.float64(1), 2, 3], [float("nan"), 1, 2], [1e10, 0, 0],
                               np.zeros((3, 1)), "abc", [10**400, 0, 0]])
def test_anything_else_goes_the_numpy_way(x):
    assert plain_numbers(x, 3) is None
