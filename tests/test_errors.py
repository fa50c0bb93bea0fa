"""The argument checks every entry point uses."""

import numpy as np
import pytest

from trms.errors import ConfigurationError, InputError, as_finite_array, check_in_range, check_seed


@pytest.mark.parametrize(
    "value, match",
    [
        ([1 + 2j], "complex values are not allowed"),
        (np.array([1.0, 2j]), "complex"),
        ("1.5", "text values"),
        ([[1.0], [1.0, 2.0]], "ragged nesting"),
        ([10**400], "beyond the float range"),
        ([object()], "not a number"),
        (np.ones(3, bool), r"booleans are not allowed \(write the values as numbers"),
        ([True, False], "booleans are not allowed"),
    ],
)
def test_as_finite_array_refuses_what_it_cannot_keep(value, match):
    with pytest.raises(InputError, match=match) as info:
        as_finite_array("x", value)
    assert str(info.value).startswith("x must be real numbers") and "\n" not in str(info.value)


def test_check_in_range_refuses_non_reals_with_the_range():
    for bad in (10**400, 1j, "2", None):
        with pytest.raises(ConfigurationError, match=r"ts must be a real number in \[0 s, 1 s\]"):
            check_in_range("ts", bad, 0, 1, unit=" s", error=ConfigurationError)


@pytest.mark.parametrize("bad", [-1, 1.5, 2.0, "3", True, np.float64(1.0), None])
def test_check_seed(bad):
    assert check_seed("seed", np.uint8(7)) == 7 and check_seed("seed", None) is None
    with pytest.raises(InputError, match="seed must be a non-negative integer"):
        check_seed("seed", bad, allow_none=False)
