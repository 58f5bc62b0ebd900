"""Fixtures of the observer tests: the OBS design plant and gains (built-in parameter sets)."""
import pytest

from tirecli.observers import lugre_observer as lo


@pytest.fixture(scope="module")
def plant():
    from tirecli.parameters.sets import load_builtin

    return lo.ObserverPlant(tire=load_builtin("canudas2003-table1").model(),
                            car=load_builtin("canudas2003-obs-quarter-car").model())


@pytest.fixture(scope="module")
def gains():
    from tirecli.parameters.sets import load_builtin

    return load_builtin("canudas2003-obs-gains").model()
