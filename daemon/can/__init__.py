"""The real robot's boards over CAN.

- `protocol`: the Hubo frame protocol, one encoder/decoder per frame kind;
- `cycle_plan`: the frames of one 5 ms cycle per bus, encoded and decoded vectorised;
- `backend`: the daemon's ``can`` backend (python-can buses, one cycle per tick);
- `emulator`: boards answering on virtual buses, for tests and benches.

Re-exported lazily: importing the package does not load python-can.
"""

from robot.lazy_exports import lazy_exports

_EXPORTS = {
    "BOARD_CMD_BYTES": "backend",
    "BoardEmulator": "emulator",
    "CanBackend": "backend",
    "CyclePlan": "cycle_plan",
    "CycleReadings": "cycle_plan",
    "EmulatorConfig": "emulator",
    "ProtocolError": "protocol",
    "parse_channels": "backend",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
