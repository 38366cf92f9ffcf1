"""Plots of a batch summary (matplotlib, Agg backend; files only, no windows).

- ``success_per_strategy.png``: success rate per ladder and strategy, Wilson error bars;
- ``success_vs_slope.png``, ``success_vs_spacing.png``: success rate per strategy against
  the ladder's slope [deg] and rung spacing [m], trials pooled over ladders with the
  same value;
- ``heatmap_<a>_<b>.png``: for a sweep of exactly two numeric parameters, the success
  rate over the grid, one panel per strategy (trials pooled over cells with the same
  pair of values).
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

from execute.batch.report import Summary
from execute.batch.stats import SuccessRate

__all__ = ["write_plots"]


def _pooled(summary: Summary, key) -> dict[str, dict]:
    """strategy → {x: SuccessRate} pooled over rows with the same key(row)."""
    acc: dict[str, dict] = defaultdict(lambda: defaultdict(lambda: [0, 0]))
    for r in summary.rows:
        k = key(r)
        if k is None:
            continue
        a = acc[r.strategy][k]
        a[0] += r.rate.successes
        a[1] += r.rate.n
    return {s: {k: SuccessRate(*v) for k, v in d.items()} for s, d in acc.items()}


def _errbars(rates: list[SuccessRate]) -> tuple[list[float], list[list[float]]]:
    y, lo, hi = [], [], []
    for r in rates:
        a, b = r.interval
        p = r.rate if r.n else float("nan")
        y.append(p)
        lo.append(0.0 if not r.n else p - a)
        hi.append(0.0 if not r.n else b - p)
    return y, [lo, hi]


def write_plots(summary: Summary, out_dir: str | Path) -> list[Path]:
    """Write the plots into ``out_dir``; returns the files written."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    files: list[Path] = []
    strategies = list(dict.fromkeys(r.strategy for r in summary.rows))
    ladders = list(dict.fromkeys(r.ladder for r in summary.rows))

    # success per strategy (grouped by ladder)
    if len(ladders) <= 40:
        fig, ax = plt.subplots(figsize=(max(5.0, 1.2 * len(ladders) * len(strategies) / 2), 4))
        width = 0.8 / max(1, len(strategies))
        x = np.arange(len(ladders))
        for i, s in enumerate(strategies):
            rates = [next(r.rate for r in summary.rows if r.ladder == lad and r.strategy == s)
                     for lad in ladders]
            y, err = _errbars(rates)
            ax.bar(x + (i - (len(strategies) - 1) / 2) * width, y, width, yerr=err, capsize=3,
                   label=s)
        ax.set_xticks(x, ladders, rotation=30 if len(ladders) > 6 else 0)
        ax.set_ylim(0, 1.05)
        ax.set_ylabel("success rate (95 % Wilson)")
        ax.set_title("success per strategy")
        ax.legend()
        fig.tight_layout()
        files.append(out / "success_per_strategy.png")
        fig.savefig(files[-1], dpi=110)
        plt.close(fig)

    for name, attr, label in (("slope", "slope_deg", "slope [deg]"),
                              ("spacing", "rung_spacing_m", "rung spacing [m]")):
        pooled = _pooled(summary, lambda r, a=attr: round(getattr(r, a), 6))
        fig, ax = plt.subplots(figsize=(5.5, 4))
        for s in strategies:
            xs = sorted(pooled.get(s, {}))
            y, err = _errbars([pooled[s][v] for v in xs])
            ax.errorbar(xs, y, yerr=err, marker="o", capsize=3, label=s)
        ax.set_ylim(-0.05, 1.05)
        ax.set_xlabel(label)
        ax.set_ylabel("success rate (95 % Wilson)")
        ax.set_title(f"success vs {name}")
        ax.legend()
        fig.tight_layout()
        files.append(out / f"success_vs_{name}.png")
        fig.savefig(files[-1], dpi=110)
        plt.close(fig)

    numeric = [f for f in summary.sweep_fields
               if all(isinstance(r.sweep.get(f), int | float) for r in summary.rows)]
    if len(summary.sweep_fields) == 2 and len(numeric) == 2:
        a, b = numeric
        pooled = _pooled(summary, lambda r: (r.sweep[a], r.sweep[b]))
        av = sorted({r.sweep[a] for r in summary.rows})
        bv = sorted({r.sweep[b] for r in summary.rows})
        fig, axes = plt.subplots(1, len(strategies), figsize=(4.2 * len(strategies), 3.8),
                                 squeeze=False)
        for ax, s in zip(axes[0], strategies, strict=True):
            grid = np.full((len(bv), len(av)), np.nan)
            for (x, y), rate in pooled.get(s, {}).items():
                if rate.n:
                    grid[bv.index(y), av.index(x)] = rate.rate
            im = ax.imshow(grid, origin="lower", vmin=0, vmax=1, cmap="viridis", aspect="auto")
            ax.set_xticks(range(len(av)), [f"{v:g}" for v in av], rotation=45)
            ax.set_yticks(range(len(bv)), [f"{v:g}" for v in bv])
            ax.set_xlabel(a)
            ax.set_ylabel(b)
            ax.set_title(s)
        fig.colorbar(im, ax=axes[0].tolist(), label="success rate")
        files.append(out / f"heatmap_{a}_{b}.png")
        fig.savefig(files[-1], dpi=110)
        plt.close(fig)
    return files
