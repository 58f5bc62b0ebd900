"""MCPS through the real CLI: tirecli compare / simulate, outputs, checks, errors, the report section."""
import json

import numpy as np
import pandas as pd
import pytest


def _write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


STATIONARY = """study: mcps-stationary
mf: simple
carcass: [complete, rigid]
fz: [3000, 4000]
kappa: {start: -0.1, stop: 0.12, num: 12}
alpha: {start: 0, stop: 0.2, num: 9}
combined: {alpha: [0.02, 0.05], kappa: [-0.05, 0, 0.05]}
curvature: [0, 0.05, 0.1]
figures: [mcps-fig7, mcps-fig10, mcps-fig11]
"""


def test_compare_output_contract(cli, tmp_path):
    cfg = _write(tmp_path, "st.yaml", STATIONARY)
    code, out, err = cli("compare", cfg, "--out", tmp_path / "o")
    assert code == 0, err
    df = pd.read_csv(tmp_path / "o" / "data" / "stationary.csv")
    for col in ("model", "carcass", "calibrated", "family", "fz", "kappa", "alpha", "phi", "fx", "fy", "mz", "x", "y", "delta"):
        assert col in df.columns
    assert set(df["model"]) == {"mcps", "mf"} and set(df["family"]) == {"kappa", "alpha", "combined", "curvature"}
    assert set(df[df["model"] == "mcps"]["carcass"]) == {"complete", "rigid"}
    assert set(df["fz"]) == {3000.0, 4000.0}
    mc = df[df["model"] == "mcps"]
    assert np.isfinite(mc[["fx", "fy", "mz", "x", "y", "delta"]].to_numpy()).all()
    assert len(df[(df["family"] == "combined") & (df["model"] == "mcps")]) == 2 * 2 * 2 * 3
    rigid = mc[mc["carcass"] == "rigid"]
    assert (rigid[["x", "y", "delta"]].to_numpy() == 0).all()
    comp = mc[(mc["carcass"] == "complete") & (mc["family"] == "alpha") & (mc["alpha"] > 0)]
    assert (comp["delta"] > 0).all() and (comp["fy"] < 0).all() and (comp["mz"] > 0).all()   # ISO-W, road on tire
    run = json.loads((tmp_path / "o" / "run.json").read_text())
    assert run["study"] == "mcps-stationary" and run["meta"]["stiffnesses"]["4000 N"]["D_yalphaF"] == pytest.approx(36909.6, abs=0.1)
    assert {c["id"].split("/")[0] for c in run["checks"]} == {"mcps-fig7", "mcps-fig10", "mcps-fig11"}
    assert all(c["passed"] for c in run["checks"]), [c for c in run["checks"] if not c["passed"]]
    assert any("tire.r_x" in a or "r_x:" in a for a in run["assumed"])
    for fid in ("mcps-fig7", "mcps-fig10", "mcps-fig11"):
        assert (tmp_path / "o" / "figures" / f"{fid}.png").exists() and (tmp_path / "o" / "figures" / f"{fid}.svg").exists()
    assert "stiffnesses at 4000 N" in out
    # deterministic
    code, _, _ = cli("compare", cfg, "--out", tmp_path / "o2")
    assert (tmp_path / "o" / "data" / "stationary.csv").read_bytes() == (tmp_path / "o2" / "data" / "stationary.csv").read_bytes()


def test_compare_calibration_writes_a_usable_set(cli, tmp_path):
    cfg = _write(tmp_path, "cal.yaml", "study: mcps-stationary\nmf: simple\nkappa: [0.02, 0.06, 0.1]\n"
                                      "alpha: [-0.1, -0.02, 0.02, 0.1]\ncalibrate: {load: 4000}\n")
    code, out, err = cli("compare", cfg, "--out", tmp_path / "o")
    assert code == 0, err
    assert "calibration to mcps-simple-mf" in out
    run = json.loads((tmp_path / "o" / "run.json").read_text())
    cal = run["meta"]["calibration"]
    assert set(cal["gaps"]["calibrated"]) == {"fx", "fy", "mz"} and cal["at_bound"]
    for n in cal["at_bound"]:  # every parameter on a bound is named with the bound and its source
        f = cal["fitted"][n]
        assert f"{n} ends at its {f['at_bound']} bound {f[f['at_bound']]:g} ({f['bound_source']})" in out
    assert cal["grids"]["alpha_fy"]["points"] == 2 and cal["grids"]["alpha"]["points"] == 2  # the drawn points
    assert run["meta"]["gaps"]["mcps-fig8"]["4000 N"]["calibrated"]["fy_points"] == 2
    assert "calibrated" in run["parameters"]
    df = pd.read_csv(tmp_path / "o" / "data" / "stationary.csv")
    assert set(df["calibrated"]) == {True, False}
    cset = tmp_path / "o" / "calibrated.yaml"
    code, out, err = cli("params", "validate", cset)
    assert code == 0, err
    code, out, err = cli("params", "show", cset)
    assert code == 0 and "calibrated to mcps-simple-mf" in out
    use = _write(tmp_path, "use.yaml", f"study: mcps-stationary\ntire: {cset}\nmf: none\nkappa: [0.05]\n")
    code, out, err = cli("compare", use, "--out", tmp_path / "o3")
    assert code == 0, err


