"""Parameter tables for the parametric Hubo models (hubo-facts §5).

One frozen table per robot. Everything else (kinematic tree, URDF, MJCF, limits) is
derived from it, so the models cannot drift apart. Lengths in metres, masses in kg,
angles in rad, torques in N·m, speeds in rad/s.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from robot.errors import InputError


@dataclass(frozen=True)
class RobotParams:
    """Dimensions, masses and limits of one Hubo variant (x forward, y left, z up)."""

    name: str
    # --- lengths [m]
    half_hip_width_m: float
    torso_to_hip_pitch_m: float
    thigh_m: float
    shin_m: float
    ankle_to_sole_m: float
    half_shoulder_width_m: float
    shoulder_above_torso_m: float
    upper_arm_m: float
    forearm_m: float
    wrist_to_palm_m: float
    neck_above_torso_m: float
    foot_length_m: float
    foot_width_m: float
    # --- masses [kg]
    mass_torso_kg: float
    mass_pelvis_kg: float
    mass_head_kg: float
    leg_masses_kg: dict[str, float]  # per leg link, keyed by joint suffix, plus "foot"
    arm_masses_kg: dict[str, float]  # per arm link, keyed by joint suffix, plus "hand"
    # --- limits
    position_limits_rad: dict[str, tuple[float, float]]  # by joint name; missing → ±3.14
    torque_limits_nm: dict[str, float]  # by joint suffix (e.g. "KN", "SP", "F1", "NKY")
    has_wrist_roll: bool = True
    #: The robot's name as users know it, for messages ("DRC-Hubo").
    title: str = ""
    # Nominal / maximum speeds per joint group [rad/s] (HuboCan description).
    speed_nominal_rad_s: dict[str, float] = field(
        default_factory=lambda: {"leg": 0.8, "knee": 0.4, "arm": 1.0, "finger": 1.0}
    )
    speed_max_rad_s: dict[str, float] = field(
        default_factory=lambda: {"leg": 7.0, "arm": 6.0, "finger": 10.0}
    )
    accel_nominal_rad_s2: float = 0.8
    # Reflected rotor inertia [kg·m²] per group: rotor ≈ 1.5e-5 kg·m² through a
    # 100–160:1 harmonic drive. Makes the simulated joints behave like geared joints.
    armature_kg_m2: dict[str, float] = field(
        default_factory=lambda: {"leg": 0.3, "arm": 0.15, "wrist": 0.05, "finger": 0.002,
                                 "neck": 0.01, "waist": 0.2}
    )

    @property
    def total_mass_kg(self) -> float:
        legs = 2 * sum(self.leg_masses_kg.values())
        arms = 2 * sum(self.arm_masses_kg.values())
        return self.mass_torso_kg + self.mass_pelvis_kg + self.mass_head_kg + legs + arms

    @property
    def pelvis_height_m(self) -> float:
        """Height of the torso origin (waist axis) above the floor in the zero pose."""
        return self.torso_to_hip_pitch_m + self.thigh_m + self.shin_m + self.ankle_to_sole_m


_DRC_LIMITS = {
    **{f"{s}HY": (-1.92, 1.92) for s in "RL"},
    **{f"{s}HR": (-0.52, 0.52) for s in "RL"},
    **{f"{s}HP": (-1.57, 1.57) for s in "RL"},
    **{f"{s}KN": (0.0, 2.61) for s in "RL"},
    **{f"{s}AP": (-1.70, 1.70) for s in "RL"},
    **{f"{s}AR": (-1.57, 1.57) for s in "RL"},
    "RSR": (-3.14, 0.26),
    "LSR": (-0.26, 3.14),
    "RSY": (-3.14, 2.0),
    "LSY": (-2.0, 3.14),
    "REB": (-2.65, 0.0),
    "LEB": (-2.65, 0.0),
}

_DRC_TORQUES = {
    "HP": 60.0, "KN": 60.0, "HR": 34.0, "AP": 34.0, "AR": 34.0, "HY": 27.0,
    "SP": 27.0, "SR": 27.0, "SY": 27.0, "WST": 27.0, "EB": 23.0, "WP": 8.9,
    "WY": 4.8, "WR": 4.8, "F": 5.0, "NK": 0.9,
}

DRC_HUBO = RobotParams(
    name="drc-hubo",
    title="DRC-Hubo",
    half_hip_width_m=0.0885,
    torso_to_hip_pitch_m=0.164,
    thigh_m=0.330,
    shin_m=0.330,
    ankle_to_sole_m=0.144,
    half_shoulder_width_m=0.2295,
    shoulder_above_torso_m=0.206,
    upper_arm_m=0.300,
    forearm_m=0.314,
    wrist_to_palm_m=0.118,
    neck_above_torso_m=0.260,
    foot_length_m=0.22,
    foot_width_m=0.14,
    mass_torso_kg=8.95,
    mass_pelvis_kg=3.86,
    mass_head_kg=1.1,
    leg_masses_kg={"HY": 1.03, "HR": 1.38, "HP": 3.40, "KN": 1.25, "AP": 2.01, "AR": 1.07,
                   "foot": 0.1},
    # upper arm on SY, elbow on EB, forearm on WY; the hand (0.55) is palm + 5 fingers.
    arm_masses_kg={"SP": 0.51, "SR": 0.48, "SY": 1.35, "EB": 0.27, "WY": 1.37, "WP": 0.30,
                   "WR": 0.47, "hand": 0.55},
    position_limits_rad=_DRC_LIMITS,
    torque_limits_nm=_DRC_TORQUES,
)

_HUBO2_LIMITS = {
    **_DRC_LIMITS,
    **{f"{s}HR": (-0.49, 0.49) for s in "RL"},
    **{f"{s}KN": (-0.07, 2.60) for s in "RL"},
    **{f"{s}AP": (-1.29, 1.69) for s in "RL"},
    **{f"{s}AR": (-0.19, 0.19) for s in "RL"},
    **{f"{s}EB": (-2.50, 0.07) for s in "RL"},
    **{f"{s}WP": (-1.64, 1.01) for s in "RL"},
    # No wrist roll on Hubo2+: the column stays in the file and must be 0.
    **{f"{s}WR": (0.0, 0.0) for s in "RL"},
}

HUBO2PLUS = RobotParams(
    name="hubo2plus",
    title="Hubo2+",
    half_hip_width_m=0.0885,
    # Sources give 0.18–0.32; this value makes thigh + shin + ankle + hip drop match the
    # published 0.991 m torso height with a 0.111 m ankle.
    torso_to_hip_pitch_m=0.280,
    thigh_m=0.300,
    shin_m=0.300,
    ankle_to_sole_m=0.111,
    half_shoulder_width_m=0.216,
    shoulder_above_torso_m=0.180,  # not published; chosen so the shoulder sits below the neck
    upper_arm_m=0.182,
    forearm_m=0.164,
    wrist_to_palm_m=0.076,
    neck_above_torso_m=0.197,
    foot_length_m=0.20,
    foot_width_m=0.13,
    mass_torso_kg=7.5,
    mass_pelvis_kg=3.4,
    mass_head_kg=0.5,
    leg_masses_kg={"HY": 1.03, "HR": 1.38, "HP": 3.36, "KN": 1.25, "AP": 2.01, "AR": 1.07,
                   "foot": 0.1},
    arm_masses_kg={"SP": 0.45, "SR": 0.45, "SY": 0.90, "EB": 0.25, "WY": 0.95, "WP": 0.40,
                   "WR": 0.0, "hand": 1.1},
    position_limits_rad=_HUBO2_LIMITS,
    torque_limits_nm={**_DRC_TORQUES, "HP": 50.0, "KN": 50.0, "HR": 50.0, "AP": 50.0,
                      "AR": 50.0, "HY": 50.0, "SP": 30.0, "SR": 30.0, "SY": 30.0, "EB": 20.0,
                      "WP": 5.0, "WY": 5.0, "WR": 5.0},
    has_wrist_roll=False,
)

ROBOTS: dict[str, RobotParams] = {p.name: p for p in (DRC_HUBO, HUBO2PLUS)}


def robot_params(name: str = "drc-hubo") -> RobotParams:
    """The parameter table of a robot by name (``drc-hubo`` or ``hubo2plus``)."""
    try:
        return ROBOTS[name]
    except KeyError:
        raise InputError(f"unknown robot {name!r}; choose one of {sorted(ROBOTS)}") from None
