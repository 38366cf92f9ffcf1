"""The torque LP of one stance on many lines of a plan (check-plan's pass).

The LP is `planner.statics.torque_lp.torque_feasibility`'s with the ``torque`` objective,
term for term: contact variables (a foot's cone coefficients at its patch corners, a
grip's split wrench), then t; |τ_j| ≤ t τmax_j for every actuated joint, the grips'
halfspaces, and the free-flyer rows met exactly; cost t plus `GRIP_LOAD_COST` per unit of
grip use. `StanceLines` writes it for a batch of lines at once with numpy
(`planner.verify.batch_kinematics` gives the Jacobians and gravity).

Solving 300,000 such LPs with HiGHS one by one took most of check-plan's time on a DRC
climb. Consecutive lines differ little, so the optimal basis of one line's LP is usually
optimal for the next ones. `StanceLines.solve` keeps the last basis HiGHS returned and
tests it on the following lines, many at once: the basic variables from the active rows
(one square solve), the duals from the basic columns (another), then the textbook
optimality test: every variable and row within its bounds, every reduced cost and row
dual of the right sign, to `BASIS_TOL` (HiGHS's own tolerance). Where the basis passes,
it is optimal and its vertex is the line's solution; at the first line where it does
not, HiGHS solves that line, warm-started from it. On a DRC climb of 300,000 lines HiGHS
ran on 3,600.

Among equally good solutions (a foot's cone coefficients can share its load many ways)
the vertex may differ from the one a cold HiGHS solve returns; the objective, the joint
torques' worst ratio and the grips' wrenches (which carry a cost) agree to rounding
(tests/test_torque_lines.py).

Size: the LP's structure (its rows, by joint, grip and free-flyer row) is what both the
batch build and the basis test read, so they stay one module with the HiGHS call that
supplies the bases.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import NamedTuple

import numpy as np

from ladders.contact_model import HandLimits
from planner.statics.config import StabilityConfig, StabilityError, default_config
from planner.statics.contact_wrenches import cone_edges_cached, grip_rows, split_wrench_basis
from planner.statics.highs_lp import pass_dense_lp, quiet_highs
from planner.statics.torque_lp import GRIP_LOAD_COST, actuated_joints
from planner.verify.batch_kinematics import BatchKinematics, JointPoses

__all__ = ["BASIS_TOL", "LineTorques", "StanceLines"]

#: A basis is kept for a line when its vertex and duals meet their bounds to this [-]
#: (body weights and torque ratios): HiGHS's own primal and dual tolerances.
BASIS_TOL = 1e-7
#: Joints whose torque ratios differ by less than this share the worst one [-].
TIE_RATIO = 1e-9
#: Lines tested at once against a basis: at first and after a failed test, and at most
#: (the window doubles while the basis holds).
MIN_WINDOW, MAX_WINDOW = 32, 256
_LOWER, _BASIC, _UPPER = 0, 1, 2  # highspy.HighsBasisStatus values
_SPLIT = split_wrench_basis(np.zeros(3))  # (6, 12) a grip's wrench from its variables


class LineTorques(NamedTuple):
    """The torque LP's answer on a batch of lines.

    Attributes:
        equilibrium: (L,) contact wrenches within their limits balance gravity.
        max_ratio: (L,) max_j |τ_j| / τmax_j (inf without equilibrium).
        worst_joint: (L,) index into `StanceLines.joint_names` of that joint (-1: none).
        grip_wrench: per gripping limb, (L, 6) the rail's force [N] and torque [N·m] on
            the hand about its palm frame, world frame (nan without equilibrium).
    """

    equilibrium: np.ndarray
    max_ratio: np.ndarray
    worst_joint: np.ndarray
    grip_wrench: dict[str, np.ndarray]


class _BasisRows(NamedTuple):
    """A basis in the LP's structure (`StanceLines._rows_of`)."""

    B: np.ndarray  # basic columns
    B_c: np.ndarray  # the contact variables among them
    t_basic: bool  # t is basic (the last of B)
    NR: np.ndarray  # active (nonbasic) rows
    g: np.ndarray  # (len(NR),) which active rows are G rows (joints, free flyer)
    v: np.ndarray  # their velocity index
    sign: np.ndarray  # their sign (−1 on the lower |τ| rows)
    tcoef: np.ndarray  # (len(NR),) every active row's coefficient of t
    sel: np.ndarray  # (G rows, nv) sign at each G row's velocity index
    grip: np.ndarray  # (grip rows, cols) the active grip rows
    at_upper: np.ndarray  # (len(NR),) the row is at its upper bound
    one_sided: np.ndarray  # (len(NR),) the row is a ≤ row (not a free-flyer equality)
    at_lower_cols: np.ndarray  # the nonbasic columns (at 0)


