"""A small certificate authority for the bridge: one CA, the robot's and the operators'
certificates, made with the ``openssl`` command.

Each node's certificate names it by its common name (CN), which the robot's access
control matches (`daemon.remote.session_config`); it carries ``serverAuth`` and
``clientAuth`` so one file serves both ends of mutual TLS, and subject alternative names
for the hosts the operators dial (the TLS client checks the robot's name). Keys are
ECDSA P-256, unencrypted, readable by the owner only. The CA's key signs every node:
keep it off the robot and the operators' computers once the certificates are made.
"""

from __future__ import annotations

import ipaddress
import os
import re
import shutil
import subprocess
from pathlib import Path

from robot.errors import HuboLadderError, InputError

__all__ = ["make_certificates"]

VALID_DAYS = 3650
_NAME_RE = re.compile(r"^[A-Za-z0-9_-]{1,40}$")


def _openssl(*args: str, cwd: Path) -> None:
    done = subprocess.run(["openssl", *args], cwd=cwd, capture_output=True, text=True)
    if done.returncode != 0:
        raise HuboLadderError(f"openssl {args[0]} failed: {done.stderr.strip()[-300:]}")


def _san(host: str) -> str:
    try:
        return f"IP:{ipaddress.ip_address(host)}"
    except ValueError:
        return f"DNS:{host}"


def make_certificates(directory: Path | str, robot: str = "robot",
                      operators: tuple[str, ...] = ("operator",),
                      hosts: tuple[str, ...] = ("localhost", "127.0.0.1")) -> list[Path]:
    """Write ``ca.pem``/``ca.key`` and ``NAME.pem``/``NAME.key`` for the robot and each
    operator into ``directory``; an existing CA there is reused, so operators can be
    added later.

    Args:
        directory: where to write (created if needed).
        robot: the robot's certificate name.
        operators: the operators' certificate names (the CNs ``--allow-writer`` lists).
        hosts: names and addresses the operators reach the robot by.

    Returns:
        The files written.

    Raises:
        InputError: a name that is not 1-40 of A-Z a-z 0-9 _ -, a name twice.
        HuboLadderError: no ``openssl`` command, or it failed.
    """
    names = (robot, *operators)
    for name in names:
        if not _NAME_RE.match(name) or name == "ca":
            raise InputError(f"certificate name {name!r}: use 1-40 characters of "
                             "A-Z a-z 0-9 _ - (and not 'ca')")
    if len(set(names)) != len(names):
        raise InputError(f"certificate names must differ: {', '.join(names)}")
    if shutil.which("openssl") is None:
        raise HuboLadderError("hubo-bridge certs needs the openssl command (Debian: openssl)")
    d = Path(directory)
    d.mkdir(parents=True, exist_ok=True)
    ec = ("-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:P-256", "-nodes")
    written = []
    if not (d / "ca.pem").is_file():
        _openssl("req", "-x509", *ec, "-keyout", "ca.key", "-out", "ca.pem",
                 "-days", str(VALID_DAYS), "-subj", "/CN=hubo-bridge-ca", cwd=d)
        written += [d / "ca.pem", d / "ca.key"]
    san = ",".join(_san(h) for h in hosts)
    for name in names:
        ext = d / f"{name}.ext"
        ext.write_text(f"subjectAltName={san}\nbasicConstraints=CA:FALSE\n"
                       "keyUsage=digitalSignature\nextendedKeyUsage=serverAuth,clientAuth\n")
        try:
            _openssl("req", *ec, "-keyout", f"{name}.key", "-out", f"{name}.csr",
                     "-subj", f"/CN={name}", cwd=d)
            _openssl("x509", "-req", "-in", f"{name}.csr", "-CA", "ca.pem", "-CAkey", "ca.key",
                     "-CAcreateserial", "-out", f"{name}.pem", "-days", str(VALID_DAYS),
                     "-extfile", ext.name, cwd=d)
        finally:
            ext.unlink(missing_ok=True)
            (d / f"{name}.csr").unlink(missing_ok=True)
        written += [d / f"{name}.pem", d / f"{name}.key"]
    for path in d.glob("*.key"):
        os.chmod(path, 0o600)
    return written
