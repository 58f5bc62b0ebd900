"""Examples: the ones reproducing paper figures equal the built-in study configs and validate."""
import pytest

from conftest import EXAMPLES

from tirecli.studies.configs import builtin_config_names


@pytest.mark.parametrize("name", builtin_config_names())
def test_example_matches_builtin(name):
    from importlib import resources

    ex = EXAMPLES / f"{name}.yaml"
    if not ex.exists():
        pytest.skip(f"{name} has no example copy")
    builtin = resources.files("tirecli.studies").joinpath("configs").joinpath(f"{name}.yaml").read_text()
    assert ex.read_text() == builtin, f"examples/{name}.yaml differs from the built-in study config"


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.yaml")), ids=lambda p: p.name)
def test_every_example_validates(cli, path):
    code, out, err = cli("params", "validate", path)
    assert code == 0, err
