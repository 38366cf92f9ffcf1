"""plan-ladder's pictures: stance plots titled in words, with a legend entry for every
mark and a title that fits; snapshot captions that say plan or simulation, the time, the
line and what the segment does."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

from synthetic_plan import synthetic_plan  # noqa: E402

from planner.plots import (  # noqa: E402
    frame_caption,
    hold_in_words,
    stance_figure,
    stance_groups,
    step_in_words,
    wrap_to_width,
)
from robot.plan_sidecar import HoldRecord, PlanSidecar, Segment  # noqa: E402


@pytest.mark.parametrize(("primitive", "phase", "rung", "words"), [
    ("moveRFoot", "limb", 4, "right foot moves to rung 4"),
    ("placeLFoot", "limb", 0, "left foot steps onto rung 0"),
    ("moveLHand", "limb", 2, "left hand moves up the left rail"),
    ("moveRHand", "release", 2, "right hand lets go of the right rail"),
    ("placeHands", "grasp", 0, "both hands close on the rails"),
    ("moveRFoot", "body", 3, "the body shifts before the right foot moves"),
    ("straighten", "body", 5, "the body straightens up on rung 5"),
    ("moveLFoot", "dwell", 1, "standing still after: left foot moves to rung 1"),
])
def test_steps_in_words(primitive, phase, rung, words):
    assert step_in_words(primitive, phase, rung) == words


def test_holds_in_words():
    assert hold_in_words("left_foot", "rung_3") == "left foot on rung 3"
    assert hold_in_words("right_hand", "rail_right") == "right hand on the right rail"
    assert hold_in_words("right_foot", "floor") == "right foot on the floor"


def _inside(fig, artist) -> bool:
    fig.canvas.draw()
    box = artist.get_window_extent(fig.canvas.get_renderer())
    return 0 <= box.x0 and box.x1 <= fig.bbox.width and 0 <= box.y0 and \
        box.y1 <= fig.bbox.height


def test_stance_plot_is_titled_in_words_and_every_mark_is_in_the_legend():
    import matplotlib.pyplot as plt

    planner, result, _ = synthetic_plan()
    holds, idx = stance_groups(result)[0]
    fig = stance_figure(result, planner, holds, idx)
    title = fig.get_suptitle()
    assert title.startswith("The body straightens up on rung 0, seen from above")
    assert "Holding: left foot on the floor; right foot on the floor" in title.replace(
        "\n", " ")
    assert _inside(fig, fig._suptitle)
    ax = fig.axes[0]
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    for mark in ("support region", "left foot on the floor (its sole's corners)",
                 "right foot on the floor (its sole's corners)", "CoM path",
                 "CoM at the start", "CoM at the end"):
        assert any(label.startswith(mark) for label in legend), (mark, legend)
    for artist in [*ax.collections, *ax.patches]:  # each hold's points, the region
        assert artist.get_label() in legend
    plt.close(fig)


def test_a_long_title_is_wrapped_to_the_figure():
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(4, 3))
    long = "right foot moves to rung 4, seen from above; " * 4
    text = fig.suptitle(wrap_to_width(fig, long.strip(), 10), fontsize=10)
    assert text.get_text().count("\n") >= 3 and _inside(fig, text)
    plt.close(fig)


def _sidecar() -> PlanSidecar:
    feet = {"left_foot": HoldRecord("rung_3", (0.3, 0.1, 1.0))}
    segs = (Segment("moveRFoot", "body", 4, 1, 200, feet),
            Segment("moveRFoot", "limb", 4, 201, 600, feet, ("right_foot",)))
    return PlanSidecar(robot="drc-hubo", ladder={}, rate_hz=200.0, line_count=600,
                       segments=segs, arm_modes={}, final_holds=feet)


def test_frames_are_captioned_plan_or_simulation_time_line_and_segment():
    text = frame_caption("plan", 1.2, 241, _sidecar())
    assert text == "plan, t = 1.2 s, line 241\nright foot moves to rung 4"
    assert frame_caption("simulation", 0.0, 1, _sidecar()).startswith(
        "simulation, t = 0.0 s, line 1\nthe body shifts")


def test_a_captioned_strip_keeps_its_frames_and_adds_a_caption_row(tmp_path):
    import imageio.v3 as iio

    from ladders.render import write_strip

    rng = np.random.default_rng(1)
    frames = [rng.integers(0, 255, (240, 320, 3), dtype=np.uint8) for _ in range(3)]
    captions = [frame_caption("plan", 0.5 * i, 100 * i + 1, _sidecar()) for i in range(3)]
    image = iio.imread(write_strip(frames, tmp_path / "s.png", captions))
    assert image.shape[1] == 960 and 240 < image.shape[0] < 320
    np.testing.assert_array_equal(image[:240, :320, :3], frames[0])  # pixel for pixel
    with pytest.raises(ValueError, match="2 captions for 3 frames"):
        write_strip(frames, tmp_path / "t.png", captions[:2])
