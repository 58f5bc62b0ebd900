"""Magic Formula identities (docs/models/magic_formula_tyre.md §5, §6, §13.1, §15.5, §2.4, §11) and robustness."""
from dataclasses import replace

import numpy as np
import pytest

from tirecli.models.magic_formula import evaluate, iso_to_sae
from tirecli.models.magic_formula.pure import pure_slip_factors
from tirecli.parameters.mf import builtin_tire_names, load_builtin_tire_data, read_tire_data

from conftest import ROOT

MF_TIRES = ["pacejka2006-205-60r15", "externdata-205-60r15", "mfeval-255-55r20", "chrono-185-80r14"]


@pytest.fixture(scope="module", params=MF_TIRES)
def tire(request):
    return load_builtin_tire_data(request.param).tire()


def test_builtin_tires_listed():
    assert set(MF_TIRES) <= set(builtin_tire_names())


@pytest.mark.parametrize("convention", ["mfeval", "teasit"])
def test_no_nan_over_the_ranges(tire, convention):
    lo, hi = tire.range("fz")
    hi = hi if np.isfinite(hi) else 2.5 * tire["FNOMIN"]
    fz = np.linspace(max(lo, 1.0), hi, 6)[:, None, None, None]
    k = np.linspace(*[x if np.isfinite(x) else np.sign(x) for x in tire.range("kappa")], 31)[None, :, None, None]
    a = np.linspace(*[x if np.isfinite(x) else 0.4 * np.sign(x) for x in tire.range("alpha")], 31)[None, None, :, None]
    g = np.linspace(*[x if np.isfinite(x) else 0.1 * np.sign(x) for x in tire.range("gamma")], 5)[None, None, None, :]
    r = evaluate(tire, k, a, g, fz, convention=convention)
    for name, v in r.as_dict().items():
        assert v.shape == (6, 31, 31, 5)
        assert np.isfinite(v).all(), f"{name} has non-finite values"
    # unloaded tyre: no force
    z = evaluate(tire, k, a, g, 0.0, convention=convention)
    assert np.isfinite(z.fx).all() and np.abs(z.fx).max() < 1e-9 and np.abs(z.fy).max() < 1e-9


def test_zero_slip_equals_shifts(tire):
    """F_x0(kappa = -S_Hx) = S_Vx and F_y0(alpha = -S_Hy) = S_Vy (§15.5); G = 1 there (§6)."""
    for fz in (0.5 * tire["FNOMIN"], tire["FNOMIN"], 1.7 * tire["FNOMIN"]):
        f = pure_slip_factors(tire, fz)
        r = evaluate(tire, -f["fx"]["SH"], 0.0, 0.0, fz, limits=False, outputs=("fx",))
        assert r.fx == pytest.approx(f["fx"]["SV"], abs=1e-9 * fz)
        r = evaluate(tire, 0.0, -f["fy"]["SH"], 0.0, fz, limits=False, outputs=("fy",))
        assert r.fy == pytest.approx(f["fy"]["SV"], abs=1e-9 * fz)


def test_slope_at_zero_slip_is_the_stiffness(tire):
    """dF_x0/dkappa at kappa_x = 0 is K_xk and dF_y0/dalpha at alpha_y = 0 is K_ya (§5, §13.1: BCD)."""
    h = 1e-7
    for fz in (0.6 * tire["FNOMIN"], tire["FNOMIN"]):
        f = pure_slip_factors(tire, fz)
        sh = f["fx"]["SH"]
        fx = evaluate(tire, np.array([-sh - h, -sh + h]), 0.0, 0.0, fz, limits=False, outputs=("fx",)).fx
        assert (fx[1] - fx[0]) / (2 * h) == pytest.approx(f["fx"]["K"], rel=1e-5)
        assert f["fx"]["B"] * f["fx"]["C"] * f["fx"]["D"] == pytest.approx(f["fx"]["K"], rel=1e-6)
        sh = f["fy"]["SH"]
        fy = evaluate(tire, 0.0, np.array([-sh - h, -sh + h]), 0.0, fz, limits=False, outputs=("fy",)).fy
        assert (fy[1] - fy[0]) / (2 * h) == pytest.approx(f["fy"]["K"], rel=1e-5)


