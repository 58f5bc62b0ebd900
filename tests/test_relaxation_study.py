"""The relaxation comparison (study ``relaxation``, figure ``relaxation-compare``): the transient Magic
Formula, MCPS and the distributed LuGre tire after slip steps, against closed forms."""
import math

import numpy as np
import pytest

from tirecli.errors import ConfigError


@pytest.fixture(scope="module")
def result():
    import tirecli

    return tirecli.run({"study": "relaxation", "figures": ["relaxation-compare"]})


def test_every_check_passes_and_the_facts_carry_units(result):
    from tirecli.studies.facts import fact_unit
    from tirecli.studies.registry import get

    assert result.checks and all(c.status == "passed" for c in result.checks), [c for c in result.checks if c.status != "passed"]
    ids = {c.id.split("/")[-1] for c in result.checks}
    assert {"mf-lag-kappa", "mf-lag-alpha", "mcps-alpha-rigid-63", "mcps-alpha-complete-95", "mcps-kappa-exact-rigid",
            "lugre-closed-form"} <= ids
    f = result.facts
    for step, models in (("kappa", ("mf", "mcps-rigid", "mcps-complete", "lugre")), ("alpha", ("mf", "mcps-rigid", "mcps-complete"))):
        for m in models:
            assert f"s63_m[{step}, {m}]" in f and f"s95_m[{step}, {m}]" in f
    assert "s63_m[alpha, lugre]" not in f  # LuGre is longitudinal only
    assert fact_unit(get("relaxation"), "s95_m[kappa, mf]") == "m"


def test_the_magic_formula_state_follows_the_first_order_lag(result):
    """The slip state reaches 63.2 % after one relaxation length: sigma from the PTX/PTY of the .tir
    (externdata-205-60r15 at Fz = FNOMIN: sigma_kappa = PTX1 R0, sigma_alpha = PTY1 sin(2 atan(1/PTY2)) R0)."""
    f = result.facts
    r0 = 0.3135
    assert f["sigma_m[kappa, mf]"] == pytest.approx(1.98 * r0, rel=1e-12)
    assert f["sigma_m[alpha, mf]"] == pytest.approx(1.8 * math.sin(2 * math.atan(1 / 1.8)) * r0, rel=1e-12)
    df = result.frames["relaxation"]
    g = df[(df.step == "kappa") & (df.model == "mf")]
    s63 = np.interp(1 - math.exp(-1), g.slip_state.to_numpy() / 0.02, g.s.to_numpy())
    assert s63 == pytest.approx(f["sigma_m[kappa, mf]"], abs=1e-5)
    # the force saturates: it gets to 63.2 % and 95 % before the state
    assert f["s63_m[kappa, mf]"] < f["state_s63_m[kappa, mf]"] and f["s95_m[alpha, mf]"] < f["state_s95_m[alpha, mf]"]


def test_the_gaps_are_stated_against_the_magic_formula(result):
    f = result.facts
    assert f["gap_s95_m[alpha, mcps-complete]"] == pytest.approx(f["s95_m[alpha, mcps-complete]"] - f["s95_m[alpha, mf]"])
    assert 0 < f["gap_rms[kappa, lugre]"] <= f["gap_max[kappa, lugre]"]
    table = result.frames["relaxation_distances"]
    assert len(table) == 7 and set(table.model) == {"mf", "mcps-rigid", "mcps-complete", "lugre"}


def test_distances_first_and_settled():
    from tirecli.studies.relaxation import distances

    s = np.linspace(0, 1, 101)
    assert distances(s, 1 - np.exp(-s / 0.1), 0.95) == pytest.approx((0.1 * math.log(20),) * 2, abs=2e-4)
    over = np.where(s < 0.5, 1.3 - 0.6 * s, 1.0)          # starts above, falls into the band at s = 0.5/0.6 * 0.25
    first, settled = distances(s, over, 0.95)
    assert first == 0.0 and settled == pytest.approx(0.25 / 0.6, abs=1e-9)
    assert distances(s, 0.5 * s, 0.95) == (None, None)


def test_lugre_closed_form():
    """FM eq. (4) once every element entered after the step; the damping terms at once at the step; zdot the
    derivative of zbar."""
    from tirecli.models.lugre import mu_ss_uniform
    from tirecli.models.lugre_pde import uniform_step_response
    from tirecli.parameters.sets import load_set

    p = load_set("canudas2003-table1").model()
    vr, romega = -0.9, 17.1
    T = p.L / romega
    t = np.linspace(0, 2 * T, 2001)
    mu, z, zd = uniform_step_response(t, vr, romega, p)
    assert mu[0] == pytest.approx((p.sigma1 + p.sigma2) * vr, rel=1e-12)
    assert np.allclose(mu[t >= T], mu_ss_uniform(vr, romega, p), rtol=1e-12, atol=0)
    assert np.allclose(np.gradient(z, t)[5:900], zd[5:900], rtol=1e-4, atol=1e-9)


def test_rigid_step_exact_generalises_the_slip_angle_solution():
    from tirecli.numerics.mcps_transient import rigid_relaxation_exact, rigid_step_exact
    from tirecli.parameters.sets import load_set

    p = load_set("sorine2000-mcps").model()
    s = np.linspace(0, 0.3, 31)
    fx, fy, mz = rigid_step_exact(p, 4000.0, 0.0, math.tan(0.02), s)
    fy2, mz2 = rigid_relaxation_exact(p, 4000.0, 0.02, s)
    assert np.array_equal(fy, fy2) and np.array_equal(mz, mz2) and not fx.any()
    # braking (sx > 0: the sliders move forwards on the road) gives a negative Fx; the sign flips with the slip
    fxb, fyb, _ = rigid_step_exact(p, 4000.0, 0.01, 0.0, s)
    fxd, _, _ = rigid_step_exact(p, 4000.0, -0.01, 0.0, s)
    assert fxb[-1] < 0 and np.allclose(fxd, -fxb) and not fyb.any()


@pytest.mark.parametrize("extra, key", [("kappa: 0\n", "kappa"), ("alpha: 0\n", "alpha"), ("mf: simple\n", "mf"),
                                        ("sigma_source: version\n", "sigma_source"), ("speed: 0\n", "speed")])
def test_bad_configs_are_refused_at_their_key(tmp_path, extra, key):
    from tirecli.config.loader import load_config
    from tirecli.studies.registry import plan

    cfg = tmp_path / "r.yaml"
    cfg.write_text("study: relaxation\n" + extra)
    with pytest.raises(ConfigError) as err:
        plan(load_config(cfg))
    assert f"r.yaml:2: {key}" in str(err.value)
    if key == "sigma_source":
        assert "LONGITUDINAL_STIFFNESS and LATERAL_STIFFNESS" in str(err.value)


def test_auto_picks_the_rule_the_file_can_give():
    from tirecli.config.loader import config_from_mapping
    from tirecli.studies.registry import plan

    own = plan(config_from_mapping({"study": "relaxation", "mf": "mfeval-255-55r20"}))
    forced = plan(config_from_mapping({"study": "relaxation"}))
    assert (own.detail.rule, forced.detail.rule) == ("stiffness", "pt")
    assert "forced" in forced.detail.rule_note and "as mfeval" in own.detail.rule_note
