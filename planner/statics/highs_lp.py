"""A small dense LP solved with HiGHS directly, for the torque LP's hot path.

The torque LP (`planner.statics.torque_lp`) runs on every interpolated configuration;
scipy's ``linprog`` wrapper costs more than HiGHS's solve of this small dense LP, so it
passes the model's arrays to one reused HiGHS instance itself.
"""

from __future__ import annotations

import numpy as np

from planner.statics.config import StabilityError

__all__ = ["pass_dense_lp", "quiet_highs", "solve_lp"]

_HIGHS = None


def quiet_highs():
    """The process's one HiGHS instance: quiet, presolve off (it only reformulates these
    small LPs, and the optimum is the same)."""
    import highspy

    global _HIGHS
    if _HIGHS is None:
        _HIGHS = highspy.Highs()
        _HIGHS.setOptionValue("output_flag", False)
        _HIGHS.setOptionValue("presolve", "off")
    return _HIGHS


def pass_dense_lp(h, cost: np.ndarray, a: np.ndarray, row_lower: np.ndarray,
                  row_upper: np.ndarray, col_upper: np.ndarray) -> None:
    """Pass min cost·x s.t. row_lower ≤ a x ≤ row_upper, 0 ≤ x ≤ col_upper (infinite
    bounds as numpy's inf), from a dense ``a``, to the HiGHS instance ``h``.

    The arrays go straight to HiGHS's array overload of ``passModel``: building a
    ``HighsLp`` attribute by attribute copied each array through pybind11 and cost about
    six times as much (1.9 against 0.3 ms for an 80 × 130 model). The model is the same.

    Raises:
        StabilityError: HiGHS refused the model.
    """
    import highspy

    inf = highspy.kHighsInf
    n_row, n_col = a.shape
    rows, cols = np.nonzero(a)
    starts = np.zeros(n_row + 1, dtype=np.int32)
    np.cumsum(np.count_nonzero(a, axis=1), out=starts[1:])
    status = h.passModel(
        n_col, n_row, len(cols), int(highspy.MatrixFormat.kRowwise),
        int(highspy.ObjSense.kMinimize), 0.0, np.ascontiguousarray(cost, dtype=float),
        np.zeros(n_col), np.where(np.isinf(col_upper), inf, col_upper),
        np.where(np.isinf(row_lower), -inf, row_lower),
        np.where(np.isinf(row_upper), inf, row_upper), starts, cols.astype(np.int32),
        a[rows, cols], np.zeros(n_col, dtype=np.int32))  # integrality: all continuous
    if status == highspy.HighsStatus.kError:  # a warning (tiny coefficients) still solves
        raise StabilityError(f"HiGHS refused the LP ({n_row} × {n_col}): {status}")


def solve_lp(cost: np.ndarray, a_ub: np.ndarray, b_ub: np.ndarray, a_eq: np.ndarray,
             b_eq: np.ndarray, upper: np.ndarray) -> tuple[str, np.ndarray | None]:
    """min cost·x s.t. a_ub x ≤ b_ub, a_eq x = b_eq, 0 ≤ x ≤ upper, with HiGHS directly.

    The torque LP runs on every interpolated configuration; scipy's ``linprog`` wrapper
    costs more than HiGHS's solve of this small dense LP (≈ 2.8 against 1.5 ms). One
    solver instance per process is reused (`quiet_highs`).

    Returns:
        ``("optimal", x)``, ``("infeasible", None)`` or (HiGHS's status name, None).
    """
    import highspy

    h = quiet_highs()
    pass_dense_lp(h, cost, np.vstack([a_ub, a_eq]),
                  np.concatenate([np.full(len(b_ub), -np.inf), b_eq]),
                  np.concatenate([b_ub, b_eq]), upper)
    h.run()
    status = h.getModelStatus()
    if status == highspy.HighsModelStatus.kOptimal:
        return "optimal", np.array(h.getSolution().col_value)
    if status == highspy.HighsModelStatus.kInfeasible:
        return "infeasible", None
    return h.modelStatusToString(status), None
