"""The registry of reference checks (tirecli.studies.checks): keyed by figure id, loaded on demand."""
from __future__ import annotations

import subprocess
import sys

import pytest


def test_every_check_belongs_to_a_registered_figure():
    from tirecli.figures.registry import load_all as load_figures
    from tirecli.studies.checks import CHECKS, load_all

    load_all()
    figures = load_figures()
    assert set(CHECKS) <= set(figures), sorted(set(CHECKS) - set(figures))
    # the paper figures carry checks, tables and generic plots may not
    assert {"fm-fig1-left", "fm-fig4", "fm-table2", "obs-fig2", "mf-lugre-compare", "mcps-fig7"} <= set(CHECKS)
    assert not {"fm-table1", "sweep-mu-slip", "transient-histories", "mcps-table"} & set(CHECKS)


def test_a_figure_without_checks_loads_no_other_family():
    """Looking up a LuGre figure without checks imports neither the MCPS nor the Magic Formula checks,
    nor the studies a sweep does not need; an MCPS figure imports only the MCPS checks."""
    code = ("import sys; from tirecli.studies.checks import checks_for; "
            "assert checks_for('fm-table1') is None and checks_for('fm-fig1-left') is not None; "
            "a = sorted(m for m in sys.modules if m.startswith('tirecli')); "
            "assert checks_for('mcps-table') is None and checks_for('mcps-fig7') is not None; "
            "b = sorted(m for m in sys.modules if m.startswith('tirecli.studies.checks.')); print(a); print(b)")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    first, second = res.stdout.strip().splitlines()[-2:]
    for unwanted in ("tirecli.studies.checks.mcps", "tirecli.studies.checks.magic_formula", "tirecli.models.magic_formula",
                     "tirecli.studies.simulate", "tirecli.studies.observe", "tirecli.studies.fit", "tirecli.figures"):
        assert f"'{unwanted}'" not in first and f"'{unwanted}." not in first
    assert "'tirecli.studies.checks.mcps'" in second and "'tirecli.studies.checks.magic_formula'" not in second


def _fn(module: str):
    def checks(result):
        return []

    checks.__module__ = module
    return checks


@pytest.mark.parametrize("fid, module, message", [
    ("fm-fig1-left", "tirecli.studies.checks.steady", "registered twice"),
    ("mcps-new", "tirecli.studies.checks.steady", "belong in tirecli.studies.checks.mcps"),
    ("mf-new", "tests.somewhere", "belong in tirecli.studies.checks.magic_formula"),
    ("fm-new", "tirecli.studies.checks.mcps", "registers checks of 'mcps' figures only"),
])
def test_register_checks_refuses_misplaced_checks(fid, module, message):
    from tirecli.studies.checks import CHECKS, load_all, register_checks

    load_all()
    before = dict(CHECKS)
    with pytest.raises(ValueError, match=message):
        register_checks(fid)(_fn(module))
    assert CHECKS == before
