"""validate-plan's pictures: a legend entry for every mark (the tracking error, the PWM
spans, MuJoCo's and the plan's torque, the torque limits), titles that fit, and snapshot
captions that say simulation, the time, the line and what the segment does."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from execute.validate import artifacts
from robot.plan_sidecar import HoldRecord, PlanSidecar, Segment


def _run() -> SimpleNamespace:
    t = np.arange(0.0, 10.0, 0.005)
    n = len(t)
    rng = np.random.default_rng(4)
    ref = rng.normal(scale=0.1, size=(n, 40))
    pwm = np.zeros((n, 40), dtype=bool)
    pwm[n // 3:, :] = True
    feet = {"left_foot": HoldRecord("rung_3", (0.3, 0.1, 1.0))}
    sidecar = PlanSidecar(
        robot="drc-hubo", ladder={}, rate_hz=200.0, line_count=n, arm_modes={},
        final_holds=feet, segments=(
            Segment("moveRHand", "release", 3, 1, n // 2, feet),
            Segment("moveRHand", "limb", 3, n // 2 + 1, n, feet, ("right_hand",))))
    log = SimpleNamespace(time_s=t, line_index=np.arange(n), ref_rad=ref,
                          pos_rad=ref + rng.normal(scale=0.01, size=(n, 40)), pwm=pwm,
                          torque_nm=rng.normal(scale=5.0, size=(n, 40)))
    return SimpleNamespace(log=log, sidecar=sidecar, verdict=SimpleNamespace(failure=None),
                           options=SimpleNamespace(strategy="mixed"))


def _fits(fig, text) -> bool:
    fig.canvas.draw()
    box = text.get_window_extent(fig.canvas.get_renderer())
    return 0 <= box.x0 and box.x1 <= fig.bbox.width


def _legend(fig) -> list[str]:
    return [t.get_text() for t in fig.legends[0].get_texts()]


def test_tracking_plot_legend_and_title():
    import matplotlib.pyplot as plt

    fig = artifacts.tracking_figure(_run(), "right")
    assert _legend(fig) == ["pos − ref (tracking error)", "shaded: joint in PWM mode"]
    assert fig.get_suptitle().startswith("right arm: tracking error pos − ref")
    assert _fits(fig, fig._suptitle)
    plt.close(fig)


def test_plan_comparison_legend_has_the_limits_and_a_long_title_fits(monkeypatch):
    import matplotlib.pyplot as plt

    from execute.validate import plan_compare

    run = _run()
    joints = [SimpleNamespace(joint=j, limit_nm=30.0) for j in ("LSR", "RHR", "RHP")]
    summary = ("at line 300282 against the plan: LSR +4.7 N·m (plan -4.7), RHR -5.0 N·m "
               "(plan +6.2), RHP +5.7 N·m (plan -12.1); body 2.5 cm and 0.8° off")
    comparison = SimpleNamespace(joints=joints, summary=lambda: summary)
    monkeypatch.setattr(plan_compare, "planned_torque_history",
                        lambda run, traj, ladder, names, verifier=None: (
                            run.log.time_s[::10],
                            np.zeros((len(run.log.time_s[::10]), len(names)))))
    fig = artifacts.plan_comparison_figure(run, comparison, None, None)
    assert _legend(fig) == ["MuJoCo", "plan (torque LP)", "torque limit (±)"]
    assert "At line 300282 against the plan" in fig.get_suptitle()
    assert "\n" in fig.get_suptitle() and _fits(fig, fig._suptitle)
    plt.close(fig)


def test_snapshot_captions_say_simulation_time_line_and_segment():
    captions = artifacts.snapshot_captions(_run(), [0.0, 9.0])
    assert captions[0] == "simulation, t = 0.0 s, line 1\nright hand lets go of the right rail"
    assert captions[1] == "simulation, t = 9.0 s, line 1,801\nright hand moves up the right rail"


@pytest.mark.parametrize("arm", ["left", "right"])
def test_tracking_plots_are_written(tmp_path, arm):
    paths = artifacts.write_tracking_plots(_run(), tmp_path)
    assert (tmp_path / f"tracking_{arm}.png") in paths
