"""The daemon's channels over the network (``hubo-bridge``), on zenoh: the role of Ach's
push and pull between the robot and the operator's computer.

- `keys`: key expressions and the freshness stamp commands carry;
- `session_config`: zenoh configurations: mutual TLS, the robot's access control;
- `certs`: a small certificate authority for the robot and the operators (openssl);
- `robot`: the robot side (state out; references, board commands, neck keys, player
  control in);
- `operator`: the operator side, a Python API;
- `mirror`: the robot's channels mirrored into a local instance (Ach's push and pull);
- `cli`: ``hubo-bridge``.

Nothing here imports zenoh at import time: it is the ``remote`` extra, and importing
`daemon` stays light.
"""

from daemon.remote.keys import Topic
from daemon.remote.session_config import TlsFiles

__all__ = ["Topic", "TlsFiles"]
