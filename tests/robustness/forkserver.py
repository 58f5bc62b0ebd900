"""A warm ``tirecli`` for the robustness corpus: import once, fork one process per command.

Started by :class:`harness.ForkServer` as ``python forkserver.py``. It imports every module of
``tirecli`` (and what they import: numpy, pandas, matplotlib, ...) once, then reads one JSON
request per line on stdin and answers one JSON line on stdout. Each request is run in a fresh
child process (``os.fork``) exactly as the console script runs it: its own session (process
group), working directory, environment, ``sys.argv``, stdin from ``/dev/null``, stdout and stderr
to files, the default SIGINT/SIGTERM handlers, and the exit code of
:func:`tirecli.cli.main.main`. A child that outlives its time limit is killed with its process
group. So a command costs milliseconds instead of the interpreter's start and imports (about a
second of CPU), and the corpus of bad inputs runs in seconds.

Request: ``{"args": [...], "cwd": str, "env": {...}, "timeout": s, "out": path, "err": path}``.
Answer: ``{"code": int, "elapsed": s, "timed_out": bool}``.
"""
from __future__ import annotations

import importlib
import json
import os
import pkgutil
import signal
import sys
import time


def _preload() -> None:
    import tirecli

    for mod in pkgutil.walk_packages(tirecli.__path__, "tirecli."):
        if mod.name.endswith("__main__"):
            continue
        try:
            importlib.import_module(mod.name)
        except Exception:  # noqa: BLE001 - an optional module; the child imports what it needs
            pass
    for name in ("pandas", "matplotlib.pyplot", "jinja2", "yaml"):
        try:
            importlib.import_module(name)
        except Exception:  # noqa: BLE001
            pass


def _child(req: dict) -> None:
    """In the forked child: become the command; never returns."""
    code = 70
    try:
        os.setsid()
        os.chdir(req["cwd"])
        os.environ.clear()
        os.environ.update(req["env"])
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        for fd, path, flags in ((0, os.devnull, os.O_RDONLY), (1, req["out"], os.O_WRONLY | os.O_TRUNC),
                                (2, req["err"], os.O_WRONLY | os.O_TRUNC)):
            new = os.open(path, flags)
            os.dup2(new, fd)
            os.close(new)
        sys.argv = ["tirecli", *req["args"]]
        from tirecli.cli.main import main

        code = main(list(req["args"]))
        sys.stdout.flush()
        sys.stderr.flush()
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    except BaseException:  # noqa: BLE001 - like the interpreter: print the traceback, exit 1
        import traceback

        traceback.print_exc()
        code = 1
    finally:
        try:
            sys.stdout.flush()
            sys.stderr.flush()
        finally:
            os._exit(code if isinstance(code, int) else 1)


def _wait(pid: int, timeout: float) -> tuple[int, bool]:
    deadline = time.monotonic() + timeout
    delay = 0.001
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            return os.waitstatus_to_exitcode(status), False
        if time.monotonic() > deadline:
            try:
                os.killpg(pid, signal.SIGKILL)
            except OSError:
                pass
            _, status = os.waitpid(pid, 0)
            return os.waitstatus_to_exitcode(status), True
        time.sleep(delay)
        delay = min(delay * 2, 0.02)


def serve() -> None:
    _preload()
    answer = sys.stdout
    sys.stdout = sys.stderr  # nothing else may write into the answer channel
    answer.write(json.dumps({"ready": True}) + "\n")
    answer.flush()
    for line in sys.stdin:
        req = json.loads(line)
        answer.flush()
        sys.stderr.flush()
        t0 = time.perf_counter()
        pid = os.fork()
        if pid == 0:
            sys.stdout = sys.__stdout__
            _child(req)
        code, timed_out = _wait(pid, float(req["timeout"]))
        answer.write(json.dumps({"code": code, "elapsed": time.perf_counter() - t0, "timed_out": timed_out}) + "\n")
        answer.flush()


if __name__ == "__main__":
    serve()
