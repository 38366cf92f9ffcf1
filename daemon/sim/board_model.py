"""The MuJoCo board model: the motor boards, sensors and grip of a Hubo, in simulation.

This is the daemon's ``sim`` backend and what ``validate-plan`` steps in lock-step. It
takes the control law's output each 5 ms tick (`daemon.joint_control.ControlOutput`) and
advances the physics by one tick.

Time step: ``physics_dt_s = 1.25 ms``, four physics steps per 5 ms tick. The boards
update their motors every physics step (the JMC's loop runs faster than the daemon's, as
here), the daemon's references and duties change once per tick. The step comes from a
convergence test on the stance feet (docs/decisions/physics-timestep.md): at 2.5 ms the
soles on `stair`'s rung 0 crept 1.0 cm in 50 s, at 1.25 ms and at 0.625 ms 0.1 cm or
less.

Actuation, per joint, two MuJoCo actuators on the same hinge:

- *position* (``robot.mjcf``'s actuator, unchanged): ``τ = kp·(ref − q) − kv·q̇``
  saturated at the joint's torque limit, ``kp`` reaching the limit at 0.02 rad of error
  (``robot.mjcf.position_gains``). This is the board's high-gain position loop. Its
  derivative acts on the error, as a board's PD does: the actuator's ``−kv·q̇`` plus a
  ``kv·ṙef`` feed-forward folded into the control (``ctrl = ref + (kv/kp)·ṙef``, ṙef
  from the change of the sent reference over the tick); without it the loop would lag a
  moving reference by ``kv/kp`` ≈ 20 ms. We keep
  it inside MuJoCo rather than computing it in numpy because ``implicitfast`` then
  integrates its damping implicitly, which keeps a stiff geared joint stable.
- *PWM* (added here, ``<joint>_pwm``): an affine actuator that is the DC-motor model of
  `robot.motors`: ``τ = g·duty − b·q̇`` with ``g = −η·gear·Kt·V/(100·R)`` and
  ``b = η·gear²·Kt·Ke/R``; the battery voltage ``V`` scales ``g``. The back-EMF damping
  ``b`` is large (≈ 56 N·m·s/rad at a shoulder) and is again integrated implicitly. The
  motor's torque is not clamped: over-current trips the board instead.

In each tick exactly one of the two is live per joint (the board is in position or PWM
mode, ``ControlOutput.pwm``); a tripped board has both off (motor unpowered: no torque,
no back-EMF braking).

Board trips: `daemon.sim.board_trip` (boards grouped as on the robot; the wrist roll shares
its board with the fingers, whose grip then lets go). Grip: `daemon.sim.grasp_latch`.
Sensors: `daemon.sim.sensors`; motor currents and battery power from `robot.motors`.

Size: one class, `BoardModel`, whose tick (actuation, physics, trips, latches, sensors)
works on one MuJoCo model and data.
"""

from __future__ import annotations

import dataclasses
import logging
import math
from dataclasses import dataclass, field

import mujoco
import numpy as np

from daemon.joint_control import ControlOutput
from daemon.sim.board_trip import BOARDS, BoardTripConfig, BoardTripMonitor, TripEvent
from daemon.sim.grasp_latch import GraspEvent, GraspLatch, GripConfig
from daemon.sim.sensors import SensorIndex, SensorReading, add_sensors, read_sensors
from ladders.geometry import wrap_rad
from ladders.scene import build_scene
from ladders.spec import LadderSpec
from robot.constants import TICK_S
from robot.errors import InputError
from robot.joints import FINGER_JOINTS, JOINT_INDEX, JOINT_NAMES, NUM_JOINTS
from robot.limits import joint_limits
from robot.motors import DEFAULT_BATTERY_V, MotorTable, battery_power, motor_table
from robot.params import robot_params

__all__ = ["BoardModel", "BoardModelConfig", "BoardState", "PlacementError",
           "default_config"]

log = logging.getLogger(__name__)

