"""Root-found peaks of steady-state curves (data/peaks.csv) against an independent reference.

The reference is written here from the closed forms (FM eq. (4), eq. (6), the parabolic load
integrated in closed form, the lumped eqs. (8)-(9)) and differentiated by complex step (exact to
rounding, no subtractive cancellation); its zero is found by brentq to 1e-15. The code under test
uses its own analytic slope and bisection, so the two share no code path.
"""
import json

import numpy as np
import pandas as pd
import pytest
from dataclasses import replace
from scipy.optimize import brentq

from conftest import EXAMPLES

from tirecli.models import lugre
from tirecli.models.steady_peaks import abs_mu, abs_mu_slope, curve_peaks
from tirecli.models.variants import FrictionVariant as FV


# --------------------------------------------------------------------------- the reference


def _shape(kind, x, k=None):
    """Closed-form shapes S(x), complex-safe."""
    if kind == "uniform":
        return 1 - (1 - np.exp(-x)) / x
    if kind == "exponential":
        return 1 - k * (1 - np.exp(-(k + x))) / ((k + x) * (1 - np.exp(-k)))
    if kind == "parabolic":  # 1 - int_0^1 6u(1-u) e^{-xu} du
        return 1 - 6 * (x - 2 + (x + 2) * np.exp(-x)) / x ** 3
    if kind == "lumped":
        return x / (x + k)
    raise ValueError(kind)


def ref_abs_mu(sig, p, speed, theta, braking, kind, k=None):
    """|mu| at |s| = sig (complex allowed): theta g S(x) + sigma2 |vr| (docs/models/lugre_friction.md §3.3, §4.2)."""
    a = speed * sig
    g = theta * (p.mu_c + (p.mu_s - p.mu_c) * np.exp(-(a / p.v_s) ** p.alpha))
    romega = speed * (1 - sig) if braking else speed
    x = p.sigma0 * a * p.L / (g * romega)
    return g * _shape(kind, x, k) + p.sigma2 * a


def ref_peak(p, speed, theta, braking, kind, k=None):
    """(|s|, |mu|) of the reference peak: complex-step slope, brentq to 1e-15 (None: no interior peak)."""
    h = 1e-30

    def slope(z):
        return float(np.imag(ref_abs_mu(complex(z, h), p, speed, theta, braking, kind, k)) / h)

    s = np.linspace(1e-3, 0.999, 2000)
    f = np.array([float(np.real(ref_abs_mu(z, p, speed, theta, braking, kind, k))) for z in s])
    tops = [j for j in range(1, len(s) - 1) if f[j - 1] <= f[j] > f[j + 1]]  # interior maxima: the highest
    if not tops:  # |mu| rises to full slide
        assert slope(0.999) > 0
        return None
    i = max(tops, key=lambda j: f[j])
    root = brentq(slope, s[i - 1], s[i + 1], xtol=1e-15, rtol=4 * np.finfo(float).eps)
    return root, float(np.real(ref_abs_mu(root, p, speed, theta, braking, kind, k)))


CASES = [  # (variant, reference kind, its parameter)
    (FV(), "uniform", None),
    (FV(model="lumped", kappa0="Z"), "uniform", None),       # kappa0(Z) equals eq. (4) exactly
    (FV(load="exponential", lam=2.0), "exponential", 2.0),
    (FV(load="parabolic"), "parabolic", None),
    (FV(model="lumped", kappa0=2.0), "lumped", 2.0),
    (FV(model="lumped", kappa0=1.0), "lumped", 1.0),
    (FV(model="lumped", load="exponential", lam=5.0), "lumped", 5.0),  # kappa = lambda/L
]


@pytest.mark.parametrize("alpha", [0.5, 1.0, 2.0])
@pytest.mark.parametrize("variant, kind, k", CASES, ids=lambda c: getattr(c, "label", None) or str(c))
def test_peak_matches_the_independent_reference(table1, variant, kind, k, alpha):
    p = replace(table1, alpha=alpha)
    for braking in (True, False):
        for speed, theta in ((7.0, 1.0), (20.0, 0.55), (33.0, 1.2)):
            pk = curve_peaks(variant, p, [speed], theta, braking)
            ref = ref_peak(p, speed, theta, braking, kind, k)
            if ref is None:  # no interior maximum: the peak is at full slide
                assert pk.at_slide[0] and pk.slip[0] == 1.0 and pk.mu[0] == pk.mu_slide[0]
                continue
            s_ref, mu_ref = ref
            assert not pk.at_slide[0]
            assert abs(pk.slip[0] - s_ref) < 1e-10, (speed, theta, braking)
            assert abs(pk.mu[0] - mu_ref) < 1e-12, (speed, theta, braking)
            slide = float(np.real(ref_abs_mu(1.0 - 1e-13, p, speed, theta, False, kind, k))) if not braking else None
            if slide is not None:  # driving at full slide: v = 0, r omega = speed (a finite x)
                assert pk.mu_slide[0] == pytest.approx(slide, abs=1e-11)


