"""The reference checks of each study's figures (``Study.checks``, functions in tirecli.studies.checks):
keyed by figure id, imported on demand."""
from __future__ import annotations

import subprocess
import sys

import pytest


def _check_ids() -> dict:
    """Figure id (or ``prefix*``) -> the study whose entry lists its checks."""
    from tirecli.studies.registry import load_all

    out = {}
    for name, study in load_all().items():
        for fid in study.checks:
            assert fid not in out, f"checks of {fid!r} listed by {out[fid]!r} and {name!r}"
            out[fid] = name
    return out


def test_every_check_belongs_to_a_registered_figure_and_resolves():
    from tirecli.figures.registry import load_all as load_figures
    from tirecli.studies.registry import load_all

    figures = load_figures()
    ids = _check_ids()
    for fid in ids:
        matched = [f for f in figures if f == fid or (fid.endswith("*") and f.startswith(fid[:-1]))]
        assert matched, f"checks of {fid!r}: no such figure"
    for study in load_all().values():
        for fn in study.checks.values():
            assert callable(getattr(fn, "resolve", lambda: fn)())  # the lazy reference names a function
    # the paper figures carry checks, tables and generic plots may not
    assert {"fm-fig1-left", "fm-fig4", "fm-table2", "obs-fig2", "mf-lugre-compare", "mcps-fig7", "mf-tire-*",
            "mf-golden-fx0"} <= set(ids)
    assert not {"fm-table1", "sweep-mu-slip", "transient-histories", "mcps-table"} & set(ids)


#: The report's figures with reference checks.
CHECKED = {"fm-fig1-left", "fm-fig1-right", "obs-fig1", "fm-fig6-surface", "fm-fig4", "fm-fig7", "fm-fig8", "fm-fig6",
           "fm-table2", "obs-fig2", "obs-speed-error", "obs-gain-study", "mf-lugre-compare", "mcps-fig3", "mcps-fig4",
           "mcps-fig5", "mcps-fig7", "mcps-fig8", "mcps-fig9", "mcps-fig10", "mcps-fig11", "mcps-calibration",
           "mcps-relaxation", "mf-fit-fx", "mf-fit-fy", "mf-fit-mz", "mf-fit-combined", "mf-fit-residuals",
           "mf-fit-coefficients", "relaxation-compare"}


def test_a_figure_of_the_report_has_the_checks_of_its_study():
    """Each report figure's checks are found in the entry of the study of its config (by exact id or prefix)."""
    from tirecli.figures.registry import load_all as load_figures
    from tirecli.studies import registry
    from tirecli.studies.configs import builtin_config

    checked = set()
    for fid, f in load_figures().items():
        if f.study is not None and registry.get(builtin_config(f.study).data["study"]).checks_for(fid) is not None:
            checked.add(fid)
    assert checked - CHECKED == {f for f in checked if f.startswith(("mf-tire-", "mf-golden-"))}
    assert CHECKED <= checked
    assert len([f for f in checked if f.startswith("mf-tire-")]) == 4 and len([f for f in checked if f.startswith("mf-golden-")]) == 4


def test_a_figure_without_checks_loads_no_other_family():
    """Looking up a LuGre figure's checks imports neither the MCPS nor the Magic Formula checks, nor the
    other studies; an MCPS figure imports only the MCPS checks."""
    code = ("import sys; from tirecli.studies import registry; sweep = registry.get('sweep'); "
            "assert sweep.checks_for('fm-table1') is None and sweep.checks_for('fm-fig1-left') is not None; "
            "sweep.checks_for('fm-fig1-left').resolve(); "
            "a = sorted(m for m in sys.modules if m.startswith('tirecli')); "
            "st = registry.get('mcps-stationary'); "
            "assert st.checks_for('mcps-table') is None; st.checks_for('mcps-fig7').resolve(); "
            "b = sorted(m for m in sys.modules if m.startswith('tirecli.studies.checks.')); print(a); print(b)")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    first, second = res.stdout.strip().splitlines()[-2:]
    for unwanted in ("tirecli.studies.checks.mcps", "tirecli.studies.checks.magic_formula", "tirecli.models.magic_formula",
                     "tirecli.studies.simulate", "tirecli.studies.observe", "tirecli.studies.fit", "tirecli.figures"):
        assert f"'{unwanted}'" not in first and f"'{unwanted}." not in first
    assert "'tirecli.studies.checks.steady'" in first
    assert "'tirecli.studies.checks.mcps'" in second and "'tirecli.studies.checks.magic_formula'" not in second


@pytest.mark.parametrize("fid, expected", [("mf-tire-chrono-185-80r14", "tire_checks"), ("mf-golden-fy0-mz", "golden_checks"),
                                           ("fm-fig1-right", "fig1_right_checks"), ("mf-tire", None)])
def test_checks_by_exact_id_or_prefix(fid, expected):
    from tirecli.studies import registry

    study = registry.get("mf-golden" if fid.startswith("mf-golden") else "sweep")
    fn = study.checks_for(fid)
    assert (fn.name if fn is not None else None) == expected
