"""Run every ``tirecli`` command that the README shows, as a new user would after its install command.

    python tests/run_readme_examples.py TIRECLI [--budget SECONDS] [--list]

``TIRECLI`` is the ``tirecli`` executable of a fresh virtual environment into which the README's install
command (``pip install .``, no extras) installed tirecli (``.ci/run`` makes one). The commands are taken
from the README's shell blocks by :func:`doc_commands.shell_commands` (the same extraction that
tests/test_cli_polish.py parses them with, so nothing is kept in sync by hand) and run in that order,
each as written (``tirecli`` replaced by ``TIRECLI``), in a temporary copy of the files they name
(``examples/``, ``tests/data/``) with empty caches (``XDG_CACHE_HOME``: matplotlib's font cache and
tirecli's study cache start empty, as on a new machine).

Fails (exit 1) when a command exits non-zero, prints a traceback or an internal error, or when the
commands together run past ``--budget`` seconds (default 600: on the 2-core CI machine they take
3-4 minutes; the budget keeps CI under its 15 minutes if one hangs). ``--list`` prints the commands only.
"""
from __future__ import annotations

import argparse
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from doc_commands import ROOT, shell_commands  # noqa: E402

#: What the README's commands read, relative to the checkout (copied into the folder they run in).
INPUTS = ("examples", "tests/data")
#: Text that no command may print.
FORBIDDEN = ("Traceback (most recent call last)", "internal error")


def readme_commands() -> list[list[str]]:
    """The argument lists (after ``tirecli``) of the README's commands, in the README's order."""
    return [c.argv for c in shell_commands([ROOT / "README.md"])]


def run(tirecli: str, budget: float) -> int:
    commands = readme_commands()
    failures = []
    t_start = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="tirecli-readme-") as tmp:
        work = Path(tmp) / "checkout"
        for rel in INPUTS:
            shutil.copytree(ROOT / rel, work / rel)
        env = dict(os.environ, MPLBACKEND="Agg", XDG_CACHE_HOME=str(Path(tmp) / "cache"))
        for key in ("TIRECLI_CACHE_DIR", "MPLCONFIGDIR", "PYTHONPATH"):
            env.pop(key, None)
        for argv in commands:
            left = budget - (time.monotonic() - t_start)
            shown = "tirecli " + shlex.join(argv)
            if left <= 0:
                failures.append(f"{shown}: not run, the budget of {budget:.0f} s is spent")
                continue
            t0 = time.monotonic()
            try:
                proc = subprocess.run([tirecli, *argv], cwd=work, env=env, stdin=subprocess.DEVNULL,
                                      capture_output=True, text=True, timeout=left)
            except subprocess.TimeoutExpired:
                failures.append(f"{shown}: still running when the budget of {budget:.0f} s was spent")
                print(f"  TIMEOUT  {shown}", flush=True)
                continue
            wall = time.monotonic() - t0
            text = proc.stdout + proc.stderr
            bad = [f for f in FORBIDDEN if f in text]
            status = "ok" if proc.returncode == 0 and not bad else "FAILED"
            print(f"{wall:7.1f} s  exit {proc.returncode}  {status:6s} {shown}", flush=True)
            for line in [ln for ln in text.splitlines() if ln.startswith(("note:", "check failed", "error:"))][:6]:
                print(f"           {line}")
            if status != "ok":
                failures.append(f"{shown}: exit {proc.returncode}" + (f", printed {bad[0]!r}" if bad else "")
                                + "\n" + "\n".join(text.strip().splitlines()[-15:]))
    total = time.monotonic() - t_start
    print(f"README examples: {len(commands) - len(failures)} passed, {len(failures)} failed in {total:.0f} s "
          f"(budget {budget:.0f} s)")
    for f in failures:
        print(f"FAILED: {f}", file=sys.stderr)
    return 1 if failures else 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("tirecli", nargs="?", default="tirecli", help="the tirecli executable to run")
    ap.add_argument("--budget", type=float, default=600.0, help="seconds for all commands together")
    ap.add_argument("--list", action="store_true", help="print the commands and exit")
    args = ap.parse_args(argv)
    if args.list:
        for a in readme_commands():
            print("tirecli " + shlex.join(a))
        return 0
    return run(args.tirecli, args.budget)


if __name__ == "__main__":
    sys.exit(main())