def test_slope_is_the_derivative_of_the_model_function(table1):
    """The analytic slope of every variant against central differences of mu_ss itself."""
    sig = np.array([1e-3, 0.02, 0.1, 0.3, 0.6, 0.95])
    h = 1e-6
    for var in [FV(), FV(load="exponential", lam=2.0), FV(load="parabolic"), FV(model="lumped", kappa0=2.0),
                FV(model="lumped", kappa0="Z"), FV(load="tabulated", u=(0, 0.3, 1), f=(1, 3, 0.5)),
                FV(load="exponential", lam=1e-10)]:
        for braking in (True, False):
            for p in (table1, replace(table1, alpha=0.5), replace(table1, alpha=2.0, sigma2=0.01)):
                fd = (abs_mu(var, p, sig + h, 15.0, 0.8, braking) - abs_mu(var, p, sig - h, 15.0, 0.8, braking)) / (2 * h)
                an = abs_mu_slope(var, p, sig, 15.0, 0.8, braking)
                assert np.max(np.abs(fd - an)) < 1e-7, (var.label, braking)


def test_h_slope_series_and_closed_form_agree():
    x = np.array([0.0, 1e-9, 1e-3, 0.05, 0.0999999, 0.1, 0.1000001, 1.0, 10.0, 1e3, np.inf])
    d = lugre.h_uniform_slope(x)
    assert d[0] == 0.5 and d[-1] == 0.0
    xx = x[1:-1]
    exact = np.array([float((1 - (1 + v) * np.exp(-v)) / v**2) if v > 0.5 else
                      sum((-1) ** (n + 1) * n * v ** (n - 1) / np.prod(np.arange(1, n + 2, dtype=float)) for n in range(1, 30))
                      for v in xx])
    assert np.allclose(d[1:-1], exact, rtol=1e-13, atol=0)


@pytest.mark.parametrize("v, peak, slip, mu1", [
    (5, 1.2818, 0.374, 1.1594), (10, 1.1770, 0.279, 0.9817), (15, 1.1074, 0.237, 0.9035),
    (20, 1.0552, 0.212, 0.8717), (25, 1.0137, 0.196, 0.8617), (30, 0.9795, 0.184, 0.8618),
])
def test_reference_values_of_the_spec(table1, v, peak, slip, mu1):
    """docs/models/lugre_friction.md §9 (printed to 4 and 3 decimals)."""
    pk = curve_peaks(FV(), table1, [v])
    assert pk.mu[0] == pytest.approx(peak, abs=5e-5)
    assert pk.slip[0] == pytest.approx(slip, abs=5e-4)
    assert pk.mu_slide[0] == pytest.approx(mu1, abs=5e-5)


def test_reference_values_driving_theta_and_table2(table1, table2):
    """docs/models/lugre_friction.md §5 and §9: driving, adhesion, Table 2 with alpha = 2, lumped kappa0 = 1, 2."""
    pk = curve_peaks(FV(), table1, [20.0], braking=False)
    assert (pk.mu[0], pk.slip[0], pk.mu_slide[0]) == pytest.approx((1.0166, 0.220, 0.8525), abs=5e-4)
    for th, (mu, s, m1) in {0.8: (0.8714, 0.187, 0.7046), 0.6: (0.6795, 0.159, 0.5374), 0.4: (0.4764, 0.128, 0.3703)}.items():
        pk = curve_peaks(FV(), table1, [20.0], th)
        assert (pk.mu[0], pk.slip[0], pk.mu_slide[0]) == pytest.approx((mu, s, m1), abs=5e-4)
    t2 = replace(table2, alpha=2.0)
    assert curve_peaks(FV(), t2, [15, 20, 25]).mu == pytest.approx([1.1247, 1.0549, 0.9970], abs=5e-5)
    # docs/models/lugre_friction.md prints 0.155 at 25 m/s; the root-found peak is 0.15448 (a grid value rounded up)
    assert curve_peaks(FV(), t2, [15, 20, 25]).slip == pytest.approx([0.206, 0.175, 0.1545], abs=5e-4)
    # sensitivity to the Stribeck exponent at 20 m/s (Table 1 alpha = 2: the reference 0.194 is 0.19347)
    for p, ref in ((replace(table1, alpha=0.5), (1.0231, 0.302)), (replace(table1, alpha=2.0), (1.1343, 0.1935)),
                   (replace(table2, alpha=0.5), (0.9748, 0.284)), (replace(table2, alpha=1.0), (0.9927, 0.199))):
        pk = curve_peaks(FV(), p, [20.0])
        assert (pk.mu[0], pk.slip[0]) == pytest.approx(ref, abs=5e-4)
    assert curve_peaks(FV(model="lumped", kappa0=2.0), t2, [15, 20, 25]).mu == pytest.approx([1.0268, 0.9530, 0.8945], abs=5e-5)
    assert curve_peaks(FV(model="lumped", kappa0=1.0), t2, [15, 20, 25]).mu == pytest.approx([1.1514, 1.0908, 1.0407], abs=5e-5)