def _symmetric(t):
    """The tyre with every shift and asymmetry term set to zero (§15.5: then Fx0, Fy0 are odd)."""
    zero = ["PHX1", "PHX2", "PVX1", "PVX2", "PEX4", "PHY1", "PHY2", "PHY3", "PVY1", "PVY2", "PEY3", "RHX1",
            "RHY1", "RHY2", "RVY1", "RVY2", "RVY3", "QHZ1", "QHZ2", "QDZ6", "QDZ7", "QEZ4", "SSZ1", "SSZ2",
            "RBY3"]
    return replace(t, coef={**t.coef, **{k: 0.0 for k in zero}})


@pytest.mark.parametrize("convention", ["mfeval", "teasit"])
def test_odd_symmetry_without_shifts(tire, convention):
    t = _symmetric(tire)
    k = np.linspace(0.0, 0.8, 17)
    a = np.linspace(0.0, 0.3, 13)[:, None]
    p = evaluate(t, k, a, 0.0, limits=False, convention=convention)
    m = evaluate(t, -k, -a, 0.0, limits=False, convention=convention)
    scale = t["FNOMIN"]
    assert np.abs(p.fx + m.fx).max() < 1e-9 * scale
    assert np.abs(p.fy + m.fy).max() < 1e-9 * scale
    assert np.abs(p.mz + m.mz).max() < 1e-9 * scale
    # pure slip: Fx odd in kappa at alpha = 0, Fy odd in alpha at kappa = 0
    assert np.abs(p.fx[0] + m.fx[0]).max() < 1e-9 * scale


def test_peak_is_d(tire):
    """The peak of |F_x0 - S_Vx| is |D_x| when C_x > 1 (§13.1, §15.5)."""
    f = pure_slip_factors(tire, tire["FNOMIN"])["fx"]
    assert f["C"] > 1
    k = np.linspace(-1.0, 1.0, 200001)
    fx = evaluate(tire, k, 0.0, 0.0, limits=False, outputs=("fx",)).fx
    assert np.abs(fx - f["SV"]).max() == pytest.approx(abs(f["D"]), rel=1e-7)


def test_mirroring_identities(tire):
    """Other side (§2.4): Fy(a, g) = -Fy_file(-a, -g), Fx(a, g) = Fx_file(-a, -g); Mx, Mz flip, My not."""
    if tire.side == "unknown":
        tire = replace(tire, side="left")
    other = "right" if tire.side == "left" else "left"
    k = np.array([-0.2, 0.0, 0.05, 0.3])[:, None]
    a = np.array([-0.2, -0.05, 0.0, 0.1])
    g = 0.03
    mir = evaluate(tire, k, a, g, side=other)
    ref = evaluate(tire, k, -a, -g, side=tire.side)
    assert mir.mirrored and not ref.mirrored
    np.testing.assert_array_equal(mir.fx, ref.fx)
    np.testing.assert_array_equal(mir.fy, -ref.fy)
    np.testing.assert_array_equal(mir.mz, -ref.mz)
    np.testing.assert_array_equal(mir.mx, -ref.mx)
    np.testing.assert_array_equal(mir.my, ref.my)
    same = evaluate(tire, k, a, g, side=tire.side)
    np.testing.assert_array_equal(same.fy, evaluate(tire, k, a, g).fy)


def test_iso_sae_conversion_is_an_involution():
    v = dict(fx=1.0, fy=2.0, fz=3.0, mx=4.0, my=5.0, mz=6.0, alpha=0.1)
    sae = iso_to_sae(**v)
    assert (sae["fx"], sae["fy"], sae["fz"], sae["mx"], sae["my"], sae["mz"], sae["alpha"]) == (1, -2, -3, 4, -5, -6, -0.1)
    back = iso_to_sae(**{k: float(x) for k, x in sae.items()})
    assert {k: float(x) for k, x in back.items()} == v


