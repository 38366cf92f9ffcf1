"""Wilson intervals against hand-computed values, and the min/median/p90 summaries."""

from __future__ import annotations

import math

import pytest

from execute.batch.stats import SuccessRate, summarize, wilson_interval

# Hand-computed with z = 1.959964 (z² = 3.841459), denominator 1 + z²/n:
#   0/10:  centre = 0.192073 / 1.384146 = 0.138766;
#          half = 1.959964 / 1.384146 · √(0 + 0.009604) = 1.416008 · 0.097998 = 0.138766
#          → [0, 0.277533]
#   5/10:  centre = 0.5; half = 1.416008 · √(0.025 + 0.009604) = 1.416008 · 0.186020
#          = 0.263407 → [0.236593, 0.763407]
#   10/10: the mirror of 0/10 → [0.722467, 1]
#   1/4:   centre = (0.25 + 0.480182) / 1.960365 = 0.372476;
#          half = 0.999796 · √(0.046875 + 0.060023) = 0.999796 · 0.326952 = 0.326885
#          → [0.045591, 0.699361]
HAND = [
    (0, 10, 0.0, 0.277533),
    (5, 10, 0.236593, 0.763407),
    (10, 10, 0.722467, 1.0),
    (1, 4, 0.045591, 0.699361),
]


@pytest.mark.parametrize("k,n,lo,hi", HAND)
def test_wilson_matches_hand_computation(k, n, lo, hi):
    a, b = wilson_interval(k, n)
    assert a == pytest.approx(lo, abs=1e-5)
    assert b == pytest.approx(hi, abs=1e-5)


def test_wilson_edges_and_errors():
    assert wilson_interval(0, 0) == (0.0, 1.0)
    lo, hi = wilson_interval(3, 3)
    assert 0.0 < lo < 1.0 and hi == 1.0
    assert wilson_interval(0, 7)[0] == 0.0 and wilson_interval(10, 10)[1] == 1.0
    with pytest.raises(ValueError, match="11/10"):
        wilson_interval(11, 10)
    with pytest.raises(ValueError):
        wilson_interval(-1, 10)


def test_success_rate_text_and_nan():
    assert str(SuccessRate(5, 10)) == "5/10 = 50% [24%, 76%]"
    assert math.isnan(SuccessRate(0, 0).rate)
    assert "0 runs" in str(SuccessRate(0, 0))


def test_summarize_min_median_p90():
    d = summarize([float(x) for x in range(1, 11)] + [None, math.nan])
    assert (d.n, d.min, d.median, d.p90) == (10, 1.0, 5.5, pytest.approx(9.1))
    one = summarize([2.5])
    assert (one.min, one.median, one.p90) == (2.5, 2.5, 2.5)
    empty = summarize([])
    assert empty.n == 0 and math.isnan(empty.median) and str(empty) == "–"