def test_curves_without_an_interior_peak(table1):
    """Held speed 0: mu = 0, no peak. Very high speed: |mu| rises to full slide (sigma2 |vr|): peak at |s| = 1.
    60 m/s: an interior adhesion peak below the sliding level is still the peak."""
    pk = curve_peaks(FV(), table1, [0.0, 100.0, 60.0])
    assert np.isnan(pk.slip[0]) and pk.mu[0] == 0.0 and pk.mu_slide[0] == 0.0
    assert pk.at_slide[1] and pk.slip[1] == 1.0 and pk.mu[1] == pk.mu_slide[1]
    s = np.linspace(1e-4, 1, 20001)
    assert pk.mu_slide[1] >= abs_mu(FV(), table1, s, 100.0).max() - 1e-15
    assert not pk.at_slide[2] and pk.mu[2] < pk.mu_slide[2]
    s_ref, mu_ref = ref_peak(table1, 60.0, 1.0, True, "uniform")
    assert abs(pk.slip[2] - s_ref) < 1e-10 and abs(pk.mu[2] - mu_ref) < 1e-12


# --------------------------------------------------------------------------- the sweep's outputs


SWEEP = """\
study: sweep
tire: canudas2003-table1
sweep:
  slip: {start: -1, stop: 1, num: 21}
  speeds: [10, 20]
  theta: [1.0, 0.6]
  models:
    - distributed
    - {model: distributed, load: exponential, lambda: 2}
    - {model: lumped, kappa0: Z}
    - {model: lumped, kappa0: 1.5, label: k15}
    - {model: lumped, load: exponential, lambda: 5}
"""


@pytest.fixture(scope="module")
def sweep_run(tmp_path_factory):
    from tirecli.cli.main import main

    d = tmp_path_factory.mktemp("peaks")
    (d / "s.yaml").write_text(SWEEP)
    assert main(["--quiet", "sweep", str(d / "s.yaml"), "--out", str(d / "o")]) == 0
    return d / "o"


def test_peaks_csv_has_one_row_per_curve(sweep_run, table1):
    pk = pd.read_csv(sweep_run / "data" / "peaks.csv")
    assert list(pk.columns) == ["model", "variant", "load", "lambda", "kappa0", "direction", "speed", "theta",
                                "theta_obs", "slip_peak", "mu_peak", "mu_slide"]
    assert len(pk) == 5 * 2 * 2 * 2  # models x speeds x theta x directions
    assert not pk.duplicated(["model", "direction", "speed", "theta"]).any()
    # signed like the sweep: braking negative
    br = pk["direction"] == "braking"
    assert (pk.loc[br, ["slip_peak", "mu_peak", "mu_slide"]] < 0).all().all()
    assert (pk.loc[~br, ["slip_peak", "mu_peak", "mu_slide"]] > 0).all().all()
    # identifying columns
    row = pk[(pk["model"] == "k15")].iloc[0]
    assert row["variant"] == "lumped" and row["kappa0"] == "1.5" or float(row["kappa0"]) == 1.5
    assert set(pk.loc[pk["model"] == "lumped kappa0(Z)", "kappa0"]) == {"Z"}
    assert pk.loc[pk["variant"] == "distributed", "kappa0"].isna().all()
    lam = pk.loc[pk["load"] == "exponential", "lambda"]
    assert set(lam) == {2.0, 5.0} and pk.loc[pk["load"] != "exponential", "lambda"].isna().all()
    assert set(pk.loc[pk["model"] == "lumped kappa=lambda/L (lambda=5)", "kappa0"].astype(float)) == {5.0}
    # root-found, not the grid (the grid has a step of 0.1 in slip)
    r = pk[(pk["model"] == "distributed uniform") & (pk["speed"] == 20) & (pk["theta"] == 1.0) & br].iloc[0]
    s_ref, mu_ref = ref_peak(table1, 20.0, 1.0, True, "uniform")
    assert abs(-r["slip_peak"] - s_ref) < 1e-10 and abs(-r["mu_peak"] - mu_ref) < 1e-12
    assert -r["mu_slide"] == pytest.approx(0.8717, abs=5e-5)