def test_iso_signs(tire):
    """ISO-W (§2.2): alpha > 0 gives Fy < 0 and (small alpha) Mz > 0; braking Fx < 0; My < 0 rolling."""
    r = evaluate(tire, np.array([-0.1, 0.1, 0.0]), np.array([0.0, 0.0, 0.03]), 0.0)
    assert r.fx[0] < 0 < r.fx[1]
    assert r.fy[2] < 0 and r.mz[2] > 0
    assert (r.my < 0).all()
    cam = evaluate(tire, 0.0, 0.0, np.array([-0.03, 0.03]))
    assert cam.fy[1] < cam.fy[0]  # camber thrust towards -y for gamma > 0


def test_broadcasting_blocks_and_threads_do_not_change_results(tire):
    rng = np.random.default_rng(1)
    n = 5003
    args = (rng.uniform(-0.5, 0.5, n), rng.uniform(-0.3, 0.3, n), rng.uniform(-0.05, 0.05, n),
            rng.uniform(0.3, 1.8, n) * tire["FNOMIN"])
    one = evaluate(tire, *args, threads=1, block=1 << 20)
    many = evaluate(tire, *args, threads=3, block=257)
    for k in ("fx", "fy", "mz", "mx", "my"):
        np.testing.assert_array_equal(getattr(one, k), getattr(many, k))
    s = evaluate(tire, 0.1, 0.02, 0.0)
    assert s.fx.shape == () and np.isfinite(s.fx)
    grid = evaluate(tire, np.zeros((3, 1)), np.zeros((1, 4)), 0.0, np.full((2, 1, 1), tire["FNOMIN"]))
    assert grid.fy.shape == (2, 3, 4)


def test_limits_clip_and_count():
    t = load_builtin_tire_data("externdata-205-60r15").tire()  # ALPMAX 0.5, KPUMAX 1, FZMAX 10000
    r = evaluate(t, np.array([0.5, 1.0, 3.0]), np.array([0.2, 0.5, 0.9]), 0.0, np.array([4000, 4000, 20000.0]))
    assert r.counts["kappa"] == 1 and r.counts["alpha"] == 1 and r.counts["fz"] == 1
    edge = evaluate(t, 1.0, 0.5, 0.0, 10000.0)
    assert r.fx[2] == edge.fx and r.fy[2] == edge.fy
    free = evaluate(t, np.array([3.0]), np.array([0.9]), 0.0, 20000.0, limits=False)
    assert not any(free.counts.values()) and free.fx[0] != edge.fx


def test_low_speed_handling():
    t = load_builtin_tire_data("externdata-205-60r15").tire()  # VXLOW = 1 m/s
    v = np.array([0.0, 0.5, 1.0, 5.0])
    r = evaluate(t, 0.1, 0.1, 0.0, vx=v)
    assert r.counts["low_speed"] == 3
    assert r.fx[0] == 0.0 and r.fy[0] == 0.0 and r.my[0] == 0.0  # standstill: no slip, no rolling resistance
    assert abs(r.fx[1]) < abs(r.fx[3])
    off = evaluate(t, 0.1, 0.1, 0.0, vx=v, low_speed=False)
    assert "low_speed" not in off.counts and off.fx[1] == off.fx[3]


def test_turn_slip_zero_spin_is_the_plain_model():
    t = load_builtin_tire_data("mfeval-255-55r20").tire()
    k = np.linspace(-0.2, 0.2, 9)[:, None]
    a = np.linspace(-0.2, 0.2, 7)
    plain = evaluate(t, k, a, 0.0, limits=False)
    ts = evaluate(t, k, a, 0.0, phit=0.0, limits=False)
    for name in ("fx", "fy", "mz"):
        np.testing.assert_allclose(getattr(ts, name), getattr(plain, name), rtol=1e-12, atol=1e-9)


