"""The simulated robot: the MuJoCo board model and the world it stands in.

- `board_model`: motor boards (position PD, PWM through a DC-motor model), physics tick;
- `board_trip`: boards grouped as on the robot, tripping on sustained saturation;
- `grasp_latch`: a hand holds a rail only if it closed on it, and slips past its grip;
- `sensors`: encoders, F/T, IMUs in the state struct's units;
- `backend`: the daemon's ``sim`` backend, the same board model behind the 200 Hz loop.

Only the sim backend and `execute` import this package (tests/test_layering.py). The
names below are re-exported lazily: importing the package does not load MuJoCo.
"""

from robot.lazy_exports import lazy_exports

_EXPORTS = {
    "BOARDS": "board_trip",
    "BoardModel": "board_model",
    "BoardModelConfig": "board_model",
    "BoardState": "board_model",
    "BoardTripConfig": "board_trip",
    "BoardTripMonitor": "board_trip",
    "FT_SENSORS": "sensors",
    "GraspEvent": "grasp_latch",
    "GraspLatch": "grasp_latch",
    "GripCapacity": "grasp_latch",
    "GripConfig": "grasp_latch",
    "GripState": "grasp_latch",
    "IMU_SENSORS": "sensors",
    "PlacementError": "board_model",
    "RELEASE_LOADS": "grasp_latch",
    "SLIP_LOADS": "grasp_latch",
    "SensorReading": "sensors",
    "SimBackend": "backend",
    "TripEvent": "board_trip",
    "add_sensors": "sensors",
    "board_of_joint": "board_trip",
    "default_config": "board_model",
    "read_sensors": "sensors",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
