"""The public Python API (docs/api.md): tirecli.run gives what the CLI writes, raises what it prints, writes
nothing unless asked; load_params / load_tire give the models' parameter objects; import tirecli is cheap."""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from conftest import EXAMPLES

SWEEP = EXAMPLES / "fm-fig1-right.yaml"


def _cell(x) -> str:
    return "" if x is None or (isinstance(x, float) and x != x) else str(x)


def _read(path) -> pd.DataFrame:
    return pd.read_csv(path, comment="#", keep_default_na=False, na_values=[""])


def test_frames_facts_and_checks_are_those_of_the_command(cli, tmp_path, monkeypatch):
    import tirecli

    monkeypatch.chdir(tmp_path)
    res = tirecli.run(SWEEP, set=["sweep.slip.num=201"])
    assert list(tmp_path.iterdir()) == []  # nothing written without out
    code, _, err = cli("--quiet", "sweep", SWEEP, "--set", "sweep.slip.num=201", "--out", tmp_path / "cli")
    assert code == 0, err
    run = json.loads((tmp_path / "cli" / "run.json").read_text())
    assert sorted(res.frames) == sorted(p.stem for p in (tmp_path / "cli" / "data").iterdir()) == ["peaks", "sweep"]
    for name, frame in res.frames.items():
        written = _read(tmp_path / "cli" / "data" / f"{name}.csv")
        assert list(written.columns) == list(frame.columns) and len(written) == len(frame)
        for col in frame.columns:
            a, b = written[col].to_numpy(), frame[col].to_numpy()
            if np.issubdtype(np.asarray(a).dtype, np.number) and np.issubdtype(np.asarray(b).dtype, np.number):
                np.testing.assert_array_equal(a, b)  # the CSV's 17 digits give back every float exactly
            else:  # texts; an empty cell is a missing value (None or NaN) of the frame
                assert [_cell(x) for x in a] == [_cell(x) for x in b], col
    assert [(c.id, c.value, c.reference, c.tolerance, c.status == "passed") for c in res.checks] == \
        [(c["id"], c["value"], c["reference"], c["tolerance"], c["passed"]) for c in run["checks"]]
    assert len(res.checks) == 13 and res.facts["mu_peak[0]"] == run["meta"]["facts"]["peaks"][0]["mu_peak"]


def test_write_gives_the_files_of_the_command(cli, tmp_path):
    import tirecli

    cfg = {"study": "simulate", "tire": "canudas2003-table2", "t_end": 0.4,
           "input": {"brake_torque": {"table": {"t": [0, 0.2], "value": [0, 900]}}},
           "cases": [{"model": "lumped", "kappa0": "Z", "label": "a"}, {"model": "lumped", "kappa0": 1, "label": "b"}]}
    res = tirecli.run(cfg, out=tmp_path / "api")
    (tmp_path / "c.yaml").write_text(json.dumps(cfg))  # JSON is YAML
    code, _, err = cli("--quiet", "simulate", tmp_path / "c.yaml", "--out", tmp_path / "cli")
    assert code == 0, err

    def files(d):
        return sorted(str(p.relative_to(d)) for p in d.rglob("*") if p.is_file())

    assert files(tmp_path / "api") == files(tmp_path / "cli")
    for rel in files(tmp_path / "cli"):
        if rel.startswith("data/"):
            assert (tmp_path / "api" / rel).read_bytes() == (tmp_path / "cli" / rel).read_bytes(), rel
    a, b = (json.loads((tmp_path / d / "run.json").read_text()) for d in ("api", "cli"))
    assert sorted(a) == sorted(b) and a["meta"]["events"] == b["meta"]["events"]
    assert a["command"].startswith("tirecli.run(") and res.out == tmp_path / "api"
    assert res.facts["peak_abs_slip[a]"] == b["meta"]["events"][0]["peak_abs_slip"]
    again = res.write(tmp_path / "again")
    assert files(again) == files(tmp_path / "cli")


@pytest.mark.parametrize("text, overrides", [
    ("study: sweep\ntire: {set: canudas2003-table1, sigma0: -3}\n", []),
    ("study: swep\ntire: canudas2003-table1\n", []),
    ("study: sweep\ntire: canudas2003-table1\nfigures: [fm-fig1-lef]\n", []),
    ("study: sweep\ntire: canudas2003-table1\n", ["sweep.speeds=[x]"]),
    ("study: simulate\ntire: canudas2003-table2\nt_end: 3000\noutput: {dt: 0.0000001}\n", []),
])
def test_errors_are_the_cli_messages(cli, tmp_path, text, overrides):
    import tirecli
    from tirecli.errors import TirecliError

    cfg = tmp_path / "bad.yaml"
    cfg.write_text(text)
    with pytest.raises(TirecliError) as err:
        tirecli.run(cfg, set=overrides)
    command = "sweep" if "sweep" in text else "simulate"
    code, _, printed = cli(command, cfg, *[a for o in overrides for a in ("--set", o)], "--out", tmp_path / "o")
    assert code == err.value.exit_code == 2
    assert printed.splitlines() == [f"error: {line}" for line in str(err.value).splitlines()]
    assert not (tmp_path / "o").exists()


def test_a_mapping_config_names_its_keys():
    import tirecli
    from tirecli.errors import ConfigError

    with pytest.raises(ConfigError, match=r"^<config>: tire.sigma0: out of range: must be > 0, got -3$"):
        tirecli.run({"study": "sweep", "tire": {"set": "canudas2003-table1", "sigma0": -3}})


def test_parameters_and_models():
    import tirecli
    from tirecli.models import LuGreParams, MFTire, evaluate, mu_ss_uniform

    p = tirecli.load_params("canudas2003-table1")
    assert isinstance(p, LuGreParams) and p.sigma0 == 181.54  # the set's value (FM Table 1)
    # the uniform-load steady state at zero slip is zero, and odd in v_r
    assert float(mu_ss_uniform(np.array([0.0]), np.array([20.0]), p)[0]) == 0.0
    tire = tirecli.load_tire("pacejka2006-205-60r15")
    assert isinstance(tire, MFTire) and isinstance(tirecli.load_params("pacejka2006-205-60r15"), MFTire)
    f = evaluate(tire, kappa=0.0, alpha=np.array([-0.02, 0.02]), gamma=0.0, fz=4000.0, outputs=("fy",), combined=False)
    assert f.fy[0] > 0 > f.fy[1]  # ISO-W: alpha > 0 gives Fy < 0
    assert type(tirecli.load_params("sorine2000-mcps")).__name__ == "MCPSParams"


def test_import_tirecli_is_cheap():
    code = ("import sys, tirecli, tirecli.models; "
            "print(sorted(m for m in sys.modules if m.startswith('tirecli'))); "
            "print(sorted(m for m in ('numpy', 'pandas', 'scipy', 'matplotlib', 'yaml') if m in sys.modules))")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    mods, libs = res.stdout.strip().splitlines()
    assert mods == "['tirecli', 'tirecli._version', 'tirecli.models']" and libs == "[]"