@dataclass(frozen=True)
class PlacementError:
    """How far the real ladder is from where the plan assumed: shift and yaw of the
    ladder frame in the world [m, m, rad]."""

    dx_m: float = 0.0
    dy_m: float = 0.0
    dyaw_rad: float = 0.0

    @classmethod
    def parse(cls, text: str) -> PlacementError:
        """``"dx,dy,dyaw"`` [m, m, rad]."""
        parts = text.split(",")
        try:
            vals = [float(p) for p in parts]
        except ValueError:
            vals = []
        if len(vals) != 3 or not all(math.isfinite(v) for v in vals):
            raise InputError(f"--placement-error {text!r}: expected three numbers "
                             "dx,dy,dyaw in m, m, rad (e.g. 0.03,0,0)")
        if max(abs(vals[0]), abs(vals[1])) > 1.0 or abs(vals[2]) > math.pi / 2:
            raise InputError(f"--placement-error {text!r}: |dx|, |dy| must be ≤ 1 m and "
                             "|dyaw| ≤ π/2 rad")
        return cls(*vals)

    @classmethod
    def between(cls, planned: LadderSpec, real: LadderSpec) -> PlacementError:
        """The error that `apply` turns ``planned`` into ``real`` with."""
        return cls(real.placement_x_m - planned.placement_x_m,
                   real.placement_y_m - planned.placement_y_m,
                   wrap_rad(real.placement_yaw_rad - planned.placement_yaw_rad))

    def apply(self, ladder: LadderSpec) -> LadderSpec:
        """The ladder as it really stands."""
        return dataclasses.replace(ladder, placement_x_m=ladder.placement_x_m + self.dx_m,
                                   placement_y_m=ladder.placement_y_m + self.dy_m,
                                   placement_yaw_rad=wrap_rad(ladder.placement_yaw_rad
                                                              + self.dyaw_rad))

    def __bool__(self) -> bool:
        return any((self.dx_m, self.dy_m, self.dyaw_rad))


@dataclass(frozen=True)
class BoardModelConfig:
    """Attributes:
        battery_v: battery bus voltage [V] (PWM torque scales with it).
        physics_dt_s: physics step; must divide the 5 ms tick [s].
        trip: board protection thresholds.
        grip: grasp latch thresholds.
        gyro_bias_rad_s: what the IMUs' gyros read at rest, ``wx, wy, wz`` [rad/s]. The
            default, 0.006°/s about z and 0.003°/s about x and y (about 20°/h and 10°/h),
            is the in-run bias instability of a tactical-grade MEMS gyro: what is left
            after ``iniSensors`` zeroes it at rest (docs/decisions/gyro-heading.md).
    """

    battery_v: float = DEFAULT_BATTERY_V
    physics_dt_s: float = 0.00125
    gyro_bias_rad_s: tuple[float, float, float] = (5e-5, -5e-5, 1e-4)
    trip: BoardTripConfig = field(default_factory=BoardTripConfig)
    grip: GripConfig = field(default_factory=GripConfig)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.battery_v) and 10.0 <= self.battery_v <= 60.0):
            raise InputError(f"battery voltage {self.battery_v!r} V: allowed [10, 60] V "
                             "(a 48 V pack runs 40–54 V)")
        n = TICK_S / self.physics_dt_s
        if abs(n - round(n)) > 1e-9 or round(n) < 1:
            raise InputError(f"physics_dt_s = {self.physics_dt_s}: must divide the 5 ms tick")


def default_config() -> BoardModelConfig:
    """48 V, 1.25 ms physics, 0.5 s trips, the grip of `daemon.sim.grasp_latch`."""
    return BoardModelConfig()


@dataclass(frozen=True, eq=False)
class BoardState:
    """What the boards report after a tick (hubo-state units), arrays of shape (40,).

    Attributes:
        time_s: simulated time [s].
        ref_rad: reference the board ran on [rad].
        pos_rad, vel_rad_s: encoder position [rad] and velocity [rad/s].
        torque_nm: joint torque the motor applied [N·m].
        cur_a: motor current [A].
        duty_pct: PWM duty [%] (PWM joints).
        pwm: board in PWM mode.
        active: motor powered (its board has not tripped).
        sensors: FT and IMU readings.
        power_v, power_a, power_w: battery voltage [V], current [A], power [W].
    """

    time_s: float
    ref_rad: np.ndarray
    pos_rad: np.ndarray
    vel_rad_s: np.ndarray
    torque_nm: np.ndarray
    cur_a: np.ndarray
    duty_pct: np.ndarray
    pwm: np.ndarray
    active: np.ndarray
    sensors: SensorReading
    power_v: float
    power_a: float
    power_w: float


