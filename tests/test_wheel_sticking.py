"""A locked wheel at the brake release: Filippov sticking at omega = 0, no lock/unlock chattering.

The wheel leaves omega = 0 only when the rolling wheel's speed actually rises (the brake's holding
margin crosses 0 downwards); a state on the switching surface from which the rolling wheel would
turn backwards stays locked. Before this was handled, a few per cent of the FM Monte Carlo
brakings (examples/campaign-fm-fig4-mc.yaml: the wheel locked until the linear release) looped in
zero-length lock/unlock steps at one time until the step budget ran out.
"""
import numpy as np
import pytest

from tirecli.models.lugre import LuGreParams
from tirecli.models.profiles import Constant
from tirecli.models.vehicle import QuarterCarParams
from tirecli.numerics.lumped import LumpedStepper
from tirecli.numerics.ros2 import integrate

from conftest import EXAMPLES

#: Campaign points (tire.sigma0, tire.mu_c, tire.mu_s, tire.v_s, input.theta) that looped: points 37 of
#: the campaign at n = 200 and 450, 946 at n = 1000 (the last two also after a first, partial fix).
LOOPED = [
    (185.35320389202235, 0.8320391013146566, 1.3752717671909014, 5.472809362542209, 0.6893842327725694),
    (180.38009950924217, 0.7138301399069855, 1.4107877796145174, 4.904911298159041, 0.9625698246117649),
    (185.49562199615374, 0.7870924035432664, 1.619840330293108, 5.250887167342815, 0.8477625483208421),
]
KEYS = ("tire.sigma0", "tire.mu_c", "tire.mu_s", "tire.v_s", "input.theta")


@pytest.mark.parametrize("point", LOOPED)
def test_fm_campaign_brakings_lock_once_and_release(point):
    """The campaign's braking at points that looped: one lock, released during the brake release, in
    as many steps as any other braking of the campaign (about 800); v never increases, omega never < 0,
    and while locked the brake holds the tire torque."""
    from tirecli.campaign.spec import load_campaign, point_config
    from tirecli.studies.registry import run_study

    c = load_campaign(EXAMPLES / "campaign-fm-fig4-mc.yaml")
    values = tuple(point[KEYS.index(k)] for k in c.design.keys)
    res = run_study(point_config(c.base, c.fixed + c.point_overrides(values)))   # as the campaign runs it
    tr = res.payload["runs"]["braking"]
    car = res.payload["car"]
    assert tr.events["reason"] == "t_end"
    assert tr.stats["steps"] < 1500 and tr.stats["rejected"] < 100
    (t_lock, t_unlock), = tr.events["lock"]                 # one lock: no chattering
    assert 0.5 < t_lock < 2.0 < t_unlock < 2.6               # locked under pressure, released during the release
    v, omega = tr.y[:, 0], tr.y[:, 1]
    assert np.all(np.diff(v) <= 1e-12) and np.all(omega >= 0.0)
    locked = (tr.t > t_lock) & (tr.t < t_unlock)
    assert np.all(omega[locked] == 0.0) and np.all(tr.out["locked"][locked] == 1.0)
    F = tr.out["mu"] * car.F_n
    assert np.all(-car.r * F[locked] <= tr.out["brake_torque"][locked] + 1e-6)
    # at the unlock the brake torque has fallen to the tire torque (to the solution's accuracy: tol in mu)
    k = int(np.searchsorted(tr.t, t_unlock))
    assert abs(tr.out["brake_torque"][k] + car.r * F[k]) < car.r * car.F_n * 2e-3
    # after it the wheel spins up to rolling: the slip is back near 0 at the end (no brake)
    assert abs(tr.out["slip"][-1]) < 0.05


def _sticking_start(eps):
    """A locked wheel at 10 m/s under a constant brake torque that holds at any speed (1.2 r F_n mu_s),
    with the bristles over-deflected so that the holding margin is ``-eps`` [N m] and rising: the
    rolling wheel would turn backwards at once (omega'' < 0), so the wheel must stay locked."""
    p = LuGreParams(sigma0=180.0, sigma1=1.0, sigma2=0.0, mu_c=0.8, mu_s=1.5, v_s=5.5, L=0.2, alpha=2.0,
                    kappa0=2.0, sigma_w=1.0)
    car = QuarterCarParams(r=0.25, m=350.0, J=0.234375, F_n=3500.0)
    v = 10.0
    tb = 1.2 * car.r * car.F_n * p.mu_s
    g = p.mu_c + (p.mu_s - p.mu_c) * np.exp(-(v / p.v_s) ** 2)
    a = p.sigma0 * v / g                                   # bristle decay at omega = 0 (kappa term 0)
    # mu = sigma0 z + sigma1 (vr - a z) + sigma2 vr at vr = -v, solved for r F_n mu + T_b = -eps
    mu = -(tb + eps) / (car.r * car.F_n)
    z = (mu + (p.sigma1 + p.sigma2) * v) / (p.sigma0 - p.sigma1 * a)
    st = LumpedStepper(p, car, 2.0, Constant(-tb).at, Constant(1.0).at, tol=1e-3)
    return st, [v, 0.0, z]


@pytest.mark.parametrize("eps", [1e-9, 1e-3, 1.0])
def test_state_on_the_switching_surface_sticks(eps):
    st, y0 = _sticking_start(eps)
    margin0 = st.lock_margin(0.0, y0)
    assert -2 * eps < margin0 < 0.0                         # the brake 'does not hold' by eps ...
    assert st.lock_margin(1e-6, st.attempt(st.start(0.0, y0, 1), 1e-6)[0]) > margin0   # ... but the margin rises
    tr = integrate(st, y0, 0.0, 0.5, tol=1e-3, h_max=0.05, max_steps=5000)
    assert tr.events["lock"] == [[0.0, None]]               # locked throughout, one event
    assert np.all(tr.y[:, 1] == 0.0) and tr.stats["steps"] < 200
    assert np.all(np.diff(tr.y[:, 0]) < 0.0)
