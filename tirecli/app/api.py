"""The public Python API: ``tirecli.run``, ``tirecli.load_params``, ``tirecli.load_tire`` (``docs/api.md``).

The same work as the commands, without the CLI: a config (a file or a mapping) is planned, run and,
when asked, written exactly as its command writes it (:mod:`tirecli.app.run`). Errors are the tool's
exception types (:mod:`tirecli.errors`) with the one-line messages the CLI prints.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tirecli.config.loader import Config, config_from_mapping, load_config
from tirecli.studies.base import StudyResult


@dataclass(frozen=True)
class CheckRecord:
    """One reference check of a run: ``status`` is ``passed`` or ``failed``; ``value`` against
    ``reference`` within ``tolerance`` (in ``unit``)."""

    id: str
    status: str
    value: float
    reference: float
    tolerance: float
    unit: str = "-"
    description: str = ""


class Result:
    """The outcome of :func:`run`.

    Attributes
    ----------
    study : str
        The study that ran (the config's ``study:``).
    result : StudyResult
        Everything the study produced (frames, parameter sets, ``meta``, the payload its figures draw).
    out : Path or None
        Where the outputs were written (``run(..., out=DIR)`` or :meth:`write`), else None.
    """

    def __init__(self, result: StudyResult, checks=None, out: Path | None = None, command: str = ""):
        self.result, self.out, self._command = result, out, command
        self._checks = checks
        self._frames = None

    def __repr__(self) -> str:
        return f"<tirecli.Result of study {self.study!r}: frames {', '.join(self.result.data)}>"

    @property
    def study(self) -> str:
        return self.result.study

    @property
    def frames(self) -> dict:
        """Data name -> pandas DataFrame: the values the CLI writes to ``data/NAME.csv``."""
        if self._frames is None:
            self._frames = {k: (v.to_frame() if hasattr(v, "to_frame") else v) for k, v in self.result.data.items()}
        return self._frames

    @property
    def facts(self) -> dict:
        """The run's scalar facts by name (those a campaign can tabulate, ``NAME[LABEL]`` per case)."""
        from tirecli.studies import registry

        return registry.get(self.study).facts(self.result)

    @property
    def checks(self) -> list[CheckRecord]:
        """The reference checks of the figures the config asks for by name (those of ``run.json``)."""
        if self._checks is None:
            from tirecli.app.draw import checks_of

            self._checks = checks_of(self.result)
        return [CheckRecord(c.id, "passed" if c.passed else "failed", c.value, c.reference, c.tolerance, c.unit,
                            c.description) for c in self._checks]

    def write(self, out: str | Path) -> Path:
        """Write the run's outputs into the folder ``out`` as its command does (``run.json``, ``data/``,
        ``figures/``, extra files such as ``fitted.yaml``; written atomically); returns the folder."""
        import time

        from tirecli.app.draw import close_figures, draw
        from tirecli.app.results import write_result
        from tirecli.io.staging import out_path, staged_dir
        from tirecli.io.files import check_output_dir

        out = out_path(out)
        check_output_dir(out, files=("run.json",), dirs=("data", "figures"))
        t0 = time.perf_counter()
        with staged_dir(out) as stage:
            figs, checks = draw(self.result)
            write_result(stage, self.result, figs, checks, self._command, time.perf_counter() - t0)
            close_figures(figs)
        self._checks, self.out = checks, out
        return out


def _config(config: Any, overrides) -> Config:
    if isinstance(config, Config):
        return config
    if isinstance(config, dict):
        return config_from_mapping(config, overrides=overrides)
    if isinstance(config, (str, Path)):
        return load_config(config, overrides)
    from tirecli.errors import UsageError

    raise UsageError(f"tirecli.run: config must be a path or a mapping, not {type(config).__name__}")


def run(config, *, set=None, out=None) -> Result:  # noqa: A002 - the name of the command-line option
    """Run a study config: ``config`` is a path or a mapping with the content of a YAML config, ``set`` a
    list of ``KEY=VALUE`` overrides as on the command line (``--set``). With ``out`` (a folder), the
    outputs are written as the study's command writes them; without, nothing is written."""
    from tirecli.app.run import execute, run_config

    overrides = list(set or [])
    if isinstance(overrides, str):
        overrides = [overrides]
    cfg = _config(config, overrides)
    what = repr(str(config)) if isinstance(config, (str, Path)) else "{...}"
    command = f"tirecli.run({what}" + (f", set={overrides!r}" if overrides else "") + ")"
    if out is None:
        return Result(execute(cfg), command=command)
    summary = run_config(None, cfg, out=out, command_text=command)
    return Result(summary.result, summary.checks, summary.out, command)


def load_params(name_or_path: str | Path):
    """The model parameter object of a parameter set (a built-in name, ``tirecli params list``, or a file):
    ``LuGreParams``, ``QuarterCarParams``, ``ObserverGains``, ``MCPSParams``, or an ``MFTire`` for a
    Magic Formula tyre (a ``.tir`` file or a built-in tyre)."""
    from tirecli.parameters.sets import load_set

    ps = load_set(str(name_or_path), Path.cwd())
    if ps.kind == "magic_formula":
        from tirecli.parameters.mf import tire_from_set

        return tire_from_set(ps)
    return ps.model()


def load_tire(path: str | Path):
    """The ``MFTire`` of a Magic Formula tyre: a ``.tir`` file, its YAML form, or a built-in tyre name."""
    from tirecli.app.mf import load_tire as load

    return load(str(path))[1]


__all__ = ["run", "load_params", "load_tire", "Result", "CheckRecord"]