def test_standstill_outputs(cli, tmp_path):
    cfg = _write(tmp_path, "ss.yaml", "study: mcps-standstill\ncycles: 2\nsamples: 200\n")
    code, out, err = cli("simulate", cfg, "--out", tmp_path / "o")
    assert code == 0, err
    st = pd.read_csv(tmp_path / "o" / "data" / "standstill.csv")
    pa = pd.read_csv(tmp_path / "o" / "data" / "patch.csv")
    assert {"t", "psi", "mz", "leg", "cycle"} <= set(st.columns) and {"t", "xi", "fy"} <= set(pa.columns)
    assert pa["xi"].nunique() == 81 and np.isfinite(pa["fy"]).all()
    run = json.loads((tmp_path / "o" / "run.json").read_text())
    f = run["meta"]["facts"]
    assert f["C_z_eq11_Nm_per_rad"] == pytest.approx(1937.54, abs=0.01)
    assert f["Mz_inf_frame_term_Nm"] == pytest.approx(249.995, abs=1e-3)
    assert f["mz_at_minus_A_Nm"] == pytest.approx(301.92, abs=0.01)
    assert f["loop_energy_last_cycle_J"] > 0
    assert all(c["passed"] for c in run["checks"]), [c for c in run["checks"] if not c["passed"]]
    assert any("0.45 rad" in a for a in run["assumed"])
    assert "C_z = 1937.54" in out


def test_slider_and_relaxation_outputs(cli, tmp_path):
    cfg = _write(tmp_path, "sl.yaml", "study: mcps-slider\nsamples: 400\n")
    code, out, err = cli("simulate", cfg, "--out", tmp_path / "s")
    assert code == 0, err
    sl = pd.read_csv(tmp_path / "s" / "data" / "slider.csv")
    assert {"t", "ux", "psi", "fx", "m", "period"} <= set(sl.columns)
    run = json.loads((tmp_path / "s" / "run.json").read_text())
    assert run["meta"]["facts"]["first_peak_force_N"] == pytest.approx(26.37, abs=0.01)
    assert all(c["passed"] for c in run["checks"])
    cfg = _write(tmp_path, "rx.yaml", "study: mcps-relaxation\ndistance: 0.5\ncarcass: [rigid, complete]\n")
    code, out, err = cli("simulate", cfg, "--out", tmp_path / "r")
    assert code == 0, err
    rx = pd.read_csv(tmp_path / "r" / "data" / "relaxation.csv")
    assert {"case", "s", "fy", "mz", "ratio"} <= set(rx.columns) and set(rx["case"]) == {"rigid", "complete"}
    f = json.loads((tmp_path / "r" / "run.json").read_text())["meta"]["facts"]
    assert f["rigid"]["s63_first_m"] == pytest.approx(0.051685, abs=2e-4)
    assert f["complete"]["s95_first_m"] is None          # not reached within 0.5 m: said, not invented
    assert "95 % not reached" in out


