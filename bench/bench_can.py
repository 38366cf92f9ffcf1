"""Benchmark: encode + decode of one whole 5 ms CAN cycle (`daemon.can.cycle_plan.CyclePlan`).

Per cycle: the reference frames and requests of both buses are encoded from 40 joint
references, and a full set of replies (encoder, FT, tilt/IMU, power) is decoded into
readings. Reply frames are made once, outside the timed loop, as the bus would deliver
them. Also reports the planned bus loads against the 108-bit-per-frame budget.

Target (issue): encode + decode ≤ 0.5 ms per cycle.
"""

from __future__ import annotations

import logging
import time

import numpy as np

log = logging.getLogger(__name__)

CYCLE_TARGET_MS = 0.5


def _replies(plan, ref_rad: np.ndarray) -> dict[int, list]:
    from daemon.can import protocol as cp

    rx: dict[int, list] = {b: [] for b in plan.buses}
    for b, msgs in plan.encode(ref_rad).items():
        for m in msgs:
            if m.arbitration_id not in (cp.CMD_ID, cp.SENSOR_REQ_ID):
                jmc, pair, counts = cp.decode_ref(m)
                rx[b].append(cp.encode_enc_reply(jmc, counts, pair))
    for b, p in plan.buses.items():
        for f in p.frames:
            if f.kind == "ft_reply":
                rx[b].append(cp.encode_ft_reply(f.board, 0.5, -0.5, 300.0))
            elif f.kind == "tilt_reply":
                rx[b].append(cp.encode_tilt_reply(f.board, (0.0, 0.0, 9.81)))
            elif f.kind == "gyro_reply":
                rx[b].append(cp.encode_gyro_reply(f.board, (0.0, 0.0, 0.0)))
            elif f.kind == "power_reply":
                rx[b].append(cp.encode_power_reply(48.0, 5.0))
    return rx


def measure_cycle(n: int = 2000) -> tuple[np.ndarray, object]:
    """Per-cycle encode + decode times [ms] over ``n`` cycles, and the plan."""
    from daemon.can.cycle_plan import CyclePlan
    from daemon.tables import load_joint_table, load_sensor_table

    plan = CyclePlan(load_joint_table(), load_sensor_table())
    rng = np.random.default_rng(0)
    refs = rng.uniform(-1.0, 1.0, size=(n, 40))
    rx = _replies(plan, refs[0])
    times = np.empty(n)
    for k in range(n):
        t0 = time.perf_counter()
        plan.encode(refs[k])
        plan.decode(rx)
        times[k] = time.perf_counter() - t0
    return times * 1e3, plan


def run() -> list[dict]:
    """Figures: median and p99 encode+decode per cycle [ms]; bus loads [%]."""
    t, plan = measure_cycle()
    med, p99 = float(np.median(t)), float(np.percentile(t, 99))
    log.info("CAN cycle encode+decode: median %.3f ms, p99 %.3f ms", med, p99)
    out = [
        {
            "name": "CAN encode+decode per 5 ms cycle, median",
            "value": round(med, 4),
            "unit": "ms",
            "target": CYCLE_TARGET_MS,
            "ok": med <= CYCLE_TARGET_MS,
        },
        {
            "name": "CAN encode+decode per 5 ms cycle, p99",
            "value": round(p99, 4),
            "unit": "ms",
            "target": CYCLE_TARGET_MS,
            "ok": p99 <= CYCLE_TARGET_MS,
        },
    ]
    for b, p in plan.buses.items():
        out.append(
            {
                "name": f"can{b} planned load ({len(p.frames)} frames × 108 bits / 5 ms)",
                "value": round(100.0 * p.load, 1),
                "unit": "%",
                "target": 100.0,
                "ok": p.load <= 1.0,
            }
        )
    return out
