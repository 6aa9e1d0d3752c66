"""Headless check of `make lab`: JupyterLab starts, answers over HTTP and serves the notebooks.

Starts JupyterLab on a free port of 127.0.0.1 with ``--no-browser`` and a random token (with
``--make MAKE`` through ``make lab LAB_ARGS=...``, as a user starts it; otherwise directly from
the interpreter running this script, which must be .venv-notebooks'), waits for ``/api/status``,
then checks that the contents API lists every ``notebooks/*.py`` as a *notebook* (jupytext's
contents manager is active) and that the Lab page of the first one is served. Stops the server it
started (its process group) in every case. Exits non-zero naming what failed.
"""

from __future__ import annotations

import argparse
import json
import os
import secrets
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
START_TIMEOUT_S = 120


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def get(url: str, token: str) -> tuple[int, bytes]:
    request = urllib.request.Request(url, headers={"Authorization": f"token {token}"})
    try:
        with urllib.request.urlopen(request, timeout=10) as response:
            return response.status, response.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--make", help="start it through this make as `make lab`")
    args = parser.parse_args(argv)

    port, token = free_port(), secrets.token_hex(16)
    lab_args = [
        "--no-browser",
        "--ip=127.0.0.1",
        f"--port={port}",
        f"--IdentityProvider.token={token}",
        "--ServerApp.open_browser=False",
    ]
    if args.make:
        cmd = [
            args.make,
            "--no-print-directory",
            "-C",
            str(ROOT),
            "lab",
            f"LAB_ARGS={' '.join(lab_args)}",
        ]
    else:
        jupyter = Path(sys.executable).parent / "jupyter"
        cmd = [str(jupyter), "lab", f"--notebook-dir={ROOT / 'notebooks'}", *lab_args]
        if os.geteuid() == 0:  # as `make lab` does: Jupyter refuses root without it
            cmd.append("--allow-root")
    print("$", " ".join(cmd), flush=True)
    log = open(ROOT / ".cache" / "lab_check.log", "w") if (ROOT / ".cache").is_dir() else None
    server = subprocess.Popen(
        cmd, stdout=log or subprocess.DEVNULL, stderr=subprocess.STDOUT, start_new_session=True
    )
    base = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + START_TIMEOUT_S
        while True:
            if server.poll() is not None:
                sys.exit(f"lab_check: JupyterLab exited with {server.returncode} before answering")
            try:
                status, _ = get(f"{base}/api/status", token)
                if status == 200:
                    break
            except (urllib.error.URLError, ConnectionError, TimeoutError):
                pass
            if time.monotonic() > deadline:
                sys.exit(f"lab_check: no answer from {base} within {START_TIMEOUT_S} s")
            time.sleep(1)
        waited = START_TIMEOUT_S - (deadline - time.monotonic())
        print(f"JupyterLab answers at {base} after {waited:.1f} s")

        status, body = get(f"{base}/api/contents/", token)
        if status != 200:
            sys.exit(f"lab_check: /api/contents/ answered {status}")
        listing = {item["name"]: item["type"] for item in json.loads(body)["content"]}
        expected = sorted(p.name for p in (ROOT / "notebooks").glob("*.py"))
        wrong = {name: listing.get(name) for name in expected if listing.get(name) != "notebook"}
        if not expected or wrong:
            sys.exit(
                f"lab_check: notebooks not served as notebooks (jupytext?): {wrong or listing}"
            )
        for name in expected:
            print(f"served as a notebook: {name}")

        status, body = get(f"{base}/lab/tree/{expected[0]}", token)
        if status != 200 or b"JupyterLab" not in body:
            sys.exit(f"lab_check: /lab/tree/{expected[0]} answered {status}")
        print(f"lab page of {expected[0]}: HTTP {status}")
        print("lab_check: ok")
        return 0
    finally:
        # Our server only: its own process group (make and jupyter under it).
        try:
            os.killpg(server.pid, signal.SIGTERM)
            server.wait(timeout=20)
        except ProcessLookupError:
            pass
        except subprocess.TimeoutExpired:
            os.killpg(server.pid, signal.SIGKILL)
        if log:
            log.close()


if __name__ == "__main__":
    sys.exit(main())