@pytest.mark.parametrize("cfg,override,where", [
    ("study: mcps-stationary\nkappa: [0.1]\n", "tire.r_x=-1", "tire.r_x"),
    ("study: mcps-stationary\nkappa: [0.1]\n", "tire.mu_y=0", "tire.mu_y"),
    ("study: mcps-stationary\nkappa: [0.1]\n", "tire.alpha_x=1", "tire.alpha_x"),
    ("study: mcps-stationary\nkappa: [0.1]\n", "tire.beta_z=0.5", "tire.beta_z"),
    ("study: mcps-stationary\nkappa: [0.1]\n", "fz=0", "fz"),
    ("study: mcps-stationary\nkappa: [0.1]\n", "kappa=[-1]", "kappa"),
    ("study: mcps-stationary\nkappa: [0.1]\n", "mf=no-such-tyre", "mf"),
    ("study: mcps-stationary\nkappa: [0.1]\n", "calibrate=true", "calibrate"),
    ("study: mcps-stationary\nkappa: [0.1]\n", "carcas=rigid", "carcas"),
    ("study: mcps-relaxation\n", "distance=0", "distance"),
    ("study: mcps-relaxation\n", "alpha=0", "alpha"),
    ("study: mcps-relaxation\n", "speed=0", "speed"),
    ("study: mcps-relaxation\n", "tire.k_y=-5", "tire.k_y"),
    ("study: mcps-standstill\n", "fz=-4000", "fz"),
    ("study: mcps-standstill\n", "amplitude=0", "amplitude"),
    ("study: mcps-slider\n", "tire.U=0", "tire.U"),
])
def test_bad_values_are_one_line_usage_errors(cli, tmp_path, cfg, override, where):
    if "calibrate" in override:
        cfg += "mf: none\n"
    path = _write(tmp_path, "c.yaml", cfg)
    command = "compare" if "stationary" in cfg else "simulate"
    code, out, err = cli(command, path, "--set", override, "--out", tmp_path / "o")
    assert code == 2, (out, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:") and where in lines[0], err
    assert "Traceback" not in err
    assert not (tmp_path / "o" / "run.json").exists()


def test_option_forms(cli, tmp_path):
    path = _write(tmp_path, "s.yaml", "study: mcps-slider\ncompare_period: null\nsamples: 40\n")
    code, out, err = cli("simulate", path, "--out", tmp_path / "o")
    assert code == 0, err
    assert set(pd.read_csv(tmp_path / "o" / "data" / "slider.csv")["period"]) == {2.0}
    path = _write(tmp_path, "c.yaml", "study: mcps-stationary\nkappa: [0.1]\nmf: simple\ncalibrate: {mz_weight: -1}\n")
    code, out, err = cli("compare", path)
    assert code == 2 and "calibrate.mz_weight" in err and ">= 0" in err, err


def test_non_converging_fixed_point_writes_nothing(cli, tmp_path):
    path = _write(tmp_path, "c.yaml", "study: mcps-stationary\nalpha: [0.05, 0.2]\nmf: none\n")
    code, out, err = cli("compare", path, "--set", "tire.k_delta=0.001", "--out", tmp_path / "o")
    assert code == 1
    assert "did not converge" in err and "k_delta" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o" / "run.json").exists() and not (tmp_path / "o" / "data" / "stationary.csv").exists()


def test_wrong_command_and_help(cli, tmp_path):
    path = _write(tmp_path, "c.yaml", "study: mcps-standstill\n")
    code, out, err = cli("compare", path)
    assert code == 2 and "tirecli simulate" in err
    code, out, err = cli("simulate", _write(tmp_path, "d.yaml", "study: mcps-stationary\nkappa: [0.1]\n"))
    assert code == 2 and "tirecli compare" in err
    code, out, err = cli("compare", "--help")
    assert code == 0 and "Magic Formula" in out
    code, out, err = cli("--help")
    assert "compare" in out


def test_params_show_lists_units_and_flags_assumed(cli):
    code, out, err = cli("params", "show", "sorine2000-mcps")
    assert code == 0
    assert "N/m^3" in out and "N m/rad" in out and out.count("[ASSUMED]") == 26
    code, out, err = cli("params", "list")
    assert "sorine2000-mcps" in out and "mcps-simple-mf" in out


def test_report_mcps_section_strict(cli, tmp_path):
    code, out, err = cli("--quiet", "report", "--out", tmp_path, "--only", "MCPS", "--strict")
    assert code == 0, out + err
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["n_failed"] == 0 and summary["n_checks"] >= 70
    html = (tmp_path / "index.html").read_text()
    for fid in ("mcps-fig3", "mcps-fig4", "mcps-fig5", "mcps-fig7", "mcps-fig8", "mcps-fig9", "mcps-fig10", "mcps-fig11",
                "mcps-relaxation", "mcps-calibration", "mcps-table", "mcps-fig1-2", "mcps-fig6"):
        assert f'id="{fid}"' in html
    assert "../shared" not in html and "mcps_tire.md" in html
    ids = {c["id"] for c in summary["checks"]}
    for cid in ("mcps-relaxation/rigid-63", "mcps-relaxation/rigid-99", "mcps-relaxation/complete-hump",
                "mcps-relaxation/complete-dip", "mcps-relaxation/complete-steady", "mcps-relaxation/complete, twist locked-63",
                "mcps-fig5/mz-minus-A", "mcps-fig5/max-mz", "mcps-fig4/first-cycle", "mcps-fig3/peak-force",
                "mcps-fig7/fx-0.12", "mcps-fig8/fy-12deg", "mcps-fig9/mz-peak", "mcps-fig10/fy-a4-k0.05",
                "mcps-fig11/rigid-fy-0.1", "mcps-calibration/fx-target", "mcps-calibration/fy-target",
                "mcps-calibration/mz-peak-target", "mcps-fig7/stand-in-fx-complete-4000",
                "mcps-fig8/stand-in-fy-complete-4000", "mcps-fig9/stand-in-mz-complete-4000",
                "mcps-fig8/gap-fy-calibrated-4000", "mcps-fig10/gap-fy-complete-4000-4deg"):
        assert cid in ids, cid  # the paper's scenario runs its reference checks (none silently skipped)
    bounded = [c for c in summary["checks"] if c.get("bound")]
    assert bounded and "&le;" in html


def test_yaml_blocks_of_the_mcps_guide_validate(cli, tmp_path):
    """Every config or parameter-set block of docs/models/mcps_tire.md passes 'tirecli params validate'."""
    import re
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "docs" / "models" / "mcps_tire.md").read_text()
    blocks = [b for b in re.findall(r"```yaml\n(.*?)```", text, re.S) if "study:" in b or "kind:" in b]
    assert len(blocks) >= 5
    for i, b in enumerate(blocks):
        code, out, err = cli("params", "validate", _write(tmp_path, f"b{i}.yaml", b))
        assert code == 0, (b, err)
