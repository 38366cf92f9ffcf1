"""``make bench``: run every benchmark and print its figures against the targets.

Usage: ``python -m bench [--only planner,sim,tracking,daemon,channels,can,batch,bridge,station]
[--json FILE]``.
Figures are measurements on this machine; a target missed is shown, not hidden.
"""

from __future__ import annotations

import argparse
import importlib
import json
import sys
import time

SUITES = ("planner", "sim", "tracking", "daemon", "channels", "can", "batch", "bridge",
          "station")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench", description=__doc__.splitlines()[0])
    parser.add_argument("--only", default=",".join(SUITES),
                        help=f"comma-separated suites out of {', '.join(SUITES)}")
    parser.add_argument("--json", help="also write every figure to this JSON file")
    args = parser.parse_args(argv)
    chosen = [s.strip() for s in args.only.split(",") if s.strip()]
    unknown = sorted(set(chosen) - set(SUITES))
    if unknown:
        print(f"python -m bench: unknown suite(s) {unknown}; choose from {SUITES}",
              file=sys.stderr)
        return 2
    from rich.console import Console
    from rich.table import Table

    console = Console()
    figures: list[dict] = []
    for suite in chosen:
        t0 = time.perf_counter()
        console.print(f"[bold]bench {suite}[/] ...")
        module = importlib.import_module(f"bench.bench_{suite}")
        for fig in module.run():
            figures.append({"suite": suite, **fig})
        console.print(f"  done in {time.perf_counter() - t0:.1f} s")
    table = Table(title="hubo-ladder benchmarks")
    for col in ("suite", "figure", "value", "unit", "target", "met"):
        table.add_column(col)
    for f in figures:
        target = "" if f.get("target") is None else str(f["target"])
        met = "—" if f.get("target") is None or f.get("ok", False) is None else (
            "yes" if f.get("ok") else "[red]NO[/]")
        table.add_row(f["suite"], f["name"], str(f["value"]), f.get("unit", ""), target, met)
    console.print(table)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(figures, fh, indent=1, default=str)
    return 0


if __name__ == "__main__":
    sys.exit(main())
