"""``python -m ladders``: show a ladder (parameters, mesh, side picture) or check a spec file.

- ``python -m ladders show LADDER [--out DIR]``: prints the parameters with their units and
  allowed ranges, writes ``DIR/NAME.glb`` (mesh) and ``DIR/NAME.png`` (side view).
- ``python -m ladders check FILE.yaml``: validates a spec; exit 2 names the line and field.
"""

from __future__ import annotations

import argparse
from dataclasses import fields
from pathlib import Path

from ladders.geometry import LadderGeometry
from ladders.loader import load_ladder
from ladders.spec import FIELD_RULES, LadderSpec
from robot.errors import run_cli


def parameter_rows(spec: LadderSpec) -> list[tuple[str, str, str, str]]:
    """(field, value, unit, meaning and allowed range) for every field of a spec."""
    rows = []
    for f in fields(spec):
        rule = FIELD_RULES[f.name]
        value = getattr(spec, f.name)
        if value is None:  # a part the ladder does not have (its landing)
            shown = "none"
        elif isinstance(value, bool):
            shown = str(value).lower()
        else:
            shown = f"{value:g}" if isinstance(value, float) else str(value)
        rows.append((f.name, shown, rule.unit, f"{rule.doc}; allowed {rule.describe()}"))
    return rows


def side_view_png(spec: LadderSpec, path: Path) -> Path:
    """Side view (world x–z) of rungs, rails, stringers and the landing, with the start
    sole, as PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon

    geom = LadderGeometry(spec)
    fig, ax = plt.subplots(figsize=(6, 7))
    slabs = tuple(s for s in geom.landing if s.kind == "box")
    for solid in geom.stringers + geom.rungs + slabs:
        h = solid.half_extents_m
        if solid.kind == "cylinder" and solid.name.startswith("rung"):
            centre = solid.centre_m
            ax.add_patch(plt.Circle((centre[0], centre[2]), solid.radius_m, color="tab:orange"))
            continue
        corners = [[sx * h[0], 0.0, sz * h[2]] for sx, sz in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
        pts = [solid.T_world_solid[:3, :3] @ c + solid.centre_m for c in corners]
        color = ("tab:orange" if solid.name.startswith("rung") else
                 "tab:brown" if solid.name == "landing" else "0.8")
        ax.add_patch(Polygon([(p[0], p[2]) for p in pts], closed=True, color=color,
                             zorder=1 if color == "0.8" else 2,
                             label="top landing" if solid.name == "landing" else None))
    p0, p1 = geom.rail_axis("left")
    ax.plot([p0[0], p1[0]], [p0[2], p1[2]], color="0.4", lw=3, label="handrail axis")
    for solid in geom.landing:
        if solid.kind == "cylinder":  # a handrail over the landing, axis along local z
            ends = [solid.centre_m + sign * solid.half_extents_m[2] * solid.R_world_solid[:, 2]
                    for sign in (-1, 1)]
            ax.plot([e[0] for e in ends], [e[2] for e in ends], color="0.4", lw=3)
    ax.plot([-0.11, 0.11], [0.0, 0.0], color="tab:blue", lw=4, label="robot's sole at start")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.set_aspect("equal")
    lo, hi = geom.bounds_m()
    ax.set_xlim(min(lo[0], -0.3) - 0.1, hi[0] + 0.1)
    ax.set_ylim(-0.05, hi[2] + 0.1)
    ax.set_xlabel("x [m] (forward)")
    ax.set_ylabel("z [m] (up)")
    ax.set_title(f"{spec.name}: {spec.slope_deg:g}°, {spec.num_rungs} rungs, "
                 f"{spec.rung_spacing_m:g} m apart")
    ax.legend(loc="upper left")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _show(args: argparse.Namespace) -> int:
    from rich.table import Table

    from ladders.mesh import export_ladder_mesh
    from robot.text_console import text_console

    spec = load_ladder(args.ladder)
    table = Table(title=f"ladder {spec.name}")
    for col in ("field", "value", "unit", "meaning"):
        table.add_column(col)
    for row in parameter_rows(spec):
        table.add_row(*row)
    console = text_console()  # spec names and paths verbatim
    console.print(table)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    mesh = export_ladder_mesh(spec, out / f"{spec.name}.glb")
    png = side_view_png(spec, out / f"{spec.name}.png")
    console.print(f"wrote {mesh} and {png}")
    return 0


def _check(args: argparse.Namespace) -> int:
    spec = load_ladder(args.file)
    print(f"{args.file}: ladder '{spec.name}' is valid")
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m ladders", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    show = sub.add_parser("show", help="print a ladder's parameters; write its mesh and picture")
    show.add_argument("ladder", help="bundled name (drc, ship, stair) or a .yaml file")
    show.add_argument("--out", default=".", help="directory for NAME.glb and NAME.png")
    show.set_defaults(run=_show)
    check = sub.add_parser("check", help="validate a ladder spec file")
    check.add_argument("file")
    check.set_defaults(run=_check)
    args = parser.parse_args(argv)
    return run_cli("python -m ladders", lambda: args.run(args))
