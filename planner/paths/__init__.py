"""Motion between configurations.

- `interpolation`: contact-space recursive interpolation of the body between stances;
- `limb_path`: the moving limb's way-points (lift, carry, place);
- `limb_rrt`: an OMPL path for the limb where the way-point arcs fail.

Re-exported lazily: importing the package does not load placo or OMPL.
"""

from robot.lazy_exports import lazy_exports

_EXPORTS = {
    "InterpolationError": "interpolation",
    "InterpolationStats": "interpolation",
    "OMPL_SEED": "limb_rrt",
    "contact_space_interpolate": "interpolation",
    "foot_waypoints": "limb_path",
    "hand_waypoints": "limb_path",
    "plan_limb_path": "limb_rrt",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