class _Basis(NamedTuple):
    """HiGHS's last optimal basis: for a warm start, and in the LP's structure for the
    test on the following lines (None: the test does not apply)."""

    highs: object  # the highspy.HighsBasis
    rows: _BasisRows | None


class _Terms(NamedTuple):
    """Per line: every hold's frame Jacobian stacked (L, 6 holds, nv), each hold's wrench
    basis (L, 6, n_h), or (6, n_h) for a grip's constant one, and gravity (L, nv) per
    body weight."""

    jac: np.ndarray
    wrench: list[np.ndarray]
    grav: np.ndarray

    def slice(self, i: int, j: int) -> _Terms:
        return _Terms(self.jac[i:j], [w if w.ndim == 2 else w[i:j] for w in self.wrench],
                      self.grav[i:j])


class _Hold(NamedTuple):
    limb: str
    parent: int  # the limb frame's joint
    R_joint_frame: np.ndarray
    p_joint_frame: np.ndarray
    limits: HandLimits | None
    points_local: np.ndarray | None  # (m, 3) contact points in the limb frame [m]
    edges: np.ndarray | None  # (m k, 3) cone edges, world frame


class StanceLines:
    """The torque LP of one stance, built and solved on batches of lines.

    Args:
        kin: the robot's `BatchKinematics`.
        holds: the stance's holds (`planner.contacts.Hold`), in the stance's order.
        torque_max_nm_by_joint: torque limit of every actuated joint [N·m].
        frame_ids: the model frame of each held limb.
        config: the stability tunables (`planner.statics.config.default_config` if None).
    """

    def __init__(self, kin: BatchKinematics, holds: Sequence, torque_max_nm_by_joint:
                 Mapping[str, float], frame_ids: Mapping[str, int],
                 config: StabilityConfig | None = None):
        cfg = config or default_config()
        model = kin.model
        self.kin = kin
        # The actuated joints, their velocity indices and limits, and the weight [N]:
        # `torque_feasibility`'s.
        self.joint_names, self.v_idx, self.tmax, self.weight_n = actuated_joints(
            model, torque_max_nm_by_joint)
        self.holds: list[_Hold] = []
        starts, costs, grips = [0], [], []
        for hold in holds:
            frame = model.frames[frame_ids[hold.limb]]
            if isinstance(hold.limits, HandLimits):
                rows, rhs = grip_rows(hold.limits, self.weight_n)
                grips.append((starts[-1], rows, rhs))
                cap = hold.limits.capacity
                per = np.array([cap.radial_n] * 3 + [cap.bending_nm] * 3)
                costs.append(np.tile(GRIP_LOAD_COST * self.weight_n / per, 2))
                self.holds.append(_Hold(hold.limb, frame.parentJoint, frame.placement.rotation,
                                        frame.placement.translation, hold.limits, None, None))
            else:
                pts = hold.points_in_frame_m
                e = cone_edges_cached(np.ascontiguousarray(hold.normals, dtype=float).tobytes(),
                                      float(hold.friction), cfg.cone_edges)
                costs.append(np.zeros(e.shape[0] * e.shape[1]))
                self.holds.append(_Hold(hold.limb, frame.parentJoint, frame.placement.rotation,
                                        frame.placement.translation, None, pts,
                                        e.reshape(-1, 3)))
            starts.append(starts[-1] + len(costs[-1]))
        self.starts = np.array(starts)
        self.n_c = int(self.starts[-1])
        na = len(self.joint_names)
        n_grip = sum(len(r) for _, r, _ in grips)
        self.grip_block = np.zeros((n_grip, self.n_c + 1))
        self.grip_rhs = np.concatenate([rhs for _, _, rhs in grips]) if grips else np.zeros(0)
        k = 0
        for s, rows, _ in grips:
            self.grip_block[k:k + len(rows), s:s + 12] = rows
            k += len(rows)
        self.cost = np.concatenate(costs + [[1.0]])
        self.tm = self.tmax / self.weight_n
        self.upper = np.full(self.n_c + 1, cfg.force_max_weights)
        self.upper[self.n_c] = np.inf
        self.n_rows = 2 * na + n_grip + 6
        self._basis: _Basis | None = None
        self.highs_solves = 0

    # ------------------------------------------------------------------ the LP
    def _line_terms(self, poses: JointPoses) -> _Terms:
        """Every line's hold Jacobians, wrench bases and gravity."""
        L, nv = len(poses.p), self.kin.model.nv
        jac = np.empty((L, 6 * len(self.holds), nv))
        wrench = []
        for h, hold in enumerate(self.holds):
            R_f, p_f = poses.frame(hold.parent, hold.R_joint_frame, hold.p_joint_frame)
            jac[:, 6 * h:6 * h + 6] = self.kin.frame_jacobian(poses, hold.parent, p_f)
            if hold.limits is not None:
                wrench.append(_SPLIT)
                continue
            # [E; r × E]: the constant edges, and their moments about the frame origin,
            # which turn with the frame.
            k = len(hold.edges) // len(hold.points_local)
            r = np.repeat(np.einsum("lij,mj->lmi", R_f, hold.points_local), k, axis=1)
            w = np.empty((L, 6, len(hold.edges)))
            w[:, :3] = hold.edges.T
            w[:, 3:] = np.cross(r, hold.edges).swapaxes(1, 2)
            wrench.append(w)
        return _Terms(jac, wrench, self.kin.gravity_torques(poses) / self.weight_n)

    def _generalized(self, terms: _Terms, x_c: np.ndarray) -> np.ndarray:
        """(L, nv) Σ Jᵀ W x: the generalized force of contact variables ``x_c`` (L, n_c)."""
        u = np.empty((len(x_c), terms.jac.shape[1]))
        for h, (w, s, e) in enumerate(zip(terms.wrench, self.starts[:-1], self.starts[1:],
                                          strict=True)):
            u[:, 6 * h:6 * h + 6] = x_c[:, s:e] @ w.T if w.ndim == 2 else \
                np.einsum("lac,lc->la", w, x_c[:, s:e])
        return np.einsum("lav,la->lv", terms.jac, u)

    def _matrix(self, terms: _Terms, line: int) -> np.ndarray:
        """One line's A, in `torque_feasibility`'s row order (HiGHS's input)."""
        gmat = np.hstack([terms.jac[line, 6 * h:6 * h + 6].T @ (w if w.ndim == 2 else w[line])
                          for h, w in enumerate(terms.wrench)])
        na = len(self.v_idx)
        A = np.zeros((self.n_rows, self.n_c + 1))
        A[:na, :self.n_c], A[:na, self.n_c] = gmat[self.v_idx], -self.tm
        A[na:2 * na, :self.n_c], A[na:2 * na, self.n_c] = -gmat[self.v_idx], -self.tm
        A[2 * na:-6] = self.grip_block
        A[-6:, :self.n_c] = gmat[:6]
        return A

    def _bounds(self, terms: _Terms) -> tuple[np.ndarray, np.ndarray]:
        """The rows' lower and upper bounds on every line (L, rows)."""
        grav = terms.grav
        g_a = grav[:, self.v_idx]
        upper = np.concatenate([g_a, -g_a, np.broadcast_to(self.grip_rhs,
                                                           (len(grav), len(self.grip_rhs))),
                                grav[:, :6]], axis=1)
        lower = np.full_like(upper, -np.inf)
        lower[:, -6:] = grav[:, :6]
        return lower, upper

    def solve(self, poses: JointPoses) -> LineTorques:
        """The LP of every line of the batch (in order, carrying the basis from the last
        batch of this stance)."""
        terms = self._line_terms(poses)
        lower, upper = self._bounds(terms)
        L = len(lower)
        X = np.full((L, self.n_c + 1), np.nan)
        ok = np.zeros(L, dtype=bool)
        i, window = 0, MIN_WINDOW
        while i < L:
            if self._basis is not None and self._basis.rows is not None:
                j = min(L, i + window)
                passed, x = self._test(self._basis.rows, terms.slice(i, j), lower[i:j],
                                       upper[i:j])
                n = len(passed) if passed.all() else int(np.argmin(passed))
                X[i:i + n], ok[i:i + n] = x[:n], True
                i += n
                if n == len(passed):  # the basis holds on the whole window
                    window = min(2 * window, MAX_WINDOW)
                    continue
                window = max(MIN_WINDOW, n)
            status, x = self._highs(self._matrix(terms, i), lower[i], upper[i])
            if status == "optimal":
                X[i], ok[i] = x, True
            i += 1
        return self._answer(terms, X, ok)

    def _answer(self, terms: _Terms, X: np.ndarray, ok: np.ndarray) -> LineTorques:
        gx = self._generalized(terms, np.nan_to_num(X[:, :self.n_c]))
        tau = (terms.grav[:, self.v_idx] - gx[:, self.v_idx]) * self.weight_n
        ratios = np.abs(tau) / self.tmax
        top = ratios.max(axis=1)
        # At the min-max optimum several joints share the worst ratio: name the first
        # (in the model's order) within `TIE_RATIO` of it, not whichever rounding favours.
        worst = np.where(ok, np.argmax(ratios >= top[:, None] - TIE_RATIO, axis=1), -1)
        max_ratio = np.where(ok, top, math.inf)
        grips = {}
        for hold, s in zip(self.holds, self.starts[:-1], strict=True):
            if hold.limits is not None:
                grips[hold.limb] = (X[:, s:s + 6] - X[:, s + 6:s + 12]) * self.weight_n
        return LineTorques(ok, max_ratio, worst, grips)

    # ------------------------------------------------------------------ the basis test
    def _rows_of(self, col_status: np.ndarray, row_status: np.ndarray) -> _BasisRows | None:
        """The active rows and basic columns of a basis in the LP's structure, or None
        when the test does not apply (a variable at its upper bound, or not square)."""
        if ((col_status != _LOWER) & (col_status != _BASIC)).any():
            return None
        B, NR = np.flatnonzero(col_status == _BASIC), np.flatnonzero(row_status != _BASIC)
        if len(B) != len(NR):
            return None
        na, n_grip = len(self.v_idx), len(self.grip_rhs)
        joint = NR < 2 * na
        g = joint | (NR >= 2 * na + n_grip)
        a = NR % na
        v = np.where(joint, self.v_idx[a], NR - 2 * na - n_grip)
        sign = np.where((NR >= na) & joint, -1.0, 1.0)
        sel = np.zeros((int(g.sum()), self.kin.model.nv))
        sel[np.arange(len(sel)), v[g]] = sign[g]
        return _BasisRows(B, B[B < self.n_c], bool(B[-1] == self.n_c) if len(B) else False,
                          NR, g, v[g], sign[g], np.where(joint, -self.tm[a], 0.0), sel,
                          self.grip_block[NR[~g] - 2 * na], row_status[NR] == _UPPER,
                          NR < 2 * na + n_grip, np.flatnonzero(col_status == _LOWER))

    def _test(self, rows: _BasisRows, terms: _Terms, lower: np.ndarray, upper: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
        """Which of these lines a basis is optimal for, and its vertex on each."""
        W, n, k = len(lower), self.n_c + 1, len(rows.B)
        M = np.empty((W, k, k))
        kc = len(rows.B_c)
        g_pos = np.flatnonzero(rows.g)
        jac_g = terms.jac[:, :, rows.v]  # (W, 6 holds, G rows)
        for h, (w, s, e) in enumerate(zip(terms.wrench, self.starts[:-1], self.starts[1:],
                                          strict=True)):
            in_h = np.flatnonzero((rows.B_c >= s) & (rows.B_c < e))
            if len(in_h):
                cols = rows.B_c[in_h] - s
                sub = jac_g[:, 6 * h:6 * h + 6].swapaxes(1, 2) @ (w[:, cols] if w.ndim == 2
                                                                   else w[:, :, cols])
                M[:, g_pos[:, None], in_h[None, :]] = sub * rows.sign[:, None]
        if rows.t_basic:
            M[:, :, kc] = rows.tcoef
        M[:, ~rows.g] = rows.grip[:, rows.B]
        bound = np.where(rows.at_upper, upper[:, rows.NR], lower[:, rows.NR])
        try:
            xb = np.linalg.solve(M, bound[..., None])[..., 0]
            y = np.linalg.solve(M.swapaxes(1, 2), np.broadcast_to(self.cost[rows.B], (W, k))
                                [..., None])[..., 0]
        except np.linalg.LinAlgError:  # a singular line: test them one by one
            if W == 1:
                return np.zeros(1, dtype=bool), np.zeros((1, n))
            out = [self._test(rows, terms.slice(w, w + 1), lower[w:w + 1], upper[w:w + 1])
                   for w in range(W)]
            return (np.concatenate([o[0] for o in out]), np.concatenate([o[1] for o in out]))
        x = np.zeros((W, n))
        x[:, rows.B] = xb
        tol = BASIS_TOL
        passed = ((xb >= -tol) & (xb <= self.upper[rows.B] + tol)).all(axis=1)
        # Every row within its bounds: |τ| rows, grip rows, free-flyer rows.
        na = len(self.v_idx)
        gx = self._generalized(terms, x[:, :self.n_c])
        g_a, t_m = gx[:, self.v_idx], self.tm * x[:, self.n_c:]
        passed &= (g_a - t_m <= upper[:, :na] + tol).all(axis=1)
        passed &= (-g_a - t_m <= upper[:, na:2 * na] + tol).all(axis=1)
        if len(self.grip_rhs):
            passed &= (x @ self.grip_block.T <= self.grip_rhs + tol).all(axis=1)
        passed &= (np.abs(gx[:, :6] - upper[:, -6:]) <= tol).all(axis=1)
        # Reduced costs d = c − A[NR]ᵀ y ≥ 0 on the columns at 0, and ≤-row duals ≤ 0.
        z = y[:, rows.g] @ rows.sel  # (W, nv)
        cols = rows.at_lower_cols
        d = self.cost[cols] - y[:, ~rows.g] @ rows.grip[:, cols]
        jz = np.einsum("lav,lv->la", terms.jac, z)  # (W, 6 holds)
        for h, (w, s, e) in enumerate(zip(terms.wrench, self.starts[:-1], self.starts[1:],
                                          strict=True)):
            in_h = np.flatnonzero((cols >= s) & (cols < e))
            if len(in_h):
                wc = w[:, cols[in_h] - s] if w.ndim == 2 else w[:, :, cols[in_h] - s]
                d[:, in_h] -= jz[:, 6 * h:6 * h + 6] @ wc if w.ndim == 2 else \
                    np.einsum("lac,la->lc", wc, jz[:, 6 * h:6 * h + 6])
        c_cols = cols[cols < self.n_c]
        if len(c_cols) < len(cols):  # t at 0
            d[:, -1] -= y @ rows.tcoef
        passed &= (d >= -tol).all(axis=1)
        passed &= (y[:, rows.one_sided] <= tol).all(axis=1)
        return passed, x

    def _highs(self, A: np.ndarray, lower: np.ndarray, upper: np.ndarray
               ) -> tuple[str, np.ndarray | None]:
        """One line with HiGHS, warm-started from the last basis; keeps the new one."""
        import highspy

        h = quiet_highs()
        pass_dense_lp(h, self.cost, A, lower, upper, self.upper)
        if self._basis is not None:
            h.setBasis(self._basis.highs)
        h.run()
        self.highs_solves += 1
        status = h.getModelStatus()
        if status == highspy.HighsModelStatus.kInfeasible:
            return "infeasible", None
        if status != highspy.HighsModelStatus.kOptimal:
            raise StabilityError(f"torque LP failed on the holds of "
                                 f"{[hd.limb for hd in self.holds]}: HiGHS status "
                                 f"{h.modelStatusToString(status)}")
        b = h.getBasis()
        cs = np.array([int(s) for s in b.col_status])
        rs = np.array([int(s) for s in b.row_status])
        self._basis = _Basis(b, self._rows_of(cs, rs))
        return "optimal", np.array(h.getSolution().col_value)