class BoardModel:
    """The simulated robot, its boards, sensors and grip on a ladder.

    Args:
        ladder: the ladder as it really stands (apply a `PlacementError` first).
        robot: robot name.
        config: tunables; `default_config` when None.
    """

    def __init__(self, ladder: LadderSpec, robot: str = "drc-hubo",
                 config: BoardModelConfig | None = None):
        self.config = config or default_config()
        self.ladder = ladder
        self.robot = robot
        self.params = robot_params(robot)
        self.limits = joint_limits(robot)
        self.motors: MotorTable = motor_table()
        spec = build_scene(ladder, robot)
        spec.option.timestep = self.config.physics_dt_s
        self._substeps = round(TICK_S / self.config.physics_dt_s)
        present = [n for n in JOINT_NAMES if spec.joint(n) is not None]
        for name in present:
            act = spec.add_actuator(name=f"{name}_pwm", target=name,
                                    trntype=mujoco.mjtTrn.mjTRN_JOINT)
            act.gaintype = mujoco.mjtGain.mjGAIN_FIXED
            act.biastype = mujoco.mjtBias.mjBIAS_AFFINE
            act.gainprm[0] = 0.0
        for hand, side in (("left", "L"), ("right", "R")):
            spec.add_equality(name=f"grasp_{hand}", type=mujoco.mjtEq.mjEQ_WELD,
                              objtype=mujoco.mjtObj.mjOBJ_BODY, name1=f"{side}_hand",
                              name2="ladder", active=False)
        add_sensors(spec)
        for key in spec.keys:
            key.ctrl = list(key.ctrl) + [0.0] * len(present)
        self.spec = spec
        self.model = spec.compile()
        self.data = mujoco.MjData(self.model)
        m = self.model
        self.cols = np.array([JOINT_INDEX[n] for n in present])
        self.pos_act = np.array([mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, n)
                                 for n in present])
        self.pwm_act = np.array([mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR,
                                                   f"{n}_pwm") for n in present])
        jids = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n) for n in present]
        self.qpos_adr = np.array([m.jnt_qposadr[j] for j in jids])
        self.dof_adr = np.array([m.jnt_dofadr[j] for j in jids])
        self._kp0 = m.actuator_gainprm[self.pos_act, 0].copy()
        self._kv0 = -m.actuator_biasprm[self.pos_act, 2].copy()
        self._sensor_index = SensorIndex(m)
        self._gyro_bias_rad_s = np.asarray(self.config.gyro_bias_rad_s, dtype=float)
        self._separate_fingers_from_rails()
        self.trips = BoardTripMonitor(self.limits.torque_max_nm, self.config.trip)
        rails = {}
        for side in ("left", "right"):
            rails[f"rail_{side}"] = (
                mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, f"rail_{side}_p0"),
                mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, f"rail_{side}_p1"),
                mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, f"rail_{side}"))
        self.latches: dict[str, GraspLatch] = {}
        for hand in ("left", "right"):
            fingers = FINGER_JOINTS[hand]
            fq = np.array([m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f)]
                           for f in fingers])
            eq = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, f"grasp_{hand}")
            self.latches[hand] = GraspLatch(m, self.data, hand, eq, fq,
                                            np.array([JOINT_INDEX[f] for f in fingers]),
                                            rails, ladder.friction, ladder.rail_radius_m,
                                            self.config.grip)
        self._wrist_roll_board = {"left": "EJMC5", "right": "EJMC4"}
        self.reset()

    # ------------------------------------------------------------------ setup
    def _separate_fingers_from_rails(self) -> None:
        """Fingers collide with rungs, stringers and floor but not with the rails.

        The finger capsules of the robot model curl through the grip centre (at ≈ 0.7 rad
        of curl a finger passes where a grasped rail's axis is), so finger–rail contact
        would stop the fingers half-way and shove the hand off the rail. The grip on a
        rail is the latch (`daemon.sim.grasp_latch`), so finger–rail contact is switched off
        with two extra contact bits: fingers (4/8), non-rail environment (+8/+4).
        """
        m = self.model
        finger_bodies = {i for i in range(m.nbody) if "_finger" in m.body(i).name}
        ladder = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "ladder")
        for g in range(m.ngeom):
            body = int(m.geom_bodyid[g])
            name = m.geom(g).name
            if body in finger_bodies:
                m.geom_contype[g], m.geom_conaffinity[g] = 4, 8
            elif (body == ladder and not name.startswith("rail_")) or name == "floor":
                m.geom_contype[g] |= 8
                m.geom_conaffinity[g] |= 4

    def reset(self, q_rad: np.ndarray | None = None,
              sole_targets_m: dict[str, np.ndarray] | None = None) -> None:
        """Robot at rest in joint pose ``q_rad`` (40,) (zero pose if None), standing.

        The floating base is turned so that the left sole lies flat and faces the world's
        x axis, as a plan's start stance has its soles (and as the motion layer's
        estimator assumes): a plan for a ladder placed at a yaw starts with the pelvis
        turned towards it on straight feet, and an upright base would turn the whole
        robot away from its plan by that yaw. It is then lowered until the lowest sole
        touches the floor and, with ``sole_targets_m`` (``"left"``/``"right"`` → sole
        position [m]), shifted so the soles' mean matches the targets' mean horizontally.
        """
        m, d = self.model, self.data
        mujoco.mj_resetDataKeyframe(m, d, 0)
        q = np.zeros(NUM_JOINTS) if q_rad is None else np.asarray(q_rad, dtype=float)
        d.qpos[self.qpos_adr] = q[self.cols]
        d.qpos[3:7] = (1.0, 0.0, 0.0, 0.0)
        mujoco.mj_kinematics(m, d)
        # with the base upright, the sole's orientation is the base's frame to the sole's;
        # the base's orientation that levels the sole is its transpose
        base_quat = np.zeros(4)
        mujoco.mju_mat2Quat(base_quat, d.site("L_sole").xmat.reshape(3, 3).T.flatten())
        d.qpos[3:7] = base_quat
        mujoco.mj_kinematics(m, d)
        soles = {h: d.site(f"{h[0].upper()}_sole").xpos.copy() for h in ("left", "right")}
        shift = np.zeros(3)
        shift[2] = -min(p[2] for p in soles.values())
        if sole_targets_m:
            got = np.mean([soles[h] for h in sole_targets_m], axis=0)
            want = np.mean([np.asarray(p) for p in sole_targets_m.values()], axis=0)
            shift[:2] = (want - got)[:2]
        d.qpos[:3] += shift
        d.qvel[:] = 0.0
        d.ctrl[:] = 0.0
        d.ctrl[self.pos_act] = q[self.cols]
        self._pwm_mask = np.zeros(len(self.cols), dtype=bool)
        self._off_mask = np.zeros(len(self.cols), dtype=bool)
        self._duty = np.zeros(NUM_JOINTS)
        self._ref = q.copy()
        self._set_actuation(self._pwm_mask, self._off_mask)
        self.trips.reset()
        for latch in self.latches.values():
            latch.reset()
        mujoco.mj_forward(m, d)

    def set_battery(self, battery_v: float) -> None:
        """Change the bus voltage [V] (takes effect for PWM joints at once)."""
        self.config = dataclasses.replace(self.config, battery_v=battery_v)
        self._set_actuation(self._pwm_mask, self._off_mask)

    def _set_actuation(self, pwm: np.ndarray, off: np.ndarray) -> None:
        m = self.model
        pos_on = ~pwm & ~off
        pwm_on = pwm & ~off
        m.actuator_gainprm[self.pos_act, 0] = np.where(pos_on, self._kp0, 0.0)
        m.actuator_biasprm[self.pos_act, 1] = np.where(pos_on, -self._kp0, 0.0)
        m.actuator_biasprm[self.pos_act, 2] = np.where(pos_on, -self._kv0, 0.0)
        gain = self.motors.torque_per_duty(self.config.battery_v)[self.cols]
        damp = self.motors.back_emf_damping[self.cols]
        m.actuator_gainprm[self.pwm_act, 0] = np.where(pwm_on, gain, 0.0)
        m.actuator_biasprm[self.pwm_act, 2] = np.where(pwm_on, -damp, 0.0)

    # ------------------------------------------------------------------ tick
    @property
    def time_s(self) -> float:
        return float(self.data.time)

    def joint_pos(self) -> np.ndarray:
        """Encoder positions [rad], shape (40,) (0 for columns without a joint)."""
        q = np.zeros(NUM_JOINTS)
        q[self.cols] = self.data.qpos[self.qpos_adr]
        return q

    def joint_vel(self) -> np.ndarray:
        """Joint velocities [rad/s], shape (40,)."""
        v = np.zeros(NUM_JOINTS)
        v[self.cols] = self.data.qvel[self.dof_adr]
        return v

    def joint_torque(self) -> np.ndarray:
        """Motor torque at each joint [N·m], shape (40,)."""
        t = np.zeros(NUM_JOINTS)
        f = self.data.actuator_force
        t[self.cols] = f[self.pos_act] + f[self.pwm_act]
        return t

    def apply(self, out: ControlOutput) -> None:
        """Load one tick of the control law's output into the boards."""
        pwm = np.asarray(out.pwm, dtype=bool)[self.cols]
        off = self.trips.tripped[self.cols]
        if not (np.array_equal(pwm, self._pwm_mask) and np.array_equal(off, self._off_mask)):
            self._pwm_mask, self._off_mask = pwm, off.copy()
            self._set_actuation(pwm, off)
        ref = np.asarray(out.ref_sent_rad, dtype=float)[self.cols]
        ref_vel = (ref - self._ref[self.cols]) / TICK_S
        # D on the error: kp·(ref − q) + kv·(ṙef − q̇) = kp·(ref + (kv/kp)·ṙef − q) − kv·q̇
        self.data.ctrl[self.pos_act] = ref + self._kv0 / self._kp0 * ref_vel
        self.data.ctrl[self.pwm_act] = out.duty_pct[self.cols]
        self._duty = np.where(out.pwm, out.duty_pct, 0.0)
        self._ref = np.array(out.ref_sent_rad, dtype=float)

    def step(self) -> tuple[list[TripEvent], list[GraspEvent]]:
        """Advance one 5 ms tick; returns the board trips and grip events it caused."""
        m, d = self.model, self.data
        dt = m.opt.timestep
        trips: list[TripEvent] = []
        for _ in range(self._substeps):
            mujoco.mj_step(m, d)
            new = self.trips.update(self.joint_torque(), dt, float(d.time))
            if new:
                trips += new
                for ev in new:
                    log.info("%s", ev)
                self._off_mask = self.trips.tripped[self.cols].copy()
                self._set_actuation(self._pwm_mask, self._off_mask)
        grasps: list[GraspEvent] = []
        for hand, latch in self.latches.items():
            finger_ok = not self.trips.tripped[JOINT_INDEX[BOARDS[
                self._wrist_roll_board[hand]][1]]]
            ev = latch.update(float(d.time), TICK_S, self._ref[latch.finger_cols], finger_ok)
            if ev is not None:
                log.info("%s", ev)
                grasps.append(ev)
        return trips, grasps

    # ------------------------------------------------------------------ report
    def state(self) -> BoardState:
        """The boards' report of the current instant."""
        tau = self.joint_torque()
        vel = self.joint_vel()
        v = self.config.battery_v
        amps, watts = battery_power(tau, vel, v, self.motors)
        active = ~self.trips.tripped.copy()
        pwm = np.zeros(NUM_JOINTS, dtype=bool)
        pwm[self.cols] = self._pwm_mask
        sensors = read_sensors(self.data, self._sensor_index, self._gyro_bias_rad_s)
        return BoardState(self.time_s, self._ref.copy(), self.joint_pos(), vel, tau,
                          self.motors.current_a(tau), self._duty.copy(), pwm, active,
                          sensors, v, amps, watts)

    def fill_state(self, sample: np.ndarray) -> None:
        """Write the current state into a ``daemon.structs.STATE_DTYPE`` sample."""
        from daemon.structs import StatusFlag

        s = self.state()
        sample["time_s"] = s.time_s
        sample["ref"], sample["pos"], sample["vel"] = s.ref_rad, s.pos_rad, s.vel_rad_s
        sample["cur"], sample["duty"] = s.cur_a, s.duty_pct
        sample["comply"], sample["active"] = s.pwm, s.active
        sample["zeroed"] = 1
        status = np.where(s.active, 0, int(StatusFlag.TRIPPED)) | \
            np.where(s.pwm, int(StatusFlag.COMPLIANT), 0)
        sample["status"] = status
        ft, imu = sample["ft"], sample["imu"]
        for i, f in enumerate(("mx", "my", "fz")):
            ft[f] = s.sensors.ft[:, i]
        for i, f in enumerate(("ax", "ay", "az", "wx", "wy", "wz")):
            imu[f] = s.sensors.imu[:, i]
        sample["power"]["V"], sample["power"]["I"], sample["power"]["P"] = \
            s.power_v, s.power_a, s.power_w
