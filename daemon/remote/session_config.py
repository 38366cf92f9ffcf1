"""Zenoh session configurations of the bridge: mutual TLS and the robot's access control.

Who may do what is zenoh's to enforce, not ours:

- **TLS with client certificates** (``transport.link.tls``, ``enable_mtls``): the robot
  listens only on ``tls/`` endpoints and accepts a connection only from a peer whose
  certificate our certificate authority signed (`daemon.remote.certs` makes them). Its
  certificate's common name (CN) is the peer's name.
- **Access control** (``access_control``), default deny, on the robot's session:
  - every TLS peer may subscribe to the ``state`` (read-only stations);
  - only the peers whose CN is in ``writers`` may put ``ref`` samples and send command
    queries (and get their replies).

  Zenoh drops anything else at the robot's ingress, before any subscriber or queryable of
  the bridge sees it, so a command from a peer that is not configured never reaches the
  channels.
- No multicast or gossip scouting: the operator connects to the robot's endpoint.

The operator's session is a zenoh ``client`` of the robot's ``peer``: clients never route
for each other, so a read-only station cannot relay a writer's messages.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from daemon.remote.keys import COMMANDS, Topic, key
from robot.errors import HuboLadderError, InputError

__all__ = ["TlsFiles", "check_endpoint", "open_session", "operator_config", "robot_config"]


@dataclass(frozen=True)
class TlsFiles:
    """One node's TLS files: the certificate authority, its certificate and its key (PEM)."""

    ca_pem: Path
    cert_pem: Path
    key_pem: Path

    @classmethod
    def from_dir(cls, directory: Path | str, name: str) -> TlsFiles:
        """``ca.pem``, ``NAME.pem`` and ``NAME.key`` in ``directory`` (the layout
        ``hubo-bridge certs`` writes).

        Raises:
            InputError: a file is missing (named, with the option that chose it).
        """
        d = Path(directory)
        files = cls(d / "ca.pem", d / f"{name}.pem", d / f"{name}.key")
        for path in (files.ca_pem, files.cert_pem, files.key_pem):
            if not path.is_file():
                raise InputError(f"--tls-dir {d} --name {name}: no file {path} "
                                 "(hubo-bridge certs writes ca.pem, NAME.pem, NAME.key)")
        return files


_NO_SCOUTING = {"multicast": {"enabled": False}, "gossip": {"enabled": False}}


def _mutual_tls(tls: TlsFiles, side: str) -> dict:
    """The ``transport`` section: TLS with ``tls``'s files on the ``listen`` or ``connect``
    side, the peer's certificate checked against the same CA. Zenoh's shared-memory
    transport is off: the bridge's peers are on other computers, and it left a segment
    in /dev/shm behind every session."""
    return {"link": {"tls": {"root_ca_certificate": str(tls.ca_pem),
                             f"{side}_certificate": str(tls.cert_pem),
                             f"{side}_private_key": str(tls.key_pem),
                             "enable_mtls": True}},
            "shared_memory": {"enabled": False}}


def robot_config(listen: str, tls: TlsFiles, instance: str,
                 writers: tuple[str, ...]) -> dict:
    """The robot bridge's zenoh configuration (see the module docstring).

    Args:
        listen: the endpoint, ``tls/HOST:PORT``.
        tls: the robot's TLS files.
        instance: the daemon instance whose keys the rules name.
        writers: certificate common names of the peers that may write.
    """
    rules = [
        {"id": "read-state", "permission": "allow", "flows": ["ingress", "egress"],
         "messages": ["declare_subscriber", "put"], "key_exprs": [key(instance, Topic.STATE)]},
    ]
    subjects = [{"id": "tls-peers", "link_protocols": ["tls"]}]
    policies = [{"id": "readers", "rules": ["read-state"], "subjects": ["tls-peers"]}]
    if writers:
        rules += [
            {"id": "write-ref", "permission": "allow", "flows": ["ingress", "egress"],
             "messages": ["put", "declare_subscriber"], "key_exprs": [key(instance, Topic.REF)]},
            {"id": "commands", "permission": "allow", "flows": ["ingress", "egress"],
             "messages": ["query", "reply", "declare_queryable"],
             "key_exprs": [key(instance, COMMANDS)]},
        ]
        subjects.append({"id": "writers", "cert_common_names": list(writers)})
        policies.append({"id": "writers", "rules": ["write-ref", "commands"],
                         "subjects": ["writers"]})
    return {
        "mode": "peer",
        "listen": {"endpoints": [listen]},
        "scouting": _NO_SCOUTING,
        "transport": _mutual_tls(tls, "listen"),
        "access_control": {"enabled": True, "default_permission": "deny", "rules": rules,
                           "subjects": subjects, "policies": policies},
    }


def operator_config(connect: str, tls: TlsFiles) -> dict:
    """An operator's zenoh configuration: a client of the robot at ``connect``
    (``tls/HOST:PORT``), presenting its certificate."""
    return {
        "mode": "client",
        "connect": {"endpoints": [connect]},
        "scouting": _NO_SCOUTING,
        "transport": _mutual_tls(tls, "connect"),
    }


def check_endpoint(option: str, endpoint: str) -> str:
    """``endpoint`` if it is ``tls/HOST:PORT``; the bridge speaks nothing unauthenticated.

    Raises:
        InputError: another protocol or no port (naming ``option``).
    """
    proto, _, address = endpoint.partition("/")
    host, _, port = address.rpartition(":")
    if proto != "tls" or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise InputError(f"{option} {endpoint!r} refused: use tls/HOST:PORT (port 1-65535); "
                         "the bridge accepts only mutually authenticated TLS")
    return endpoint


def open_session(config: dict):
    """Open a zenoh session (zenoh imported here, so that importing `daemon` stays light).

    Raises:
        HuboLadderError: zenoh refused the configuration or could not listen or connect.
    """
    import zenoh

    try:
        return zenoh.open(zenoh.Config.from_json5(json.dumps(config)))
    except zenoh.ZError as exc:
        raise HuboLadderError(f"zenoh: {exc}") from None
