"""The page's layout (nicegui): joints, sensors, buttons, neck keys, head camera and a log
of every command with its outcome.

Only layout and wiring live here. The rows come from `daemon.station.state_view`, the
state and the commands from a `daemon.station.link.StationLink` (the daemon's channels
here, or the robot through hubo-bridge: one page for both), the frames from
`daemon.station.head_camera`. Each browser gets its own page; they share one `Station`
(the link of the process). nicegui is imported only by `build_page`, so importing
`daemon` stays light.
"""

from __future__ import annotations

import base64
from dataclasses import dataclass

import numpy as np

from daemon.station.head_camera import SimHeadCamera
from daemon.station.link import Outcome, StationLink
from daemon.station.state_view import Severity, joint_rows, sensor_rows, summary_line
from robot.joints import JOINT_NAMES

__all__ = ["Station", "build_page"]

NECK_KEY_LAYOUT = (("q", "w", "e"), ("a", "s", "d"), ("c",))
NECK_KEYS = "wsadqec"

COLUMNS = [
    {"name": "name", "label": "joint", "field": "name", "align": "left"},
    {"name": "pos", "label": "pos [rad]", "field": "pos"},
    {"name": "ref", "label": "ref [rad]", "field": "ref"},
    {"name": "err", "label": "error [rad]", "field": "err"},
    {"name": "mode", "label": "mode", "field": "mode", "align": "left"},
    {"name": "board", "label": "board", "field": "board", "align": "left"},
]
#: A joint row coloured by its severity (0 OK, 1 warning, 2 fault).
ROW_TEMPLATE = f"""
<q-tr :props="props" :class="props.row.severity == {int(Severity.FAULT)} ? 'bg-red-3 text-red-10'
    : props.row.severity == {int(Severity.WARNING)} ? 'bg-amber-2' : ''">
  <q-td v-for="col in props.cols" :key="col.name" :props="props">{{{{ col.value }}}}</q-td>
</q-tr>
"""


@dataclass
class Station:
    """What one ``hubo-init`` process shares between its pages.

    Attributes:
        link: the state source and command sink (local channels, or the bridge).
        rate_hz: how often a page refreshes the state [Hz].
        camera: the simulated head camera, or None (on the robot: no image channel).
    """

    link: StationLink
    rate_hz: float
    camera: SimHeadCamera | None = None

    def close(self) -> None:
        if self.camera is not None:
            self.camera.close()
        self.link.close()


def _fmt(rad: float) -> str:
    return f"{round(rad, 4) + 0.0:+.4f}"  # + 0.0: no "-0.0000" for a joint at rest


def _table_rows(state: np.ndarray, ref_mode: np.ndarray | None) -> list[dict]:
    return [{"name": r.name, "pos": _fmt(r.pos_rad), "ref": _fmt(r.ref_rad),
             "err": _fmt(r.error_rad), "mode": r.mode, "board": r.board,
             "severity": int(r.severity)} for r in joint_rows(state, ref_mode)]


def _sensor_rows(state: np.ndarray) -> list[dict]:
    return [{"name": r.name, "values": "   ".join(f"{k} {v:+.2f} {u}" for k, v, u in r.readings)}
            for r in sensor_rows(state)]


def _show_rows(table, rows: list[dict]) -> None:
    """Send ``rows`` to the browser only when they differ from the table's: at rest the
    joints' and sensors' rows read the same refresh after refresh, and resending all 40
    every refresh kept a browser on a busy machine behind its server."""
    if table.rows != rows:
        table.rows = rows