def test_turn_slip_camber_sign_matches_the_plain_model():
    """With phi_t = 0 the camber part of the spin gives camber thrust of the same sign and about the
    same size as the model without turn slip (the book's spin sign, §8)."""
    t = load_builtin_tire_data("mfeval-255-55r20").tire()
    g = np.array([-0.02, 0.02])
    plain = evaluate(t, 0.0, 0.0, g, limits=False).fy
    ts = evaluate(t, 0.0, 0.0, g, phit=0.0, limits=False).fy
    d_plain, d_ts = plain[1] - plain[0], ts[1] - ts[0]
    assert np.sign(d_plain) == np.sign(d_ts) == -1
    assert 0.5 < d_ts / d_plain < 2.0
    # a curvature response: Fy changes with phi_t at zero slip and camber (MCPS fig., docs/models/magic_formula_tyre.md §16)
    r = evaluate(t, 0.0, 0.0, 0.0, phit=np.array([-0.1, 0.1]), limits=False)
    assert np.isfinite(r.fy).all() and r.fy[0] != r.fy[1]


def test_turn_slip_refused_for_mf52():
    t = load_builtin_tire_data("chrono-185-80r14").tire()
    with pytest.raises(ValueError, match="turn slip"):
        evaluate(t, 0.0, 0.0, 0.0, phit=0.1)


def test_pac89_form():
    """PAC89 (§13.2): BCD is the slope at x = -SH (in its units), D the peak; ISO signs of Chrono."""
    from tirecli.models.magic_formula.pac89 import factors

    t = read_tire_data(ROOT / "tests" / "data" / "tir" / "pac89-hmmwv.tir").tire()
    assert t.version == "pac89"
    fz = 5000.0
    f = factors(t, fz)
    h = 1e-6
    fx = evaluate(t, np.array([-h, h]) / 100.0, 0.0, 0.0, fz, outputs=("fx",)).fx  # kappa in %: x = 100 kappa
    assert (fx[1] - fx[0]) / (2 * h) == pytest.approx(f["fx"]["B"] * f["fx"]["C"] * f["fx"]["D"], rel=1e-6)
    k = np.linspace(-1, 1, 40001)
    assert np.abs(evaluate(t, k, 0.0, 0.0, fz).fx).max() == pytest.approx(f["fx"]["D"], rel=1e-6)
    r = evaluate(t, 0.0, np.radians([2.0]), 0.0, fz)
    assert r.fy[0] < 0 and r.mz[0] > 0 and r.mx[0] == 0 and r.my[0] == 0


def test_effective_rolling_radius():
    from tirecli.models.magic_formula.radius import effective_rolling_radius

    t = load_builtin_tire_data("mfeval-255-55r20").tire()
    re, om = effective_rolling_radius(t, np.array([2000.0, 6752.0, 12000.0]), 0.0, 16.6)
    assert (np.diff(re) < 0).all() and (re < t["UNLOADED_RADIUS"]).all() and (re > 0.3).all()
    assert np.allclose(om * re, 16.6)  # kappa = 0: Omega R_e = Vx


def test_uncombined_equals_combined_at_zero_cross_slip(tire):
    k = np.linspace(-0.4, 0.4, 9)
    a = np.linspace(-0.2, 0.2, 7)
    pure = evaluate(tire, k[:, None], a, 0.01, combined=False, outputs=("fx", "fy"))
    fx_a0 = evaluate(tire, k, 0.0, 0.01, outputs=("fx",)).fx
    fy_k0 = evaluate(tire, 0.0, a, 0.01, outputs=("fy",)).fy
    np.testing.assert_array_equal(pure.fx, np.broadcast_to(fx_a0[:, None], pure.fx.shape))
    np.testing.assert_array_equal(pure.fy, np.broadcast_to(fy_k0, pure.fy.shape))