def test_run_json_facts_hold_the_peaks(sweep_run):
    pk = pd.read_csv(sweep_run / "data" / "peaks.csv", keep_default_na=False)
    facts = json.loads((sweep_run / "run.json").read_text())["meta"]["facts"]
    rows = facts["peaks"]
    assert len(rows) == len(pk) and "peaks_note" in facts
    for rec, (_, row) in zip(rows, pk.iterrows()):
        assert rec["model"] == row["model"] and rec["direction"] == row["direction"]
        assert rec["slip_peak"] == float(row["slip_peak"]) and rec["mu_peak"] == float(row["mu_peak"])
        assert rec["mu_slide"] == float(row["mu_slide"])
        assert (rec["kappa0"] is None) == (row["kappa0"] == "")
        assert (rec["lambda"] is None) == (row["lambda"] == "")


def test_lumped_rows_carry_kappa0_and_Z(sweep_run, table1):
    df = pd.read_csv(sweep_run / "data" / "sweep.csv")
    assert list(df.columns)[-2:] == ["kappa0", "Z"]
    dist = df[df["model"].str.startswith("distributed")]
    assert dist["kappa0"].isna().all() and dist["Z"].isna().all()
    k15 = df[df["model"] == "k15"]
    assert (k15["kappa0"] == 1.5).all()
    z = df[df["model"] == "lumped kappa0(Z)"]
    inner = z[(z["slip"] != 0) & (z["slip"].abs() != 1) | (z["direction"] == "driving") & (z["slip"] != 0)]
    # Z = |r omega| theta g / (sigma0 |vr|), kappa0 = kappa0(L/Z) of FM eq. (10)
    vr = inner["romega"] - inner["v"]
    g = lugre.stribeck(vr, table1, inner["theta"])
    assert np.allclose(inner["Z"], inner["romega"].abs() * g / (table1.sigma0 * vr.abs()), rtol=1e-13)
    assert np.allclose(inner["kappa0"], lugre.kappa0_of_x(table1.L / inner["Z"]), rtol=1e-13)
    zero = z[z["slip"] == 0]
    assert np.isinf(zero["Z"]).all() and (zero["kappa0"] == 2.0).all()          # no slip: Z = inf, kappa0 = 2
    locked = z[(z["slip"] == -1)]
    assert (locked["Z"] == 0).all() and (locked["kappa0"] == 1.0).all()         # locked wheel: Z = 0, kappa0 = 1
    lam5 = df[df["model"] == "lumped kappa=lambda/L (lambda=5)"]
    assert (lam5["kappa0"] == 5.0).all()


def test_figures_mark_the_peaks(sweep_run):
    """Generic sweep figure: one peak marker per curve with the value in the legend, or markers and one
    legend entry when there are many curves."""
    from tirecli.config.loader import config_from_text
    from tirecli.figures.registry import get
    from tirecli.studies.registry import run_study

    few = config_from_text("study: sweep\ntire: canudas2003-table1\nsweep:\n  slip: {start: -1, stop: 0, num: 11}\n"
                           "  speeds: [10, 20]\n", label="<test>")
    fig = get("sweep-mu-slip").draw(run_study(few))
    ax = fig.axes[0]
    markers = [ln for ln in ax.get_lines() if ln.get_linestyle() == "None"]
    assert len(markers) == 2
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "v = 20 m/s: peak 1.0552 at |s| = 0.212" in texts and texts[-1].startswith("peak of each curve")
    (x,), (y,) = markers[1].get_data()
    assert (x, y) == pytest.approx((0.2121316507, 1.0552387337), abs=1e-9)  # not a grid point (step 0.1)


def test_paper_checks_use_the_root_found_peaks(cli, tmp_path):
    """FM Fig. 1 (left) on a grid of 21 slips still passes its peak checks (a grid peak would not)."""
    code, out, err = cli("sweep", EXAMPLES / "fm-fig1-left.yaml", "--out", tmp_path / "o",
                         "--set", "sweep.slip={start: -1, stop: 0, num: 21}")
    run = json.loads((tmp_path / "o" / "run.json").read_text())
    peaks = [c for c in run["checks"] if "/peak-" in c["id"] or "/speak-" in c["id"] or "/mu1-" in c["id"]]
    assert len(peaks) == 18 and all(c["passed"] for c in peaks), [c for c in peaks if not c["passed"]]
    pk = pd.read_csv(tmp_path / "o" / "data" / "peaks.csv")
    v20 = pk[pk["speed"] == 20].iloc[0]
    assert next(c for c in peaks if c["id"].endswith("speak-v20"))["value"] == -v20["slip_peak"]
