"""``hubo-init``, the operator's web page: joints, sensors, board commands, neck keys, the
player's pause and stop, and the simulated head camera; on the daemon's computer or
through ``hubo-bridge``.

- `state_view`: a state sample as rows (joints graded by `Severity`, sensors);
- `link`: what the page talks to, a state source and a command sink (`StationLink`),
  whose commands return `Outcome`\\ s;
- `local_link`: the daemon's channels and the local tools (hubo-console's, hubo-neck's,
  the player's pause and stop of `daemon.player_control`);
- `bridge_link`: the robot through hubo-bridge (`daemon.remote.operator`);
- `head_camera`: the sim's head camera rendered by MuJoCo (imported only with
  ``--camera sim``);
- `page`: the nicegui layout; `cli`: ``hubo-init``.

Re-exports only numpy-level names: nicegui, zenoh and MuJoCo load when the page is served.
"""

from daemon.station.link import Outcome, StateReading, StationLink
from daemon.station.local_link import LocalLink
from daemon.station.state_view import JointRow, SensorRow, Severity, joint_rows, sensor_rows

__all__ = ["JointRow", "LocalLink", "Outcome", "SensorRow", "Severity", "StateReading",
           "StationLink", "joint_rows", "sensor_rows"]
