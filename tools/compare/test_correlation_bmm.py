# SPDX-License-Identifier: Apache-2.0
"""correlation_bmm equals the reference's correlation (tools/reference/flownet2.py).

    .venv-reference/bin/python -m pytest -q -p no:cacheprovider tools/compare
"""

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "reference"))

import pytest  # noqa: E402
import torch  # noqa: E402

import flownet2  # noqa: E402
from correlation_bmm import correlation_bmm  # noqa: E402


@pytest.mark.parametrize("shape", [(1, 8, 6, 10), (2, 16, 12, 20), (1, 4, 3, 50), (1, 3, 30, 2)])
@pytest.mark.parametrize("max_displacement,stride2", [(20, 2), (4, 1), (6, 3)])
def test_equals_the_reference(shape, max_displacement, stride2):
    g = torch.Generator().manual_seed(sum(shape) + max_displacement)
    f1 = torch.randn(*shape, generator=g, dtype=torch.float64)
    f2 = torch.randn(*shape, generator=g, dtype=torch.float64)
    expected = flownet2.correlation(f1, f2, max_displacement, stride2)
    got = correlation_bmm(f1, f2, max_displacement, stride2)
    assert got.shape == expected.shape
    assert torch.allclose(got, expected, rtol=0, atol=1e-12)


def test_float32_at_flownetc_size():
    g = torch.Generator().manual_seed(3)
    f1 = torch.randn(1, 256, 12, 16, generator=g)
    f2 = torch.randn(1, 256, 12, 16, generator=g)
    expected = flownet2.correlation(f1.double(), f2.double())
    assert (correlation_bmm(f1, f2).double() - expected).abs().max() < 1e-6
