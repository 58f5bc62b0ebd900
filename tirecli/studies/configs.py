"""The report's study configs by name: the built-in ones (package data ``tirecli/studies/configs/NAME.yaml``)
and those registered at runtime (:func:`register_config`, e.g. for a study added by a plugin).

A figure of the registry names the config its card is drawn from (``FigureDef.study``); a fit may read
the samples of one (``data: {simulate: fm-fig4}``) and a campaign may start from one (``base: NAME``).
"""
from __future__ import annotations

from importlib import resources

from tirecli.config.loader import Config, config_from_text
from tirecli.errors import ConfigError, Problem, token

#: Configs registered at runtime: name -> YAML text.
REGISTERED: dict[str, str] = {}


def register_config(name: str, text: str) -> None:
    """Make the YAML ``text`` the config named ``name`` (ValueError if a built-in config has that name)."""
    if name in _package_names():
        raise ValueError(f"{name!r} is a built-in study config")
    REGISTERED[name] = text


def unregister_config(name: str) -> None:
    """Forget the config ``name`` registered at runtime."""
    REGISTERED.pop(name, None)


def _package_names() -> list[str]:
    root = resources.files("tirecli.studies").joinpath("configs")
    return sorted(p.name[:-5] for p in root.iterdir() if p.name.endswith(".yaml"))


def builtin_config_names() -> list[str]:
    """Names of the study configs the report can run: built-in and registered."""
    return sorted(set(_package_names()) | set(REGISTERED))


def builtin_config_text(name: str) -> str:
    """The YAML text of config ``name`` (ConfigError naming the available ones if there is none)."""
    if name in REGISTERED:
        return REGISTERED[name]
    res = resources.files("tirecli.studies").joinpath("configs").joinpath(name + ".yaml")
    if not res.is_file():
        raise ConfigError(Problem("<built-in configs>", None, "", f"no built-in study config {token(name)} "
                                                                 f"(available: {', '.join(builtin_config_names())})"))
    return res.read_text(encoding="utf-8")


def builtin_config(name: str, overrides=()) -> Config:
    """A study config by name (built-in or registered), with ``overrides`` (``KEY=VALUE``)."""
    return config_from_text(builtin_config_text(name), label=f"<built-in {name}>", overrides=overrides)


__all__ = ["builtin_config", "builtin_config_names", "builtin_config_text", "register_config", "unregister_config"]
