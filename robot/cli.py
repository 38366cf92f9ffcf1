"""``python -m robot``: the robot models as files.

    python -m robot export [--robot drc-hubo|hubo2plus] --format urdf|mjcf [--ladder L]
                           -o FILE

``export`` writes the model generated from the robot's parameter table
(`robot.params` → `robot.kinematic_tree`): the URDF of `robot.urdf` (for RViz-style tools,
``check_urdf``, pinocchio, yourdfpy) or the MJCF of `robot.mjcf` (the robot standing on a
floor, its 40 position actuators, the ``home`` keyframe). With ``--ladder`` (MJCF only) it
writes the whole MuJoCo scene ``validate-plan`` and the sim daemon run: floor, ladder,
robot at its start pose, side camera (`ladders.scene`). ``-o -`` writes to stdout. When
``--format`` is left out, the file's suffix says it (``.urdf``; ``.xml``, ``.mjcf``).

This command is the one place where ``robot`` reaches above itself: ``--ladder`` imports
`ladders` inside the subcommand. The library modules of ``robot`` import nothing of the
project above them.

Exit codes: 0 written, 2 bad input (unknown robot or ladder, URDF with a ladder, a file
that cannot be written).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from robot.errors import InputError, run_cli

__all__ = ["export_text", "main"]

FORMATS = ("urdf", "mjcf")
_SUFFIX_FORMAT = {".urdf": "urdf", ".xml": "mjcf", ".mjcf": "mjcf"}


def export_text(robot: str, fmt: str, ladder: str | None = None) -> str:
    """The model as text.

    Args:
        robot: robot name (`robot.params.ROBOTS`).
        fmt: ``"urdf"`` or ``"mjcf"``.
        ladder: with ``"mjcf"``, a ladder name or spec file: the whole scene.

    Raises:
        InputError: unknown robot, format or ladder; a ladder with URDF.
    """
    from robot.params import robot_params

    params = robot_params(robot)
    if fmt not in FORMATS:
        raise InputError(f"--format {fmt!r}: choose one of {', '.join(FORMATS)}")
    if fmt == "urdf":
        if ladder is not None:
            raise InputError("--ladder needs --format mjcf: a URDF describes one robot, "
                             "not a scene")
        from robot.urdf import robot_urdf

        return robot_urdf(params)
    if ladder is None:
        from robot.mjcf import robot_spec

        spec = robot_spec(params)
    else:
        from ladders.loader import load_ladder
        from ladders.scene import build_scene

        spec = build_scene(load_ladder(ladder), params)
    spec.compile()  # to_xml() writes a compiled spec; a model error surfaces here
    return spec.to_xml()


def _format(args) -> str:
    if args.format:
        return args.format
    suffix = Path(args.output).suffix.lower()
    if suffix in _SUFFIX_FORMAT:
        return _SUFFIX_FORMAT[suffix]
    raise InputError(f"-o {args.output}: give --format urdf or mjcf (the suffix "
                     f"{suffix or '(none)'} does not say which)")


def _export(args) -> int:
    fmt = _format(args)
    text = export_text(args.robot, fmt, args.ladder)
    if args.output == "-":
        sys.stdout.write(text)
        return 0
    out = Path(args.output)
    try:
        out.write_text(text)
    except OSError as exc:
        raise InputError(f"-o {out}: cannot write: {exc.strerror}") from None
    what = f"{args.robot} on the {args.ladder} ladder" if args.ladder else args.robot
    print(f"robot export: {out}: {fmt.upper()} of {what}, {len(text)} bytes", file=sys.stderr)
    return 0


def _parser() -> argparse.ArgumentParser:
    from robot.params import ROBOTS

    p = argparse.ArgumentParser(prog="python -m robot", description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="command", required=True)
    e = sub.add_parser("export", help="write the URDF or MJCF model (or MJCF scene)")
    e.add_argument("--robot", default="drc-hubo", choices=sorted(ROBOTS),
                   help="robot (default drc-hubo)")
    e.add_argument("--format", choices=FORMATS,
                   help="urdf or mjcf (default: from the suffix of -o)")
    e.add_argument("--ladder", metavar="L",
                   help="MJCF only: the whole scene with this ladder (name or spec file)")
    e.add_argument("-o", "--output", required=True, metavar="FILE",
                   help="the file to write; - for stdout")
    return p


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``python -m robot``; returns the exit code."""
    args = _parser().parse_args(argv)
    return run_cli("robot export", lambda: _export(args))


if __name__ == "__main__":
    sys.exit(main())
