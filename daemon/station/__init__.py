"""``hubo-init``, the operator's web page: joints, sensors, board commands, neck keys, the
player's pause and stop, and the simulated head camera.

- `state_view`: a state sample as rows (joints graded by `Severity`, sensors);
- `commands`: the page's commands (hubo-console's, hubo-neck's, the player's pause and
  stop of `daemon.player_control`) as `Outcome`\\ s;
- `head_camera`: the sim's head camera rendered by MuJoCo (imported only with
  ``--camera sim``);
- `page`: the nicegui layout; `cli`: ``hubo-init``.

Re-exports only numpy-level names: nicegui and MuJoCo load when the page is served.
"""

from daemon.station.commands import Outcome, StationCommands
from daemon.station.state_view import JointRow, SensorRow, Severity, joint_rows, sensor_rows

__all__ = ["JointRow", "Outcome", "SensorRow", "Severity", "StationCommands", "joint_rows",
           "sensor_rows"]
