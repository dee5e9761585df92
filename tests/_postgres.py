"""A throwaway PostgreSQL server for the tests: Debian's binaries (``initdb``, ``pg_ctl`` under
/usr/lib/postgresql/VERSION/bin), a cluster in a temporary directory on a free loopback port,
run as the ``postgres`` user when the tests run as root (the server refuses root).

Without the binaries the PostgreSQL tests skip and say why; with
``GEARCHAOS_POSTGRES_TESTS=required`` (set by ``.ci/run`` once it has installed them) they fail.
"""

from __future__ import annotations

import glob
import os
import pwd
import shutil
import subprocess
import tempfile
import uuid
from pathlib import Path

import psycopg
import pytest


def binaries() -> Path | None:
    """The newest installed PostgreSQL's bin directory (with initdb and pg_ctl), else None."""
    found = [Path(d) for d in glob.glob("/usr/lib/postgresql/*/bin")]
    found += [Path(p).parent for p in [shutil.which("initdb")] if p]
    usable = [d for d in found if (d / "initdb").exists() and (d / "pg_ctl").exists()]
    return max(usable, key=lambda d: d.parent.name, default=None)


def unavailable(reason: str) -> None:
    """Skip, or fail when the PostgreSQL tests are required."""
    if os.environ.get("GEARCHAOS_POSTGRES_TESTS") == "required":
        pytest.fail(f"PostgreSQL tests required: {reason}")
    pytest.skip(f"{reason} (apt-get install postgresql; .ci/run does this as root)")


class PostgresCluster:
    """``initdb`` + ``pg_ctl start`` in a temporary directory; trust auth on 127.0.0.1:port."""

    def __init__(self, bin_dir: Path, port: int) -> None:
        self.bin, self.port = bin_dir, port
        self.dir = Path(tempfile.mkdtemp(prefix="gearchaos-pg-"))
        self.data = self.dir / "data"
        self.user: pwd.struct_passwd | None = None
        if os.geteuid() == 0:
            self.user = pwd.getpwnam("postgres")
            os.chown(self.dir, self.user.pw_uid, self.user.pw_gid)
        self._run("initdb", "-D", self.data, "-A", "trust", "-U", "postgres", "-E", "UTF8",
                  "--no-sync")  # fmt: skip
        options = (
            f"-p {port} -c listen_addresses=127.0.0.1 -k {self.dir} -c fsync=off "
            "-c max_connections=200"
        )
        self._run("pg_ctl", "-D", self.data, "-l", self.dir / "server.log", "-o", options, "-w",
                  "start")  # fmt: skip

    def _run(self, tool: str, *args: object) -> None:
        cmd = [str(self.bin / tool), *map(str, args)]
        if self.user is not None:
            cmd = ["runuser", "-u", "postgres", "--", *cmd]
        subprocess.run(cmd, check=True, capture_output=True, cwd=self.dir, timeout=120)

    def url(self, database: str = "postgres") -> str:
        return f"postgresql://postgres@127.0.0.1:{self.port}/{database}"

    def new_database(self) -> str:
        """A fresh empty database's URL (one per test: no state leaks between tests)."""
        name = f"t_{uuid.uuid4().hex[:12]}"
        with psycopg.connect(self.url(), autocommit=True) as conn:
            conn.execute(f"CREATE DATABASE {name}")
        return self.url(name)

    def stop(self) -> None:
        self._run("pg_ctl", "-D", self.data, "-m", "immediate", "-w", "stop")
        shutil.rmtree(self.dir, ignore_errors=True)
