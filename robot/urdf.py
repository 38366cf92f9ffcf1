"""URDF text for a Hubo, written from its kinematic tree.

Loads in pinocchio, placo and yourdfpy. Capsules are written as cylinders (URDF has no
capsule); the planner's collision model is built from the tree itself, with real capsules.
"""

from __future__ import annotations

from xml.sax.saxutils import quoteattr

from robot.kinematic_tree import Frame, Geom, KinematicTree, Link, build_tree
from robot.params import RobotParams, robot_params


def _v(x) -> str:
    return " ".join(repr(float(c)) for c in x)


def _geom_xml(g: Geom, tag: str) -> str:
    if g.kind == "box":
        shape, origin = f'<box size="{_v(2 * h for h in g.half)}"/>', g.p0
    elif g.kind == "sphere":
        shape, origin = f'<sphere radius="{g.radius!r}"/>', g.p0
    else:  # capsule along z in the zero pose (all limbs hang along z)
        length = abs(g.p1[2] - g.p0[2])
        shape = f'<cylinder radius="{g.radius!r}" length="{length!r}"/>'
        origin = tuple((a + b) / 2 for a, b in zip(g.p0, g.p1, strict=True))
    return (f'<{tag}><origin xyz="{_v(origin)}" rpy="0 0 0"/>'
            f"<geometry>{shape}</geometry></{tag}>")


def _link_xml(lk: Link) -> str:
    ix, iy, iz = lk.inertia_kg_m2
    mass = max(lk.mass_kg, 1e-4)
    geoms = "".join(_geom_xml(g, "visual") + _geom_xml(g, "collision") for g in lk.geoms)
    return (
        f"<link name={quoteattr(lk.name)}><inertial><origin xyz=\"{_v(lk.com_m)}\" rpy=\"0 0 0\"/>"
        f'<mass value="{mass!r}"/><inertia ixx="{max(ix, 1e-6)!r}" ixy="0" ixz="0" '
        f'iyy="{max(iy, 1e-6)!r}" iyz="0" izz="{max(iz, 1e-6)!r}"/></inertial>{geoms}</link>'
    )


def _joint_xml(lk: Link) -> str:
    if lk.joint is None:
        name = f"{lk.name}_fixed"
        return (f'<joint name="{name}" type="fixed"><parent link="{lk.parent}"/>'
                f'<child link="{lk.name}"/><origin xyz="{_v(lk.origin_m)}" rpy="0 0 0"/></joint>')
    return (
        f'<joint name="{lk.joint}" type="revolute"><parent link="{lk.parent}"/>'
        f'<child link="{lk.name}"/><origin xyz="{_v(lk.origin_m)}" rpy="0 0 0"/>'
        f'<axis xyz="{_v(lk.axis)}"/><limit lower="{lk.lower_rad!r}" upper="{lk.upper_rad!r}" '
        f'effort="{lk.effort_nm!r}" velocity="{lk.velocity_rad_s!r}"/></joint>'
    )


def _frame_xml(f: Frame) -> str:
    # Operational frames become massless links on fixed joints (pinocchio/placo frames).
    return (f'<link name="{f.name}"/><joint name="{f.name}_fixed" type="fixed">'
            f'<parent link="{f.link}"/><child link="{f.name}"/>'
            f'<origin xyz="{_v(f.offset_m)}" rpy="0 0 0"/></joint>')


def urdf_from_tree(tree: KinematicTree) -> str:
    parts = [f'<?xml version="1.0"?>\n<robot name="{tree.robot}">']
    for lk in tree.links:
        parts.append(_link_xml(lk))
        if lk.parent is not None:
            parts.append(_joint_xml(lk))
    parts += [_frame_xml(f) for f in tree.frames]
    parts.append("</robot>\n")
    return "\n".join(parts)


def robot_urdf(robot: str | RobotParams = "drc-hubo") -> str:
    """The URDF of a robot, by name or parameter table."""
    p = robot_params(robot) if isinstance(robot, str) else robot
    return urdf_from_tree(build_tree(p))
