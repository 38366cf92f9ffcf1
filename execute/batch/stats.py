"""Statistics of a batch: Wilson score intervals for success rates, and distributions.

A success rate from ``n`` Bernoulli trials with ``k`` successes gets the Wilson score
interval (Wilson 1927), which, unlike the normal approximation ``p ± z·√(p(1−p)/n)``,
stays inside [0, 1] and is not degenerate at 0/n or n/n:

    centre = (p + z²/2n) / (1 + z²/n)
    half   = z / (1 + z²/n) · √(p(1−p)/n + z²/4n²)

with ``p = k/n`` and ``z = 1.959964`` for 95 %. Example: 0/10 gives [0, 0.278].

Timing figures (planning time, simulated seconds per rung) are summarised as
min / median / p90 (linear interpolation between order statistics).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

__all__ = ["Z_95", "Distribution", "SuccessRate", "summarize", "wilson_interval"]

#: Two-sided 95 % standard-normal quantile.
Z_95 = 1.959963984540054


def wilson_interval(successes: int, n: int, z: float = Z_95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion.

    Args:
        successes: number of successes ``k`` (0 ≤ k ≤ n).
        n: number of trials; 0 gives the uninformative interval (0, 1).
        z: standard-normal quantile (1.96 for a 95 % interval).

    Returns:
        (low, high), both in [0, 1].

    Raises:
        ValueError: ``k`` outside [0, n] or ``n`` negative.
    """
    if n < 0 or not 0 <= successes <= n:
        raise ValueError(f"wilson_interval: need 0 <= successes <= n, got {successes}/{n}")
    if n == 0:
        return 0.0, 1.0
    p = successes / n
    z2 = z * z
    denom = 1.0 + z2 / n
    centre = (p + z2 / (2 * n)) / denom
    half = z / denom * math.sqrt(p * (1 - p) / n + z2 / (4 * n * n))
    # k = 0 and k = n give exactly 0 and 1 in theory; rounding must not move them.
    lo = 0.0 if successes == 0 else max(0.0, centre - half)
    hi = 1.0 if successes == n else min(1.0, centre + half)
    return lo, hi


@dataclass(frozen=True)
class SuccessRate:
    """``successes`` out of ``n`` with the 95 % Wilson interval [low, high]."""

    successes: int
    n: int

    @property
    def rate(self) -> float:
        """Observed success fraction (NaN when n = 0)."""
        return self.successes / self.n if self.n else math.nan

    @property
    def interval(self) -> tuple[float, float]:
        """95 % Wilson interval."""
        return wilson_interval(self.successes, self.n)

    def __str__(self) -> str:
        if not self.n:
            return "– (0 runs)"
        lo, hi = self.interval
        return f"{self.successes}/{self.n} = {self.rate:.0%} [{lo:.0%}, {hi:.0%}]"


@dataclass(frozen=True)
class Distribution:
    """min / median / p90 of a sample (all NaN when it is empty); units are the caller's."""

    n: int
    min: float
    median: float
    p90: float

    def __str__(self) -> str:
        if not self.n:
            return "–"
        return f"{self.min:.3g} / {self.median:.3g} / {self.p90:.3g} (n={self.n})"


def _quantile(sorted_values: list[float], q: float) -> float:
    pos = q * (len(sorted_values) - 1)
    lo = math.floor(pos)
    hi = min(lo + 1, len(sorted_values) - 1)
    return sorted_values[lo] + (sorted_values[hi] - sorted_values[lo]) * (pos - lo)


def summarize(values: Iterable[float | None]) -> Distribution:
    """min, median and 90th percentile of the finite values (None and NaN are skipped)."""
    v = sorted(float(x) for x in values if x is not None and math.isfinite(x))
    if not v:
        return Distribution(0, math.nan, math.nan, math.nan)
    return Distribution(len(v), v[0], _quantile(v, 0.5), _quantile(v, 0.9))
