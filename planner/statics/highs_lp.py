"""A small dense LP solved with HiGHS directly, for the torque LP's hot path.

The torque LP (`planner.statics.torque_lp`) runs on every interpolated configuration;
scipy's ``linprog`` wrapper costs more than HiGHS's solve of this small dense LP, so it
passes the model to one reused HiGHS instance itself.
"""

from __future__ import annotations

import numpy as np

__all__ = ["solve_lp"]

_HIGHS = None


def solve_lp(cost: np.ndarray, a_ub: np.ndarray, b_ub: np.ndarray, a_eq: np.ndarray,
             b_eq: np.ndarray, upper: np.ndarray) -> tuple[str, np.ndarray | None]:
    """min cost·x s.t. a_ub x ≤ b_ub, a_eq x = b_eq, 0 ≤ x ≤ upper, with HiGHS directly.

    The torque LP runs on every interpolated configuration; scipy's ``linprog`` wrapper
    costs more than HiGHS's solve of this small dense LP (≈ 2.8 against 1.5 ms). One
    solver instance per process is reused; presolve is off (it only reformulates this
    LP, and the optimum is the same).

    Returns:
        ``("optimal", x)``, ``("infeasible", None)`` or (HiGHS's status name, None).
    """
    import highspy

    global _HIGHS
    if _HIGHS is None:
        _HIGHS = highspy.Highs()
        _HIGHS.setOptionValue("output_flag", False)
        _HIGHS.setOptionValue("presolve", "off")
    inf = highspy.kHighsInf
    a = np.vstack([a_ub, a_eq])
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = a.shape[1], a.shape[0]
    lp.col_cost_ = cost
    lp.col_lower_ = np.zeros(a.shape[1])
    lp.col_upper_ = np.where(np.isinf(upper), inf, upper)
    lp.row_lower_ = np.concatenate([np.full(len(b_ub), -inf), b_eq])
    lp.row_upper_ = np.concatenate([b_ub, b_eq])
    lp.a_matrix_.format_ = highspy.MatrixFormat.kRowwise
    rows, cols = np.nonzero(a)
    lp.a_matrix_.start_ = np.concatenate([[0], np.cumsum(np.count_nonzero(a, axis=1))])
    lp.a_matrix_.index_ = cols
    lp.a_matrix_.value_ = a[rows, cols]
    _HIGHS.passModel(lp)
    _HIGHS.run()
    status = _HIGHS.getModelStatus()
    if status == highspy.HighsModelStatus.kOptimal:
        return "optimal", np.array(_HIGHS.getSolution().col_value)
    if status == highspy.HighsModelStatus.kInfeasible:
        return "infeasible", None
    return _HIGHS.modelStatusToString(status), None