def build_page(station: Station) -> None:
    """Lay out one browser's page and start its refresh timers."""
    from nicegui import run, ui

    commands = station.link
    ui.page_title(f"hubo-init · {station.link.instance}")

    def show(outcome: Outcome) -> None:
        log.push(outcome.line(), classes="" if outcome.ok else "text-negative")
        if not outcome.ok:
            ui.notify(outcome.line(), type="negative", multi_line=True)

    async def do(fn, *args) -> None:
        outcome = await run.io_bound(fn, *args)
        if outcome is not None:
            show(outcome)

    with ui.row().classes("w-full items-center"):
        ui.label(f"hubo-init · {station.link.where}").classes("text-h6")
        summary = ui.label("waiting for the daemon's state").classes("text-mono")
    with ui.row().classes("w-full no-wrap items-start"):
        joints = ui.table(columns=COLUMNS, rows=[], row_key="name", pagination=0)
        joints.props("dense flat bordered hide-bottom").classes("text-mono")
        joints.add_slot("body", ROW_TEMPLATE)
        with ui.column().classes("grow"):
            with ui.card().classes("w-full"):
                ui.label("Boards").classes("text-subtitle1")
                with ui.row().classes("items-center"):
                    ui.button("Home all", on_click=lambda: do(commands.home_all))
                    ui.button("Initialise sensors", on_click=lambda: do(commands.init_sensors))
                with ui.row().classes("items-center"):
                    joint = ui.select(list(JOINT_NAMES), value=JOINT_NAMES[0],
                                      label="joint").classes("w-24")
                    ui.button("Home", on_click=lambda: do(commands.home, joint.value))
                    ui.button("Reset", on_click=lambda: do(commands.reset, joint.value))
                with ui.row().classes("items-center"):
                    line = ui.input("command (hubo-console)",
                                    placeholder="goto RKN 0.5 · kp RSP 20").classes("w-64")
                    line.on("keydown.enter", lambda: do(commands.console_line, line.value))
                    ui.button("Run", on_click=lambda: do(commands.console_line, line.value))
            with ui.card().classes("w-full"):
                ui.label("Player").classes("text-subtitle1")
                with ui.row():
                    ui.button("Pause / resume", on_click=lambda: do(commands.pause_player))
                    ui.button("Stop", color="negative",
                              on_click=lambda: do(commands.stop_player))
            with ui.card().classes("w-full"):
                ui.label("Neck (keys w s a d q e c)").classes("text-subtitle1")
                for keys in NECK_KEY_LAYOUT:
                    with ui.row():
                        for key in keys:
                            ui.button(key, on_click=lambda k=key: do(commands.neck_key, k)) \
                                .props("dense").classes("w-10")
            with ui.card().classes("w-full"):
                ui.label("Head camera").classes("text-subtitle1")
                if station.camera is None:
                    ui.label("no image channel exists on the robot's daemon; start with "
                             "--camera sim against a sim daemon")
                    image = None
                else:
                    image = ui.interactive_image().classes("w-80")
                    camera_note = ui.label("starting the renderer")
            with ui.card().classes("w-full"):
                ui.label("Sensors").classes("text-subtitle1")
                sensors = ui.table(columns=[
                    {"name": "name", "label": "sensor", "field": "name", "align": "left"},
                    {"name": "values", "label": "readings", "field": "values",
                     "align": "left"}], rows=[], row_key="name",
                    pagination=0).props("dense flat hide-bottom").classes("text-mono")
            with ui.card().classes("w-full"):
                ui.label("Log").classes("text-subtitle1")
                log = ui.log(max_lines=200).classes("h-40 text-mono")

    async def on_key(e) -> None:
        """hubo-neck's keys; a held key's repeats are ignored (rapid steps whip the head)."""
        name = e.key.name.lower() if isinstance(e.key.name, str) else ""
        if e.action.keydown and not e.action.repeat and len(name) == 1 and name in NECK_KEYS:
            await do(commands.neck_key, name)

    ui.keyboard(on_key=on_key)

    def refresh() -> None:
        reading = station.link.read()
        age_s = float("inf") if reading is None else reading.age_s()
        if age_s > station.link.stale_after_s:
            since = "yet" if reading is None else f"for {age_s:.0f} s"
            summary.set_text(f"no state {since} from {station.link.where}: "
                             f"{station.link.silent_means}")
            summary.classes(replace="text-mono text-negative")
            return
        summary.set_text(summary_line(reading.state, age_s))
        summary.classes(replace="text-mono")
        _show_rows(joints, _table_rows(reading.state, reading.ref_mode))
        _show_rows(sensors, _sensor_rows(reading.state))

    ui.timer(1.0 / station.rate_hz, refresh)

    if image is not None:
        shown = {"frames": -1}

        def new_frame() -> None:
            cam = station.camera
            if cam.error:
                camera_note.set_text(cam.error)
                return
            jpeg = cam.latest_jpeg()
            if jpeg is not None and cam.frames != shown["frames"]:
                shown["frames"] = cam.frames
                image.set_source("data:image/jpeg;base64," + base64.b64encode(jpeg).decode())
                camera_note.set_text(f"simulated, at the state's joint angles; base at the "
                                     f"ladder's foot · frame {cam.frames}")

        ui.timer(1.0 / station.camera.fps, new_frame)
