"""The ``tirecli`` command lines of the README and docs/, and parsing one as the CLI would
(options, arity and required arguments checked; nothing run)."""
from __future__ import annotations

import re
import shlex
from dataclasses import dataclass
from pathlib import Path

#: The checkout (also run without pytest: tests/run_readme_examples.py imports this module).
ROOT = Path(__file__).resolve().parents[1]

DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
SHELL = ("sh", "bash", "shell", "console", "")  # an untyped block too (docs/observe.md has one)
GLOBAL_FLAGS = ("--debug", "--quiet", "-q")


@dataclass
class Command:
    file: str    # relative to the repository
    line: int
    argv: list   # after "tirecli"

    @property
    def id(self) -> str:
        return f"{self.file}:{self.line}: tirecli {' '.join(self.argv)}"


def split(text: str) -> list[list[str]]:
    """The tirecli commands of one shell line (``a && tirecli b``: ``[b]``), comments removed."""
    out = []
    for part in re.split(r"&&|;|\|\|", text):
        words = shlex.split(part, comments=True)
        if words and words[0] == "tirecli":
            out.append(words[1:])
    return out


def fenced_blocks(path) -> list[tuple[str, int, list[str]]]:
    """The fenced blocks of a Markdown file: (language, line of the first content line, lines)."""
    out, current = [], None
    for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        if current is None and line.startswith("```"):
            current = (line[3:].strip(), n + 1, [])
        elif current is not None and line.startswith("```"):
            out.append(current)
            current = None
        elif current is not None:
            current[2].append(line)
    return out


def shell_commands(paths=DOCS) -> list[Command]:
    """Every tirecli command in the shell blocks of ``paths`` (lines that start with ``tirecli``
    or hold one after ``&&``)."""
    out = []
    for path in paths:
        for lang, first, lines in fenced_blocks(path):
            if lang not in SHELL:
                continue
            for k, line in enumerate(lines):
                if re.match(r"\s*(tirecli\s|pip .*&&\s*tirecli\s)", line):
                    out += [Command(str(path.relative_to(ROOT)), first + k, argv) for argv in split(line)]
    return out


def parse(argv: list[str]) -> tuple[list[str], dict]:
    """Parse ``tirecli ARGV`` as the CLI does, without running it: (command path, parameters).
    Raises click's exception for an unknown option, a missing argument, a bad value."""
    import typer.main

    from tirecli.cli.main import app

    cmd = typer.main.get_command(app)
    ctx = cmd.make_context("tirecli", [a for a in argv if a not in GLOBAL_FLAGS])
    path = []
    while hasattr(cmd, "resolve_command"):  # a group (Typer may carry its own copy of click)
        protected = getattr(ctx, "_protected_args", None)
        rest = [*(protected if protected is not None else ctx.protected_args), *ctx.args]
        name, cmd, rest = cmd.resolve_command(ctx, rest)
        path.append(name)
        ctx = cmd.make_context(name, rest, parent=ctx)
    return path, dict(ctx.params)
