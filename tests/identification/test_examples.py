"""The Examples sections of the identification modules run and print what they show."""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = ["frequency", "oe_bj", "pem", "rbf", "subspace", "validation"]


@pytest.mark.parametrize("name", MODULES)
def test_examples_run(name):
    module = importlib.import_module(f"trms.identification.{name}")
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
